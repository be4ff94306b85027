"""The robot model: one parse of the URDF, its tree, link poses and geometry, without ROS."""

import math
import pathlib

import pytest
from robot_fixtures import ARM_URDF

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.transforms import rotate
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.share import DEFAULT_DESCRIPTION, package_share


def pan_tilt_model():
    return load_description(package_share() / DEFAULT_DESCRIPTION).model


def arm_model():
    return parse_urdf(ARM_URDF, pathlib.Path('arm.urdf'))


def test_the_pan_tilt_example_has_two_moving_joints_and_no_fixed_ones():
    tree = pan_tilt_model()
    assert tree.root == 'base_link'
    assert [joint.name for joint in tree.moving_joints] == ['pan_joint', 'tilt_joint']
    assert tree.fixed_joints == ()


def test_the_pan_tilt_example_tilt_link_is_0_3_m_up_and_turned_by_the_tilt():
    tree = pan_tilt_model()
    pose = tree.link_poses({'pan_joint': 0.0, 'tilt_joint': -math.pi / 2})['tilt_link']
    assert pose.translation == pytest.approx((0.0, 0.0, 0.3))
    assert rotate(pose.rotation, (0, 0, 1)) == pytest.approx((-1.0, 0.0, 0.0), abs=1e-12)


def test_link_reach_is_the_far_end_of_the_visual_along_z():
    pan_tilt, arm = pan_tilt_model(), arm_model()
    assert pan_tilt.link('tilt_link').reach() == pytest.approx(0.2)  # 0.4 m cylinder, centred
    assert pan_tilt.link('pan_link').reach() == pytest.approx(0.29)  # offset 0.09 + 0.2
    assert arm.link('upper').reach() == pytest.approx(0.5)  # box from 0 to 0.5
    assert arm.link('base').reach() == 0.0  # no visual


# --- one parser, one error policy -------------------------------------------------

def test_inertials_are_read_and_a_link_without_one_has_none():
    model = arm_model()
    assert model.link('base').inertial is None  # a massless frame, as URDF says
    shoulder = model.link('shoulder').inertial
    assert (shoulder.mass, shoulder.ixx, shoulder.iyy, shoulder.izz) == (1.0, 0.1, 0.1, 0.1)


def test_joints_carry_their_origin_axis_and_links():
    pitch = arm_model().joint('pitch')
    assert (pitch.parent, pitch.child) == ('shoulder', 'upper')
    assert pitch.axis == pytest.approx((0.0, math.sqrt(0.5), math.sqrt(0.5)))  # 0 1 1
    assert pitch.origin.translation == (0.0, 0.05, 0.1)


PITCH_ORIGIN = '<origin xyz="0 0.05 0.1" rpy="0.2 -0.4 0.1"/>'


@pytest.mark.parametrize(('old', 'new', 'message'), [
    (PITCH_ORIGIN, '<origin xyz="0 0.05"/>',
     'joint \'pitch\': <origin xyz="0 0.05"> is not three numbers'),
    (PITCH_ORIGIN, '<origin rpy="a b c"/>',
     'joint \'pitch\': <origin rpy="a b c"> is not three numbers'),
    ('<axis xyz="0 1 1"/>', '<axis xyz="0 1 nan"/>',
     'joint \'pitch\': <axis xyz="0 1 nan"> is not finite'),
    ('<parent link="shoulder"/>', '<parent link="nowhere"/>',
     "joint 'pitch': parent link 'nowhere' is not a link of this robot"),
])
def test_a_malformed_value_is_an_error_naming_the_element_not_a_silent_default(old, new,
                                                                                 message):
    # Kinematics used to read a bad vector as zero where the description layer
    # refused it: there is one parser now, and it refuses.
    assert ARM_URDF.count(old) == 1
    with pytest.raises(DescriptionError) as caught:
        parse_urdf(ARM_URDF.replace(old, new), pathlib.Path('arm.urdf'))
    assert str(caught.value) == f'arm.urdf: {message}'


# --- <ros2_control> and the Gazebo control plugins ---------------------------------

