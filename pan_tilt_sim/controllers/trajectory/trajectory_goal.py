"""FollowJointTrajectory goals in sim time, as ros2_controllers' trajectory controller runs them.

Pure Python: the node turns a ``control_msgs/action/FollowJointTrajectory``
goal into a :class:`~pan_tilt_sim.controllers.trajectory.trajectory.JointTrajectory`
plus :class:`JointTolerance` lists, and the controller runs it.  This module
holds what the controller needs for that:

* the result codes of ``FollowJointTrajectory.Result`` and the result
  strings ros2_controllers sends;
* :class:`Tolerances`: path ("state") and goal tolerances per joint and the
  goal time tolerance -- the controller's defaults from its YAML
  ``constraints`` (:func:`default_tolerances`), overridden by a goal's own
  (:func:`goal_tolerances`: > 0 replaces, 0 keeps the default, -1 erases, any
  other negative value makes the whole goal fall back to the defaults);
* :class:`TrajectoryGoal`: one goal's state machine, executing until it
  succeeds, is aborted or is canceled, with its result code and string.

A tolerance of 0 is not checked, as in ros2_controllers.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.framework.surface import GoalStatus

# control_msgs/action/FollowJointTrajectory Result.error_code
SUCCESSFUL = 0
INVALID_GOAL = -1
INVALID_JOINTS = -2
OLD_HEADER_TIMESTAMP = -3
PATH_TOLERANCE_VIOLATED = -4
GOAL_TOLERANCE_VIOLATED = -5
ERROR_NAMES = {SUCCESSFUL: 'SUCCESSFUL', INVALID_GOAL: 'INVALID_GOAL',
               INVALID_JOINTS: 'INVALID_JOINTS', OLD_HEADER_TIMESTAMP: 'OLD_HEADER_TIMESTAMP',
               PATH_TOLERANCE_VIOLATED: 'PATH_TOLERANCE_VIOLATED',
               GOAL_TOLERANCE_VIOLATED: 'GOAL_TOLERANCE_VIOLATED'}

# The result strings of ros2_controllers' JointTrajectoryController (jazzy).
SUCCEEDED_TEXT = 'Goal successfully reached!'
PATH_VIOLATED_TEXT = 'Aborted due to path tolerance violation'
GOAL_TIME_TEXT = 'Aborted due to goal_time_tolerance exceeding by {:f} seconds'
PREEMPTED_TEXT = 'Current goal preempted by new incoming action.'
DEACTIVATED_TEXT = 'Current goal cancelled during deactivate transition.'
RESET_TEXT = 'Current goal aborted: the simulation was reset.'

# control_msgs/msg/JointTolerance: -1 erases a default tolerance.
ERASE = -1.0
FLOAT_EPSILON = 1.1920929e-07  # std::numeric_limits<float>::epsilon(), as upstream compares
DEFAULT_STOPPED_VELOCITY_TOLERANCE = 0.01
DEFAULT_GOAL_TIME = 0.0
CONSTRAINTS_FIELD = 'constraints'


@dataclasses.dataclass(frozen=True)
class JointTolerance:
    """Bounds on one joint's position, velocity and acceleration error (0: not checked)."""

    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0

    def holds(self, position_error: float, velocity_error: float) -> bool:
        """Whether the errors are within the bounds that are set (acceleration: never measured)."""
        return not ((0.0 < self.position < abs(position_error))
                    or (0.0 < self.velocity < abs(velocity_error)))


@dataclasses.dataclass(frozen=True)
class Tolerances:
    """Path and goal tolerances of a controller's joints, in its joint order, and goal time (s)."""

    path: tuple[JointTolerance, ...]
    goal: tuple[JointTolerance, ...]
    goal_time: float = DEFAULT_GOAL_TIME

    @property
    def checks_anything(self) -> bool:
        """Whether any tolerance is set (all 0: nothing to check, ever)."""
        return any(t.position > 0.0 or t.velocity > 0.0 for t in (*self.path, *self.goal))

    @functools.cached_property
    def checks_path(self) -> bool:
        """Whether any path tolerance is set (all 0: nothing to check before the last point)."""
        return any(t.position > 0.0 or t.velocity > 0.0 for t in self.path)


@dataclasses.dataclass(frozen=True)
class GoalToleranceRequest:
    """A goal's ``JointTolerance`` entry as sent: joint name and three numbers."""

    name: str
    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0


