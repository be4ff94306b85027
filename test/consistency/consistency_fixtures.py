"""The consistency suite's robots, world and scripted paths, written on the fly.

A robot of the matrix is one drive's base from the existing fixtures
(:mod:`mobile_fixtures`' rover for diff_drive_controller and the three
Gazebo plugins, :mod:`roller_fixtures`' mecanum and omni bases,
:mod:`steering_fixtures`' car and trike), with

* its root link ``base_link``, or a massless ``base_footprint`` (REP 105)
  on the ground, ``rest_height`` below ``base_link`` by a fixed joint;
* a noise-free sensor payload -- a lidar, a depth camera, an IMU and a
  force-torque sensor holding a ``PAYLOAD_MASS`` block -- on fixed links of
  ``base_link`` (``mount='base'``) or on the tilt link of a pan/tilt mast
  (``mount='mast'``: ``mast_pan_joint`` about z on ``base_link``,
  ``mast_tilt_joint`` about y above it, held by a
  ``position_controllers/JointGroupPositionController`` named ``mast``).

The world (:data:`WORLD_YAML`) is the ground, two walls facing each other
across x, a pillar (cylinder) and a red ball (sphere), all static.  Every
number the truths need is a constant here: the suite computes what each
sensor must read from these numbers and the robot's true pose, not with the
simulation's own sensor code.
"""

from __future__ import annotations

import dataclasses
import pathlib
import textwrap
from typing import Any

import mobile_fixtures as mobile
import roller_fixtures as roller
import steering_fixtures as steering
import yaml

# --- the world --------------------------------------------------------------------------------

WALL_X = 2.5  # m: the front wall's face, the plane x = WALL_X, facing the robot
BACK_WALL_X = -2.0  # m: the back wall's face, x = BACK_WALL_X
WALL_THICKNESS = 0.1
WALL_HALF_WIDTH = 4.0  # along y
WALL_HEIGHT = 1.0
PILLAR_CENTRE = (0.8, 1.6)  # m, x y; a vertical cylinder standing on the ground
PILLAR_RADIUS = 0.2
PILLAR_HEIGHT = 1.0
BALL_CENTRE = (0.8, -1.4, 0.3)  # m; a sphere
BALL_RADIUS = 0.3
BALL_RGB = (1.0, 0.0, 0.0)


@dataclasses.dataclass(frozen=True)
class Box:
    """An axis-aligned box: its lower and upper corners (m, world)."""

    low: tuple[float, float, float]
    high: tuple[float, float, float]


@dataclasses.dataclass(frozen=True)
class Cylinder:
    """A vertical cylinder standing from z = ``bottom`` to ``top``."""

    centre: tuple[float, float]
    radius: float
    bottom: float
    top: float


@dataclasses.dataclass(frozen=True)
class Sphere:
    """A sphere."""

    centre: tuple[float, float, float]
    radius: float


SHAPES: tuple[Box | Cylinder | Sphere, ...] = (
    Box((WALL_X, -WALL_HALF_WIDTH, 0.0),
        (WALL_X + WALL_THICKNESS, WALL_HALF_WIDTH, WALL_HEIGHT)),
    Box((BACK_WALL_X - WALL_THICKNESS, -WALL_HALF_WIDTH, 0.0),
        (BACK_WALL_X, WALL_HALF_WIDTH, WALL_HEIGHT)),
    Cylinder(PILLAR_CENTRE, PILLAR_RADIUS, 0.0, PILLAR_HEIGHT),
    Sphere(BALL_CENTRE, BALL_RADIUS),
)


def world_yaml() -> str:
    """Return the world file: the ground and :data:`SHAPES`, each a static simple shape."""
    wall_y = 2 * WALL_HALF_WIDTH
    return yaml.safe_dump({'scenery': 'ground', 'entities': [
        {'name': 'front_wall', 'shape': 'box', 'size': [WALL_THICKNESS, wall_y, WALL_HEIGHT],
         'pose': {'position': [WALL_X + WALL_THICKNESS / 2, 0.0, WALL_HEIGHT / 2]}},
        {'name': 'back_wall', 'shape': 'box', 'size': [WALL_THICKNESS, wall_y, WALL_HEIGHT],
         'pose': {'position': [BACK_WALL_X - WALL_THICKNESS / 2, 0.0, WALL_HEIGHT / 2]}},
        {'name': 'pillar', 'shape': 'cylinder', 'size': [PILLAR_RADIUS, PILLAR_HEIGHT],
         'colour': [0.2, 0.3, 0.8],
         'pose': {'position': [*PILLAR_CENTRE, PILLAR_HEIGHT / 2]}},
        {'name': 'ball', 'shape': 'sphere', 'size': [BALL_RADIUS], 'colour': list(BALL_RGB),
         'pose': {'position': list(BALL_CENTRE)}},
    ]})


