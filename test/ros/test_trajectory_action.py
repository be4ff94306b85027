"""<controller>/follow_joint_trajectory, from a real rclpy ActionClient, as MoveIt would use it.

The three-joint arm's ``arm_controller`` (a joint_trajectory_controller on
an effort interface) serves control_msgs/action/FollowJointTrajectory with
ros2_controllers' semantics in sim time: goals it cannot run are rejected,
tolerances abort, cancel and preemption end goals the way ros2_controllers
ends them, and SUCCESSFUL comes only once the goal tolerances hold.
The simulation runs at real_time_factor 0; where timing matters the test
holds the physics (``paused``) while it acts.
"""

from __future__ import annotations

import importlib.util
import math

import pytest
from builtin_interfaces.msg import Duration, Time
from node_harness import sim_node
from rclpy.action import ActionClient
from std_msgs.msg import Float64MultiArray
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from pan_tilt_sim.share import package_share

pytestmark = pytest.mark.skipif(importlib.util.find_spec('control_msgs') is None,
                                reason='control_msgs is not installed')

ARM = package_share() / 'urdf' / 'three_joint_arm.xacro'
CONTROLLERS = package_share() / 'config' / 'three_joint_arm_controllers.yaml'
JOINTS = ['shoulder_joint', 'extend_joint', 'wrist_joint']
ACTION = '/arm_controller/follow_joint_trajectory'
# Three waypoints: every joint moves, the continuous wrist past 2*pi.
WAYPOINTS = [(1.0, [0.5, 0.05, 1.0]), (2.0, [1.0, 0.15, 3.0]), (3.0, [-0.5, 0.10, 7.0])]
WRIST_TIGHT = 0.0002  # rad: the wrist settles within it ~0.1 s after a quick swing
GOAL_TOLERANCE = {'shoulder_joint': 0.01, 'extend_joint': 0.002, 'wrist_joint': 0.02}


def duration(seconds: float) -> Duration:
    whole = math.floor(seconds)
    return Duration(sec=whole, nanosec=round((seconds - whole) * 1e9))


def point(seconds: float, positions, velocities=()) -> JointTrajectoryPoint:
    return JointTrajectoryPoint(positions=list(positions), velocities=list(velocities),
                                time_from_start=duration(seconds))


def tolerance(name, position=0.0, velocity=0.0):
    from control_msgs.msg import JointTolerance

    return JointTolerance(name=name, position=position, velocity=velocity)


class Arm:
    """The arm's sim_node and an ActionClient on its follow_joint_trajectory."""

    def __init__(self, sim) -> None:
        from control_msgs.action import FollowJointTrajectory

        self.sim = sim
        self.Goal = FollowJointTrajectory.Goal
        self.Result = FollowJointTrajectory.Result
        self.feedback = []
        self.client = ActionClient(sim.probe, FollowJointTrajectory, ACTION)
        assert sim.spin_until(self.client.server_is_ready), f'no action server {ACTION}'

    def goal(self, points, joints=JOINTS, **fields):
        return self.Goal(trajectory=JointTrajectory(joint_names=list(joints),
                                                    points=list(points)), **fields)

    def send(self, goal):
        """Send ``goal``; return its goal handle once the server has answered."""
        future = self.client.send_goal_async(goal, feedback_callback=self.feedback.append)
        assert self.sim.spin_until(future.done), 'the goal was never answered'
        return future.result()

    def result(self, handle, budget_s=60.0):
        """Wait for the goal's result; return (status, result)."""
        future = handle.get_result_async()
        assert self.sim.spin_until(future.done, budget_s), (
            f'no result (sim time {self.sim.simulation.time:.3f} s)')
        response = future.result()
        return response.status, response.result

    def positions(self):
        measured = self.sim.simulation.joint_positions()
        return [measured[joint] for joint in JOINTS]


@pytest.fixture
def arm():
    with sim_node(robot_description_file=str(ARM), controllers_file=str(CONTROLLERS)) as sim:
        yield Arm(sim)


def status_names():
    from action_msgs.msg import GoalStatus

    return GoalStatus


