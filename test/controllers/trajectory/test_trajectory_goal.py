"""FollowJointTrajectory goals in the joint trajectory controller, without ROS or PyBullet.

The controller drives real JointHandles whose measured state the test sets
by hand, so each tolerance rule of ros2_controllers' JointTrajectoryController
can be put on the spot: which goals are refused and with which code, how a
goal's tolerances override the YAML ``constraints``, when a goal succeeds or
is aborted, and what the joints hold afterwards.
"""

import math

import pytest
from trajectory_fixtures import JOINTS, controller_for, make_handles, trajectory

from pan_tilt_sim.controllers.trajectory.trajectory_goal import (
    GOAL_TOLERANCE_VIOLATED,
    INVALID_GOAL,
    INVALID_JOINTS,
    OLD_HEADER_TIMESTAMP,
    PATH_TOLERANCE_VIOLATED,
    GoalStatus,
    GoalToleranceRequest,
    JointTolerance,
    Tolerances,
    goal_tolerances,
    shortest_angular_distance,
)
from pan_tilt_sim.errors import ControllerConfigError

DT = 0.001


class Follower:
    """Steps the controller; the joints follow the desired state exactly unless told to lag."""

    def __init__(self, controller, handles, lag=None):
        self.controller, self.handles, self.lag = controller, handles, lag or {}
        self.step = -1

    def run_to(self, time):
        while self.step < round(time / DT):
            self.step += 1
            self.controller.update(self.step * DT, DT)
            for name, desired in zip(self.controller.joint_names,
                                     self.controller.desired_positions, strict=True):
                self.handles[name].position = desired - self.lag.get(name, 0.0)
                self.handles[name].velocity = 0.0

    def time(self):
        return self.step * DT


def defaults(controller):
    return controller.default_tolerances


# --- tolerances: the YAML's constraints, a goal's overrides ------------------------------

def test_constraints_give_the_default_tolerances():
    controller = controller_for(constraints={
        'goal_time': 0.5, 'stopped_velocity_tolerance': 0.05,
        'a': {'trajectory': 0.1, 'goal': 0.01}})
    assert controller.default_tolerances == Tolerances(
        path=(JointTolerance(0.1), JointTolerance(0.0)),
        goal=(JointTolerance(0.01, 0.05), JointTolerance(0.0, 0.05)), goal_time=0.5)


def test_without_constraints_only_the_stopped_velocity_tolerance_is_set():
    tolerances = controller_for().default_tolerances
    assert tolerances.goal_time == 0.0
    assert all(t == JointTolerance(0.0, 0.01) for t in tolerances.goal)
    assert all(t == JointTolerance() for t in tolerances.path)


@pytest.mark.parametrize(('constraints', 'field'), [
    ({'goal_time': -1.0}, 'constraints.goal_time'),
    ({'a': {'goal': 'close'}}, 'constraints.a.goal'),
    ({'a': {'trajectory': math.inf}}, 'constraints.a.trajectory'),
    ({'stopped_velocity_tolerance': True}, 'constraints.stopped_velocity_tolerance'),
])
def test_bad_constraints_name_the_field(constraints, field):
    with pytest.raises(ControllerConfigError, match=rf'^test.yaml: arm.{field}: '):
        controller_for(constraints=constraints)


def test_a_goal_tolerance_above_0_replaces_0_keeps_and_minus_1_erases_the_default():
    base = controller_for(constraints={'a': {'trajectory': 0.1, 'goal': 0.01},
                                       'b': {'goal': 0.02}}).default_tolerances
    tolerances, problem = goal_tolerances(
        base, JOINTS, [GoalToleranceRequest('a', 0.3)],
        [GoalToleranceRequest('a', 0.0, -1.0), GoalToleranceRequest('b', -1.0, 0.5)], 0.0)
    assert problem == ''
    assert tolerances.path[0] == JointTolerance(0.3)
    assert tolerances.goal == (JointTolerance(0.01, 0.0), JointTolerance(0.0, 0.5))
    assert goal_tolerances(base, JOINTS, [], [], 2.5)[0].goal_time == 2.5


