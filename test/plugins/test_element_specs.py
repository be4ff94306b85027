"""The plugins' element specs: each generation's element names, defaults, checks and topics."""

import dataclasses
import pathlib
import re

import pytest
from mobile_fixtures import (
    GZ_DIFF_DRIVE,
    GZ_JOINT_STATES,
    GZ_ODOMETRY,
    PLANAR_MOVE,
    ROS1_DIFF_DRIVE,
    ROS2_DIFF_DRIVE,
    WHEEL_RADIUS,
    WHEEL_SEPARATION,
    plugin_rover_urdf,
)

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.sensors import ROS1, ROS2
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.plugins.framework.elements import GZ, Element, ElementReader, ElementSpec, Kind
from pan_tilt_sim.plugins.gazebo_classic.diff_drive import ENCODER, WORLD, GazeboDiffDrive
from pan_tilt_sim.plugins.gazebo_classic.joint_state_publisher import GazeboJointStatePublisher
from pan_tilt_sim.plugins.gazebo_classic.p3d import GazeboP3d
from pan_tilt_sim.plugins.gazebo_classic.planar_move import GazeboPlanarMove
from pan_tilt_sim.plugins.gz.diff_drive import GzDiffDrive
from pan_tilt_sim.plugins.gz.odometry_publisher import GzOdometryPublisher
from pan_tilt_sim.plugins.registry import (
    base_drivers,
    create_plugins,
    read_settings,
    runs_by_plugins,
)

SOURCE = pathlib.Path('rover.urdf')


def plugins(plugin: str):
    return read_settings(parse_urdf(plugin_rover_urdf(plugin), SOURCE), GazeboDiffDrive)


def bare_ros2(*elements: str) -> str:
    return ('<plugin name="drive" filename="libgazebo_ros_diff_drive.so">'
            '<left_joint>left_wheel_joint</left_joint><right_joint>right_wheel_joint</right_joint>'
            + ''.join(elements) + '</plugin>')


def test_ros2_diff_drive_reads_its_elements():
    (plugin,) = plugins(ROS2_DIFF_DRIVE)
    assert plugin.convention == ROS2 and plugin.name == 'diff_drive'
    assert plugin.left_joints == ('left_wheel_joint',)
    assert plugin.right_joints == ('right_wheel_joint',)
    assert plugin.wheel_separation == (WHEEL_SEPARATION,)
    assert plugin.wheel_diameter == (2 * WHEEL_RADIUS,)
    assert (plugin.max_wheel_torque, plugin.max_wheel_acceleration) == (20.0, 1.0)
    assert plugin.publish_odom and plugin.publish_odom_tf
    assert plugin.odometry_source == ENCODER and plugin.robot_base_frame == 'base_link'
    assert plugin.topics() == ('/cmd_vel', '/odom')


def test_ros2_diff_drive_defaults_are_the_plugins():
    (plugin,) = plugins(bare_ros2())
    assert plugin.wheel_separation == (0.34,) and plugin.wheel_diameter == (0.15,)
    assert (plugin.max_wheel_torque, plugin.max_wheel_acceleration) == (5.0, 0.0)
    assert plugin.update_rate == 100.0 and plugin.odometry_source == WORLD
    assert not plugin.publish_odom and not plugin.publish_odom_tf
    assert (plugin.odometry_frame, plugin.robot_base_frame) == ('odom', 'base_footprint')
    assert plugin.pose_covariance == (1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3)


def test_ros2_topics_follow_the_namespace_and_remappings_and_the_node_namespace():
    (plugin,) = plugins(bare_ros2('<ros><namespace>/demo</namespace>'
                                  '<remapping>cmd_vel:=drive</remapping></ros>'))
    assert plugin.topics() == ('/demo/drive', '/demo/odom')
    assert plugin.topics('robot1') == ('/robot1/drive', '/robot1/odom')


def test_ros1_diff_drive_reads_the_ros1_names():
    (plugin,) = plugins(ROS1_DIFF_DRIVE)
    assert plugin.convention == ROS1
    assert plugin.left_joints == ('left_wheel_joint',)
    assert plugin.wheel_separation == (WHEEL_SEPARATION,)
    assert plugin.wheel_diameter == (2 * WHEEL_RADIUS,)
    assert plugin.max_wheel_torque == 20.0 and plugin.odometry_source == ENCODER
    assert plugin.publish_odom and plugin.publish_odom_tf  # ROS 1's defaults: on
    assert plugin.robot_base_frame == 'base_link'
    assert plugin.topics() == ('/cmd_vel', '/odom')
    assert plugin.topics('robot1') == ('/robot1/cmd_vel', '/robot1/odom')