def test_a_three_point_goal_succeeds_with_every_joint_within_its_goal_tolerance(arm):
    goal = arm.goal([point(t, p) for t, p in WAYPOINTS],
                    goal_tolerance=[tolerance(j, value) for j, value in GOAL_TOLERANCE.items()],
                    goal_time_tolerance=duration(2.0))
    handle = arm.send(goal)
    assert handle.accepted
    status, result = arm.result(handle)
    final = arm.positions()  # the physics runs on while we read: within tolerance still
    assert status == status_names().STATUS_SUCCEEDED
    assert (result.error_code, result.error_string) == (0, 'Goal successfully reached!')
    assert arm.sim.simulation.time >= 3.0  # not before the last point's time
    for joint, target, position in zip(JOINTS, WAYPOINTS[-1][1], final, strict=True):
        assert abs(position - target) <= GOAL_TOLERANCE[joint], (joint, position)
    # Feedback while it ran: the controller's joints, desired / actual / error.
    assert arm.feedback, 'no feedback'
    feedback = arm.feedback[len(arm.feedback) // 2].feedback
    assert list(feedback.joint_names) == JOINTS
    for index in range(3):
        assert feedback.error.positions[index] == pytest.approx(
            feedback.desired.positions[index] - feedback.actual.positions[index], abs=1e-9)
    stamps = [f.feedback.header.stamp.sec + f.feedback.header.stamp.nanosec * 1e-9
              for f in arm.feedback]
    assert stamps == sorted(stamps) and stamps[-1] - stamps[0] > 2.0


@pytest.mark.parametrize(('case', 'code'), [
    ('unknown joint', 'INVALID_JOINTS'),
    ('missing joint', 'INVALID_JOINTS'),
    ('no points', 'INVALID_GOAL'),
    ('times not increasing', 'INVALID_GOAL'),
    ('moving at the end', 'INVALID_GOAL'),
    ('ends in the past', 'OLD_HEADER_TIMESTAMP'),
    ('too few positions', 'INVALID_GOAL'),
])
def test_goals_it_cannot_run_are_rejected_and_the_log_says_why(arm, capfd, case, code):
    target = [0.3, 0.1, 0.5]
    goal = {
        'unknown joint': lambda: arm.goal([point(1.0, target)],
                                          ['shoulder_joint', 'extend_joint', 'elbow_joint']),
        'missing joint': lambda: arm.goal([point(1.0, target[:2])], JOINTS[:2]),
        'no points': lambda: arm.goal([]),
        'times not increasing': lambda: arm.goal([point(1.0, target), point(1.0, target)]),
        'moving at the end': lambda: arm.goal([point(1.0, target, [0.0, 0.0, 0.5])]),
        'ends in the past': lambda: arm.goal([point(1.0, target)]),
        'too few positions': lambda: arm.goal([point(1.0, target[:2])]),
    }[case]()
    if case == 'ends in the past':
        arm.sim.run_until_sim_time(3.0)
        goal.trajectory.header.stamp = Time(sec=1)  # ends at 2 s of sim time
    before = arm.positions()
    handle = arm.send(goal)
    assert not handle.accepted
    assert f'goal rejected ({code})' in capfd.readouterr().err
    assert arm.positions() == pytest.approx(before, abs=1e-3)  # nothing moved


def test_a_goal_to_an_inactive_controller_is_rejected(arm, capfd):
    arm.sim.simulation.manager.switch(deactivate=['arm_controller'])
    handle = arm.send(arm.goal([point(1.0, [0.3, 0.1, 0.5])]))
    assert not handle.accepted
    assert "Can't accept new action goals. Controller is not running." in capfd.readouterr().err


def test_breaking_a_path_tolerance_aborts_and_the_arm_holds_where_it_is(arm):
    # A 1 s swing of 1.5 rad: the shoulder lags its setpoint by far more than 1 mrad.
    goal = arm.goal([point(1.0, [1.5, 0.0, 0.0])],
                    path_tolerance=[tolerance('shoulder_joint', 0.001)])
    status, result = arm.result(arm.send(goal))
    assert status == status_names().STATUS_ABORTED
    assert (result.error_code, result.error_string) == (
        arm.Result.PATH_TOLERANCE_VIOLATED, 'Aborted due to path tolerance violation')
    stopped_at = arm.sim.simulation.time
    assert stopped_at < 1.0  # long before the end
    setpoints = arm.sim.setpoints('arm_controller')
    arm.sim.run_for(1.0)
    assert setpoints[0] < 0.5  # it holds near where it was, not at the goal
    assert arm.positions()[0] == pytest.approx(setpoints[0], abs=0.01)
    assert arm.sim.setpoints('arm_controller') == setpoints


def test_missing_the_goal_tolerance_past_goal_time_tolerance_aborts(arm):
    # Position only: -1 erases the default goal velocity tolerance (stopped_velocity_tolerance).
    goal = arm.goal([point(0.5, [1.0, 0.1, 1.0])],
                    goal_tolerance=[tolerance(j, 1e-7, -1.0) for j in JOINTS],
                    goal_time_tolerance=duration(0.1))
    status, result = arm.result(arm.send(goal))
    assert status == status_names().STATUS_ABORTED
    assert result.error_code == arm.Result.GOAL_TOLERANCE_VIOLATED
    assert result.error_string.startswith('Aborted due to goal_time_tolerance exceeding by 0.1')
    assert result.error_string.endswith(' seconds')
    late = float(result.error_string.split(' by ')[1].split()[0])
    assert 0.1 < late <= 0.1 + 0.0015  # the first step past it (1 ms steps)


def test_with_goal_time_tolerance_0_it_waits_for_the_goal_tolerance(arm):
    # A wrist swing too quick to follow: at 0.2 s the light wrist lags; it succeeds ~0.1 s later.
    # Paced, so that feedback comes every 50 ms of sim time, as the monitor rate says, at most
    # once per batch of steps; at a quarter of real time a stalled machine's catch-up batch
    # (0.1 s of wall time at most) is 25 ms of sim time, too short to swallow the 90 ms between
    # the last point and the wrist's arrival, as a 100 ms batch at real time could.
    assert all(r.successful for r in arm.sim.set_parameters(real_time_factor=0.25))
    goal = arm.goal([point(0.2, [0.0, 0.0, 3.0])],
                    goal_tolerance=[tolerance(joint, WRIST_TIGHT if joint == 'wrist_joint'
                                              else 0.0, -1.0) for joint in JOINTS])
    status, result = arm.result(arm.send(goal))
    assert status == status_names().STATUS_SUCCEEDED
    assert abs(arm.positions()[2] - 3.0) <= WRIST_TIGHT + 1e-3  # (the physics ran on a little)
    # It was still running, outside the tolerance, after the last point's time.
    since_start = [(f.feedback.actual.time_from_start.sec
                    + f.feedback.actual.time_from_start.nanosec * 1e-9, f.feedback)
                   for f in arm.feedback]
    late = [feedback for elapsed, feedback in since_start if elapsed > 0.205]
    assert late and abs(late[0].error.positions[2]) > WRIST_TIGHT
    assert all(elapsed <= 0.2 + 0.2 for elapsed, _ in since_start)  # not long after, either


def test_cancel_holds_the_arm_where_it_is_and_the_goal_ends_canceled(arm):
    handle = arm.send(arm.goal([point(10.0, [2.0, 0.2, 6.0])]))
    arm.sim.run_until_sim_time(3.0)
    arm.sim.node.set_paused(True)  # cancel while the physics is held: it must still answer
    cancel = handle.cancel_goal_async()
    assert arm.sim.spin_until(cancel.done)
    assert len(cancel.result().goals_canceling) == 1
    status, result = arm.result(handle)
    held = arm.sim.setpoints('arm_controller')
    assert status == status_names().STATUS_CANCELED
    assert (result.error_code, result.error_string) == (0, '')
    # Where it was when the cancel came (as measured at the last step: within a step's travel).
    assert held == pytest.approx(arm.positions(), abs=2e-3)
    arm.sim.node.set_paused(False)
    arm.sim.run_for(2.0)
    assert held[0] < 1.0 and arm.positions() == pytest.approx(held, abs=0.02)


def test_a_new_goal_preempts_the_running_one_which_ends_aborted(arm):
    first = arm.send(arm.goal([point(10.0, [2.0, 0.2, 6.0])]))
    arm.sim.run_until_sim_time(1.0)
    second = arm.send(arm.goal([point(1.0, [-0.3, 0.05, 0.5])],
                               goal_tolerance=[tolerance(j, 0.02) for j in JOINTS],
                               goal_time_tolerance=duration(3.0)))
    status, result = arm.result(first)
    assert status == status_names().STATUS_ABORTED
    assert (result.error_code, result.error_string) == (
        arm.Result.INVALID_GOAL, 'Current goal preempted by new incoming action.')
    status, result = arm.result(second)
    assert status == status_names().STATUS_SUCCEEDED
    assert arm.positions() == pytest.approx([-0.3, 0.05, 0.5], abs=0.03)


def test_a_topic_trajectory_replaces_the_goals_trajectory_and_the_goal_runs_on(arm):
    handle = arm.send(arm.goal([point(10.0, [2.0, 0.2, 6.0])],
                               goal_tolerance=[tolerance(j, 0.02) for j in JOINTS],
                               goal_time_tolerance=duration(3.0)))
    arm.sim.run_until_sim_time(0.5)
    arm.sim.command('arm_controller', JointTrajectory(
        joint_names=JOINTS, points=[point(1.0, [0.4, 0.08, -1.0])]))
    status, result = arm.result(handle)
    assert status == status_names().STATUS_SUCCEEDED
    assert arm.sim.simulation.time < 10.0  # at the topic trajectory's end, not the goal's
    assert arm.positions() == pytest.approx([0.4, 0.08, -1.0], abs=0.03)


def test_the_gripper_topic_still_works_beside_the_action(arm):
    arm.sim.command('gripper_controller', Float64MultiArray(data=[0.03]))
    arm.sim.run_for(1.0)
    assert arm.sim.simulation.joint_positions()['left_finger_joint'] == pytest.approx(
        0.03, abs=2e-3)