@pytest.mark.parametrize(('path', 'goal', 'goal_time', 'problem'), [
    ([GoalToleranceRequest('z', 0.1)], [], 0.0, "joint 'z' in goal.path_tolerance"),
    ([], [GoalToleranceRequest('a', -0.5)], 0.0, "joint 'a' in goal.goal_tolerance has an "
                                                 'illegal tolerance -0.5'),
    ([], [], -2.0, 'illegal goal_time_tolerance -2.0'),
])
def test_an_illegal_goal_tolerance_makes_the_whole_goal_use_the_defaults(path, goal, goal_time,
                                                                         problem):
    base = controller_for(constraints={'a': {'goal': 0.01}}).default_tolerances
    tolerances, said = goal_tolerances(
        base, JOINTS, [GoalToleranceRequest('b', 0.7), *path], goal, goal_time)
    assert tolerances is base
    assert problem in said and said.endswith('using the default tolerances')


# --- which goals are refused, with which code ----------------------------------------------

@pytest.mark.parametrize(('goal', 'now', 'code', 'text'), [
    (trajectory((1.0, (0.1,)), names=('a',)), 0.0, INVALID_JOINTS,
     "Joints on incoming trajectory don't match the controller joints"),
    (trajectory((1.0, (0.1, 0.1)), names=('a', 'z')), 0.0, INVALID_JOINTS,
     "Incoming joint z doesn't match the controller's joints"),
    (trajectory((1.0, (0.1, 0.1)), names=('a', 'a')), 0.0, INVALID_JOINTS,
     'named more than once'),
    (trajectory(), 0.0, INVALID_GOAL, 'Empty trajectory received.'),
    (trajectory((1.0, (0.1, 0.1), (0.0, 0.2))), 0.0, INVALID_GOAL,
     'Velocity of last trajectory point of joint b is not zero: 0.200000000000000'),
    (trajectory((1.0, (0.1, 0.1)), start=2.0), 3.5, OLD_HEADER_TIMESTAMP,
     'Received trajectory with non-zero start time (2.000000) that ends in the past '
     '(3.000000)'),
    (trajectory((1.0, (0.1, 0.1)), (0.5, (0.2, 0.2))), 0.0, INVALID_GOAL,
     'Time between points 0 and 1 is not strictly increasing, it is 1.000000 and 0.500000'),
    (trajectory((1.0, (0.1,))), 0.0, INVALID_GOAL,
     'Mismatch between joint_names size (2) and positions (1) at point #0.'),
    (trajectory((1.0, (0.1, 0.1), (), (0.0,))), 0.0, INVALID_GOAL,
     'Mismatch between joint_names size (2) and accelerations (1) at point #0.'),
    (trajectory((1.0, (0.1, 0.1), (), (), (1.0, 1.0))), 0.0, INVALID_GOAL,
     "only supported for controllers using the 'effort' command interface"),
    (trajectory((1.0, (math.nan, 0.1))), 0.0, INVALID_GOAL, 'not a finite number'),
])
def test_goals_it_cannot_follow_are_refused_with_the_code_and_text(goal, now, code, text):
    problem = controller_for().check_goal(goal, now)
    assert problem is not None and problem[0] == code
    assert text in problem[1]


def test_goals_it_can_follow_pass():
    controller = controller_for(command_interfaces=['effort'])
    assert controller.check_goal(trajectory((1.0, (0.1, 0.1), (), (), (1.0, 1.0))), 0.0) is None
    assert controller.check_goal(trajectory((1.0, (0.1, 0.1)), start=2.0), 2.5) is None


def test_options_allow_partial_goals_and_moving_ends():
    controller = controller_for(allow_partial_joints_goal=True,
                                allow_nonzero_velocity_at_trajectory_end=True)
    assert controller.check_goal(trajectory((1.0, (0.3,), (0.5,)), names=('b',)), 0.0) is None
    with pytest.raises(ControllerConfigError, match='allow_partial_joints_goal: '):
        controller_for(allow_partial_joints_goal='yes')


def test_a_partial_goal_holds_the_joints_it_leaves_out():
    handles = make_handles()
    handles['a'].position = 0.4
    controller = controller_for(handles, allow_partial_joints_goal=True)
    follower = Follower(controller, handles)
    goal = controller.start_goal(trajectory((1.0, (0.3,)), names=('b',)), defaults(controller))
    follower.run_to(1.5)
    assert controller.desired_positions == pytest.approx([0.4, 0.3])
    assert goal.status is GoalStatus.SUCCEEDED


