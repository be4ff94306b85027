"""A DiffBot-style robot on sim_node: cmd_vel in, odom and TF out, the base free on the ground.

The rover of test/support/mobile_fixtures.py runs in-process, paused, at
real_time_factor 0; each test drives it closed loop from the probe: it
reads ``/base_controller/odom``, decides the next ``cmd_vel``, and steps
the physics one odometry period (``node.step``) -- so the loop's delay is
one period, whatever the machine's load.  The true pose comes from
simulation_interfaces' GetEntityState.
"""

from __future__ import annotations

import contextlib
import math

import pytest
from geometry_msgs.msg import Twist
from mobile_base_harness import BaseKind, MobileBase, base_on_sim_node, heading
from mobile_fixtures import CONTROLLER, REST_HEIGHT, drive_parameters, write_rover
from node_harness import sim_node
from sim_interfaces_client import OK, msg, pose, srv

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.ros import controller_bindings

ROBOT = 'rover'
ODOM = f'/{CONTROLLER}/odom'
# One odometry period at the default publish_rate of 50 Hz: 20 steps.
ROVER = BaseKind(ROBOT, CONTROLLER, ODOM, update_steps=20, tf='/tf', wait_for_tf=True)


def running_rover(folder, **drive) -> contextlib.AbstractContextManager[MobileBase]:
    """Run the rover on sim_node, its controller given ``drive`` parameters."""
    return base_on_sim_node(ROVER, *write_rover(folder, drive_parameters(**drive)))


@pytest.fixture
def rover(tmp_path):
    """The rover on sim_node, its cmd_vel never stale (the probe steps at its own pace)."""
    with running_rover(tmp_path, cmd_vel_timeout=0.0) as running:
        yield running


def test_the_base_is_free_and_stands_on_its_wheels_where_it_started(rover):
    assert not rover.node.simulation.physics.fixed_base
    where, yaw, speed = rover.true_pose()
    assert where == pytest.approx((0.0, 0.0, REST_HEIGHT), abs=1e-6)
    published, subscribed = rover.sim.own_topics()
    assert subscribed[f'/{CONTROLLER}/cmd_vel'] == 'geometry_msgs/msg/TwistStamped'
    assert published[ODOM] == 'nav_msgs/msg/Odometry'
    assert published['/tf'] == 'tf2_msgs/msg/TFMessage'


def test_one_metre_straight_at_0_2_m_s_the_odometry_agrees_with_the_true_pose(rover):
    odometry = rover.update()
    while odometry.pose.pose.position.x < 1.0:
        rover.command(0.2, 0.0)
        odometry = rover.update()
    rover.command(0.0, 0.0)
    for _ in range(10):
        odometry = rover.update()
    where, yaw, speed = rover.true_pose()
    assert where[0] == pytest.approx(1.0, rel=0.02)
    assert odometry.pose.pose.position.x == pytest.approx(where[0], rel=0.02)
    assert odometry.pose.pose.position.y == pytest.approx(where[1], abs=0.02)
    assert odometry.header.frame_id == 'odom' and odometry.child_frame_id == 'base_link'
    rover.sim.drain()
    transform = [message.transforms[0] for message in rover.tf
                 if message.transforms[0].header.frame_id == 'odom'][-1]
    assert transform.child_frame_id == 'base_link'  # the wheels' TF is sim_node's
    assert transform.transform.translation.x == pytest.approx(odometry.pose.pose.position.x)


def test_a_quarter_turn_on_the_spot_the_odometry_agrees_with_the_true_heading(rover):
    odometry = rover.update()
    while heading(odometry) < math.pi / 2:
        rover.command(0.0, 0.5)
        odometry = rover.update()
    rover.command(0.0, 0.0)
    for _ in range(10):
        odometry = rover.update()
    where, yaw, speed = rover.true_pose()
    assert yaw == pytest.approx(math.pi / 2, rel=0.02)
    assert heading(odometry) == pytest.approx(yaw, rel=0.02)


def test_the_robot_stops_once_cmd_vel_times_out(tmp_path):
    with running_rover(tmp_path, cmd_vel_timeout=0.2) as rover:
        stops_after_the_timeout(rover)


def stops_after_the_timeout(rover: MobileBase) -> None:
    """Command once; check the robot moves within the timeout and stands after it."""
    rover.command(0.2, 0.0)
    for _ in range(5):  # 0.1 s: still within the timeout
        rover.update()
    assert rover.true_pose()[2] == pytest.approx(0.2, rel=0.05)
    for _ in range(20):
        rover.update()
    where, yaw, speed = rover.true_pose()
    assert abs(speed) < 1e-3
    assert rover.odometry[-1].twist.twist.linear.x == pytest.approx(0.0, abs=1e-3)
    assert where[0] < 0.2 * 0.4