def test_a_robot_without_drive_plugins_has_none():
    assert read_settings(parse_urdf(plugin_rover_urdf(''), SOURCE), GazeboDiffDrive) == ()


@pytest.mark.parametrize(('plugin', 'element', 'problem'), [
    (bare_ros2('<wheel_separation>wide</wheel_separation>'), '<wheel_separation>',
     "'wide' is not a number"),
    (bare_ros2('<wheel_diameter>0</wheel_diameter>'), '<wheel_diameter>', 'must be > 0'),
    (bare_ros2('<max_wheel_torque>-1</max_wheel_torque>'), '<max_wheel_torque>', 'must be > 0'),
    (bare_ros2('<odometry_source>2</odometry_source>'), '<odometry_source>', 'must be 0'),
    (bare_ros2('<publish_odom>yes please</publish_odom>'), '<publish_odom>', 'not a boolean'),
    (ROS1_DIFF_DRIVE.replace('<leftJoint>left_wheel_joint', '<leftJoint>left_wheel'),
     '<leftJoint>', "'left_wheel' is not a joint of this robot"),
    (ROS1_DIFF_DRIVE.replace('encoder', 'gps'), '<odometrySource>', "must be 'encoder'"),
    ('<plugin name="drive" filename="libgazebo_ros_diff_drive.so">'
     '<left_joint>left_wheel_joint</left_joint></plugin>', '<left_joint>',
     '1 left and 0 right wheels'),
])
def test_a_bad_plugin_element_ends_start_up_naming_the_plugin_and_the_element(
        plugin, element, problem):
    with pytest.raises(DescriptionError) as raised:
        plugins(plugin)
    message = str(raised.value)
    assert 'libgazebo_ros_diff_drive.so' in message and element in message
    assert problem in message and '\n' not in message


def p3d(text: str):
    return read_settings(parse_urdf(plugin_rover_urdf(ground_truth=text), SOURCE), GazeboP3d)


def test_ros2_p3d_reads_its_elements_and_topic():
    (plugin,) = read_settings(parse_urdf(plugin_rover_urdf(), SOURCE), GazeboP3d)
    assert plugin.convention == ROS2 and plugin.body_name == 'base_link'
    assert plugin.in_world and plugin.update_rate == 50.0
    assert plugin.topics() == '/ground_truth'


def test_ros2_p3d_defaults_are_the_plugins():
    (plugin,) = p3d('<plugin name="truth" filename="libgazebo_ros_p3d.so">'
                    '<body_name>base_link</body_name></plugin>')
    assert plugin.frame_name == 'world' and plugin.update_rate == 0.0
    assert plugin.gaussian_noise == 0.0 and plugin.xyz_offsets == (0.0, 0.0, 0.0)
    assert plugin.topics() == '/odom'


def test_ros1_p3d_reads_the_ros1_names():
    (plugin,) = p3d('<plugin name="truth" filename="libgazebo_ros_p3d.so">'
                    '<bodyName>base_link</bodyName><topicName>truth</topicName>'
                    '<frameName>left_wheel</frameName><xyzOffsets>1 2 3</xyzOffsets>'
                    '<gaussianNoise>0.01</gaussianNoise><updateRate>20</updateRate></plugin>')
    assert plugin.convention == ROS1 and plugin.frame_name == 'left_wheel'
    assert not plugin.in_world and plugin.xyz_offsets == (1.0, 2.0, 3.0)
    assert (plugin.gaussian_noise, plugin.update_rate) == (0.01, 20.0)
    assert plugin.topics() == '/truth' and plugin.topics('robot1') == '/robot1/truth'


def test_ros1_an_empty_robot_namespace_is_the_robots_name():
    (plugin,) = plugins(ROS1_DIFF_DRIVE.replace('<commandTopic>',
                                                '<robotNamespace></robotNamespace><commandTopic>'))
    assert plugin.topics() == ('/rover/cmd_vel', '/rover/odom')