CONTROLLED = """<robot name="c"><link name="a"/><link name="b"/><link name="f"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="g" type="prismatic"><parent link="b"/><child link="f"/>
    <limit lower="0" upper="1" effort="1" velocity="1"/></joint>
  <ros2_control name="Sys" type="system">
    <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin>
      <param name="position_proportional_gain">0.5</param></hardware>
    <joint name="j">
      <command_interface name="position"><param name="min">-1</param></command_interface>
      <command_interface name="velocity"/>
      <state_interface name="position"><param name="initial_value">0.25</param></state_interface>
      <state_interface name="velocity"/>
    </joint>
    <joint name="g"><command_interface name="effort"/><state_interface name="position"/></joint>
  </ros2_control>
  <gazebo><plugin filename="gz_ros2_control-system"
                  name="gz_ros2_control::GazeboSimROS2ControlPlugin">
    <parameters>/ws/share/c/config/controllers.yaml</parameters>
    <ros><namespace>/arm</namespace></ros></plugin></gazebo>
</robot>"""


def test_the_ros2_control_block_gives_interfaces_initial_values_and_hardware_params():
    model = parse_urdf(CONTROLLED, pathlib.Path('c.urdf'))
    (system,) = model.ros2_control
    assert (system.name, system.plugin) == ('Sys', 'gz_ros2_control/GazeboSimSystem')
    assert system.hardware_params == {'position_proportional_gain': '0.5'}
    joint = model.control_joint('j')
    assert joint.command_interface_names == ('position', 'velocity')
    assert joint.command_interfaces[0].params == {'min': '-1'}
    assert joint.state_interface_names == ('position', 'velocity')
    assert joint.initial_position == 0.25
    assert model.control_joint('g').initial_position is None
    assert model.control_joint('nothing') is None


def test_the_ros2_control_block_keeps_command_interfaces_beyond_the_usual_three():
    # ros2_control allows any name: what the simulator can drive is decided later.
    text = CONTROLLED.replace('<command_interface name="velocity"/>',
                              '<command_interface name="velocity"/>'
                              '<command_interface name="acceleration"/>'
                              '<command_interface name="pid_gain"/>')
    joint = parse_urdf(text, pathlib.Path('c.urdf')).control_joint('j')
    assert joint.command_interface_names == ('position', 'velocity', 'acceleration', 'pid_gain')


def test_the_control_plugin_names_its_controllers_file_and_namespace():
    (plugin,) = parse_urdf(CONTROLLED, pathlib.Path('c.urdf')).control_plugins
    assert plugin.filename == 'gz_ros2_control-system'
    assert plugin.parameters == ('/ws/share/c/config/controllers.yaml',)
    assert plugin.namespace == '/arm'


@pytest.mark.parametrize(('old', 'new', 'message'), [
    ('<param name="initial_value">0.25</param>', '<param name="initial_value">zero</param>',
     '<ros2_control name="Sys">: joint \'j\': <param name="initial_value">zero</param> '
     'is not a number'),
    ('<joint name="g"><command_interface', '<joint name="h"><command_interface',
     '<ros2_control name="Sys">: joint \'h\' is not a joint of this robot'),
])
def test_a_bad_ros2_control_block_is_an_error_naming_it(old, new, message):
    with pytest.raises(DescriptionError) as caught:
        parse_urdf(CONTROLLED.replace(old, new), pathlib.Path('c.urdf'))
    assert str(caught.value) == f'c.urdf: {message}'


def test_position_proportional_gain_comes_from_the_plugin_else_the_hardware():
    assert parse_urdf(CONTROLLED, pathlib.Path('c.urdf')).position_proportional_gain == 0.5
    in_plugin = CONTROLLED.replace(
        '<ros><namespace>', '<position_proportional_gain>0.2</position_proportional_gain>'
        '<ros><namespace>')
    assert parse_urdf(in_plugin, pathlib.Path('c.urdf')).position_proportional_gain == 0.2
    assert arm_model().position_proportional_gain is None


@pytest.mark.parametrize('value', ['fast', '0', '-0.1', 'nan'])
def test_a_position_proportional_gain_that_is_no_positive_number_is_an_error(value):
    text = CONTROLLED.replace('<param name="position_proportional_gain">0.5</param>',
                              f'<param name="position_proportional_gain">{value}</param>')
    with pytest.raises(DescriptionError) as caught:
        parse_urdf(text, pathlib.Path('c.urdf'))
    assert str(caught.value) == (
        'c.urdf: <ros2_control name="Sys">: <hardware> <param name="position_proportional_gain">: '
        f"'{value}' must be a number > 0")


# --- <sensor> and <gpio> in <ros2_control> -------------------------------------------------

