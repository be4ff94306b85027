"""A mecanum base on sim_node: ~/reference in; ~/odometry, ~/tf_odometry, ~/controller_state out.

The mecanum base of test/support/roller_fixtures.py runs in-process, paused, at
real_time_factor 0; each test drives it closed loop from the probe: it
reads ``/base_controller/odometry``, decides the next reference and steps
the physics one controller update (10 steps at 100 Hz) at a time.  The
true pose comes from simulation_interfaces' GetEntityState.
"""

from __future__ import annotations

import functools
import math

import pytest
import sim_process
from control_msgs.msg import MecanumDriveControllerState
from mobile_base_harness import (
    BaseKind,
    free_base_topics,
    heading,
    holonomic_stops_after_the_timeout,
    ignores_non_finite_commands,
    running,
)
from roller_fixtures import CONTROLLER, REST_HEIGHT, mecanum_parameters, write_mecanum

ROBOT = 'mecanum'
ODOMETRY = f'/{CONTROLLER}/odometry'
# One controller update at the controller_manager's 100 Hz: 10 steps.
MECANUM = BaseKind(ROBOT, CONTROLLER, ODOMETRY, update_steps=10, holonomic=True,
                   tf=f'/{CONTROLLER}/tf_odometry', log=True,
                   state=(MecanumDriveControllerState, f'/{CONTROLLER}/controller_state'))


# running_base(folder, **drive): the base on sim_node, its controller given ``drive``.
running_base = functools.partial(running, MECANUM, write_mecanum, mecanum_parameters)


@pytest.fixture
def base(tmp_path):
    """The base on sim_node, each reference good for a second of sim time."""
    with running_base(tmp_path, reference_timeout=1.0) as running:
        yield running


def test_the_base_is_free_and_the_topics_are_upstreams(base):
    published, subscribed = free_base_topics(base, REST_HEIGHT)
    assert subscribed[f'/{CONTROLLER}/reference'] == 'geometry_msgs/msg/TwistStamped'
    assert published[ODOMETRY] == 'nav_msgs/msg/Odometry'
    assert published[f'/{CONTROLLER}/tf_odometry'] == 'tf2_msgs/msg/TFMessage'
    assert published[f'/{CONTROLLER}/controller_state'] == (
        'control_msgs/msg/MecanumDriveControllerState')


def test_one_metre_sideways_the_odometry_agrees_with_the_true_pose(base):
    odometry = base.update()
    while odometry.pose.pose.position.y < 1.0:
        base.command(0.0, 0.2, 0.0)
        odometry = base.update()
    base.command(0.0, 0.0, 0.0)
    for _ in range(50):
        odometry = base.update()
    where, yaw, _ = base.true_pose()
    assert where[1] == pytest.approx(1.0, rel=0.02)
    assert odometry.pose.pose.position.y == pytest.approx(where[1], rel=0.02)
    assert abs(odometry.pose.pose.position.x) < 0.02 and abs(yaw) < 0.02
    assert odometry.header.frame_id == 'odom' and odometry.child_frame_id == 'base_link'
    base.sim.drain()
    transform = base.tf[-1].transforms[0]
    assert (transform.header.frame_id, transform.child_frame_id) == ('odom', 'base_link')
    assert transform.transform.translation.y == pytest.approx(odometry.pose.pose.position.y)
    state = base.states[-1]
    assert state.header.frame_id == 'odom'
    assert state.front_left_wheel_velocity == pytest.approx(0.0, abs=0.05)


def test_a_quarter_turn_on_the_spot_the_odometry_agrees_with_the_true_heading(base):
    odometry = base.update()
    while heading(odometry) < math.pi / 2:
        base.command(0.0, 0.0, 0.5)
        odometry = base.update()
    base.command(0.0, 0.0, 0.0)
    for _ in range(50):
        odometry = base.update()
    _, yaw, _ = base.true_pose()
    assert yaw == pytest.approx(math.pi / 2, rel=0.02)
    assert heading(odometry) == pytest.approx(yaw, rel=0.02)


def test_the_base_stops_once_the_reference_times_out(tmp_path):
    with running_base(tmp_path, reference_timeout=0.2) as base:
        holonomic_stops_after_the_timeout(base)


def test_a_stream_of_non_finite_references_is_ignored_with_a_throttled_warning(base):
    ignores_non_finite_commands(base, lambda bad: (0.0, bad, 0.0))
    assert abs(base.odometry[-1].twist.twist.linear.y) < 0.01


def test_a_wheel_joint_the_urdf_lacks_stops_start_up_with_one_line_naming_the_parameter(
        tmp_path):
    description, controllers = write_mecanum(tmp_path, mecanum_parameters(
        rear_left_wheel_command_joint_name='rear_lfet_wheel_joint'))
    result = sim_process.run('-p', f'robot_description_file:={description}',
                             '-p', f'controllers_file:={controllers}')
    line = sim_process.error_line(result)
    assert (f"{CONTROLLER}.rear_left_wheel_command_joint_name: joint 'rear_lfet_wheel_joint' "
            'is not a movable joint') in line