@pytest.mark.parametrize(('plugin', 'element', 'problem'), [
    ('<body_name>chassis</body_name>', '<body_name>', "'chassis' is not a link"),
    ('<frame_name>base_link</frame_name>', '<body_name>', 'is missing'),
    ('<body_name>base_link</body_name><frame_name>odom</frame_name>', '<frame_name>',
     "'odom' is neither world"),
    ('<body_name>base_link</body_name><xyz_offsets>1 2</xyz_offsets>', '<xyz_offsets>',
     'not three numbers'),
    ('<body_name>base_link</body_name><gaussian_noise>-1</gaussian_noise>', '<gaussian_noise>',
     'must be >= 0'),
])
def test_a_bad_p3d_element_ends_start_up_naming_the_plugin_and_the_element(
        plugin, element, problem):
    with pytest.raises(DescriptionError) as raised:
        p3d(f'<plugin name="truth" filename="libgazebo_ros_p3d.so">{plugin}</plugin>')
    message = str(raised.value)
    assert "plugin 'truth' (libgazebo_ros_p3d.so)" in message and element in message
    assert problem in message


def joint_states(text: str):
    robot = parse_urdf(plugin_rover_urdf(joint_states=text), SOURCE)
    return read_settings(robot, GazeboJointStatePublisher)


def test_ros2_joint_state_publisher_reads_its_joints_rate_and_topic():
    (plugin,) = read_settings(parse_urdf(plugin_rover_urdf(), SOURCE), GazeboJointStatePublisher)
    assert plugin.convention == ROS2
    assert plugin.joints == ('left_wheel_joint', 'right_wheel_joint')
    assert plugin.update_rate == 50.0 and plugin.topics() == '/joint_states'
    (default,) = joint_states('<plugin name="js" filename="libgazebo_ros_joint_state_publisher.so">'
                              '<joint_name>left_wheel_joint</joint_name></plugin>')
    assert default.update_rate == 100.0


def test_ros1_joint_state_publisher_reads_comma_separated_joints():
    (plugin,) = joint_states(
        '<plugin name="js" filename="libgazebo_ros_joint_state_publisher.so">'
        '<robotNamespace>/rover</robotNamespace>'
        '<jointName>left_wheel_joint, right_wheel_joint</jointName>'
        '<updateRate>20</updateRate></plugin>')
    assert plugin.convention == ROS1 and plugin.update_rate == 20.0
    assert plugin.joints == ('left_wheel_joint', 'right_wheel_joint')
    assert plugin.topics() == '/rover/joint_states'


@pytest.mark.parametrize(('elements', 'problem'), [
    ('', '<joint_name> is missing'),
    ('<joint_name>caster_joint</joint_name>', "'caster_joint' is not a movable joint"),
    ('<joint_name>left_wheel_joint</joint_name><update_rate>fast</update_rate>',
     "<update_rate> 'fast' is not a number"),
])
def test_a_bad_joint_state_publisher_element_ends_start_up(elements, problem):
    with pytest.raises(DescriptionError, match=problem) as raised:
        joint_states('<plugin name="js" filename="libgazebo_ros_joint_state_publisher.so">'
                     f'{elements}</plugin>')
    assert "plugin 'js' (libgazebo_ros_joint_state_publisher.so)" in str(raised.value)


def model(plugin: str, **others: str):
    """Return the rover's model once start-up has read every plugin element (or the error)."""
    robot = parse_urdf(plugin_rover_urdf(plugin, **others), SOURCE)
    create_plugins(robot)
    return robot


def planar(text: str):
    return read_settings(model(text), GazeboPlanarMove)


def test_ros2_planar_move_reads_its_elements_and_defaults_are_the_plugins():
    (plugin,) = planar(PLANAR_MOVE)
    assert plugin.convention == ROS2 and plugin.name == 'planar_move'
    assert (plugin.update_rate, plugin.publish_rate) == (100.0, 100.0)
    assert plugin.robot_base_frame == 'base_link'
    (bare,) = planar('<plugin name="move" filename="libgazebo_ros_planar_move.so"/>')
    assert (bare.update_rate, bare.publish_rate) == (20.0, 20.0)
    assert bare.publish_odom and bare.publish_odom_tf  # on by default, unlike diff drive
    assert (bare.odometry_frame, bare.robot_base_frame) == ('odom', 'base_footprint')
    assert bare.pose_covariance == (1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3)
    assert bare.topics() == ('/cmd_vel', '/odom')
    assert bare.command_timeout < 0.0


