"""``position_controllers/GripperActionController``: grasp goals; what the gripper types share.

A gripper's one commanded joint (``joint``; the other fingers follow it as
``<mimic>`` joints) goes where control_msgs' ``GripperCommand`` goals say,
with at most their ``max_effort``, as ros2_controllers' (jazzy) gripper
action controllers do.  The node serves the action on ``~/gripper_cmd``
(:mod:`pan_tilt_sim.ros.gripper_action`); the rules live here, in
:class:`GripperActionController` and its :class:`GripperGoal`, which the
effort type (:mod:`.effort_gripper_action_controller`) and the parallel
type (:mod:`.parallel_gripper_action_controller`) build on (see the design notes).

Design notes: docs/design/controllers.md#gripper_action_controllerpy.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from pan_tilt_sim.controllers.framework.base import (
    Actuator,
    ActuatorKind,
    Controller,
    JointHandle,
    is_sane_number,
)
from pan_tilt_sim.controllers.framework.parameter_spec import (
    BOOL,
    DOUBLE,
    Param,
    ParameterSpec,
    gt_eq,
)
from pan_tilt_sim.controllers.framework.shared_parameters import JOINT
from pan_tilt_sim.controllers.framework.surface import ActionServer, Endpoint, GoalStatus

JOINT_FIELD = 'joint'
GOAL_TOLERANCE_FIELD = 'goal_tolerance'
MAX_EFFORT_FIELD = 'max_effort'
ALLOW_STALLING_FIELD = 'allow_stalling'
STALL_VELOCITY_FIELD = 'stall_velocity_threshold'
STALL_TIMEOUT_FIELD = 'stall_timeout'
MONITOR_RATE_FIELD = 'action_monitor_rate'
ACTION_NAME = '~/gripper_cmd'
NOT_RUNNING = "Can't accept new action goals. Controller is not running."
DEACTIVATED_TEXT = 'the controller was deactivated'
RESET_TEXT = 'the simulation was reset'
UNLOADED_TEXT = 'the controller was unloaded'


def gripper_parameters(max_effort: float, *, read_only_rate: bool = False,
                       max_effort_text: str = 'Effort (N or N*m) the joint holds with before '
                       'the first goal and after a cancel.') -> tuple[Param, ...]:
    """Return the entries every gripper action controller has (jazzy's names and defaults).

    ``max_effort``: the type's default, ``max_effort_text`` its description;
    ``read_only_rate``: whether ``action_monitor_rate`` is read-only (the
    parallel type's is).
    """
    return (
        JOINT,
        Param(MONITOR_RATE_FIELD, DOUBLE, 20.0, 'Rate (Hz) at which upstream checks its goal; '
              'here results go out after the batch of steps in which the goal ended.',
              (gt_eq(0.1),), read_only=read_only_rate, simulated=False),
        Param(GOAL_TOLERANCE_FIELD, DOUBLE, 0.01, 'A goal succeeds once the joint is closer '
              'than this to its position (m or rad).', (gt_eq(0.0),)),
        Param(MAX_EFFORT_FIELD, DOUBLE, max_effort, max_effort_text, (gt_eq(0.0),)),
        Param(ALLOW_STALLING_FIELD, BOOL, False, 'A stalled goal succeeds (else it is '
              'aborted).'),
        Param(STALL_VELOCITY_FIELD, DOUBLE, 0.001, 'Speed (m/s or rad/s) at or below which the '
              'joint counts as not moving.'),
        Param(STALL_TIMEOUT_FIELD, DOUBLE, 1.0, 'Time (s) without moving after which a goal '
              'has stalled.', (gt_eq(0.0),)),
    )


@dataclasses.dataclass
class GripperResult:
    """What a goal's result says: the joint's position and effort, and how the goal ended."""

    position: float = 0.0  # m or rad
    effort: float = 0.0  # N or N*m
    stalled: bool = False
    reached_goal: bool = False


@dataclasses.dataclass(frozen=True)
class GripperRequest:
    """What a goal asks for: a position, and the effort and speed to get there with.

    ``max_effort`` (N or N*m) and ``max_velocity`` (m/s or rad/s) are taken
    by their magnitude, each within the joint's URDF limit; 0 or None leaves
    that limit (but see the effort type, which clamps its effort to 0).
    """

    position: float
    max_effort: float
    max_velocity: float | None = None


class GripperGoal:
    """One goal: executing until it succeeds, is aborted or is canceled, then its result."""

    __slots__ = ('status', 'result', 'request', 'reason')

    def __init__(self, request: GripperRequest) -> None:
        self.status = GoalStatus.EXECUTING
        # None: an empty result (a canceled or preempted goal's, as upstream makes it).
        self.result: GripperResult | None = None
        self.request = request
        self.reason = ''  # why it was aborted, when this simulator (not upstream) aborts it

    @property
    def done(self) -> bool:
        """Whether the goal has ended."""
        return self.status is not GoalStatus.EXECUTING

    def end(self, status: GoalStatus, result: GripperResult | None = None,
            reason: str = '') -> None:
        """End the goal with ``result`` (None: an empty one); only the first end counts."""
        if self.done:
            return
        self.status = status
        self.result = result
        self.reason = reason


class GripperActionController(Controller):
    """GripperCommand goals on one joint: the ideal actuator, max_effort its force cap."""

    type_names = ('position_controllers/GripperActionController',)
    parameters = ParameterSpec(gripper_parameters(max_effort=0.0))
    commands_joints = True
    # The command interface the type claims, and the action it serves.
    interface: ClassVar[str] = 'position'
    action_type: ClassVar[str] = 'control_msgs/action/GripperCommand'

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._joint_name: str = self.params[JOINT_FIELD]
        self._tolerance: float = self.params[GOAL_TOLERANCE_FIELD]
        self._default_effort: float = self.params[MAX_EFFORT_FIELD]
        self._allow_stalling: bool = self.params[ALLOW_STALLING_FIELD]
        self._stall_velocity: float = self.params[STALL_VELOCITY_FIELD]
        self._stall_timeout: float = self.params[STALL_TIMEOUT_FIELD]
        self._goal: GripperGoal | None = None
        self._handle: JointHandle | None = None

    # --- what the manager and the node ask --------------------------------------------------

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The one joint this controller commands."""
        return (self._joint_name,)

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the ``~/gripper_cmd`` action."""
        return (ActionServer(ACTION_NAME, self.action_type),)

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the joint's ``position`` (or ``effort``) command interface."""
        return {self._joint_name: (self.interface,)}

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the joint's position and velocity, which every update reads."""
        return {self._joint_name: ('position', 'velocity')}

    def actuators(self) -> dict[str, Actuator]:
        """Return what drives the joint while this controller is active."""
        return {self._joint_name: self._actuator}

    @property
    def goal(self) -> GripperGoal | None:
        """The goal being executed, if any (None once it has ended)."""
        return self._goal

    @property
    def command(self) -> GripperRequest:
        """The position, effort and speed the joint is driven with now."""
        return self._command

    # --- lifecycle ------------------------------------------------------------------------

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the joint (a mimic joint cannot be it) and its limits; then reset."""
        handle = self.handle(joints, self._joint_name, JOINT_FIELD)
        self._handle = handle
        self._effort_limit = handle.spec.effort_limit
        self._velocity_limit = handle.spec.velocity_limit
        self._actuator = self.bind(handle)
        self.reset()

    def bind(self, handle: JointHandle) -> Actuator:
        """Return what drives the joint: here the ideal position actuator."""
        return Actuator(ActuatorKind.IDEAL_POSITION, self.name, force_from_controller=True)

    def reset(self) -> None:
        """Hold the joint where it is (:meth:`hold_request`); a running goal is aborted."""
        self._end_aborted(RESET_TEXT)
        self._set_command(self.hold_request(self._handle.position))
        self._last_movement = 0.0
        self._computed_effort = 0.0

    def deactivate(self) -> None:
        """Abort the running goal (upstream leaves it pending until the next activation)."""
        self._end_aborted(DEACTIVATED_TEXT)

    def abort_goal(self, reason: str) -> None:
        """End the running goal, if any, ABORTED with the present position (``reason``: why)."""
        self._end_aborted(reason)

    # --- goals ----------------------------------------------------------------------------

    def hold_request(self, position: float) -> GripperRequest:
        """Return the command that holds ``position``: before the first goal, after a cancel."""
        return GripperRequest(position, self._default_effort)

    def check_goal(self, request: GripperRequest) -> str | None:
        """Return why ``request`` cannot be run, or None (upstream accepts every goal).

        Stricter than upstream on purpose: a cap (``max_effort``, a parallel
        gripper's velocity) is >= 0, 0 meaning none but the URDF's limit.
        """
        values = (request.position, request.max_effort) + (
            () if request.max_velocity is None else (request.max_velocity,))
        if not all(map(is_sane_number, values)):
            return (f'position {request.position!r}, max_effort {request.max_effort!r} '
                    + ('' if request.max_velocity is None
                       else f'and max velocity {request.max_velocity!r} ')
                    + 'must be finite numbers')
        if request.max_effort < 0.0:
            return (f'max_effort {request.max_effort!r} must be >= 0 (0: no cap but the '
                    "joint's URDF effort limit)")
        if request.max_velocity is not None and request.max_velocity < 0.0:
            return (f'max velocity {request.max_velocity!r} must be >= 0 (0: the '
                    "joint's URDF velocity limit)")
        return None

    def start_goal(self, request: GripperRequest, now: float) -> GripperGoal:
        """Run ``request`` (checked by :meth:`check_goal`) from sim time ``now``; return its goal.

        The goal running before it ends ABORTED with an empty result (preempted).
        """
        if self._goal is not None:
            self._goal.end(GoalStatus.ABORTED)
        self._set_command(request)
        self._last_movement = now
        goal = GripperGoal(request)
        self._goal = goal
        return goal

    def cancel_goal(self, goal: GripperGoal) -> bool:
        """Cancel ``goal`` if it is running: hold here (:meth:`hold_request`).

        Returns whether it was running; it ends CANCELED with an empty result.
        """
        if goal is not self._goal:
            return False
        self._set_command(self.hold_request(self._handle.position))
        goal.end(GoalStatus.CANCELED)
        self._goal = None
        return True

    # --- the step -------------------------------------------------------------------------

    def update(self, time: float, period: float) -> None:
        """Judge the running goal on the measured state, then drive the joint."""
        handle = self._handle
        error = self._command.position - handle.position
        if self._goal is not None:
            self._judge(self._goal, time, error, handle)
        self.drive(handle, error, period)

    def actuation(self) -> Callable[[float], None] | None:
        """Return the ideal actuator (this type's :meth:`drive`): it tracks every step."""
        return self._track if type(self).drive is GripperActionController.drive else None

    def _track(self, time_step: float) -> None:
        handle = self._handle
        self.drive(handle, self._command.position - handle.position, time_step)

    def drive(self, handle: JointHandle, error: float, period: float) -> None:
        """Drive the joint toward the command (the ideal actuator, force at most the cap)."""
        target = handle.tracking_gain / period * error
        limit = self._speed_limit
        handle.velocity_target = (limit if target > limit else
                                  -limit if target < -limit else target)
        handle.force_limit = self._force_limit

    def result_effort(self) -> float:
        """Return the effort a result reports: upstream's position adapter gives max_effort."""
        return self._command.max_effort

    def _judge(self, goal: GripperGoal, time: float, error: float, handle: JointHandle) -> None:
        """Upstream's check_for_success: reached, or stalled, or still going."""
        if abs(error) < self._tolerance:
            self._end(goal, GoalStatus.SUCCEEDED, GripperResult(
                handle.position, self.result_effort(), stalled=False, reached_goal=True))
        elif abs(handle.velocity) > self._stall_velocity:
            self._last_movement = time
        elif time - self._last_movement > self._stall_timeout:
            self._end(goal, GoalStatus.SUCCEEDED if self._allow_stalling else GoalStatus.ABORTED,
                      GripperResult(handle.position, self.result_effort(), stalled=True,
                                    reached_goal=False))

    def _end(self, goal: GripperGoal, status: GoalStatus, result: GripperResult,
             reason: str = '') -> None:
        goal.end(status, result, reason)
        self._goal = None

    def _end_aborted(self, reason: str) -> None:
        goal = self._goal
        if goal is not None:
            self._end(goal, GoalStatus.ABORTED,
                      GripperResult(self._handle.position, self.result_effort()), reason)

    def _set_command(self, request: GripperRequest) -> None:
        """Take a new command: the position, and the force and speed caps it implies."""
        self._command = request
        effort = abs(request.max_effort)
        self._force_limit = (min(effort, self._effort_limit) if effort > 0.0
                             else self._effort_limit)
        speed = self._velocity_limit
        if request.max_velocity:
            speed = min(speed, abs(request.max_velocity))
        self._speed_limit = speed
