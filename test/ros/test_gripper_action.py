"""<controller>/gripper_cmd, from a real rclpy ActionClient, as MoveIt would use it.

The small arm of gripper_fixtures.py on sim_node (real_time_factor 0), its
gripper served by the position gripper action controller
(control_msgs/action/GripperCommand) or the parallel one
(control_msgs/action/ParallelGripperCommand).  Where timing matters the
test holds the physics (``paused``) while it acts.
"""

from __future__ import annotations

import importlib.util

import pytest
from gripper_fixtures import FINGER_JOINT, FINGER_OPEN, MIMIC_JOINT, write_gripper_arm
from node_harness import sim_node
from rclpy.action import ActionClient

pytestmark = pytest.mark.skipif(importlib.util.find_spec('control_msgs') is None,
                                reason='control_msgs is not installed')

ACTION = '/gripper_controller/gripper_cmd'
POSITION_TYPE = 'position_controllers/GripperActionController'
PARALLEL_TYPE = 'parallel_gripper_action_controller/GripperActionController'


def goal_status():
    from action_msgs.msg import GoalStatus

    return GoalStatus


class Gripper:
    """The arm's sim_node and an ActionClient on its gripper_cmd."""

    def __init__(self, sim, action) -> None:
        self.sim = sim
        self.action = action
        self.client = ActionClient(sim.probe, action, ACTION)
        assert sim.spin_until(self.client.server_is_ready), f'no action server {ACTION}'

    def send(self, goal):
        """Send ``goal``; return its goal handle once the server has answered."""
        future = self.client.send_goal_async(goal)
        assert self.sim.spin_until(future.done), 'the goal was never answered'
        return future.result()

    def result(self, handle, budget_s=60.0):
        """Wait for the goal's result; return (status, result)."""
        future = handle.get_result_async()
        assert self.sim.spin_until(future.done, budget_s), (
            f'no result (sim time {self.sim.simulation.time:.3f} s)')
        return future.result().status, future.result().result

    def finger(self) -> float:
        return self.sim.simulation.joint_positions()[FINGER_JOINT]


@pytest.fixture
def gripper_node(tmp_path):
    started = []

    def start(gripper_type=POSITION_TYPE, **params):
        from control_msgs.action import GripperCommand, ParallelGripperCommand

        urdf, controllers = write_gripper_arm(tmp_path, gripper_type, **params)
        context = sim_node(robot_description_file=str(urdf), controllers_file=str(controllers))
        started.append(context)
        action = ParallelGripperCommand if gripper_type == PARALLEL_TYPE else GripperCommand
        return Gripper(context.__enter__(), action)

    yield start
    for context in reversed(started):
        context.__exit__(None, None, None)


def command(gripper, position, max_effort=0.0):
    goal = gripper.action.Goal()
    goal.command.position, goal.command.max_effort = position, max_effort
    return goal


def test_a_goal_succeeds_with_the_finger_within_its_tolerance(gripper_node):
    gripper = gripper_node()
    status, result = gripper.result(gripper.send(command(gripper, 0.04, max_effort=15.0)))
    assert status == goal_status().STATUS_SUCCEEDED
    assert result.reached_goal and not result.stalled
    assert abs(result.position - 0.04) < 0.01
    assert result.effort == 15.0  # the max_effort in force, as upstream reports it
    gripper.sim.run_for(0.5)
    positions = gripper.sim.simulation.joint_positions()
    assert positions[FINGER_JOINT] == pytest.approx(0.04, abs=1e-4)
    assert positions[MIMIC_JOINT] == pytest.approx(0.04, abs=1e-3)


def test_a_goal_past_the_joints_limit_stalls_there_and_is_aborted(gripper_node):
    gripper = gripper_node(stall_timeout=0.5)
    status, result = gripper.result(gripper.send(command(gripper, -0.02)))
    assert status == goal_status().STATUS_ABORTED
    assert result.stalled and not result.reached_goal
    assert result.position == pytest.approx(0.0, abs=1e-3)  # at the lower limit


def test_with_allow_stalling_the_stalled_goal_succeeds(gripper_node):
    gripper = gripper_node(stall_timeout=0.5, allow_stalling=True)
    status, result = gripper.result(gripper.send(command(gripper, -0.02)))
    assert status == goal_status().STATUS_SUCCEEDED
    assert result.stalled and not result.reached_goal


def test_a_new_goal_preempts_the_running_one_which_ends_aborted(gripper_node):
    gripper = gripper_node()
    gripper.sim.node.set_paused(True)  # both goals arrive while the finger has not moved
    first = gripper.send(command(gripper, FINGER_OPEN))
    second = gripper.send(command(gripper, 0.02))
    status, result = gripper.result(first)
    assert status == goal_status().STATUS_ABORTED
    assert (result.position, result.effort, result.stalled, result.reached_goal) == (
        0.0, 0.0, False, False)  # upstream's empty result
    gripper.sim.node.set_paused(False)
    status, result = gripper.result(second)
    assert status == goal_status().STATUS_SUCCEEDED
    assert abs(result.position - 0.02) < 0.01