def test_ros2_planar_move_topics_follow_the_namespace_and_remappings():
    (plugin,) = planar('<plugin name="move" filename="libgazebo_ros_planar_move.so">'
                       '<ros><namespace>/demo</namespace><remapping>odom:=odom_truth</remapping>'
                       '</ros><publish_odom_tf>false</publish_odom_tf></plugin>')
    assert plugin.topics() == ('/demo/cmd_vel', '/demo/odom_truth')
    assert plugin.topics('robot1') == ('/robot1/cmd_vel', '/robot1/odom_truth')
    assert not plugin.publish_odom_tf


def test_ros1_planar_move_reads_the_ros1_names():
    (plugin,) = planar('<plugin name="move" filename="libgazebo_ros_planar_move.so">'
                       '<commandTopic>move</commandTopic><odometryTopic>odometry</odometryTopic>'
                       '<odometryFrame>map</odometryFrame><odometryRate>10</odometryRate>'
                       '<robotBaseFrame>base_link</robotBaseFrame><cmdTimeout>0.5</cmdTimeout>'
                       '<publishOdometryTf>false</publishOdometryTf></plugin>')
    assert plugin.convention == ROS1 and plugin.update_rate == 0.0  # every step
    assert plugin.publish_rate == 10.0 and plugin.command_timeout == 0.5
    assert (plugin.odometry_frame, plugin.robot_base_frame) == ('map', 'base_link')
    assert plugin.publish_odom and not plugin.publish_odom_tf
    assert plugin.topics() == ('/move', '/odometry')


@pytest.mark.parametrize(('elements', 'problem'), [
    ('<update_rate>often</update_rate>', "<update_rate> 'often' is not a number"),
    ('<publish_rate>-5</publish_rate>', '<publish_rate> must be >= 0'),
    ('<publish_odom>sometimes</publish_odom>', "<publish_odom> 'sometimes' is not a boolean"),
    ('<odometryRate>-1</odometryRate>', '<odometryRate> must be >= 0'),
])
def test_a_bad_planar_move_element_ends_start_up_naming_it(elements, problem):
    with pytest.raises(DescriptionError, match=problem) as raised:
        planar(f'<plugin name="move" filename="libgazebo_ros_planar_move.so">{elements}</plugin>')
    assert "plugin 'move' (libgazebo_ros_planar_move.so)" in str(raised.value)


def test_a_planar_move_robot_needs_no_controllers_and_its_base_is_driven():
    robot = model(PLANAR_MOVE)
    (plugin,) = read_settings(robot, GazeboPlanarMove)
    assert runs_by_plugins(robot)
    assert base_drivers(robot) == [(plugin.name, 'libgazebo_ros_planar_move.so')]


def gz_bare(elements: str = '', filename: str = 'gz-sim-diff-drive-system',
            name: str = 'gz::sim::systems::DiffDrive') -> str:
    return (f'<plugin filename="{filename}" name="{name}">'
            '<left_joint>left_wheel_joint</left_joint><right_joint>right_wheel_joint</right_joint>'
            f'{elements}</plugin>')


def test_gz_diff_drive_reads_its_elements():
    (plugin,) = read_settings(model(GZ_DIFF_DRIVE), GzDiffDrive)
    assert plugin.convention == GZ
    assert plugin.left_joints == ('left_wheel_joint',)
    assert (plugin.wheel_separation, plugin.wheel_radius) == (WHEEL_SEPARATION, WHEEL_RADIUS)
    assert plugin.odom_publish_frequency == 100.0
    assert plugin.linear_limits[2:4] == (-1.0, 1.0)  # min/max acceleration


def test_gz_diff_drive_defaults_are_the_systems_named_after_the_model():
    (plugin,) = read_settings(model(gz_bare()), GzDiffDrive)
    assert (plugin.wheel_separation, plugin.wheel_radius) == (1.0, 0.2)
    assert plugin.odom_publish_frequency == 50.0
    assert plugin.command_topic == '/model/rover/cmd_vel'
    assert plugin.odometry_topic == '/model/rover/odometry'
    assert plugin.tf_topic == '/model/rover/tf'
    assert (plugin.frame_id, plugin.child_frame_id) == ('rover/odom', 'rover/base_link')
    assert all(value != value for value in plugin.linear_limits)  # NaN: none