def test_the_acceleration_limit_shapes_the_ramp(tmp_path):
    with running_rover(tmp_path, cmd_vel_timeout=0.0,
                       **{'linear.x.max_acceleration': 0.5}) as rover:
        ramps_at_half_a_metre_per_second_squared(rover)


def ramps_at_half_a_metre_per_second_squared(rover: MobileBase) -> None:
    """Command 0.2 m/s from rest; check the true speed follows a 0.5 m/s^2 ramp."""
    rover.command(0.2, 0.0)
    speeds = []
    for _ in range(25):  # 0.5 s
        rover.update()
        speeds.append(rover.true_pose()[2])
    # 0.5 m/s^2: 0.1 m/s after 0.2 s (10 periods), the full 0.2 m/s from 0.4 s on.
    assert speeds[9] == pytest.approx(0.1, abs=0.01)
    assert speeds[-1] == pytest.approx(0.2, rel=0.02)
    assert all(later >= earlier - 1e-3 for earlier, later in zip(speeds, speeds[1:], strict=False))


def test_reset_simulation_puts_the_base_back_and_set_entity_state_moves_it(rover):
    rover.command(0.2, 0.3)
    for _ in range(25):
        rover.update()
    assert rover.true_pose()[0][0] > 0.05
    result = rover.interfaces.reset(srv.ResetSimulation.Request.SCOPE_ALL)
    assert result.result == OK, result.error_message
    where, yaw, speed = rover.true_pose()
    assert where == pytest.approx((0.0, 0.0, REST_HEIGHT), abs=1e-6)
    assert (yaw, speed) == pytest.approx((0.0, 0.0), abs=1e-9)
    assert rover.node.simulation.controller(CONTROLLER).odometry.x == 0.0

    target = pose(2.0, -1.0, REST_HEIGHT, (0.0, 0.0, math.sin(0.5), math.cos(0.5)))
    result = rover.interfaces.set_entity_state(ROBOT, target, Twist())
    assert result.result == OK, result.error_message
    where, yaw, speed = rover.true_pose()
    assert where == pytest.approx((2.0, -1.0, REST_HEIGHT), abs=1e-6)
    assert yaw == pytest.approx(1.0)
    rover.update()  # it stands where it was put
    assert rover.true_pose()[0] == pytest.approx((2.0, -1.0, REST_HEIGHT), abs=1e-3)
    info = rover.interfaces.call('get_entity_info', srv.GetEntityInfo.Request(entity=ROBOT))
    assert info.info.category.category == msg.EntityCategory.CATEGORY_ROBOT


def test_a_twist_that_is_not_finite_leaves_the_robot_as_it_was(rover):
    rover.command(0.2, 0.0)
    rover.update()
    rover.command(math.nan, 0.0)
    for _ in range(5):
        rover.update()
    assert rover.true_pose()[2] == pytest.approx(0.2, rel=0.05)


def test_the_initial_pose_and_fixed_base_parameters_place_and_weld_the_base(tmp_path):
    description, controllers = write_rover(tmp_path)
    common = dict(paused=True, robot_description_file=str(description),
                  controllers_file=str(controllers), world='ground')
    with sim_node(initial_pose=[1.0, 2.0, 0.0, math.pi], **common) as sim:
        frame = sim.simulation.physics.base_frame()
        assert frame.translation == pytest.approx((1.0, 2.0, REST_HEIGHT), abs=1e-6)
    with sim_node(fixed_base=True, **common) as sim:
        assert sim.simulation.physics.fixed_base
    with sim_node(fixed_base='false', **common) as sim:
        assert not sim.simulation.physics.fixed_base


@pytest.mark.parametrize('parameters, problem', [
    ({'fixed_base': 'maybe'}, "parameter 'fixed_base' must be one of auto, true, false"),
    ({'initial_pose': [1.0, 2.0]}, "parameter 'initial_pose' must be four finite numbers"),
    ({'world': 'empty'}, "parameter 'world': 'empty' has no ground for the free base of "
                         "'rover' to stand on"),
])
def test_a_bad_base_parameter_stops_start_up_naming_it(tmp_path, parameters, problem):
    description, controllers = write_rover(tmp_path)
    with pytest.raises(ParameterError, match=problem):
        with sim_node(robot_description_file=str(description),
                      controllers_file=str(controllers), **parameters):
            pass


def test_without_tf2_msgs_the_controller_publishes_its_odometry_but_no_tf(tmp_path, monkeypatch):
    monkeypatch.delitem(controller_bindings.STATE_SINKS, 'tf2_msgs/msg/TFMessage')
    description, controllers = write_rover(tmp_path)
    with sim_node(paused=True, robot_description_file=str(description), publish_tf=False,
                  controllers_file=str(controllers), world='ground') as sim:
        published, _ = sim.own_topics()
        assert ODOM in published and '/tf' not in published
        sim.node.step(100)  # the controller takes no TF samples, and runs
        assert sim.simulation.time == pytest.approx(0.1)