# --- the sensors --------------------------------------------------------------------------------

LIDAR_SAMPLES = 360
LIDAR_MIN_ANGLE, LIDAR_MAX_ANGLE = 0.0, 6.28  # rad, as a TurtleBot3's
LIDAR_RANGE = (0.12, 6.0)  # m
LIDAR_RATE = 5.0  # Hz
CAMERA_SIZE = (40, 30)  # pixels: width, height
CAMERA_HFOV = 1.0  # rad
CAMERA_CLIP = (0.05, 20.0)  # m
CAMERA_RATE = 10.0
IMU_RATE = 100.0
FT_RATE = 50.0
PAYLOAD_MASS = 0.5  # kg, hung on the force-torque sensor's fixed joint
PAYLOAD_DROP = 0.02  # m: its centre of mass below that joint

# Where each sensor's link is on its carrier (base_link, or the mast's tilt link): xyz, m.
BASE_MOUNTS = {'lidar_link': (0.0, 0.0, 0.12), 'camera_link': (0.1, 0.0, 0.15),
               'imu_link': (0.05, 0.03, 0.04), 'payload_link': (-0.05, 0.0, 0.06)}
MAST_MOUNTS = {'lidar_link': (0.0, 0.0, 0.05), 'camera_link': (0.04, 0.0, 0.0),
               'imu_link': (0.02, 0.03, 0.01), 'payload_link': (-0.03, 0.0, 0.02)}
MAST_PAN_ORIGIN = (0.0, 0.0, 0.06)  # m: the pan joint on base_link
MAST_TILT_ORIGIN = (0.0, 0.0, 0.25)  # m: the tilt joint on the pan link
MAST_CONTROLLER = 'mast'
MAST_JOINTS = ('mast_pan_joint', 'mast_tilt_joint')
SENSOR_LINKS = ('lidar_link', 'camera_link', 'imu_link', 'payload_link')
INERTIA = '<inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/>'


def _fixed(name: str, parent: str, child: str, xyz: tuple[float, ...]) -> str:
    return (f'<joint name="{name}" type="fixed"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{" ".join(map(repr, xyz))}"/></joint>')


def sensors_xml(mount: str) -> str:
    """Return the sensor payload on ``base_link`` (``'base'``) or on a pan/tilt mast (``'mast'``).

    No sensor link has a collision shape (the lidar must not see its robot);
    none declares noise.
    """
    if mount == 'base':
        carrier, mounts, mast = 'base_link', BASE_MOUNTS, ''
    else:
        carrier, mounts = 'mast_tilt_link', MAST_MOUNTS
        mast = f'''
          <joint name="mast_pan_joint" type="revolute">
            <parent link="base_link"/><child link="mast_pan_link"/>
            <origin xyz="{' '.join(map(repr, MAST_PAN_ORIGIN))}"/><axis xyz="0 0 1"/>
            <limit lower="-3" upper="3" effort="20" velocity="3"/>
          </joint>
          <link name="mast_pan_link"><inertial><mass value="0.2"/>{INERTIA}</inertial></link>
          <joint name="mast_tilt_joint" type="revolute">
            <parent link="mast_pan_link"/><child link="mast_tilt_link"/>
            <origin xyz="{' '.join(map(repr, MAST_TILT_ORIGIN))}"/><axis xyz="0 1 0"/>
            <limit lower="-1" upper="1" effort="20" velocity="3"/>
          </joint>
          <link name="mast_tilt_link"><inertial><mass value="0.2"/>{INERTIA}</inertial></link>'''
    links = ''.join(
        _fixed(f'{link[:-5]}_joint', carrier, link, xyz)
        + (f'<link name="{link}"><inertial><origin xyz="0 0 -{PAYLOAD_DROP}"/>'
           f'<mass value="{PAYLOAD_MASS}"/>{INERTIA}</inertial></link>' if link == 'payload_link'
           else f'<link name="{link}"><inertial><mass value="0.05"/>{INERTIA}</inertial></link>')
        for link, xyz in mounts.items())
    width, height = CAMERA_SIZE
    return mast + links + textwrap.dedent(f'''
        <gazebo reference="lidar_link">
          <sensor type="ray" name="lidar">
            <update_rate>{LIDAR_RATE}</update_rate>
            <ray><scan><horizontal><samples>{LIDAR_SAMPLES}</samples><resolution>1</resolution>
              <min_angle>{LIDAR_MIN_ANGLE}</min_angle><max_angle>{LIDAR_MAX_ANGLE}</max_angle>
              </horizontal></scan>
              <range><min>{LIDAR_RANGE[0]}</min><max>{LIDAR_RANGE[1]}</max>
                <resolution>0.015</resolution></range></ray>
            <plugin name="scan" filename="libgazebo_ros_ray_sensor.so">
              <ros><remapping>~/out:=scan</remapping></ros>
              <output_type>sensor_msgs/LaserScan</output_type>
              <frame_name>lidar_link</frame_name>
            </plugin>
          </sensor>
        </gazebo>
        <gazebo reference="camera_link">
          <sensor type="depth" name="depth">
            <update_rate>{CAMERA_RATE}</update_rate>
            <camera><horizontal_fov>{CAMERA_HFOV}</horizontal_fov>
              <image><width>{width}</width><height>{height}</height><format>R8G8B8</format></image>
              <clip><near>{CAMERA_CLIP[0]}</near><far>{CAMERA_CLIP[1]}</far></clip></camera>
            <plugin name="depth_driver" filename="libgazebo_ros_camera.so">
              <camera_name>depth</camera_name><frame_name>camera_optical</frame_name>
              <min_depth>0.05</min_depth><max_depth>20</max_depth>
            </plugin>
          </sensor>
        </gazebo>
        <gazebo reference="imu_link">
          <sensor type="imu" name="imu">
            <update_rate>{IMU_RATE}</update_rate>
            <plugin name="imu_driver" filename="libgazebo_ros_imu_sensor.so">
              <ros><remapping>~/out:=imu</remapping></ros><frame_name>imu_link</frame_name>
            </plugin>
          </sensor>
        </gazebo>
        <gazebo reference="payload_joint">
          <sensor type="force_torque" name="ft">
            <update_rate>{FT_RATE}</update_rate>
            <force_torque><frame>child</frame>
              <measure_direction>parent_to_child</measure_direction></force_torque>
            <plugin name="ft_driver" filename="libgazebo_ros_ft_sensor.so">
              <ros><remapping>wrench:=ft</remapping></ros>
            </plugin>
          </sensor>
        </gazebo>''')