# --- running a goal ------------------------------------------------------------------------

def test_a_goal_succeeds_once_its_goal_tolerances_hold_past_the_last_point():
    handles = make_handles()
    controller = controller_for(handles)
    follower = Follower(controller, handles, lag={'a': 0.05})
    goal = controller.start_goal(trajectory((1.0, (1.0, 0.2))), Tolerances(
        path=(JointTolerance(), JointTolerance()),
        goal=(JointTolerance(0.01), JointTolerance(0.01)), goal_time=0.0))
    follower.run_to(2.0)
    assert goal.status is GoalStatus.EXECUTING  # 50 mrad off: it waits (goal_time 0)
    assert controller.goal is goal
    follower.lag = {}
    follower.run_to(2.1)
    assert (goal.status, goal.error_code, goal.error_string) == (
        GoalStatus.SUCCEEDED, 0, 'Goal successfully reached!')
    assert controller.goal is None
    assert controller.desired_positions == [1.0, 0.2]  # the last point is held


def test_with_default_tolerances_a_goal_succeeds_at_the_first_step_past_its_end():
    handles = make_handles()
    controller = controller_for(handles)
    follower = Follower(controller, handles, lag={'a': 0.5})
    goal = controller.start_goal(trajectory((1.0, (1.0, 0.2))), defaults(controller))
    follower.run_to(0.999)
    assert goal.status is GoalStatus.EXECUTING
    follower.run_to(1.001)
    assert goal.status is GoalStatus.SUCCEEDED


def test_breaking_a_path_tolerance_aborts_and_holds_the_measured_position():
    handles = make_handles()
    controller = controller_for(handles)
    follower = Follower(controller, handles)
    tolerances = Tolerances(path=(JointTolerance(0.1), JointTolerance()),
                            goal=(JointTolerance(), JointTolerance()))
    goal = controller.start_goal(trajectory((2.0, (1.5, 0.2))), tolerances)
    follower.run_to(0.5)
    follower.lag = {'a': 0.2}
    follower.run_to(0.6)
    assert (goal.status, goal.error_code, goal.error_string) == (
        GoalStatus.ABORTED, PATH_TOLERANCE_VIOLATED, 'Aborted due to path tolerance violation')
    held = controller.desired_positions
    # Measured at the abort: the desired position a step earlier (1.5 rad over 2 s), 0.2 behind.
    assert held == pytest.approx([0.75 * 0.501 - 0.2, 0.2 * 0.501 / 2.0], abs=1e-9)
    follower.lag = {}
    follower.run_to(3.0)
    assert controller.desired_positions == held  # it holds; the trajectory is gone


def test_the_velocity_error_counts_only_with_an_effort_or_velocity_command_interface():
    for interfaces, counts in ((['effort'], True), (['position'], False)):
        handles = make_handles()
        controller = controller_for(handles, command_interfaces=interfaces)
        follower = Follower(controller, handles)
        goal = controller.start_goal(trajectory((0.5, (0.5, 0.0))), defaults(controller))
        follower.run_to(0.4)
        handles['a'].velocity = 0.5  # still moving when the end comes
        controller.update(0.5, DT)
        assert (goal.status is GoalStatus.EXECUTING) is counts, interfaces
        assert controller.measures_velocity_error is counts


def test_missing_the_goal_for_longer_than_goal_time_tolerance_aborts():
    handles = make_handles()
    controller = controller_for(handles)
    follower = Follower(controller, handles, lag={'b': 0.1})
    goal = controller.start_goal(trajectory((1.0, (0.5, 0.3))), Tolerances(
        path=(JointTolerance(), JointTolerance()),
        goal=(JointTolerance(0.01), JointTolerance(0.01)), goal_time=0.25))
    follower.run_to(1.25)
    assert goal.status is GoalStatus.EXECUTING
    follower.run_to(1.3)
    assert (goal.status, goal.error_code) == (GoalStatus.ABORTED, GOAL_TOLERANCE_VIOLATED)
    assert goal.error_string == 'Aborted due to goal_time_tolerance exceeding by 0.251000 seconds'
    assert controller.desired_positions == pytest.approx([0.5, 0.2])  # held where it is


