"""What every controller action server does with rclpy's goal handles.

The controllers keep each goal's state (pure Python); a server keeps, per
running goal, its :class:`ServerGoalHandle` and a Future that completes when
the goal ends.  These functions end a handle as its goal ended, and cancel
the goal a handle stands for.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from rclpy.action import CancelResponse
from rclpy.action.server import ServerGoalHandle
from rclpy.task import Future

from pan_tilt_sim.controllers.framework.surface import GoalStatus


def end_handle(goal_handle: ServerGoalHandle, status: GoalStatus) -> None:
    """Move ``goal_handle`` to the terminal state of ``status`` (anything else: aborted)."""
    if status is GoalStatus.SUCCEEDED:
        goal_handle.succeed()
    elif status is GoalStatus.CANCELED:
        goal_handle.canceled()
    else:
        goal_handle.abort()


def cancel_running(running: Mapping[Any, tuple[ServerGoalHandle, Future]],
                   goal_handle: ServerGoalHandle, cancel: Callable[[Any], None],
                   poll: Callable[[], None]) -> CancelResponse:
    """Cancel the running goal of ``goal_handle`` (``cancel(goal)``, then ``poll()``).

    A handle whose goal has ended already is refused: its result stands.
    """
    for goal, (handle, _future) in running.items():
        if handle is goal_handle:
            cancel(goal)
            poll()
            return CancelResponse.ACCEPT
    return CancelResponse.REJECT