# --- the drives ---------------------------------------------------------------------------------

AXLE_AHEAD = 0.05  # m: mobile_fixtures' wheel joints stand this far ahead of base_link


@dataclasses.dataclass(frozen=True)
class Drive:
    """One way to drive a base: its robot, its controllers file and what it can do."""

    name: str
    rest_height: float  # m: base_link above the ground at rest
    controller: str | None  # the driving controller's name; None: a URDF plugin drives
    holonomic: bool = False  # takes linear.y
    turns_in_place: bool = True
    # m ahead of base_link: the point whose motion the odometry integrates (the
    # rover's wheel axle is ahead of its base frame; the others' is under it).
    odometry_point: float = 0.0


DRIVES = {
    'diff_drive_controller': Drive('diff_drive_controller', mobile.REST_HEIGHT,
                                   mobile.CONTROLLER,
                                   odometry_point=AXLE_AHEAD),
    'gazebo_ros_diff_drive': Drive('gazebo_ros_diff_drive', mobile.REST_HEIGHT, None,
                                   odometry_point=AXLE_AHEAD),
    'planar_move': Drive('planar_move', mobile.REST_HEIGHT, None, holonomic=True),
    'gz_diff_drive': Drive('gz_diff_drive', mobile.REST_HEIGHT, None,
                                   odometry_point=AXLE_AHEAD),
    'mecanum': Drive('mecanum', roller.REST_HEIGHT, roller.CONTROLLER, holonomic=True),
    'omni': Drive('omni', roller.REST_HEIGHT, roller.CONTROLLER, holonomic=True),
    'ackermann': Drive('ackermann', steering.REST_HEIGHT, steering.CONTROLLER,
                       turns_in_place=False),
    'tricycle': Drive('tricycle', steering.REST_HEIGHT, steering.TRICYCLE_NAME,
                      turns_in_place=False),
}
PLUGINS = {'gazebo_ros_diff_drive': mobile.ROS2_DIFF_DRIVE, 'planar_move': mobile.PLANAR_MOVE,
           'gz_diff_drive': mobile.GZ_DIFF_DRIVE}
MAST_CONTROL = ''.join(
    f'<joint name="{joint}"><command_interface name="position"/>'
    '<state_interface name="position"/><state_interface name="velocity"/></joint>'
    for joint in MAST_JOINTS)


def _base_urdf(drive: str) -> str:
    """Return the drive's robot as its own fixture writes it (no sensors)."""
    if drive in PLUGINS:
        return mobile.rover_urdf('rover', ros2_control=False,
                                 extra=f'<gazebo>{PLUGINS[drive]}</gazebo>')
    if drive == 'diff_drive_controller':
        return mobile.rover_urdf('rover')
    if drive == 'mecanum':
        return roller.mecanum_urdf()
    if drive == 'omni':
        return roller.omni_urdf()
    if drive == 'ackermann':
        return steering.steered_urdf(*steering.ARRANGEMENTS[steering.ACKERMANN])
    return steering.steered_urdf('single', 'pair', driven=['front_wheel_joint'], name='trike')


