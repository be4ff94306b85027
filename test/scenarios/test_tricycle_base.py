"""A tricycle on sim_node: tricycle_controller drives its steered front wheel; odometry vs truth.

The tricycle of test/support/steering_fixtures.py (one front wheel that steers and
drives, two rear wheels rolling freely) runs in-process, paused, at
real_time_factor 0; each test drives it closed loop from the probe one
controller update (10 ms) at a time.  The true pose comes from
simulation_interfaces' GetEntityState.
"""

from __future__ import annotations

import contextlib
import math

import pytest
from mobile_base_harness import BaseKind, MobileBase, base_on_sim_node, heading
from std_srvs.srv import Empty
from steering_fixtures import REST_HEIGHT, TRICYCLE_NAME, write_tricycle

from pan_tilt_sim.ros import controller_bindings

ROBOT = 'trike'
ODOM = f'/{TRICYCLE_NAME}/odom'
BAD_COUNT = 20
# One controller update at 100 Hz (10 steps): one odometry message per period.
TRIKE = BaseKind(ROBOT, TRICYCLE_NAME, ODOM, update_steps=10)


def running(folder, **params) -> contextlib.AbstractContextManager[MobileBase]:
    """Run the tricycle on sim_node, its controller given ``params``."""
    return base_on_sim_node(TRIKE, *write_tricycle(folder, params))


def test_one_metre_straight_at_0_2_m_s_the_odometry_agrees_with_the_true_pose(tmp_path):
    with running(tmp_path) as trike:
        assert not trike.node.simulation.physics.fixed_base
        assert trike.true_pose()[0] == pytest.approx((0.0, 0.0, REST_HEIGHT), abs=1e-3)
        odometry = trike.update()
        while odometry.pose.pose.position.x < 1.0:
            trike.command(0.2, 0.0)
            odometry = trike.update()
        trike.command(0.0, 0.0)
        for _ in range(10):
            odometry = trike.update()
        where, yaw, _ = trike.true_pose()
        assert where[0] == pytest.approx(1.0, rel=0.02)
        assert odometry.pose.pose.position.x == pytest.approx(where[0], rel=0.02)
        assert odometry.pose.pose.position.y == pytest.approx(where[1], abs=0.02)
        assert (odometry.header.frame_id, odometry.child_frame_id) == ('odom', 'base_link')


def test_an_arc_of_one_metre_radius_the_odometry_and_the_truth_agree(tmp_path):
    with running(tmp_path) as trike:
        odometry = trike.update()
        radius = None
        while heading(odometry) < math.pi / 2:
            trike.command(0.2, 0.2)
            odometry = trike.update()
            if radius is None and heading(odometry) > math.pi / 4:  # turning steadily
                radius = trike.true_speed() / trike.true_yaw_rate()
        trike.command(0.0, 0.0)
        for _ in range(10):
            odometry = trike.update()
        where, yaw, _ = trike.true_pose()
        assert radius == pytest.approx(1.0, rel=0.02)
        assert yaw == pytest.approx(math.pi / 2, rel=0.02)
        assert heading(odometry) == pytest.approx(yaw, rel=0.02)
        apart = math.hypot(odometry.pose.pose.position.x - where[0],
                           odometry.pose.pose.position.y - where[1])
        assert apart < 0.02 * (math.pi / 2)


def test_it_stops_once_cmd_vel_times_out(tmp_path):
    with running(tmp_path, cmd_vel_timeout=200) as trike:
        trike.command(0.2, 0.0)
        for _ in range(15):  # 0.15 s: within the timeout, the rolling mean full
            trike.update()
        assert trike.odometry[-1].twist.twist.linear.x == pytest.approx(0.2, rel=0.05)
        for _ in range(50):
            trike.update()
        where, yaw, _ = trike.true_pose()
        assert trike.odometry[-1].twist.twist.linear.x == pytest.approx(0.0, abs=1e-3)
        assert where[0] < 0.2 * 0.4


def test_a_twist_that_is_not_finite_is_refused_with_a_throttled_warning(tmp_path, capfd):
    with running(tmp_path) as trike:
        trike.command(0.2, 0.0)
        trike.update()
        for _ in range(BAD_COUNT):
            trike.command(math.nan, 0.0)
        for _ in range(15):
            trike.update()
        assert trike.odometry[-1].twist.twist.linear.x == pytest.approx(0.2, rel=0.05)
    lines = [line for line in capfd.readouterr().err.splitlines()
             if f'{TRICYCLE_NAME}: ignored cmd_vel' in line]
    assert lines and 'not finite numbers' in lines[0]
    assert len(lines) < BAD_COUNT  # throttled


def test_reset_odometry_puts_the_odometry_back_at_the_origin(tmp_path):
    with running(tmp_path, enable_odom_tf=True) as trike:
        published, _ = trike.sim.own_topics()
        assert published['/tf'] == 'tf2_msgs/msg/TFMessage'
        trike.command(0.2, 0.0)
        for _ in range(20):
            trike.update()
        controller = trike.node.simulation.controller(TRICYCLE_NAME)
        assert controller.odometry.x > 0.02
        client = trike.sim.probe.create_client(Empty, f'/{TRICYCLE_NAME}/reset_odometry')
        assert trike.sim.spin_until(client.service_is_ready)
        future = client.call_async(Empty.Request())
        assert trike.sim.spin_until(future.done)
        assert controller.odometry.x == 0.0


def test_without_ackermann_msgs_cmd_ackermann_is_left_out_with_one_warning(
        tmp_path, capfd, monkeypatch):
    monkeypatch.setitem(controller_bindings.STATE_SINKS, controller_bindings.ACKERMANN_DRIVE,
                        (None, controller_bindings.STATE_SINKS[
                            controller_bindings.ACKERMANN_DRIVE][1]))
    with running(tmp_path, publish_ackermann_command=True) as trike:
        published, _ = trike.sim.own_topics()
        assert f'/{TRICYCLE_NAME}/cmd_ackermann' not in published
        trike.command(0.2, 0.0)
        for _ in range(20):
            trike.update()
        assert trike.odometry[-1].twist.twist.linear.x == pytest.approx(0.2, rel=0.05)
    lines = [line for line in capfd.readouterr().err.splitlines()
             if f'{TRICYCLE_NAME}: no topic' in line]
    assert len(lines) == 1 and line_is_warning(lines[0])
    assert f'/{TRICYCLE_NAME}/cmd_ackermann (ackermann_msgs/msg/AckermannDrive): ' \
        'ackermann_msgs is not installed' in lines[0]


def line_is_warning(line: str) -> bool:
    """Whether a log line on stderr is a warning."""
    return line.startswith('[WARN]')
