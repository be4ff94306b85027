"""Steered robots on sim_node: reference in, odometry out, the front wheels steering on the ground.

The robots of test/support/steering_fixtures.py run in-process, paused, at
real_time_factor 0; each test drives one closed loop from the probe: it
reads ``/steering_controller/odometry``, decides the next reference, and
steps the physics one period (``node.step``).  The true pose comes from
simulation_interfaces' GetEntityState.
"""

from __future__ import annotations

import contextlib
import math
import re
import time

import pytest
import sim_process
from control_msgs.msg import SteeringControllerStatus
from mobile_base_harness import BaseKind, MobileBase, base_on_sim_node, heading
from node_harness import PROBE_QUEUE, sim_node
from rcl_interfaces.msg import Log
from steering_fixtures import (
    ACKERMANN,
    BICYCLE,
    CONTROLLER,
    REST_HEIGHT,
    TRICYCLE,
    steering_parameters,
    write_steered,
)

from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.ros.controller_bindings import WARNING_THROTTLE_S

ROBOT = 'car'
ODOMETRY = f'/{CONTROLLER}/odometry'
# One controller update (100 Hz, 10 steps): one odometry message per period.
CAR = BaseKind(ROBOT, CONTROLLER, ODOMETRY, update_steps=10, tf=f'/{CONTROLLER}/tf_odometry',
               state=(SteeringControllerStatus, f'/{CONTROLLER}/controller_state'))
BAD_COUNT = 20


def running(folder, type_name: str = ACKERMANN,
            **overrides) -> contextlib.AbstractContextManager[MobileBase]:
    """Run the robot ``type_name`` drives on sim_node, its controller given ``overrides``."""
    return base_on_sim_node(CAR, *write_steered(
        folder, type_name, steering_parameters(type_name, **overrides)))


def test_the_base_is_free_and_stands_on_its_wheels_with_its_topics(tmp_path):
    with running(tmp_path) as car:
        assert not car.node.simulation.physics.fixed_base
        where, yaw, speed = car.true_pose()
        assert where == pytest.approx((0.0, 0.0, REST_HEIGHT), abs=1e-3)
        published, subscribed = car.sim.own_topics()
        assert subscribed[f'/{CONTROLLER}/reference'] == 'geometry_msgs/msg/TwistStamped'
        assert published[ODOMETRY] == 'nav_msgs/msg/Odometry'
        assert published[f'/{CONTROLLER}/tf_odometry'] == 'tf2_msgs/msg/TFMessage'
        assert published[f'/{CONTROLLER}/controller_state'] == \
            'control_msgs/msg/SteeringControllerStatus'


@pytest.mark.parametrize('type_name', [ACKERMANN, TRICYCLE, BICYCLE])
def test_one_metre_straight_at_0_2_m_s_the_odometry_agrees_with_the_true_pose(
        tmp_path, type_name):
    with running(tmp_path, type_name) as car:
        odometry = car.update()
        while odometry.pose.pose.position.x < 1.0:
            car.command(0.2, 0.0)
            odometry = car.update()
        car.command(0.0, 0.0)
        for _ in range(10):
            odometry = car.update()
        where, yaw, speed = car.true_pose()
        assert where[0] == pytest.approx(1.0, rel=0.02)
        assert odometry.pose.pose.position.x == pytest.approx(where[0], rel=0.02)
        assert odometry.pose.pose.position.y == pytest.approx(where[1], abs=0.02)
        assert odometry.header.frame_id == 'odom' and odometry.child_frame_id == 'base_link'
        car.sim.drain()
        transform = car.tf[-1].transforms[0]
        assert (transform.header.frame_id, transform.child_frame_id) == ('odom', 'base_link')
        assert transform.transform.translation.x == pytest.approx(
            odometry.pose.pose.position.x)


@pytest.mark.parametrize('type_name', [ACKERMANN, TRICYCLE, BICYCLE])
def test_an_arc_of_one_metre_radius_the_odometry_and_the_truth_agree(tmp_path, type_name):
    with running(tmp_path, type_name) as car:
        odometry = car.update()
        radius = None
        while heading(odometry) < math.pi / 2:  # a quarter circle: 1.57 m at 0.2 m/s
            car.command(0.2, 0.2)
            odometry = car.update()
            if radius is None and heading(odometry) > math.pi / 4:  # turning steadily
                radius = car.true_speed() / car.true_yaw_rate()
        car.sim.drain()
        status = car.states[-1]  # turning: the steering stands where it was sent
        assert status.steer_positions[0] == pytest.approx(status.steering_angle_command[0],
                                                          abs=0.01)
        assert status.steering_angle_command[0] > 0.2
        car.command(0.0, 0.0)
        for _ in range(10):
            odometry = car.update()
        where, yaw, speed = car.true_pose()
        assert radius == pytest.approx(1.0, rel=0.02)
        assert yaw == pytest.approx(math.pi / 2, rel=0.02)
        assert heading(odometry) == pytest.approx(yaw, rel=0.02)
        apart = math.hypot(odometry.pose.pose.position.x - where[0],
                           odometry.pose.pose.position.y - where[1])
        assert apart < 0.02 * (math.pi / 2)  # within 2 % of the arc's length


def test_the_car_stops_once_the_reference_times_out(tmp_path):
    with running(tmp_path, reference_timeout=0.2) as car:
        car.command(0.2, 0.0)
        for _ in range(10):  # 0.1 s: still within the timeout
            car.update()
        assert car.true_pose()[2] == pytest.approx(0.2, rel=0.05)
        for _ in range(50):
            car.update()
        where, yaw, speed = car.true_pose()
        assert abs(speed) < 1e-3
        assert where[0] < 0.2 * 0.4


def test_a_twist_that_is_not_finite_is_refused_with_a_throttled_warning(tmp_path):
    with running(tmp_path) as car:
        log = car.sim.collect(Log, '/rosout', PROBE_QUEUE)
        car.command(0.2, 0.0)
        car.update()
        start = time.monotonic()
        for _ in range(BAD_COUNT):
            car.command(math.nan, 0.0)
            car.command(0.2, math.inf)
        elapsed = time.monotonic() - start
        for _ in range(5):
            car.update()
        assert car.true_pose()[2] == pytest.approx(0.2, rel=0.05)  # the last good one holds
        car.sim.drain()
        warnings = [entry.msg for entry in log if entry.level == Log.WARN and
                    entry.msg.startswith(f'{CONTROLLER}: ignored reference')]
        assert warnings, 'no warning at all'
        assert 'not finite numbers' in warnings[0]
        assert len(warnings) <= 1 + int(elapsed / WARNING_THROTTLE_S)


def test_a_steering_joint_the_robot_lacks_stops_start_up_naming_the_parameter(tmp_path):
    description, controllers = write_steered(tmp_path, BICYCLE, steering_parameters(
        BICYCLE, steering_joints_names=['front_steer_joint']))
    problem = (f"{controllers}: steering_controller.steering_joints_names: joint "
               "'front_steer_joint' is not a movable joint of the robot")
    with pytest.raises(ControllerConfigError, match=re.escape(problem)):
        with sim_node(robot_description_file=str(description),
                      controllers_file=str(controllers), world='ground'):
            pass
    result = sim_process.run('-p', f'robot_description_file:={description}',
                             '-p', f'controllers_file:={controllers}', '-p', 'world:=ground')
    assert problem in sim_process.error_line(result)
