"""control_sensors: what a <ros2_control> sensor measures and where the URDF puts it."""

import pathlib

from pan_tilt_sim.model import control_sensors as kinds
from pan_tilt_sim.model.robot import ControlInterface, ControlSensor
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.model.urdf import parse_urdf

URDF = """<robot name="r">
  <link name="base"/><link name="tool"/><link name="imu_sensor"/>
  <joint name="tool_joint" type="fixed"><parent link="base"/><child link="tool"/></joint>
  <joint name="imu_joint" type="fixed"><parent link="base"/><child link="imu_sensor"/></joint>
  <gazebo reference="tool_joint">
    <sensor name="gz_ft" type="force_torque"><pose>0 0 0.1 0 0 0</pose>
      <update_rate>50</update_rate></sensor>
  </gazebo>
</robot>"""


def model():
    return parse_urdf(URDF, pathlib.Path('r.urdf'))


def sensor(name, *interfaces, **params):
    return ControlSensor(name, tuple(ControlInterface(i) for i in interfaces), params)


def test_a_gazebo_sensor_of_the_same_name_places_it_with_its_pose():
    placed = kinds.placement(model(), sensor('gz_ft', *kinds.WRENCH, frame_id='base'))
    assert (placed.link, placed.gazebo.name) == ('tool', 'gz_ft')
    assert placed.pose == Transform((0.0, 0.0, 0.1))


def test_else_its_frame_id_param_naming_a_link_places_it():
    placed = kinds.placement(model(), sensor('fts', *kinds.WRENCH, frame_id='tool'))
    assert (placed.link, placed.gazebo, placed.pose) == ('tool', None, Transform())
    assert 'frame_id' in placed.via


def test_else_a_link_of_its_name_places_it():
    assert kinds.placement(model(), sensor('imu_sensor', *kinds.IMU)).link == 'imu_sensor'


def test_nothing_else_places_it_and_the_reason_says_what_was_looked_for():
    assert kinds.placement(model(), sensor('tcp_fts_sensor', *kinds.WRENCH)) is None
    assert kinds.placement(model(), sensor('x', 'range', frame_id='nowhere')) is None
    reason = kinds.unplaced_reason(sensor('x', 'range', frame_id='nowhere'))
    assert "'nowhere' is not a link" in reason and "broadcaster's frame_id" in reason
    # A pose broadcaster's frame_id is the frame the pose is in, not the sensor's place.
    assert kinds.unplaced_reason(sensor('tcp_pose', *kinds.POSE)).endswith('it reads NaN')


def test_interface_names_the_simulator_does_not_produce_are_listed_in_file_order():
    thermo = sensor('t', 'temperature', 'force.x', 'humidity')
    assert kinds.unsimulated(thermo) == ('temperature', 'humidity')
    assert kinds.unsimulated(sensor('f', *kinds.WRENCH, *kinds.IMU, *kinds.POSE,
                                    'range')) == ()


def test_an_orientation_is_an_imus_unless_the_sensor_has_a_position():
    assert kinds.reads_imu(sensor('i', *kinds.IMU))
    assert kinds.reads_imu(sensor('o', *kinds.ORIENTATION))
    assert not kinds.reads_imu(sensor('p', *kinds.POSE))
    assert not kinds.reads_imu(sensor('f', *kinds.WRENCH))


def test_the_mass_a_link_carries_is_its_own_and_everything_beyond_it():
    urdf = """<robot name="r">
      <link name="base"><inertial><mass value="5"/>
        <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <link name="flange"/>
      <link name="tool"><inertial><mass value="0.5"/>
        <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <link name="tip"/>
      <joint name="a" type="fixed"><parent link="base"/><child link="flange"/></joint>
      <joint name="b" type="fixed"><parent link="flange"/><child link="tool"/></joint>
      <joint name="c" type="fixed"><parent link="tool"/><child link="tip"/></joint>
    </robot>"""
    arm = parse_urdf(urdf, pathlib.Path('r.urdf'))
    assert kinds.carried_mass(arm, 'flange') == 0.5
    assert kinds.carried_mass(arm, 'base') == 5.5
    assert kinds.carried_mass(arm, 'tip') == 0.0
