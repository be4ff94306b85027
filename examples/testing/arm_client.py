"""A user's trajectory client: moves an arm through control_msgs' FollowJointTrajectory action."""

from __future__ import annotations

from collections.abc import Sequence

from builtin_interfaces.msg import Duration
from control_msgs.action import FollowJointTrajectory
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.task import Future
from trajectory_msgs.msg import JointTrajectoryPoint

ACTION = '/arm_controller/follow_joint_trajectory'
JOINTS = ('shoulder_joint', 'extend_joint', 'wrist_joint')


class ArmClient(Node):
    """Sends one-point trajectories; :meth:`move_to` returns a future of the action's result."""

    def __init__(self, **kwargs) -> None:
        super().__init__('arm_client', **kwargs)
        self._client = ActionClient(self, FollowJointTrajectory, ACTION)

    def ready(self) -> bool:
        """Whether the action server is there."""
        return self._client.server_is_ready()

    def move_to(self, positions: Sequence[float], seconds: float) -> Future:
        """Go to ``positions`` (rad, m, rad) in ``seconds``; the future gets the Result."""
        goal = FollowJointTrajectory.Goal()
        goal.trajectory.joint_names = list(JOINTS)
        goal.trajectory.points = [JointTrajectoryPoint(
            positions=[float(p) for p in positions],
            time_from_start=Duration(sec=int(seconds), nanosec=round(seconds % 1 * 1e9)))]
        done = Future()

        def accepted(sent: Future) -> None:
            handle = sent.result()
            if not handle.accepted:
                done.set_exception(RuntimeError('the arm rejected the goal'))
                return
            handle.get_result_async().add_done_callback(
                lambda result: done.set_result(result.result().result))

        self._client.send_goal_async(goal).add_done_callback(accepted)
        return done