def test_cancel_holds_where_the_joints_are_and_only_the_running_goal_is_canceled():
    handles = make_handles()
    controller = controller_for(handles)
    follower = Follower(controller, handles)
    old = controller.start_goal(trajectory((1.0, (1.0, 0.2))), defaults(controller))
    goal = controller.start_goal(trajectory((2.0, (1.0, 0.2))), defaults(controller))
    follower.run_to(1.0)
    assert not controller.cancel_goal(old)
    assert controller.cancel_goal(goal)
    assert (goal.status, goal.error_code, goal.error_string) == (GoalStatus.CANCELED, 0, '')
    held = controller.desired_positions
    assert held == pytest.approx([0.5, 0.1], abs=2e-3)
    follower.run_to(3.0)
    assert controller.desired_positions == held


def test_a_new_goal_preempts_the_running_one():
    controller = controller_for()
    first = controller.start_goal(trajectory((1.0, (1.0, 0.2))), defaults(controller))
    second = controller.start_goal(trajectory((1.0, (0.5, 0.2))), defaults(controller))
    assert (first.status, first.error_code, first.error_string) == (
        GoalStatus.ABORTED, INVALID_GOAL, 'Current goal preempted by new incoming action.')
    assert controller.goal is second


def test_a_topic_trajectory_replaces_the_trajectory_and_the_goal_goes_on():
    handles = make_handles()
    controller = controller_for(handles)
    follower = Follower(controller, handles)
    goal = controller.start_goal(trajectory((5.0, (1.0, 0.2))), defaults(controller))
    follower.run_to(1.0)
    controller.set_command(trajectory((0.5, (-0.5, 0.0))))
    follower.run_to(1.45)
    assert goal.status is GoalStatus.EXECUTING
    follower.run_to(1.6)
    assert goal.status is GoalStatus.SUCCEEDED
    assert controller.desired_positions == [-0.5, 0.0]


def test_deactivation_and_reset_abort_the_goal():
    controller = controller_for()
    goal = controller.start_goal(trajectory((1.0, (1.0, 0.2))), defaults(controller))
    controller.deactivate()
    assert (goal.status, goal.error_code, goal.error_string) == (
        GoalStatus.ABORTED, INVALID_GOAL, 'Current goal cancelled during deactivate transition.')
    goal = controller.start_goal(trajectory((1.0, (1.0, 0.2))), defaults(controller))
    controller.reset()
    assert (goal.status, goal.error_code) == (GoalStatus.ABORTED, INVALID_GOAL)
    assert 'reset' in goal.error_string


def test_a_future_stamp_waits_and_the_old_trajectory_cannot_end_the_new_goal():
    handles = make_handles()
    controller = controller_for(handles)
    follower = Follower(controller, handles)
    controller.set_command(trajectory((0.1, (0.2, 0.0))))
    follower.run_to(0.5)  # the old trajectory has ended: it is held
    goal = controller.start_goal(trajectory((1.0, (1.0, 0.2)), start=2.0), defaults(controller))
    follower.run_to(2.9)
    assert goal.status is GoalStatus.EXECUTING
    follower.run_to(3.001)
    assert goal.status is GoalStatus.SUCCEEDED


def test_topic_trajectories_follow_the_yaml_path_constraints_too():
    handles = make_handles()
    controller = controller_for(handles, constraints={'a': {'trajectory': 0.1}})
    follower = Follower(controller, handles)
    controller.set_command(trajectory((2.0, (1.5, 0.2))))
    follower.run_to(0.5)
    follower.lag = {'a': 0.3}
    follower.run_to(0.6)
    assert controller.notices and 'path tolerance broken' in controller.notices[0]
    held = controller.desired_positions
    follower.run_to(1.0)
    assert controller.desired_positions == held


def test_continuous_joints_compare_angles_the_short_way():
    assert shortest_angular_distance(0.1, 2 * math.pi) == pytest.approx(-0.1)
    assert shortest_angular_distance(-3.0, 3.0) == pytest.approx(6.0 - 2 * math.pi)
    handles = make_handles()
    controller = controller_for(handles, joints=['c'])
    handles['c'].position = 2 * math.pi + 0.05
    controller.reset()
    handles['c'].position = 0.05
    assert controller.position_errors() == pytest.approx([0.0], abs=1e-12)
