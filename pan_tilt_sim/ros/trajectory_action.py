"""``<controller>/follow_joint_trajectory``: a joint trajectory controller's action server.

``control_msgs/action/FollowJointTrajectory`` (built by the standalone path,
or a ROS install's), served with rclpy's ActionServer on sim_node's one
executor, with ros2_controllers' semantics in sim time (the rules are the
controller's, :mod:`pan_tilt_sim.controllers.trajectory.joint_trajectory_controller`).

Design notes: docs/design/ros.md#trajectory_actionpy.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.action.server import ServerGoalHandle
from rclpy.node import Node
from rclpy.task import Future

from pan_tilt_sim.controllers.trajectory.joint_trajectory_controller import (
    JointTrajectoryController,
)
from pan_tilt_sim.controllers.trajectory.trajectory_goal import (
    ERROR_NAMES,
    INVALID_GOAL,
    GoalStatus,
    GoalToleranceRequest,
    TrajectoryGoal,
    goal_tolerances,
)
from pan_tilt_sim.ros.goal_handles import cancel_running, end_handle
from pan_tilt_sim.ros.ros_interfaces import joint_trajectory, seconds, stamp

ACTION = 'follow_joint_trajectory'
NOT_RUNNING = "Can't accept new action goals. Controller is not running."


def _tolerance_requests(entries) -> list[GoalToleranceRequest]:
    return [GoalToleranceRequest(entry.name, entry.position, entry.velocity, entry.acceleration)
            for entry in entries]


class TrajectoryActionServer:
    """The follow_joint_trajectory action of one joint trajectory controller."""

    def __init__(self, node: Node, controller: JointTrajectoryController, action_name: str, *,
                 now: Callable[[], float], is_active: Callable[[], bool]) -> None:
        from control_msgs.action import FollowJointTrajectory

        self._type = FollowJointTrajectory
        self._controller = controller
        self._now = now
        self._is_active = is_active
        self._logger = node.get_logger()
        self._label = f'{controller.name}/{ACTION}'
        # Goals accepted and not yet finished: goal -> (handle, Future completed when it ends).
        self._running: dict[TrajectoryGoal, tuple[ServerGoalHandle, Future]] = {}
        self._goals: dict[int, TrajectoryGoal] = {}  # by id(goal handle)
        self._feedback = FollowJointTrajectory.Feedback()
        self._feedback.joint_names = list(controller.joint_names)
        self._last_feedback = -math.inf
        self.name = action_name
        self._server = ActionServer(
            node, FollowJointTrajectory, action_name,
            execute_callback=self._execute, goal_callback=self._on_goal,
            handle_accepted_callback=self._on_accepted, cancel_callback=self._on_cancel)

    # --- rclpy callbacks (the executor's thread, between batches of physics steps) -------------

    def _on_goal(self, request) -> GoalResponse:
        if not self._is_active():
            self._logger.error(f'{self._label}: {NOT_RUNNING}')
            return GoalResponse.REJECT
        problem = self._controller.check_goal(joint_trajectory(request.trajectory), self._now())
        if problem is not None:
            code, text = problem
            self._logger.error(f'{self._label}: goal rejected ({ERROR_NAMES[code]}): {text}')
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def _on_accepted(self, goal_handle: ServerGoalHandle) -> None:
        request = goal_handle.request
        controller = self._controller
        tolerances, problem = goal_tolerances(
            controller.default_tolerances, controller.joint_names,
            _tolerance_requests(request.path_tolerance),
            _tolerance_requests(request.goal_tolerance), seconds(request.goal_time_tolerance))
        if problem:
            self._logger.error(f'{self._label}: {problem}')
        goal = controller.start_goal(joint_trajectory(request.trajectory), tolerances)
        self._running[goal] = (goal_handle, Future())
        self._goals[id(goal_handle)] = goal
        self._last_feedback = -math.inf
        self.poll()  # the goal it preempted ends now
        goal_handle.execute()

    async def _execute(self, goal_handle: ServerGoalHandle):
        goal = self._goals.pop(id(goal_handle))
        running = self._running.get(goal)
        if running is not None:
            await running[1]
        result = self._type.Result(error_code=goal.error_code, error_string=goal.error_string)
        end_handle(goal_handle, goal.status)
        return result

    def _on_cancel(self, goal_handle: ServerGoalHandle) -> CancelResponse:
        return cancel_running(self._running, goal_handle, self._controller.cancel_goal,
                              self.poll)

    # --- called by the node ---------------------------------------------------------------------

    def needs_attention(self) -> bool:
        """Whether :meth:`poll` has something to do: a goal ended, or feedback is due.

        Cheap, and touches no rclpy entity: asked after every batch of steps,
        from whichever thread runs the physics.
        """
        if not self._running:
            return False
        if any(goal.done for goal in self._running):
            return True
        return self._controller.goal is not None and self._controller.following and (
            self._now() - self._last_feedback >= self._controller.monitor_period - 1e-9)

    def poll(self) -> None:
        """Complete the Futures of goals that have ended; send feedback of the running one.

        Runs on the executor (between batches of steps): after
        :meth:`needs_attention` said so, and after callbacks that end goals.
        """
        if not self._running:
            return
        for goal, (_handle, future) in list(self._running.items()):
            if goal.done:
                del self._running[goal]
                future.set_result(goal.status)
        goal = self._controller.goal
        if goal is None or goal not in self._running or not self._controller.following:
            return
        now = self._now()
        if now - self._last_feedback < self._controller.monitor_period - 1e-9:
            return
        self._last_feedback = now
        self._running[goal][0].publish_feedback(self._fill_feedback(now))

    def _fill_feedback(self, now: float):
        controller = self._controller
        desired_p, desired_v, actual_p, actual_v, start = controller.feedback()
        feedback = self._feedback
        stamp(now, feedback.header.stamp)
        feedback.desired.positions, feedback.desired.velocities = desired_p, desired_v
        feedback.actual.positions, feedback.actual.velocities = actual_p, actual_v
        feedback.error.positions = controller.position_errors()
        feedback.error.velocities = (
            [d - a for d, a in zip(desired_v, actual_v, strict=True)]
            if controller.measures_velocity_error else [0.0] * len(desired_v))
        elapsed = stamp(max(0.0, now - start))
        for point in (feedback.desired, feedback.actual, feedback.error):
            point.time_from_start.sec, point.time_from_start.nanosec = (
                elapsed.sec, elapsed.nanosec)
        return feedback

    def destroy(self) -> None:
        """Abort what runs (the controller is going away) and remove the action server."""
        for goal, (_handle, future) in list(self._running.items()):
            goal.end(GoalStatus.ABORTED, INVALID_GOAL, 'The controller was unloaded.')
            future.set_result(goal.status)
        self._running.clear()
        self._server.destroy()
