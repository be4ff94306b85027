"""What the browser view reads from sim_node and sends back, without a web server.

The sliders' commands (which joints get one, on which topic, in which
message), the sensors' messages as points and pixels, where each frame is,
the view's parameters and address check, and what a snapshot holds of
several robots, the first deleted too.
"""

import array
import importlib.util
import math
import socket

import numpy as np
import pytest
import rclpy
from rclpy.context import Context
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import Image, LaserScan, PointCloud2
from std_msgs.msg import Float64, Float64MultiArray
from trajectory_msgs.msg import JointTrajectory

from pan_tilt_sim.controllers.framework.registry import create_controller
from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.robot import JointKind, JointSpec
from pan_tilt_sim.model.transforms import Transform, quaternion_from_axis_angle
from pan_tilt_sim.ros import sensor_messages
from pan_tilt_sim.ros.view_feed import (
    FLOAT64,
    FLOAT64_ARRAY,
    JOINT_TRAJECTORY,
    TRAJECTORY_MIN_S,
    CommandChannel,
    ViewerSettings,
    check_viewer,
    cloud_points,
    command_message,
    declare_viewer,
    frame_poses,
    image_pixels,
    position_sliders,
    scan_points,
    slider_range,
    take_snapshot,
)
from pan_tilt_sim.share import package_share

PAN_TILT = load_description(package_share() / 'urdf' / 'pan_tilt.xacro')
ARM = load_description(package_share() / 'urdf' / 'three_joint_arm.xacro')


def topic(*names: str) -> str:
    return '/ns/' + '/'.join(names)


def controller(type_name: str, name: str, **params):
    return create_controller(name, type_name, params)


# --- which joints get a slider, and on which topic ----------------------------------------

def test_each_position_controllers_joint_gets_a_slider_on_its_command_topic():
    active = [controller('position_controllers/JointPositionController', 'pan', joint='pan_joint'),
              controller('effort_controllers/JointPositionController', 'tilt',
                         joint='tilt_joint')]
    sliders = position_sliders(active, PAN_TILT.model, topic)
    assert [(s.joint, s.channel.topic, s.channel.message) for s in sliders] == [
        ('pan_joint', '/ns/pan/command', FLOAT64), ('tilt_joint', '/ns/tilt/command', FLOAT64)]
    assert (sliders[0].lower, sliders[0].upper) == (-3.14, 3.14)
    assert (sliders[1].lower, sliders[1].upper) == (-4.71239, -1.570796)


def test_group_and_trajectory_controllers_give_a_slider_per_joint_velocity_and_effort_none():
    active = [
        controller('joint_trajectory_controller/JointTrajectoryController', 'arm',
                   joints=['shoulder_joint', 'extend_joint', 'wrist_joint'],
                   command_interfaces=['position'], state_interfaces=['position']),
        controller('position_controllers/JointGroupPositionController', 'gripper',
                   joints=['left_finger_joint']),
    ]
    sliders = position_sliders(active, ARM.model, topic)
    assert [(s.joint, s.channel.topic, s.channel.message) for s in sliders] == [
        ('shoulder_joint', '/ns/arm/joint_trajectory', JOINT_TRAJECTORY),
        ('extend_joint', '/ns/arm/joint_trajectory', JOINT_TRAJECTORY),
        ('wrist_joint', '/ns/arm/joint_trajectory', JOINT_TRAJECTORY),
        ('left_finger_joint', '/ns/gripper/commands', FLOAT64_ARRAY)]
    others = [controller('velocity_controllers/JointVelocityController', 'spin',
                         joint='wrist_joint'),
              controller('forward_command_controller/ForwardCommandController', 'push',
                         joints=['left_finger_joint'], interface_name='effort')]
    assert position_sliders(others, ARM.model, topic) == ()


def test_a_joint_without_limits_gets_a_turn_or_a_metre_either_way():
    assert slider_range(JointSpec('c', JointKind.CONTINUOUS)) == (-math.pi, math.pi)
    assert slider_range(JointSpec('p', JointKind.PRISMATIC)) == (-1.0, 1.0)
    assert slider_range(JointSpec('p', JointKind.PRISMATIC, lower=0.0)) == (0.0, 1.0)
    assert slider_range(JointSpec('r', JointKind.REVOLUTE, lower=-0.5, upper=0.25)) == (-0.5,
                                                                                         0.25)


