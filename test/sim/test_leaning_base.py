"""A free base that leans on its nose says so, and its lidar reads the floor it is tilted to.

The robot is a TurtleBot3-shaped rover described the gazebo_ros way: a massless
``base_footprint`` root, a fixed joint to ``base_link`` (a tall box reaching
ahead of the axle), two wheels under ``base_link``'s origin, a box caster
behind, no support ahead of the wheels, and a lidar link 0.12 m above
``base_link`` and 0.1 m ahead of it.  With its centre of mass ahead of the
axle it cannot stand on its wheels: it rests on the box's front edge, and a
level lidar on it meets the floor at its height / sin(tilt) -- the same
range wherever it drives, in any world.  That is physics (Gazebo tips it too);
what must not happen is that it goes unsaid.  With the centre of mass
behind the axle the same robot drives level and its lidar reads the wall.
"""

from __future__ import annotations

import logging
import math

import numpy
import pytest
import yaml

from pan_tilt_sim.controllers.framework.surface import StampedTwist
from pan_tilt_sim.model.world_file import read_world_file
from pan_tilt_sim.sim.engine import LEANING_TILT, TIPPED_TILT, make_simulation
from pan_tilt_sim.sim.entities import Entities, spawn_world_objects
from pan_tilt_sim.sim.sensors.lidar import Lidar

DT = 0.001  # s
FOOTPRINT_TO_BASE = 0.01  # m: base_link above base_footprint
LIDAR_ON_BASE = (0.1, 0.0, 0.12)  # m: lidar_link in base_link
LIDAR_MASS = 0.12  # kg
BODY_MASS = 0.8  # kg, base_link's
WALL_FACE = 2.0  # m: the wall's face, the plane x = WALL_FACE
# base_link's centre of mass (x in base_link, m): the robot's then lies ahead of the
# wheel axle (x = 0) or 2 cm behind it.
NOSE_HEAVY = 0.0
BALANCED = -0.045
RANGE = (0.12, 3.5)  # m, a TurtleBot3's


class Collector(logging.Handler):
    """The warnings a simulation logs."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.lines.append(record.getMessage())


def _inertia(value: float) -> str:
    return f'<inertia ixx="{value}" ixy="0" ixz="0" iyy="{value}" iyz="0" izz="{value}"/>'


def rover_urdf(body_com_x: float) -> str:
    """Return the rover, ``base_link``'s centre of mass ``body_com_x`` ahead of its origin."""
    wheels = ''.join(f'''
      <joint name="{side}_wheel_joint" type="continuous">
        <parent link="base_link"/><child link="{side}_wheel"/>
        <origin xyz="0 {y} 0.023"/><axis xyz="0 1 0"/>
      </joint>
      <link name="{side}_wheel">
        <collision><origin rpy="1.5707963 0 0"/>
          <geometry><cylinder radius="0.033" length="0.02"/></geometry></collision>
        <inertial><mass value="0.03"/>{_inertia(1e-5)}</inertial>
      </link>''' for side, y in (('left', 0.08), ('right', -0.08)))
    lidar = ' '.join(map(repr, LIDAR_ON_BASE))
    return f'''<?xml version="1.0"?>
    <robot name="leaning_rover">
      <link name="base_footprint"/>
      <joint name="base_joint" type="fixed">
        <parent link="base_footprint"/><child link="base_link"/>
        <origin xyz="0 0 {FOOTPRINT_TO_BASE}"/>
      </joint>
      <link name="base_link">
        <collision><origin xyz="-0.03 0 0.075"/>
          <geometry><box size="0.14 0.14 0.14"/></geometry></collision>
        <inertial><origin xyz="{body_com_x} 0 0"/><mass value="{BODY_MASS}"/>
          {_inertia(2e-3)}</inertial>
      </link>
      {wheels}
      <joint name="caster_joint" type="fixed">
        <parent link="base_link"/><child link="caster"/><origin xyz="-0.08 0 -0.005"/>
      </joint>
      <link name="caster">
        <collision><geometry><box size="0.03 0.02 0.01"/></geometry></collision>
        <inertial><mass value="0.005"/>{_inertia(1e-6)}</inertial>
      </link>
      <gazebo reference="caster"><mu1>0.1</mu1><mu2>0.1</mu2></gazebo>
      <joint name="lidar_joint" type="fixed">
        <parent link="base_link"/><child link="lidar_link"/><origin xyz="{lidar}"/>
      </joint>
      <link name="lidar_link">
        <inertial><mass value="{LIDAR_MASS}"/>{_inertia(1e-4)}</inertial>
      </link>
      <gazebo reference="lidar_link">
        <sensor type="ray" name="lidar"><update_rate>5</update_rate>
          <ray><scan><horizontal><samples>360</samples><resolution>1</resolution>
            <min_angle>0</min_angle><max_angle>6.28</max_angle></horizontal></scan>
            <range><min>{RANGE[0]}</min><max>{RANGE[1]}</max></range></ray>
          <plugin name="scan" filename="libgazebo_ros_ray_sensor.so">
            <ros><remapping>~/out:=scan</remapping></ros>
            <output_type>sensor_msgs/LaserScan</output_type>
          </plugin>
        </sensor>
      </gazebo>
      <gazebo>
        <plugin name="diff_drive" filename="libgazebo_ros_diff_drive.so">
          <left_joint>left_wheel_joint</left_joint><right_joint>right_wheel_joint</right_joint>
          <wheel_separation>0.16</wheel_separation><wheel_diameter>0.066</wheel_diameter>
          <max_wheel_torque>20</max_wheel_torque>
          <odometry_frame>odom</odometry_frame><robot_base_frame>base_footprint</robot_base_frame>
        </plugin>
        <plugin name="joint_states" filename="libgazebo_ros_joint_state_publisher.so">
          <joint_name>left_wheel_joint</joint_name><joint_name>right_wheel_joint</joint_name>
        </plugin>
      </gazebo>
    </robot>'''