@pytest.mark.parametrize(('filename', 'name'), [
    ('libgz-sim-diff-drive-system.so', 'anything'),
    ('ignition-gazebo-diff-drive-system', 'ignition::gazebo::systems::DiffDrive'),
    ('some-other-file', 'gz::sim::systems::DiffDrive'),
])
def test_gz_diff_drive_is_known_by_either_generations_file_or_name(filename, name):
    (plugin,) = read_settings(model(gz_bare(filename=filename, name=name)), GzDiffDrive)
    assert plugin.joint_names == ('left_wheel_joint', 'right_wheel_joint')


def test_gz_diff_drive_topics_are_absolute_and_a_groups_own_limit_overrides_the_shared_one():
    (plugin,) = read_settings(model(gz_bare('<topic>cmd_vel</topic><odom_topic>odom</odom_topic>'
                              '<max_velocity>2</max_velocity>'
                              '<max_angular_velocity>1</max_angular_velocity>')), GzDiffDrive)
    assert (plugin.command_topic, plugin.odometry_topic) == ('/cmd_vel', '/odom')
    assert plugin.linear_limits[1] == 2.0 and plugin.angular_limits[1] == 1.0


@pytest.mark.parametrize(('plugin', 'problem'), [
    ('<plugin filename="gz-sim-diff-drive-system" name="d">'
     '<right_joint>right_wheel_joint</right_joint></plugin>', '<left_joint> is missing'),
    (gz_bare().replace('<right_joint>right_wheel_joint', '<right_joint>rear_wheel'),
     "<right_joint> 'rear_wheel' is not a joint of this robot"),
    (gz_bare('<wheel_radius>0</wheel_radius>'), '<wheel_radius> must be > 0'),
    (gz_bare('<wheel_separation>far</wheel_separation>'), "'far' is not a number"),
    (gz_bare('<min_linear_velocity>1</min_linear_velocity>'
             '<max_linear_velocity>0.5</max_linear_velocity>'),
     '<min_linear_velocity> 1 is above max_linear_velocity 0.5'),
])
def test_a_bad_gz_diff_drive_element_ends_start_up_naming_it(plugin, problem):
    with pytest.raises(DescriptionError, match=problem) as raised:
        model(plugin)
    assert '\n' not in str(raised.value)


def test_gz_odometry_publisher_reads_its_elements_and_defaults():
    (plugin,) = read_settings(model(GZ_DIFF_DRIVE, ground_truth=GZ_ODOMETRY), GzOdometryPublisher)
    assert (plugin.odom_frame, plugin.robot_base_frame) == ('odom', 'base_link')
    assert plugin.odometry_topic == '/ground_truth' and plugin.odom_publish_frequency == 50.0
    (bare,) = read_settings(model(GZ_DIFF_DRIVE, ground_truth=(
        '<plugin filename="gz-sim-odometry-publisher-system" '
        'name="gz::sim::systems::OdometryPublisher"/>')), GzOdometryPublisher)
    assert (bare.odom_frame, bare.robot_base_frame) == ('rover/odom', 'rover/base_footprint')
    assert (bare.odometry_topic, bare.tf_topic) == ('/model/rover/odometry', '/model/rover/pose')
    assert bare.dimensions == 2 and bare.odom_publish_frequency == 50.0


def test_a_bad_gz_odometry_dimension_ends_start_up():
    with pytest.raises(DescriptionError, match='<dimensions> must be 2 or 3, got 4'):
        model(GZ_DIFF_DRIVE, ground_truth=(
            '<plugin filename="gz-sim-odometry-publisher-system" name="odometry">'
            '<dimensions>4</dimensions></plugin>'))


def test_gz_joint_state_publisher_defaults_to_every_movable_joint_on_the_worlds_topic():
    robot = model(GZ_DIFF_DRIVE, joint_states=(
        '<plugin filename="gz-sim-joint-state-publisher-system" '
        'name="gz::sim::systems::JointStatePublisher"/>'))
    (plugin,) = read_settings(robot, GazeboJointStatePublisher)
    assert plugin.convention == GZ and plugin.update_rate == 0.0  # every step
    assert plugin.joints == ('left_wheel_joint', 'right_wheel_joint')
    assert plugin.topics() == '/world/default/model/rover/joint_state'
    assert plugin.topics('robot1') == '/world/default/model/rover/joint_state'
    (given,) = read_settings(model(GZ_DIFF_DRIVE, joint_states=GZ_JOINT_STATES),
                             GazeboJointStatePublisher)
    assert given.topics() == '/joint_states'


