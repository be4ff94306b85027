"""GripperActionController (position_controllers/), without a simulator.

GripperCommand goals as ros2_controllers (jazzy) runs them: a goal succeeds
once the joint is closer than goal_tolerance, stalls after stall_timeout
without moving (succeeding with allow_stalling, else aborted), is preempted
by the next goal (aborted: ROS 2 has no CANCELED without a cancel request)
and canceled on request (both with empty results); max_effort bounds the
force on the fingers; the result carries position, effort, stalled and
reached_goal.  The joint is moved by hand here: each step it goes where the
ideal actuator's velocity target takes it, or stays blocked (an object
between the fingers).  The effort type's own law is
test_effort_gripper_action_controller.py's.
"""

import math

import pytest
from controller_fixtures import DT, raises_naming
from hand_moved_gripper import (
    EFFORT_LIMIT,
    EFFORT_TYPE,
    FINGER,
    FOLLOWER,
    POSITION_TYPE,
    VELOCITY_LIMIT,
    HandMovedGripper,
)

from pan_tilt_sim.controllers import JointHandle, create_controller
from pan_tilt_sim.controllers.framework.base import ActuatorKind
from pan_tilt_sim.controllers.framework.manager import ACTIVE
from pan_tilt_sim.controllers.framework.surface import ActionServer
from pan_tilt_sim.controllers.grippers.gripper_action_controller import GripperRequest
from pan_tilt_sim.controllers.trajectory.trajectory_goal import GoalStatus

JAZZY_DEFAULTS = {'action_monitor_rate': 20.0, 'goal_tolerance': 0.01, 'max_effort': 0.0,
                  'allow_stalling': False, 'stall_velocity_threshold': 0.001,
                  'stall_timeout': 1.0}


# --- parameters ----------------------------------------------------------------------------

@pytest.mark.parametrize('type_name', [POSITION_TYPE, EFFORT_TYPE])
def test_the_defaults_are_jazzys(type_name):
    controller = create_controller('g', type_name, {'joint': 'finger'})
    assert {key: controller.params[key] for key in JAZZY_DEFAULTS} == JAZZY_DEFAULTS
    assert controller.config_warnings == []


@pytest.mark.parametrize(('field', 'value'), [
    ('goal_tolerance', -0.01), ('max_effort', -1.0), ('stall_timeout', -1.0),
    ('action_monitor_rate', 0.05), ('allow_stalling', 'yes'), ('stall_velocity_threshold', 'x'),
    ('joint', ''), ('joint', ['finger'])])
def test_a_wrong_value_is_a_configuration_error_naming_the_field(field, value):
    with raises_naming(f'g.{field}'):
        create_controller('g', POSITION_TYPE, {'joint': 'finger', field: value}, 'f.yaml')


def test_a_missing_joint_is_a_configuration_error():
    with raises_naming('g.joint'):
        create_controller('g', POSITION_TYPE, {'goal_tolerance': 0.01})


def test_a_joint_the_robot_lacks_fails_at_configure_naming_the_joint_field():
    controller = create_controller('g', POSITION_TYPE, {'joint': 'thumb'})
    with raises_naming('g.joint'):
        controller.configure({'finger': JointHandle(FINGER)})


def test_the_mimic_finger_cannot_be_the_commanded_joint():
    controller = create_controller('g', POSITION_TYPE, {'joint': 'follower'})
    with raises_naming('g.joint'):
        controller.configure({'finger': JointHandle(FINGER), 'follower': JointHandle(FOLLOWER)})


def test_the_position_type_has_no_gains_an_unknown_key_is_named_in_a_warning():
    controller = create_controller('g', POSITION_TYPE, {'joint': 'finger',
                                                       'gains': {'finger': {'p': 5.0}}})
    assert controller.config_warnings == ['g.gains.finger.p: unknown parameter, ignored']


# --- surface, interfaces, actuator ---------------------------------------------------------

@pytest.mark.parametrize(('type_name', 'interface', 'kind'), [
    (POSITION_TYPE, 'position', ActuatorKind.IDEAL_POSITION),
    (EFFORT_TYPE, 'effort', ActuatorKind.POSITION_PID)])
