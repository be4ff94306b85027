"""``joint_trajectory_controller/JointTrajectoryController``: follow waypoints in sim time.

Takes ``trajectory_msgs/msg/JointTrajectory`` on ``<controller>/joint_trajectory``
(as ros2_controllers' controller does; its follow_joint_trajectory action
needs control_msgs, which this simulator does without).

* The message names every joint of the controller, in any order (partial
  goals are rejected); points need increasing ``time_from_start``, finite
  positions (clamped to the joints' limits) and velocities in every point
  or in none.  Accelerations are not used.
* A trajectory starts at its ``header.stamp`` in sim time; a zero stamp
  means now.  Until then the previous trajectory goes on; from then on the
  new one replaces it.  From the desired state at that moment the joints go
  to the first point still in the future -- points already past are
  skipped -- by cubic Hermite interpolation when the points carry
  velocities, linearly otherwise, and hold the last point after the end.
* A joint with PID gains -- ``gains: {<joint>: {p, i, d, i_clamp,
  ff_velocity_scale}}``, else ``gazebo_ros_control/pid_gains/<joint>`` -- is
  driven by effort from a PID on the position error whose derivative acts
  on the velocity error (desired minus measured velocity), plus
  ``ff_velocity_scale`` times the desired velocity, as in ros2_controllers.
* A joint without gains is driven by the ideal actuator (see
  :mod:`~pan_tilt_sim.controllers.actuator`): a velocity motor capped at the
  effort limit tracks the desired position, with the desired velocity as
  feed-forward -- what gz_ros2_control does for a position (or velocity)
  command interface.  Only on the ``effort`` command interface (which has
  no ideal actuator) does a joint without gains fall back to the position
  controller's default PID (p 100, i 0.01, d 10).
* Before the first trajectory every joint holds its position at start.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.controllers.base import (
    MAX_COMMAND_MAGNITUDE,
    Actuator,
    ActuatorKind,
    CommandKind,
    CommandResult,
    JointHandle,
    is_sane_number,
)
from pan_tilt_sim.controllers.gains import (
    GAINS_FIELD,
    choose_gains,
    feedforward_scales,
    joint_gains_from_params,
)
from pan_tilt_sim.controllers.joint_position_controller import DEFAULT_POSITION_GAINS
from pan_tilt_sim.controllers.limits import PositionLimits, clamp_effort
from pan_tilt_sim.controllers.multi_joint import JOINTS_FIELD, MultiJointController
from pan_tilt_sim.controllers.pid import Pid
from pan_tilt_sim.controllers.trajectory import (
    JointTrajectory,
    TrajectoryPlan,
    TrajectoryPoint,
)

COMMAND_INTERFACES_FIELD = 'command_interfaces'
COMMAND_INTERFACES = ('position', 'velocity', 'effort')
EFFORT_INTERFACE = 'effort'
# A knot this close after the start is taken as at the start (float stamps).
TIME_EPSILON = 1e-9


class JointTrajectoryController(MultiJointController):
    """Follows a joint trajectory with one PID per joint."""

    type_names = ('joint_trajectory_controller/JointTrajectoryController',)
    command_topic = 'joint_trajectory'
    command_kind = CommandKind.JOINT_TRAJECTORY

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        interfaces = params.get(COMMAND_INTERFACES_FIELD, [])
        if not isinstance(interfaces, list | tuple) or any(
                interface not in COMMAND_INTERFACES for interface in interfaces):
            raise self.error(COMMAND_INTERFACES_FIELD, f'{interfaces!r} must be a list of '
                             f"{', '.join(COMMAND_INTERFACES)}")
        self._effort_interface = EFFORT_INTERFACE in interfaces
        self._command_interfaces = tuple(interfaces)
        gains = joint_gains_from_params(self, self._joint_names)
        self._gains = [gains.get(joint) for joint in self._joint_names]
        scales = feedforward_scales(self, self._joint_names)
        self._feedforward = [scales[joint] for joint in self._joint_names]

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the ``command_interfaces`` listed, for every joint."""
        return {joint: self._command_interfaces for joint in self._joint_names}

    def pids(self) -> dict[str, Pid]:
        """Return the PID of every joint that has one (their gains may be changed live)."""
        return {joint: pid for joint, pid in zip(self._joint_names, self._pids, strict=True)
                if pid is not None}

    def actuators(self) -> dict[str, Actuator]:
        """Return what drives each joint while this controller is active."""
        return dict(zip(self._joint_names, self._actuators, strict=True))

    def setpoints(self) -> dict[str, float]:
        """Return the desired positions the PIDs track now."""
        return dict(zip(self._joint_names, self._desired_positions, strict=True))

    @property
    def desired_positions(self) -> list[float]:
        """The positions the PIDs track now, per joint."""
        return list(self._desired_positions)

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the joints and their limits; give each a PID or the ideal actuator."""
        self._handles = [self.handle(joints, joint, JOINTS_FIELD) for joint in self._joint_names]
        self._limits = [PositionLimits(handle.spec) for handle in self._handles]
        self._effort_limits = [handle.spec.effort_limit for handle in self._handles]
        self._max_velocities = [handle.spec.velocity_limit for handle in self._handles]
        self._tracking_gains = [handle.tracking_gain for handle in self._handles]
        default = DEFAULT_POSITION_GAINS if self._effort_interface else None
        self._pids: list[Pid | None] = []
        self._actuators: list[Actuator] = []
        for handle, own, limit in zip(self._handles, self._gains, self._effort_limits,
                                      strict=True):
            gains, source = choose_gains(own, f'{self.name}.{GAINS_FIELD}.{handle.name}',
                                         handle, default)
            if gains is None:
                self._pids.append(None)
                self._actuators.append(Actuator(ActuatorKind.IDEAL_POSITION, self.name))
            else:
                pid = Pid(gains.with_default_clamp(limit))
                self._pids.append(pid)
                self._actuators.append(
                    Actuator(ActuatorKind.POSITION_PID, self.name, pid, source))
        count = len(self._handles)
        self._desired_positions = [0.0] * count
        self._desired_velocities = [0.0] * count
        self._indices = range(count)
        self.reset()

    def reset(self) -> None:
        """Hold every joint where it is; forget trajectories and integrals."""
        for index, handle in enumerate(self._handles):
            self._desired_positions[index] = handle.position
            self._desired_velocities[index] = 0.0
            pid = self._pids[index]
            if pid is not None:
                pid.reset()
        self._plan: TrajectoryPlan | None = None
        self._pending: JointTrajectory | None = None

    def set_command(self, value: JointTrajectory) -> CommandResult:
        """Check a trajectory, put it in the controller's joint order and queue it."""
        problem = self._check(value)
        if problem:
            self._problem = f'ignored trajectory: {problem}'
            return CommandResult.REJECTED
        order = [value.joint_names.index(joint) for joint in self._joint_names]
        clamped = set()
        points = []
        for point in value.points:
            positions = []
            for index, column in enumerate(order):
                position, result = self._limits[index].check(point.positions[column])
                if result is CommandResult.CLAMPED:
                    clamped.add(self._joint_names[index])
                positions.append(position)
            velocities = tuple(point.velocities[column] for column in order
                               ) if point.velocities else ()
            points.append(TrajectoryPoint(point.time_from_start, tuple(positions), velocities))
        self._pending = JointTrajectory(self._joint_names, tuple(points), value.start_time)
        if clamped:
            self._problem = (f"trajectory positions of {', '.join(sorted(clamped))} are "
                             "outside the joints' limits; clamped")
            return CommandResult.CLAMPED
        return CommandResult.ACCEPTED

    def update(self, time: float, period: float) -> None:
        """Start a due trajectory, sample the desired state, run the PIDs."""
        pending = self._pending
        if pending is not None and (pending.start_time is None
                                    or time + TIME_EPSILON >= pending.start_time):
            self._start(pending, time)
        desired_positions = self._desired_positions
        desired_velocities = self._desired_velocities
        if self._plan is not None:
            self._plan.sample(time, desired_positions, desired_velocities)
        handles, pids = self._handles, self._pids
        feedforward, effort_limits = self._feedforward, self._effort_limits
        max_velocities, tracking_gains = self._max_velocities, self._tracking_gains
        for index in self._indices:
            handle = handles[index]
            desired_velocity = desired_velocities[index]
            pid = pids[index]
            if pid is None:  # the ideal actuator: track the desired state
                target = desired_velocity + tracking_gains[index] / period * (
                    desired_positions[index] - handle.position)
                limit = max_velocities[index]
                handle.velocity_target = (limit if target > limit else
                                          -limit if target < -limit else target)
                continue
            effort = pid.compute(
                desired_positions[index], handle.position, period,
                handle.velocity - desired_velocity)
            effort += feedforward[index] * desired_velocity
            handle.effort = clamp_effort(effort, effort_limits[index])

    def _start(self, trajectory: JointTrajectory, time: float) -> None:
        """Replace the plan by ``trajectory``, from the desired state at ``time``.

        The first knot is the desired state now -- or a point that falls due
        exactly now; points already past are skipped.
        """
        self._pending = None
        if self._plan is not None:
            self._plan.sample(time, self._desired_positions, self._desired_velocities)
        start = time if trajectory.start_time is None else trajectory.start_time
        past = [point for point in trajectory.points
                if start + point.time_from_start <= time + TIME_EPSILON]
        future = trajectory.points[len(past):]
        cubic = bool(trajectory.points[0].velocities)
        if past and start + past[-1].time_from_start >= time - TIME_EPSILON:
            first = past[-1]  # due now: it is the start
            first_positions, first_velocities = first.positions, first.velocities
        elif future:
            first_positions = self._desired_positions
            first_velocities = self._desired_velocities
        else:  # every point is past: go to the last one and hold it
            self._plan = TrajectoryPlan([time], [trajectory.points[-1].positions], None)
            return
        times = [time] + [start + point.time_from_start for point in future]
        positions = [first_positions] + [point.positions for point in future]
        velocities = ([first_velocities] + [point.velocities for point in future]
                      if cubic else None)
        self._plan = TrajectoryPlan(times, positions, velocities)

    def _check(self, trajectory: Any) -> str:
        """Return what is wrong with ``trajectory``, or '' if it can be followed."""
        if not isinstance(trajectory, JointTrajectory):
            return f'expected a JointTrajectory, got {type(trajectory).__name__}'
        names = trajectory.joint_names
        if len(set(names)) != len(names):
            return 'a joint is named more than once'
        missing = [joint for joint in self._joint_names if joint not in names]
        unknown = [joint for joint in names if joint not in self._joint_names]
        if missing or unknown:
            return (f"joint_names must be this controller's joints "
                    f"({', '.join(self._joint_names)}) in any order; "
                    + '; '.join(filter(None, (
                        f"missing {', '.join(missing)}" if missing else '',
                        f"unknown {', '.join(unknown)}" if unknown else ''))))
        if not trajectory.points:
            return 'no points'
        if trajectory.start_time is not None and not math.isfinite(trajectory.start_time):
            return 'the start time is not finite'
        with_velocities = bool(trajectory.points[0].velocities)
        previous = -math.inf
        for number, point in enumerate(trajectory.points):
            when = point.time_from_start
            if not (math.isfinite(when) and when >= 0.0 and when > previous):
                return f'point {number}: time_from_start {when} must be >= 0 and increasing'
            previous = when
            if len(point.positions) != len(names):
                return (f'point {number}: {len(point.positions)} positions for '
                        f'{len(names)} joints')
            if bool(point.velocities) != with_velocities:
                return 'velocities must be given in every point or in none'
            if with_velocities and len(point.velocities) != len(names):
                return (f'point {number}: {len(point.velocities)} velocities for '
                        f'{len(names)} joints')
            if not all(map(is_sane_number, (*point.positions, *point.velocities))):
                return (f'point {number}: a position or velocity is not a finite number '
                        f'(within +-{MAX_COMMAND_MAGNITUDE:g})')
        return ''