def test_a_gz_joint_state_publisher_naming_a_fixed_joint_ends_start_up():
    with pytest.raises(DescriptionError, match="'caster_joint' is not a movable joint"):
        model(GZ_DIFF_DRIVE, joint_states=(
            '<plugin filename="gz-sim-joint-state-publisher-system" name="js">'
            '<joint_name>caster_joint</joint_name></plugin>'))


# --- a plugin's wheels and frames get a controller's checks ---------------------------------

def bare_ros1(*elements: str) -> str:
    return ('<plugin name="drive" filename="libgazebo_ros_diff_drive.so">'
            + ''.join(elements) + '</plugin>')


def bare_gz(*elements: str) -> str:
    return ('<plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">'
            + ''.join(elements) + '</plugin>')


def _replace(text: str, old: str, new: str) -> str:
    assert old in text
    return text.replace(old, new)


@pytest.mark.parametrize(('plugin', 'filename', 'problem'), [
    pytest.param(_replace(ROS2_DIFF_DRIVE, '<right_joint>right_wheel_joint<',
                          '<right_joint>left_wheel_joint<'), 'libgazebo_ros_diff_drive.so',
                 "<right_joint> 'left_wheel_joint' is already a wheel (<left_joint>)",
                 id='ros2: one joint left and right'),
    pytest.param(_replace(ROS2_DIFF_DRIVE, '<left_joint>left_wheel_joint<',
                          '<left_joint>caster_joint<'), 'libgazebo_ros_diff_drive.so',
                 "<left_joint> 'caster_joint' is a fixed joint: a wheel must be a movable",
                 id='ros2: a fixed wheel'),
    pytest.param(_replace(ROS2_DIFF_DRIVE, '<left_joint>left_wheel_joint</left_joint>',
                          '<left_joint>left_wheel_joint</left_joint>'
                          '<left_joint>left_wheel_joint</left_joint>'
                          '<right_joint>right_wheel_joint</right_joint>'
                          '<num_wheel_pairs>2</num_wheel_pairs>'),
                 'libgazebo_ros_diff_drive.so',
                 "<left_joint> 'left_wheel_joint' is already a wheel (<left_joint>)",
                 id='ros2: one joint in two pairs'),
    pytest.param(bare_ros1('<leftJoint>right_wheel_joint</leftJoint>',
                           '<rightJoint>right_wheel_joint</rightJoint>'),
                 'libgazebo_ros_diff_drive.so',
                 "<rightJoint> 'right_wheel_joint' is already a wheel (<leftJoint>)",
                 id='ros1: one joint left and right'),
    pytest.param(bare_ros1('<leftJoint>caster_joint</leftJoint>',
                           '<rightJoint>right_wheel_joint</rightJoint>'),
                 'libgazebo_ros_diff_drive.so', "<leftJoint> 'caster_joint' is a fixed joint",
                 id='ros1: a fixed wheel'),
    pytest.param(bare_gz('<left_joint>left_wheel_joint</left_joint>',
                         '<right_joint>left_wheel_joint</right_joint>'),
                 'gz-sim-diff-drive-system',
                 "<right_joint> 'left_wheel_joint' is already a wheel (<left_joint>)",
                 id='gz: one joint left and right'),
    pytest.param(bare_gz('<left_joint>left_wheel_joint</left_joint>',
                         '<right_joint>caster_joint</right_joint>'),
                 'gz-sim-diff-drive-system', "<right_joint> 'caster_joint' is a fixed joint",
                 id='gz: a fixed wheel'),
])
def test_a_plugin_wheel_twice_or_fixed_ends_start_up_naming_the_file_and_plugin(
        plugin, filename, problem):
    with pytest.raises(DescriptionError) as raised:
        model(plugin)
    message = str(raised.value)
    assert message.startswith(f"{SOURCE}: plugin '")
    assert f'({filename}): {problem}' in message