def test_a_cancel_holds_the_finger_where_it_is_and_the_goal_ends_canceled(gripper_node):
    gripper = gripper_node()
    handle = gripper.send(command(gripper, -0.02))  # stalls at the limit: runs a while
    gripper.sim.run_until_sim_time(0.5)
    gripper.sim.node.set_paused(True)
    cancel = handle.cancel_goal_async()
    assert gripper.sim.spin_until(cancel.done)
    assert len(cancel.result().goals_canceling) == 1
    status, result = gripper.result(handle)
    assert status == goal_status().STATUS_CANCELED
    assert not result.stalled and not result.reached_goal
    held = gripper.finger()
    gripper.sim.node.set_paused(False)
    gripper.sim.run_for(1.0)
    assert gripper.finger() == pytest.approx(held, abs=1e-3)


def test_a_goal_to_an_inactive_controller_is_rejected(gripper_node, capfd):
    gripper = gripper_node()
    gripper.sim.simulation.manager.switch(deactivate=['gripper_controller'])
    handle = gripper.send(command(gripper, 0.03))
    assert not handle.accepted
    assert "Can't accept new action goals. Controller is not running." in capfd.readouterr().err


def test_a_goal_that_is_not_finite_is_rejected_and_nothing_moves(gripper_node, capfd):
    gripper = gripper_node()
    before = gripper.finger()
    handle = gripper.send(command(gripper, float('nan')))
    assert not handle.accepted
    assert 'gripper_controller/gripper_cmd: goal rejected' in capfd.readouterr().err
    gripper.sim.run_for(0.3)
    assert gripper.finger() == pytest.approx(before, abs=1e-4)


def test_a_goal_with_a_negative_max_effort_is_rejected_with_a_warning_and_nothing_moves(
        gripper_node, capfd):
    gripper = gripper_node()
    before = gripper.finger()
    handle = gripper.send(command(gripper, 0.04, max_effort=-10.0))
    assert not handle.accepted
    err = capfd.readouterr().err
    assert 'gripper_controller/gripper_cmd: goal rejected: max_effort -10.0 must be >= 0' in err
    assert 'WARN' in err
    gripper.sim.run_for(0.3)
    assert gripper.finger() == pytest.approx(before, abs=1e-4)
    status, _result = gripper.result(gripper.send(command(gripper, 0.04, max_effort=0.0)))
    assert status == goal_status().STATUS_SUCCEEDED  # 0: no cap, the simulation kept running


def parallel_goal(gripper, positions, efforts=()):
    goal = gripper.action.Goal()
    goal.command.name = [FINGER_JOINT]
    goal.command.position, goal.command.effort = list(positions), list(efforts)
    return goal


def test_a_parallel_goal_succeeds_with_one_position_and_one_effort_in_its_state(gripper_node):
    gripper = gripper_node(PARALLEL_TYPE, max_effort_interface=f'{FINGER_JOINT}/max_effort')
    status, result = gripper.result(gripper.send(parallel_goal(gripper, [0.04], [5.0])))
    assert status == goal_status().STATUS_SUCCEEDED
    assert result.reached_goal and not result.stalled
    assert len(result.state.position) == 1 and abs(result.state.position[0] - 0.04) < 0.01
    assert len(result.state.effort) == 1
    assert abs(result.state.effort[0]) <= 5.0 + 1e-9  # what the actuator applied, within it


@pytest.mark.parametrize('positions', [[], [0.01, 0.02]])
def test_a_parallel_goal_without_exactly_one_position_is_rejected(gripper_node, capfd,
                                                                  positions):
    gripper = gripper_node(PARALLEL_TYPE)
    handle = gripper.send(parallel_goal(gripper, positions))
    assert not handle.accepted
    assert ('Received action goal with wrong number of position values, expects 1, got '
            f'{len(positions)}') in capfd.readouterr().err


def test_a_canceled_parallel_goals_result_has_an_empty_state(gripper_node):
    gripper = gripper_node(PARALLEL_TYPE)
    gripper.sim.node.set_paused(True)
    handle = gripper.send(parallel_goal(gripper, [FINGER_OPEN]))
    cancel = handle.cancel_goal_async()
    assert gripper.sim.spin_until(cancel.done)
    status, result = gripper.result(handle)
    assert status == goal_status().STATUS_CANCELED
    assert (list(result.state.position), list(result.state.effort)) == ([], [])