def test_it_serves_gripper_command_and_claims_its_packages_interface(type_name, interface, kind):
    gripper = HandMovedGripper(type_name)
    controller = gripper.controller
    assert gripper.manager.state('gripper') == ACTIVE
    assert controller.ros_surface() == (
        ActionServer('~/gripper_cmd', 'control_msgs/action/GripperCommand'),)
    assert controller.command_interfaces() == {'finger': (interface,)}
    assert controller.state_interfaces() == {'finger': ('position', 'velocity')}
    actuator = controller.actuators()['finger']
    assert actuator.kind is kind
    # The ideal actuator's force is the controller's to set (max_effort), every step.
    assert actuator.force_from_controller is (kind is ActuatorKind.IDEAL_POSITION)
    assert 'max_effort' in actuator.describe(FINGER) or actuator.pid is not None
    assert controller.commands_joints


def test_until_the_first_goal_it_holds_where_it_was_activated_with_the_max_effort_parameter():
    gripper = HandMovedGripper(start=0.03, max_effort=12.0)
    gripper.handle.position = 0.031
    gripper.run(0.2)
    assert gripper.controller.command == GripperRequest(0.03, 12.0)
    assert gripper.handle.position == pytest.approx(0.03, abs=1e-6)
    assert gripper.handle.force_limit == 12.0


# --- goals ---------------------------------------------------------------------------------

def test_a_goal_succeeds_once_the_joint_is_closer_than_the_goal_tolerance():
    gripper = HandMovedGripper(start=0.0, goal_tolerance=2.0 ** -6)
    goal = gripper.goal(2.0 ** -5, max_effort=15.0)
    gripper.handle.position = 2.0 ** -6  # exactly the tolerance away: not yet
    gripper.controller.update(gripper.time, DT)
    assert goal.status is GoalStatus.EXECUTING
    gripper.handle.position = 0.0157
    gripper.controller.update(gripper.time, DT)
    assert goal.status is GoalStatus.SUCCEEDED
    assert (goal.result.position, goal.result.effort, goal.result.stalled,
            goal.result.reached_goal) == (0.0157, 15.0, False, True)
    assert gripper.controller.goal is None


def test_after_a_goal_ends_the_joint_is_still_driven_to_its_position():
    gripper = HandMovedGripper(start=0.0)
    goal = gripper.goal(0.04)
    gripper.run(1.0)
    assert goal.status is GoalStatus.SUCCEEDED
    assert gripper.handle.position == pytest.approx(0.04, abs=1e-6)


def test_a_blocked_joint_stalls_after_stall_timeout_and_the_goal_is_aborted():
    gripper = HandMovedGripper(start=0.04, stall_timeout=0.5)
    goal = gripper.goal(0.0, max_effort=8.0)
    gripper.run(0.15, blocked_at=0.02)  # closes onto the object within 0.1 s, rests on it
    assert gripper.handle.position == 0.02
    gripper.run(0.4, blocked_at=0.02)
    assert goal.status is GoalStatus.EXECUTING  # not a full stall_timeout without moving yet
    gripper.run(0.2, blocked_at=0.02)
    assert goal.status is GoalStatus.ABORTED
    assert (goal.result.position, goal.result.effort, goal.result.stalled,
            goal.result.reached_goal) == (0.02, 8.0, True, False)
    gripper.run(0.1, blocked_at=0.02)
    assert gripper.handle.velocity_target < 0.0  # still squeezing toward the goal


def test_with_allow_stalling_a_stalled_goal_succeeds():
    gripper = HandMovedGripper(start=0.04, allow_stalling=True)
    goal = gripper.goal(0.0)
    gripper.run(1.2, blocked_at=0.02)
    assert goal.status is GoalStatus.SUCCEEDED
    assert goal.result.stalled and not goal.result.reached_goal


def test_moving_faster_than_the_stall_velocity_threshold_is_not_stalling():
    gripper = HandMovedGripper(start=0.05, stall_timeout=0.2, stall_velocity_threshold=0.001)
    goal = gripper.goal(0.0)
    controller, handle = gripper.controller, gripper.handle
    for _ in range(400):  # 0.4 s creeping at 2 mm/s: moving
        controller.update(gripper.time, DT)
        handle.velocity = -0.002
        handle.position += handle.velocity * DT
        gripper.time += DT
    assert goal.status is GoalStatus.EXECUTING
    for _ in range(300):  # then 0.5 mm/s: not moving
        controller.update(gripper.time, DT)
        handle.velocity = -0.0005
        gripper.time += DT
    assert goal.status is GoalStatus.ABORTED and goal.result.stalled