def robot_urdf(drive: str, root: str, mount: str) -> str:
    """Return the matrix's robot: ``drive``'s base, its ``root`` link, sensors on ``mount``."""
    text = _base_urdf(drive)
    extra = sensors_xml(mount)
    if root == 'base_footprint':
        extra += ('<link name="base_footprint"/>'
                  + _fixed('base_footprint_joint', 'base_footprint', 'base_link',
                           (0.0, 0.0, DRIVES[drive].rest_height)))
    if mount == 'mast':
        if '<ros2_control' in text:
            text = text.replace('</ros2_control>', MAST_CONTROL + '</ros2_control>', 1)
        else:
            extra += ('<ros2_control name="mast" type="system"><hardware>'
                      '<plugin>gazebo_ros2_control/GazeboSystem</plugin></hardware>'
                      f'{MAST_CONTROL}</ros2_control>')
    head, tail = text.rsplit('</robot>', 1)
    return f'{head}{extra}\n</robot>{tail}'


def _drive_controllers(drive: str) -> dict[str, Any] | None:
    """Return the driving controller's file (as a dict), None for a URDF plugin."""
    if drive == 'diff_drive_controller':
        text = mobile.rover_controllers()
    elif drive == 'mecanum':
        text = roller.controllers_file(roller.MECANUM, roller.mecanum_parameters())
    elif drive == 'omni':
        text = roller.controllers_file(roller.OMNI, roller.omni_parameters())
    elif drive == 'ackermann':
        text = steering.steered_controllers(steering.ACKERMANN, steering.steering_parameters())
    elif drive == 'tricycle':
        text = steering.tricycle_controllers()
    else:
        return None
    return yaml.safe_load(text)


def controllers(drive: str, mount: str) -> dict[str, Any] | None:
    """Return the robot's controllers file as a dict (None: none, the URDF's plugins drive)."""
    loaded = _drive_controllers(drive)
    if mount != 'mast':
        return loaded
    if loaded is None:
        loaded = {'controller_manager': {'ros__parameters': {'update_rate': 100}}}
    manager = loaded['controller_manager']['ros__parameters']
    manager[MAST_CONTROLLER] = {'type': 'position_controllers/JointGroupPositionController'}
    loaded[MAST_CONTROLLER] = {'ros__parameters': {'joints': list(MAST_JOINTS)}}
    return loaded


def write_robot(folder: pathlib.Path, drive: str, root: str,
                mount: str) -> tuple[pathlib.Path, pathlib.Path | None, pathlib.Path]:
    """Write the robot's URDF, its controllers file (or None) and the world file into ``folder``."""
    urdf = folder / 'robot.urdf'
    urdf.write_text(robot_urdf(drive, root, mount), encoding='utf-8')
    loaded = controllers(drive, mount)
    config = None
    if loaded is not None:
        config = folder / 'controllers.yaml'
        config.write_text(yaml.safe_dump(loaded), encoding='utf-8')
    world = folder / 'world.yaml'
    world.write_text(world_yaml(), encoding='utf-8')
    return urdf, config, world


# --- the scripted path ----------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Leg:
    """One leg of the path: a twist (forward m/s, left m/s, yaw rate rad/s) held ``seconds``."""

    name: str
    twist: tuple[float, float, float]
    seconds: float


def path(drive: Drive) -> list[Leg]:
    """Return the scripted path for ``drive``: straight, turn in place, arc, reverse, stop.

    A base that cannot turn in place (steering) drives a tight arc instead;
    a holonomic one also goes sideways.
    """
    legs = [Leg('straight', (0.3, 0.0, 0.0), 1.0), Leg('stop', (0.0, 0.0, 0.0), 0.6)]
    legs.append(Leg('turn', (0.0, 0.0, 1.0), 0.8) if drive.turns_in_place
                else Leg('turn', (0.15, 0.0, 0.5), 0.8))
    legs.append(Leg('arc', (0.2, 0.0, 0.4), 0.8))
    if drive.holonomic:
        legs.append(Leg('sideways', (0.0, 0.15, 0.0), 0.6))
    legs += [Leg('reverse', (-0.2, 0.0, 0.0), 0.8), Leg('stop', (0.0, 0.0, 0.0), 1.0)]
    return legs


def mast_pose(leg_index: int) -> tuple[float, float]:
    """Return the mast's (pan, tilt) command during leg ``leg_index`` (rad)."""
    poses = ((0.0, 0.0), (0.6, -0.08), (-0.9, 0.05), (1.4, 0.0))
    return poses[leg_index % len(poses)]

