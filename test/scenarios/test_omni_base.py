"""An omni base on sim_node: ~/cmd_vel in; ~/odom and /tf out, the base free on the ground.

The three-wheel omni base of test/support/roller_fixtures.py runs in-process,
paused, at real_time_factor 0; each test drives it closed loop from the
probe: it reads ``/base_controller/odom``, decides the next command and
steps the physics one controller update (10 steps at 100 Hz) at a time.
The true pose comes from simulation_interfaces' GetEntityState.
"""

from __future__ import annotations

import functools

import pytest
import sim_process
from mobile_base_harness import (
    BaseKind,
    free_base_topics,
    holonomic_stops_after_the_timeout,
    ignores_non_finite_commands,
    running,
)
from roller_fixtures import CONTROLLER, REST_HEIGHT, omni_parameters, write_omni

ROBOT = 'omni'
ODOM = f'/{CONTROLLER}/odom'
# One controller update at the controller_manager's 100 Hz: 10 steps.
OMNI = BaseKind(ROBOT, CONTROLLER, ODOM, update_steps=10, holonomic=True, tf='/tf', log=True)


# running_base(folder, **drive): the base on sim_node, its controller given ``drive``.
running_base = functools.partial(running, OMNI, write_omni, omni_parameters)


@pytest.fixture
def base(tmp_path):
    """The base on sim_node, each command good for a second of sim time."""
    with running_base(tmp_path, cmd_vel_timeout=1.0) as running:
        yield running


def test_the_base_is_free_and_the_topics_are_upstreams(base):
    published, subscribed = free_base_topics(base, REST_HEIGHT)
    assert subscribed[f'/{CONTROLLER}/cmd_vel'] == 'geometry_msgs/msg/TwistStamped'
    assert published[ODOM] == 'nav_msgs/msg/Odometry'
    assert published['/tf'] == 'tf2_msgs/msg/TFMessage'


def test_one_metre_sideways_the_odometry_agrees_with_the_true_pose(base):
    base.command(0.0, 0.2, 0.0)
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
    transform = [message.transforms[0] for message in base.tf
                 if message.transforms[0].header.frame_id == 'odom'][-1]
    assert transform.child_frame_id == 'base_link'
    assert transform.transform.translation.y == pytest.approx(odometry.pose.pose.position.y)


def test_the_base_stops_once_cmd_vel_times_out(tmp_path):
    with running_base(tmp_path, cmd_vel_timeout=0.2) as base:
        holonomic_stops_after_the_timeout(base)


def test_a_stream_of_non_finite_twists_is_ignored_with_a_throttled_warning(base):
    ignores_non_finite_commands(base, lambda bad: (0.0, 0.0, bad))
    assert abs(base.odometry[-1].twist.twist.angular.z) < 0.01


def test_a_wheel_joint_the_urdf_lacks_stops_start_up_with_one_line_naming_the_parameter(
        tmp_path):
    description, controllers = write_omni(tmp_path, omni_parameters(
        wheel_names=['wheel_0_joint', 'wheel_1_joint', 'wheel_3_joint']))
    result = sim_process.run('-p', f'robot_description_file:={description}',
                             '-p', f'controllers_file:={controllers}')
    line = sim_process.error_line(result)
    assert f"{CONTROLLER}.wheel_names: joint 'wheel_3_joint' is not a movable joint" in line