WITH_IO = CONTROLLED.replace('</ros2_control>', """
    <sensor name="fts">
      <state_interface name="force.x"/>
      <state_interface name="torque.z"><param name="initial_value">-2.5</param></state_interface>
      <param name="frame_id">f</param>
    </sensor>
    <gpio name="io">
      <command_interface name="out1"/>
      <state_interface name="out1"/>
      <state_interface name="in1"><param name="initial_value">1.0</param></state_interface>
    </gpio>
  </ros2_control>""")


def test_sensors_and_gpios_of_a_block_keep_their_interfaces_params_and_initial_values():
    model = parse_urdf(WITH_IO, pathlib.Path('c.urdf'))
    (sensor,) = model.control_sensors
    assert (sensor.name, sensor.state_interface_names) == ('fts', ('force.x', 'torque.z'))
    assert sensor.params == {'frame_id': 'f'}
    assert math.isnan(sensor.state_interfaces[0].initial_value)
    assert sensor.state_interfaces[1].initial_value == -2.5
    (gpio,) = model.control_gpios
    assert (gpio.name, gpio.command_interface_names, gpio.state_interface_names) == (
        'io', ('out1',), ('out1', 'in1'))
    assert gpio.state_interfaces[1].initial_value == 1.0
    assert model.ros2_control[0].joints[0].name == 'j'


@pytest.mark.parametrize(('old', 'new', 'message'), [
    ('<param name="initial_value">1.0</param>', '<param name="initial_value">on</param>',
     '<ros2_control name="Sys">: <gpio name="io">: <state_interface name="in1">: '
     '<param name="initial_value">on</param> is not a number'),
    ('<sensor name="fts">', '<sensor name="io">',
     '<gpio name="io"> of <ros2_control name="Sys">: the name is already taken by '
     '<sensor name="io"> of <ros2_control name="Sys">'),
    ('<sensor name="fts">', '<sensor name="j">',
     '<sensor name="j"> of <ros2_control name="Sys">: the name is already taken by '
     '<joint name="j"> of <ros2_control name="Sys">'),
    ('<gpio name="io">', '<gpio>',
     '<ros2_control name="Sys">: a <gpio> has no name'),
])
def test_a_bad_sensor_or_gpio_is_an_error_naming_it(old, new, message):
    with pytest.raises(DescriptionError) as caught:
        parse_urdf(WITH_IO.replace(old, new), pathlib.Path('c.urdf'))
    assert str(caught.value) == f'c.urdf: {message}'


def test_the_parent_joint_of_a_link_is_the_joint_whose_child_it_is():
    model = parse_urdf(CONTROLLED, pathlib.Path('c.urdf'))
    assert model.parent_joint('f').name == 'g'
    assert model.parent_joint('a') is None


def _wheeled(axle_z: float, wheel: str = 'cylinder radius="0.05" length="0.03"',
             kind: str = 'continuous') -> str:
    """A box body 0.04 m tall at the origin, one wheel on an axle ``axle_z`` below it."""
    return f'''<robot name="cart">
      <link name="body"><collision><geometry><box size="0.3 0.2 0.04"/></geometry></collision>
      </link>
      <joint name="wheel_joint" type="{kind}"><parent link="body"/><child link="wheel"/>
        <origin xyz="0 0 {axle_z}"/><axis xyz="0 1 0"/>
        {'<limit lower="-1" upper="1" effort="1" velocity="1"/>' if kind == 'revolute' else ''}
      </joint>
      <link name="wheel"><collision><origin rpy="1.5707963267948966 0 0"/>
        <geometry><{wheel}/></geometry></collision></link>
    </robot>'''


@pytest.mark.parametrize('urdf, wheels', [
    (_wheeled(-0.06), ('wheel_joint',)),  # a wheel below the body: it stands on it
    (_wheeled(-0.06, 'sphere radius="0.05"'), ('wheel_joint',)),
    (_wheeled(0.05), ()),  # the wheel's bottom 0.02 m above the body's
    (_wheeled(-0.06, kind='revolute'), ()),  # a joint that does not turn round is no wheel
    (_wheeled(-0.06, 'box size="0.1 0.1 0.1"'), ()),  # a box is no wheel
])
def test_the_ground_wheels_are_continuous_joints_whose_round_links_are_lowest(urdf, wheels):
    assert parse_urdf(urdf, pathlib.Path('cart.urdf')).ground_wheels == wheels


def test_an_arm_and_the_pan_tilt_example_stand_on_no_wheels():
    assert arm_model().ground_wheels == ()
    assert pan_tilt_model().ground_wheels == ()