# --- the messages they publish ------------------------------------------------------------

def test_a_position_controllers_slider_publishes_its_value_as_float64():
    channel = CommandChannel('pan', '/ns/pan/command', FLOAT64, ('pan_joint',))
    message = command_message(channel, {'pan_joint': 0.5}, {'pan_joint': 0.0}, PAN_TILT.model)
    assert isinstance(message, Float64)
    assert message.data == 0.5


def test_a_groups_slider_sends_every_joint_of_the_group_the_others_where_they_are():
    channel = CommandChannel('g', '/ns/g/commands', FLOAT64_ARRAY,
                             ('shoulder_joint', 'extend_joint'))
    message = command_message(channel, {'extend_joint': 0.1},
                              {'shoulder_joint': 0.3, 'extend_joint': 0.0}, ARM.model)
    assert isinstance(message, Float64MultiArray)
    assert list(message.data) == [0.3, 0.1]


def test_a_trajectory_slider_sends_one_point_reached_no_faster_than_the_velocity_limits():
    channel = CommandChannel('arm', '/ns/arm/joint_trajectory', JOINT_TRAJECTORY,
                             ('shoulder_joint',))
    limit = ARM.model.joint('shoulder_joint').velocity_limit
    near = command_message(channel, {'shoulder_joint': 0.01}, {'shoulder_joint': 0.0},
                           ARM.model)
    far = command_message(channel, {'shoulder_joint': 1.0}, {'shoulder_joint': -1.0},
                          ARM.model)
    assert isinstance(far, JointTrajectory)
    assert list(far.joint_names) == ['shoulder_joint']
    assert list(far.points[0].positions) == [1.0]
    seconds = [m.points[0].time_from_start.sec + m.points[0].time_from_start.nanosec * 1e-9
               for m in (near, far)]
    assert seconds == pytest.approx([TRAJECTORY_MIN_S, max(TRAJECTORY_MIN_S, 2.0 / limit)],
                                    abs=1e-9)


# --- sensors ------------------------------------------------------------------------------

def test_a_laser_scans_returns_become_points_in_its_frame_the_misses_dropped():
    message = LaserScan(angle_min=0.0, angle_increment=math.pi / 2, range_min=0.1,
                        range_max=10.0, ranges=[1.0, 2.0, math.inf, 0.05])
    assert scan_points(message) == pytest.approx(np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]]),
                                                 abs=1e-6)


def test_a_point_clouds_finite_points_are_read_whatever_its_other_fields():
    xyz = np.array([[[1.0, 2.0, 3.0], [np.nan, np.nan, np.nan]]])
    message = sensor_messages.point_cloud(xyz, 'lidar', 0.0,
                                          ('intensity', np.zeros((1, 2), np.float32)))
    assert cloud_points(message).tolist() == [[1.0, 2.0, 3.0]]
    assert cloud_points(PointCloud2()).shape == (0, 3)


@pytest.mark.parametrize(('encoding', 'data', 'pixel'), [
    ('rgb8', [10, 20, 30], [10, 20, 30]),
    ('bgr8', [10, 20, 30], [30, 20, 10]),
    ('mono8', [7], [7, 7, 7]),
])
def test_images_become_rgb_pixels(encoding, data, pixel):
    step = len(data) * 2 + 2  # rows padded beyond their two pixels
    row = data * 2 + [0, 0]
    message = Image(height=2, width=2, encoding=encoding, step=step,
                    data=array.array('B', row * 2))
    pixels = image_pixels(message)
    assert pixels.shape == (2, 2, 3)
    assert pixels[1, 1].tolist() == pixel


def test_an_image_of_another_encoding_is_not_shown():
    assert image_pixels(Image(height=1, width=1, encoding='32FC1', step=4,
                              data=array.array('B', [0] * 4))) is None


# --- frames -------------------------------------------------------------------------------

