"""``<controller>/gripper_cmd``: a gripper action controller's action server.

``control_msgs/action/GripperCommand`` (:class:`GripperCommandServer`) and
``control_msgs/action/ParallelGripperCommand``
(:class:`ParallelGripperCommandServer`), served with rclpy's ActionServer
on sim_node's one executor.  The goals' rules are the controller's
(:mod:`pan_tilt_sim.controllers.grippers.gripper_action_controller`); these classes
only translate (see the design notes).

Design notes: docs/design/ros.md#gripper_actionpy.
"""

from __future__ import annotations

import abc
from collections.abc import Callable
from typing import Any

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.action.server import ServerGoalHandle
from rclpy.node import Node
from rclpy.task import Future

from pan_tilt_sim.controllers.grippers.gripper_action_controller import (
    NOT_RUNNING,
    UNLOADED_TEXT,
    GripperActionController,
    GripperGoal,
    GripperRequest,
    GripperResult,
)
from pan_tilt_sim.ros.goal_handles import cancel_running, end_handle

ACTION = 'gripper_cmd'
WARNING_THROTTLE_S = 1.0  # wall seconds between two warnings about refused goals


class GripperActionServer(abc.ABC):
    """The gripper_cmd action of one gripper action controller (see the subclasses)."""

    def __init__(self, node: Node, controller: GripperActionController, action_name: str, *,
                 now: Callable[[], float], is_active: Callable[[], bool]) -> None:
        self._type = self.action_type()
        self._controller = controller
        self._now = now
        self._is_active = is_active
        self._logger = node.get_logger()
        self._label = f'{controller.name}/{ACTION}'
        # Goals accepted and not yet finished: goal -> (handle, Future completed when it ends).
        self._running: dict[GripperGoal, tuple[ServerGoalHandle, Future]] = {}
        self._goals: dict[int, GripperGoal] = {}  # by id(goal handle)
        self.name = action_name
        self._server = ActionServer(
            node, self._type, action_name, execute_callback=self._execute,
            goal_callback=self._on_goal, handle_accepted_callback=self._on_accepted,
            cancel_callback=self._on_cancel)

    # --- the action type's messages (the subclasses) ------------------------------------------

    @staticmethod
    @abc.abstractmethod
    def action_type() -> Any:
        """Return the action's class."""

    @abc.abstractmethod
    def request(self, command: Any) -> tuple[GripperRequest | None, str]:
        """Return the request a goal's ``command`` makes, or None and why it cannot be run."""

    @abc.abstractmethod
    def result_message(self, result: GripperResult | None) -> Any:
        """Return the action's Result message for ``result`` (None: an empty one)."""

    # --- rclpy callbacks (the executor's thread, between batches of physics steps) -------------

    def _on_goal(self, goal) -> GoalResponse:
        if not self._is_active():
            self._logger.error(f'{self._label}: {NOT_RUNNING}')
            return GoalResponse.REJECT
        request, problem = self.request(goal.command)
        if request is not None:
            problem = self._controller.check_goal(request) or ''
        if problem:
            self._logger.warning(f'{self._label}: goal rejected: {problem}',
                                 throttle_duration_sec=WARNING_THROTTLE_S)
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def _on_accepted(self, goal_handle: ServerGoalHandle) -> None:
        request, _problem = self.request(goal_handle.request.command)
        goal = self._controller.start_goal(request, self._now())
        self._running[goal] = (goal_handle, Future())
        self._goals[id(goal_handle)] = goal
        self.poll()  # the goal it preempted ends now
        goal_handle.execute()

    async def _execute(self, goal_handle: ServerGoalHandle):
        goal = self._goals.pop(id(goal_handle))
        running = self._running.get(goal)
        if running is not None:
            await running[1]
        if goal.reason:
            self._logger.warning(f'{self._label}: goal aborted: {goal.reason}')
        end_handle(goal_handle, goal.status)
        return self.result_message(goal.result)

    def _on_cancel(self, goal_handle: ServerGoalHandle) -> CancelResponse:
        return cancel_running(self._running, goal_handle, self._controller.cancel_goal,
                              self.poll)

    # --- called by the node ---------------------------------------------------------------------

    def needs_attention(self) -> bool:
        """Whether :meth:`poll` has something to do: a goal has ended.

        Cheap, and touches no rclpy entity: asked after every batch of steps,
        from whichever thread runs the physics.
        """
        return any(goal.done for goal in self._running)

    def poll(self) -> None:
        """Complete the Futures of goals that have ended (on the executor)."""
        for goal, (_handle, future) in list(self._running.items()):
            if goal.done:
                del self._running[goal]
                future.set_result(goal.status)

    def destroy(self) -> None:
        """Abort what runs (the controller is going away) and remove the action server."""
        self._controller.abort_goal(UNLOADED_TEXT)
        self.poll()
        self._server.destroy()


class GripperCommandServer(GripperActionServer):
    """``control_msgs/action/GripperCommand``: position and max_effort in, result out."""

    @staticmethod
    def action_type() -> Any:
        """Return control_msgs' GripperCommand action."""
        from control_msgs.action import GripperCommand

        return GripperCommand

    def request(self, command: Any) -> tuple[GripperRequest | None, str]:
        """Return the request of a ``control_msgs/msg/GripperCommand``."""
        return GripperRequest(command.position, command.max_effort), ''

    def result_message(self, result: GripperResult | None) -> Any:
        """Return the Result: position, effort, stalled, reached_goal (empty: all zero)."""
        if result is None:
            return self._type.Result()
        return self._type.Result(position=result.position, effort=result.effort,
                                 stalled=result.stalled, reached_goal=result.reached_goal)


class ParallelGripperCommandServer(GripperActionServer):
    """``control_msgs/action/ParallelGripperCommand``: a JointState in, a JointState out."""

    @staticmethod
    def action_type() -> Any:
        """Return control_msgs' ParallelGripperCommand action."""
        from control_msgs.action import ParallelGripperCommand

        return ParallelGripperCommand

    def request(self, command: Any) -> tuple[GripperRequest | None, str]:
        """Return the request of a ``sensor_msgs/msg/JointState`` command (one position)."""
        return self._controller.goal_request(list(command.position), list(command.velocity),
                                             list(command.effort))

    def result_message(self, result: GripperResult | None) -> Any:
        """Return the Result: ``state`` with one position and one effort, stalled, reached_goal.

        An empty result has a ``state`` without entries.
        """
        if result is None:
            return self._type.Result()
        message = self._type.Result(stalled=result.stalled, reached_goal=result.reached_goal)
        message.state.position = [result.position]
        message.state.effort = [result.effort]
        return message