def test_a_plugin_wheel_that_mimics_another_joint_ends_start_up():
    urdf = plugin_rover_urdf(ROS2_DIFF_DRIVE).replace(
        '<axis xyz="0 1 0"/>', '<axis xyz="0 1 0"/><mimic joint="left_wheel_joint"/>', 2)
    urdf = urdf.replace('<mimic joint="left_wheel_joint"/>', '', 1)  # the right wheel mimics
    with pytest.raises(DescriptionError, match="<right_joint> 'right_wheel_joint' mimics "
                                               "'left_wheel_joint'"):
        create_plugins(parse_urdf(urdf, SOURCE))


@pytest.mark.parametrize(('plugin', 'problem'), [
    pytest.param(_replace(ROS2_DIFF_DRIVE, '<odometry_frame>odom<', '<odometry_frame>base_link<'),
                 "<robot_base_frame> 'base_link' is <odometry_frame> too", id='ros2 same frames'),
    pytest.param(_replace(ROS2_DIFF_DRIVE, '<odometry_frame>odom<', '<odometry_frame>a b<'),
                 "<odometry_frame> 'a b' is not a valid frame id", id='ros2 frame with a space'),
    pytest.param(bare_ros1('<leftJoint>left_wheel_joint</leftJoint>',
                           '<rightJoint>right_wheel_joint</rightJoint>',
                           '<robotBaseFrame>/odom</robotBaseFrame>'),
                 "<robotBaseFrame> '/odom' is <odometryFrame> too", id='ros1 same frames'),
    pytest.param(bare_gz('<left_joint>left_wheel_joint</left_joint>',
                         '<right_joint>right_wheel_joint</right_joint>',
                         '<frame_id>odom//x</frame_id>'),
                 "<frame_id> 'odom//x' is not a valid frame id", id='gz empty token'),
    pytest.param('<plugin name="move" filename="libgazebo_ros_planar_move.so">'
                 '<odometry_frame>..</odometry_frame></plugin>',
                 "<odometry_frame> '..' is not a valid frame id", id='planar move ..'),
])
def test_a_plugin_frame_that_is_no_frame_id_or_the_same_twice_ends_start_up(plugin, problem):
    with pytest.raises(DescriptionError, match=re.escape(problem)):
        model(plugin)


def test_a_gz_odometry_publisher_with_one_frame_for_both_ends_start_up():
    with pytest.raises(DescriptionError, match="<robot_base_frame> 'odom' is <odom_frame> too"):
        model(GZ_DIFF_DRIVE, ground_truth=GZ_ODOMETRY.replace('>base_link<', '>odom<'),
              joint_states='')


@pytest.mark.parametrize(('plugin', 'element'), [
    (bare_ros2('<update_rate>5e-324</update_rate>'), 'update_rate'),
    (bare_gz('<left_joint>left_wheel_joint</left_joint>',
             '<right_joint>right_wheel_joint</right_joint>',
             '<odom_publish_frequency>1e-320</odom_publish_frequency>'),
     'odom_publish_frequency'),
    ('<plugin name="move" filename="libgazebo_ros_planar_move.so">'
     '<publish_rate>5e-324</publish_rate></plugin>', 'publish_rate'),
])
def test_a_plugin_rate_whose_period_overflows_ends_start_up(plugin, element):
    with pytest.raises(DescriptionError, match=f'<{element}> .* must be a rate > 0 Hz'):
        model(plugin)


def test_an_element_spec_reads_each_kind_with_its_default_and_check():
    spec = ElementSpec(Element('rate', 10.0, non_negative=True),
                       Element('frame', 'odom', Kind.TEXT), Element('on', True, Kind.FLAG),
                       Element('offset', kind=Kind.VECTOR), Element('gain', 1.0, positive=True))
    element = PluginElement(filename='libx.so', name='x', source='r.urdf',
                            values={'rate': ('5',), 'offset': ('1 2 3',), 'frame': ('',)})
    assert spec.names == ('rate', 'frame', 'on', 'offset', 'gain')
    assert spec.read(ElementReader(element, 'robot')) == {
        'rate': 5.0, 'frame': 'odom', 'on': True, 'offset': (1.0, 2.0, 3.0), 'gain': 1.0}
    bad = dataclasses.replace(element, values={'gain': ('0',)})
    with pytest.raises(DescriptionError) as raised:
        spec.read(ElementReader(bad, 'robot'))
    assert str(raised.value) == "r.urdf: plugin 'x' (libx.so): <gain> must be > 0, got 0"