def test_frames_are_the_links_in_the_world_and_extra_frames_hung_on_them():
    base = Transform((1.0, 0.0, 0.0))
    optical = Transform(rotation=quaternion_from_axis_angle((0, 0, 1), math.pi / 2))
    poses = frame_poses(PAN_TILT.model, {'pan_joint': math.pi / 2, 'tilt_joint': -math.pi / 2},
                        base, [('tilt_link', 'tilt_link_optical', optical),
                               ('nowhere', 'lost', Transform())])
    assert set(poses) == {'base_link', 'pan_link', 'tilt_link', 'tilt_link_optical'}
    assert poses['tilt_link'].translation == pytest.approx((1.0, 0.0, 0.3))
    assert poses['tilt_link_optical'].translation == pytest.approx((1.0, 0.0, 0.3))
    assert poses['tilt_link_optical'].rotation == pytest.approx(
        poses['tilt_link'].then(optical).rotation)


# --- parameters and address ---------------------------------------------------------------

def test_a_port_in_use_is_one_line_naming_the_parameter_and_the_port():
    with socket.socket() as taken:
        taken.bind(('127.0.0.1', 0))
        taken.listen()
        port = taken.getsockname()[1]
        with pytest.raises(ParameterError) as raised:
            check_viewer(ViewerSettings(True, '127.0.0.1', port))
    text = str(raised.value)
    assert '\n' not in text
    assert text.startswith(f"parameter 'viewer.port': port {port} on 127.0.0.1 is in use")


def test_an_address_that_is_not_this_machines_is_one_line_naming_viewer_host():
    with pytest.raises(ParameterError, match=r"^parameter 'viewer.host': cannot serve the view"):
        check_viewer(ViewerSettings(True, '192.0.2.1', 0))


def test_a_free_port_passes_and_the_url_names_it():
    check_viewer(ViewerSettings(True, '127.0.0.1', 0))
    assert ViewerSettings(True, '127.0.0.1', 8080).url == 'http://127.0.0.1:8080/'
    assert ViewerSettings(True, '::1', 8080).url == 'http://[::1]:8080/'
    assert ViewerSettings(True, '0.0.0.0', 9).url == f'http://{socket.gethostname()}:9/'


@pytest.mark.parametrize(('overrides', 'expected'), [
    ({'viewer.port': 70000}, "parameter 'viewer.port' must be 0..65535, got 70000"),
    ({'viewer': True, 'viewer.host': ' '}, "parameter 'viewer.host' is empty"),
])
def test_bad_viewer_parameters_are_refused(overrides, expected):
    context = Context()
    rclpy.init(context=context)
    try:
        node = Node('viewer_parameters', context=context, parameter_overrides=[
            Parameter(name, value=value) for name, value in overrides.items()])
        with pytest.raises(ParameterError, match=f'^{expected}'):
            declare_viewer(node)
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)



needs_spawning = pytest.mark.skipif(importlib.util.find_spec('simulation_interfaces') is None,
                                    reason='simulation_interfaces is not installed')


@needs_spawning
def test_a_later_robot_is_drawn_with_its_own_description_and_joints():
    from stand_in_fixtures import two_rovers, world_only

    with world_only() as (harness, node):
        two_rovers(harness)
        robot2 = node.spawned_robots['robot2'].simulation
        snapshot = take_snapshot(node)
        assert snapshot.robot_pose.translation[1] == pytest.approx(0.0, abs=0.05)
        assert 'robot1' not in snapshot.entities  # the first robot is the snapshot's own
        drawn = snapshot.entities['robot2']
        assert drawn.description is robot2.description
        assert drawn.positions == robot2.joint_positions() != {}
        assert drawn.pose.translation[1] == pytest.approx(1.0, abs=0.05)


@needs_spawning
def test_a_deleted_first_robot_leaves_the_snapshot_and_the_later_one_stays_in_place():
    from stand_in_fixtures import srv, two_rovers, world_only

    with world_only() as (harness, node):
        two_rovers(harness)
        response = harness.call(srv().DeleteEntity, '/sim_node/delete_entity',
                                srv().DeleteEntity.Request(entity='robot1'))
        assert response.result.result == 1, response.result.error_message
        snapshot = take_snapshot(node)
        assert snapshot.robot_pose is None
        assert (dict(snapshot.positions), snapshot.sliders) == ({}, ())
        assert 'robot1' not in snapshot.entities
        assert snapshot.entities['robot2'].pose.translation[1] == pytest.approx(1.0, abs=0.05)
