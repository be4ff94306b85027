"""The sim_node program with the ROS 2 toolchain: spawner calls, then a MoveIt-style action goal.

Started as a ros2_control launch file with spawners starts it
(``autostart_controllers:=false``, real_time_factor 1, its physics in its
own thread), sim_node's controller_manager answers jazzy spawner.py's calls
between two batches of physics, and the spawned joint trajectory
controller's follow_joint_trajectory action ends its goals -- succeeded,
canceled -- in about the time the trajectory takes.
"""

from __future__ import annotations

import importlib.util
import signal
import time

import pytest
import sim_process
from builtin_interfaces.msg import Duration
from node_harness import NodeHarness
from rclpy.action import ActionClient
from spawner_client import Spawner
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from pan_tilt_sim.share import package_share

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('control_msgs') is None
    or importlib.util.find_spec('controller_manager_msgs') is None,
    reason='control_msgs or controller_manager_msgs is not installed')

ARM = package_share() / 'urdf' / 'three_joint_arm.xacro'
JOINTS = ['shoulder_joint', 'extend_joint', 'wrist_joint']
STOP_BUDGET_S = 10.0
# A 1 s trajectory at real_time_factor 1 ends within this much wall time of being sent
# (DDS, the goal tolerances settling and a loaded machine included).
RESULT_BUDGET_S = 4.0


@pytest.fixture
def program():
    process = sim_process.start('-p', f'robot_description_file:={ARM}',
                                '-p', 'autostart_controllers:=false',
                                '-p', 'real_time_factor:=1.0')
    harness = NodeHarness()
    try:
        yield harness
    finally:
        harness.close()
        process.send_signal(signal.SIGINT)
        _out, err = process.communicate(timeout=STOP_BUDGET_S)
        assert process.returncode == 0, err


def test_spawned_controllers_serve_follow_joint_trajectory_in_the_program(program):
    from action_msgs.msg import GoalStatus
    from control_msgs.action import FollowJointTrajectory
    from control_msgs.msg import JointTolerance

    spawner = Spawner(program)
    assert spawner.controllers() == {}
    assert spawner.spawn('joint_state_broadcaster') == 0
    assert spawner.spawn('arm_controller') == 0
    assert {name: c.state for name, c in spawner.controllers().items()} == {
        'joint_state_broadcaster': 'active', 'arm_controller': 'active'}

    client = ActionClient(program.probe, FollowJointTrajectory,
                          '/arm_controller/follow_joint_trajectory')
    assert program.spin_until(client.server_is_ready)
    goal = FollowJointTrajectory.Goal(
        trajectory=JointTrajectory(joint_names=JOINTS, points=[JointTrajectoryPoint(
            positions=[0.6, 0.1, 1.5], time_from_start=Duration(sec=1))]),
        goal_tolerance=[JointTolerance(name=joint, position=0.02) for joint in JOINTS],
        goal_time_tolerance=Duration(sec=2))
    started = time.monotonic()
    sent = client.send_goal_async(goal)
    assert program.spin_until(sent.done) and sent.result().accepted
    result = sent.result().get_result_async()
    assert program.spin_until(result.done, RESULT_BUDGET_S), 'no result in time'
    took = time.monotonic() - started
    assert result.result().status == GoalStatus.STATUS_SUCCEEDED
    assert result.result().result.error_string == 'Goal successfully reached!'
    assert took > 0.9  # not before the trajectory's second of sim time

    # A long goal, canceled: it ends canceled at once, the arm held where it was.
    long_goal = FollowJointTrajectory.Goal(trajectory=JointTrajectory(
        joint_names=JOINTS, points=[JointTrajectoryPoint(
            positions=[-1.0, 0.15, -2.0], time_from_start=Duration(sec=30))]))
    sent = client.send_goal_async(long_goal)
    assert program.spin_until(sent.done) and sent.result().accepted
    program.spin_for(0.5)
    cancel = sent.result().cancel_goal_async()
    assert program.spin_until(cancel.done)
    result = sent.result().get_result_async()
    assert program.spin_until(result.done, RESULT_BUDGET_S)
    assert result.result().status == GoalStatus.STATUS_CANCELED
