"""Gazebo drive plugins in a URDF: each generation's element names, defaults and topics."""

import pathlib

import pytest
from mobile_fixtures import (
    ROS1_DIFF_DRIVE,
    ROS2_DIFF_DRIVE,
    WHEEL_RADIUS,
    WHEEL_SEPARATION,
    plugin_rover_urdf,
)

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.drive_plugins import ENCODER, WORLD
from pan_tilt_sim.model.sensors import ROS1, ROS2
from pan_tilt_sim.model.urdf import parse_urdf

SOURCE = pathlib.Path('rover.urdf')


def plugins(plugin: str):
    return parse_urdf(plugin_rover_urdf(plugin), SOURCE).drive_plugins


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
    assert parse_urdf(plugin_rover_urdf(''), SOURCE).drive_plugins == ()


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
    return parse_urdf(plugin_rover_urdf(ground_truth=text), SOURCE).p3d_plugins


def test_ros2_p3d_reads_its_elements_and_topic():
    (plugin,) = parse_urdf(plugin_rover_urdf(), SOURCE).p3d_plugins
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
    return parse_urdf(plugin_rover_urdf(joint_states=text), SOURCE).joint_state_plugins


def test_ros2_joint_state_publisher_reads_its_joints_rate_and_topic():
    (plugin,) = parse_urdf(plugin_rover_urdf(), SOURCE).joint_state_plugins
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