def _world(tmp_path):
    path = tmp_path / 'wall.yaml'
    path.write_text(yaml.safe_dump({'scenery': 'ground', 'entities': [
        {'name': 'wall', 'shape': 'box', 'size': [0.1, 4.0, 0.5],
         'pose': {'position': [WALL_FACE + 0.05, 0.0, 0.25]}}]}), encoding='utf-8')
    return read_world_file(path)


def _drive_out_and_stop(tmp_path, body_com_x: float):
    """Drive 0.2 m/s for 5 s toward the wall, stop, wait 2 s; return what was seen.

    The warnings, the root link's pose, the lidar's ranges and the links on the ground.
    """
    urdf = tmp_path / 'rover.urdf'
    urdf.write_text(rover_urdf(body_com_x), encoding='utf-8')
    collector = Collector()
    logger = logging.getLogger(f'test_leaning_base_{body_com_x}')
    logger.addHandler(collector)
    with make_simulation(str(urdf), None, DT, fixed_base=None, logger=logger) as simulation:
        spawn_world_objects(Entities(simulation.physics, simulation.description.model.name),
                            _world(tmp_path))
        lidar = Lidar(simulation.physics, simulation.description.model.sensors[0], 'ground')
        drive = simulation.plugins[0]
        drive.set_command(StampedTwist(0.0, (0.2, 0.0, 0.0), (0.0, 0.0, 0.0)))
        for _ in range(500):  # in 10 ms batches, as sim_node steps
            simulation.advance(10)
        drive.set_command(StampedTwist(simulation.time, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
        for _ in range(200):
            simulation.advance(10)
        root = simulation.physics.base_frame()
        ranges = lidar.scan()[0]
        touching = simulation.physics.links_on_ground()
    return collector.lines, root, ranges, touching


def _lidar_truth(root) -> tuple[numpy.ndarray, numpy.ndarray]:
    """The lidar's origin and forward beam in the world, from the root's pose (own kinematics)."""
    x, y, z, w = root.rotation
    rotation = numpy.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    on_root = numpy.array(LIDAR_ON_BASE) + (0.0, 0.0, FOOTPRINT_TO_BASE)
    return numpy.array(root.translation) + rotation @ on_root, rotation[:, 0]


def test_a_rover_resting_on_its_nose_says_so_once_and_its_lidar_reads_the_floor(tmp_path):
    lines, root, ranges, touching = _drive_out_and_stop(tmp_path, NOSE_HEAVY)
    origin, forward = _lidar_truth(root)
    qx, qy, _, _ = root.rotation
    tilt = math.degrees(math.acos(1.0 - 2.0 * (qx * qx + qy * qy)))  # the base's z from up
    assert LEANING_TILT < tilt < TIPPED_TILT, f'the rover is not leaning: {tilt:.1f} deg'
    assert forward[2] < 0.0  # its nose down
    floor = -origin[2] / forward[2]  # where the forward beam meets the floor z = 0
    wall = (WALL_FACE - origin[0]) / forward[0]
    assert floor < wall
    assert ranges[0] == pytest.approx(floor, abs=0.01)  # the floor, not the wall: as tilted
    leaning = [line for line in lines if 'has leant' in line]
    assert len(leaning) == 1, lines  # once per lean, not once per check
    line = leaning[0]
    assert "robot 'leaning_rover' has leant" in line
    assert 'nose down' in line
    assert 'touching the ground with: ' in line
    assert touching == ('base_link', 'left_wheel', 'right_wheel')  # its nose on the floor
    assert 'a level lidar sees the floor' in line
    assert 'the simulation goes on' in line


def test_the_same_rover_balanced_behind_its_axle_drives_level_and_reads_the_wall(tmp_path):
    lines, root, ranges, touching = _drive_out_and_stop(tmp_path, BALANCED)
    origin, forward = _lidar_truth(root)
    assert abs(forward[2]) < math.sin(math.radians(1.0))  # level within 1 degree
    assert root.translation[0] == pytest.approx(1.0, abs=0.03)  # 5 s at 0.2 m/s
    wall = (WALL_FACE - origin[0]) / forward[0]
    assert ranges[0] == pytest.approx(wall, abs=0.01)
    assert not [line for line in lines if 'has leant' in line], lines
    assert touching == ('left_wheel', 'right_wheel', 'caster')