def _number(controller: Any, field: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not (
            math.isfinite(value) and value >= 0.0):
        raise controller.error(field, f'{value!r} must be a number >= 0')
    return float(value)


def default_tolerances(controller: Any, params: Mapping[str, Any],
                       joints: Sequence[str]) -> Tolerances:
    """Return the tolerances the ``constraints`` parameters give (ros2_controllers' defaults).

    ``constraints.goal_time`` (default 0: wait for the goal tolerances
    forever), ``constraints.stopped_velocity_tolerance`` (0.01, the goal
    velocity tolerance of every joint), ``constraints.<joint>.trajectory``
    (path position tolerance, default 0) and ``constraints.<joint>.goal``
    (goal position tolerance, default 0).  ``controller.error`` names a bad field.
    """
    constraints = params.get(CONSTRAINTS_FIELD) or {}
    if not isinstance(constraints, Mapping):
        raise controller.error(CONSTRAINTS_FIELD, f'{constraints!r} must be a mapping')
    goal_time = _number(controller, f'{CONSTRAINTS_FIELD}.goal_time',
                        constraints.get('goal_time', DEFAULT_GOAL_TIME))
    stopped = _number(controller, f'{CONSTRAINTS_FIELD}.stopped_velocity_tolerance',
                      constraints.get('stopped_velocity_tolerance',
                                      DEFAULT_STOPPED_VELOCITY_TOLERANCE))
    path, goal = [], []
    for joint in joints:
        entry = constraints.get(joint) or {}
        if not isinstance(entry, Mapping):
            raise controller.error(f'{CONSTRAINTS_FIELD}.{joint}', f'{entry!r} must be a mapping')
        path.append(JointTolerance(position=_number(
            controller, f'{CONSTRAINTS_FIELD}.{joint}.trajectory', entry.get('trajectory', 0.0))))
        goal.append(JointTolerance(
            position=_number(controller, f'{CONSTRAINTS_FIELD}.{joint}.goal',
                             entry.get('goal', 0.0)),
            velocity=stopped))
    return Tolerances(tuple(path), tuple(goal), goal_time)


def _resolve(default: float, requested: float) -> float:
    """Return a goal's tolerance over a default: > 0 wins, 0 keeps, -1 erases, else ValueError."""
    if requested > 0.0:
        return requested
    if abs(requested - ERASE) < FLOAT_EPSILON:
        return 0.0
    if requested < 0.0 or not math.isfinite(requested):
        raise ValueError(requested)
    return default


def goal_tolerances(defaults: Tolerances, joints: Sequence[str],
                    path: Sequence[GoalToleranceRequest],
                    goal: Sequence[GoalToleranceRequest],
                    goal_time: float) -> tuple[Tolerances, str]:
    """Return the tolerances of a goal, and '' or why the defaults were used instead.

    As ros2_controllers: a joint the controller lacks, or an illegal value
    (negative other than -1), makes the whole goal use the defaults.
    """
    try:
        resolved_time = _resolve(defaults.goal_time, goal_time)
    except ValueError:
        return defaults, (f'illegal goal_time_tolerance {goal_time}; using the default '
                          'tolerances')
    lists = {'path_tolerance': list(defaults.path), 'goal_tolerance': list(defaults.goal)}
    for field, requests in (('path_tolerance', path), ('goal_tolerance', goal)):
        target = lists[field]
        for request in requests:
            if request.name not in joints:
                return defaults, (f"joint '{request.name}' in goal.{field} is not a joint of "
                                  'this controller; using the default tolerances')
            index = list(joints).index(request.name)
            old = target[index]
            try:
                target[index] = JointTolerance(
                    _resolve(old.position, request.position),
                    _resolve(old.velocity, request.velocity),
                    _resolve(old.acceleration, request.acceleration))
            except ValueError as err:
                return defaults, (f"joint '{request.name}' in goal.{field} has an illegal "
                                  f'tolerance {err.args[0]}; using the default tolerances')
    return Tolerances(tuple(lists['path_tolerance']), tuple(lists['goal_tolerance']),
                      resolved_time), ''


class TrajectoryGoal:
    """One FollowJointTrajectory goal: executing until it ends, then its result."""

    __slots__ = ('status', 'error_code', 'error_string', 'tolerances')

    def __init__(self, tolerances: Tolerances) -> None:
        self.status = GoalStatus.EXECUTING
        self.error_code = SUCCESSFUL
        self.error_string = ''
        self.tolerances = tolerances

    @property
    def done(self) -> bool:
        """Whether the goal has ended (succeeded, aborted or canceled)."""
        return self.status is not GoalStatus.EXECUTING

    def end(self, status: GoalStatus, error_code: int = SUCCESSFUL,
            error_string: str = '') -> None:
        """End the goal (only the first end counts)."""
        if self.done:
            return
        self.status = status
        self.error_code = error_code
        self.error_string = error_string


def shortest_angular_distance(start: float, end: float) -> float:
    """Return ``end - start`` wrapped into [-pi, pi] (angles' shortest_angular_distance)."""
    difference = math.fmod(end - start, 2.0 * math.pi)
    if difference > math.pi:
        difference -= 2.0 * math.pi
    elif difference < -math.pi:
        difference += 2.0 * math.pi
    return difference