def test_a_new_goal_preempts_the_running_one_which_ends_aborted_with_an_empty_result():
    gripper = HandMovedGripper(start=0.0)
    first = gripper.goal(0.04)
    gripper.run(0.05)
    second = gripper.goal(0.01, max_effort=3.0)
    assert first.status is GoalStatus.ABORTED and first.result is None
    assert gripper.controller.goal is second
    assert gripper.controller.command == GripperRequest(0.01, 3.0)
    gripper.run(0.5)
    assert second.status is GoalStatus.SUCCEEDED


def test_a_cancel_holds_where_the_joint_is_with_the_max_effort_parameter():
    gripper = HandMovedGripper(start=0.0, max_effort=5.0)
    goal = gripper.goal(0.04, max_effort=20.0)
    gripper.run(0.05)
    here = gripper.handle.position
    assert 0.0 < here < 0.03
    assert gripper.controller.cancel_goal(goal)
    assert goal.status is GoalStatus.CANCELED and goal.result is None
    assert gripper.controller.command == GripperRequest(here, 5.0)
    gripper.run(0.2)
    assert gripper.handle.position == pytest.approx(here, abs=1e-6)
    assert not gripper.controller.cancel_goal(goal)  # it has ended: nothing to cancel


@pytest.mark.parametrize('reason', ['deactivate', 'reset'])
def test_deactivation_or_a_reset_aborts_the_running_goal_with_the_present_position(reason):
    gripper = HandMovedGripper(start=0.0)
    goal = gripper.goal(0.04, max_effort=9.0)
    gripper.run(0.05)
    here = gripper.handle.position
    if reason == 'deactivate':
        gripper.manager.switch(deactivate=['gripper'])
    else:
        gripper.controller.reset()
    assert goal.status is GoalStatus.ABORTED
    assert (goal.result.position, goal.result.stalled, goal.result.reached_goal) == (
        here, False, False)
    assert goal.reason


@pytest.mark.parametrize(('position', 'max_effort'), [
    (math.nan, 1.0), (math.inf, 1.0), (0.01, math.nan), (0.01, -math.inf), (1e300, 1.0)])
def test_a_goal_that_is_not_finite_is_refused(position, max_effort):
    gripper = HandMovedGripper()
    problem = gripper.controller.check_goal(GripperRequest(position, max_effort))
    assert problem is not None and 'finite' in problem
    assert gripper.controller.check_goal(GripperRequest(0.01, 1.0)) is None


@pytest.mark.parametrize('request_', [GripperRequest(0.01, -10.0), GripperRequest(0.01, -1e-9),
                                      GripperRequest(0.01, 1.0, -0.1)])
def test_a_goal_with_a_negative_cap_is_refused(request_):
    problem = HandMovedGripper().controller.check_goal(request_)
    assert problem is not None and 'must be >= 0' in problem


def test_a_goal_with_max_effort_0_is_taken_as_no_cap():
    assert HandMovedGripper().controller.check_goal(GripperRequest(0.01, 0.0)) is None


# --- how the joint is driven ---------------------------------------------------------------

@pytest.mark.parametrize(('max_effort', 'force'), [
    (5.0, 5.0), (-5.0, 5.0), (0.0, EFFORT_LIMIT), (100.0, EFFORT_LIMIT)])
def test_the_position_type_caps_the_actuators_force_at_max_effort_within_the_limit(
        max_effort, force):
    gripper = HandMovedGripper()
    gripper.goal(0.0, max_effort=max_effort)
    gripper.run(DT)
    assert gripper.handle.force_limit == force


def test_the_position_type_tracks_the_goal_within_the_velocity_limit():
    gripper = HandMovedGripper(start=0.05)
    gripper.goal(0.0)
    gripper.controller.update(0.0, DT)
    assert gripper.handle.velocity_target == -VELOCITY_LIMIT
    gripper.handle.position = 0.0001
    gripper.controller.update(DT, DT)
    assert gripper.handle.velocity_target == pytest.approx(
        -gripper.handle.tracking_gain / DT * 0.0001)
