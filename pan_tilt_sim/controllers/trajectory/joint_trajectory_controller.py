"""``joint_trajectory_controller/JointTrajectoryController``: follow waypoints in sim time.

Takes ``trajectory_msgs/msg/JointTrajectory`` on ``<controller>/joint_trajectory``
as ros2_controllers' controller does, and FollowJointTrajectory goals (below;
the node serves them as ``<controller>/follow_joint_trajectory``).  As
upstream, it reports its state on ``<controller>/controller_state`` every
update (:meth:`JointTrajectoryController.connect_state`) and answers
``<controller>/query_state`` (:meth:`~JointTrajectoryController.query_state`).

Design notes: docs/design/controllers.md#joint_trajectory_controllerpy.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.framework.base import (
    MAX_COMMAND_MAGNITUDE,
    Actuator,
    ActuatorKind,
    CommandKind,
    CommandResult,
    JointHandle,
    is_sane_number,
)
from pan_tilt_sim.controllers.framework.multi_joint import JOINTS_FIELD, MultiJointController
from pan_tilt_sim.controllers.framework.parameter_spec import (
    BOOL,
    DOUBLE,
    STRING,
    STRING_ARRAY,
    Param,
    Validator,
    gt_eq,
    one_of,
    unique,
)
from pan_tilt_sim.controllers.framework.shared_parameters import joint_gains
from pan_tilt_sim.controllers.framework.surface import (
    ActionServer,
    Endpoint,
    Service,
    StateTopic,
    TrajectoryStateAnswer,
)
from pan_tilt_sim.controllers.toolbox.gains import (
    DEFAULT_POSITION_GAINS,
    GAINS_FIELD,
    choose_gains,
    feedforward_scales,
    joint_gains_from_params,
)
from pan_tilt_sim.controllers.toolbox.limits import PositionLimits, clamp_effort
from pan_tilt_sim.controllers.toolbox.pid import Pid
from pan_tilt_sim.controllers.trajectory.trajectory import (
    JointTrajectory,
    TrajectoryPlan,
    TrajectoryPoint,
)
from pan_tilt_sim.controllers.trajectory.trajectory_goal import (
    CONSTRAINTS_FIELD,
    DEACTIVATED_TEXT,
    DEFAULT_GOAL_TIME,
    DEFAULT_STOPPED_VELOCITY_TOLERANCE,
    FLOAT_EPSILON,
    GOAL_TIME_TEXT,
    GOAL_TOLERANCE_VIOLATED,
    INVALID_GOAL,
    INVALID_JOINTS,
    OLD_HEADER_TIMESTAMP,
    PATH_TOLERANCE_VIOLATED,
    PATH_VIOLATED_TEXT,
    PREEMPTED_TEXT,
    RESET_TEXT,
    SUCCEEDED_TEXT,
    GoalStatus,
    Tolerances,
    TrajectoryGoal,
    default_tolerances,
    shortest_angular_distance,
)
from pan_tilt_sim.model.robot import JointKind

COMMAND_INTERFACES_FIELD = 'command_interfaces'
COMMAND_INTERFACES = ('position', 'velocity', 'acceleration', 'effort')
EFFORT_INTERFACE = 'effort'
STATE_INTERFACES_FIELD = 'state_interfaces'
STATE_INTERFACES = ('position', 'velocity', 'acceleration')
DEFAULT_STATE_INTERFACES = ('position', 'velocity')
MONITOR_RATE_FIELD = 'action_monitor_rate'
DEFAULT_MONITOR_RATE = 20.0  # Hz: how often a goal's feedback is sent
PARTIAL_FIELD = 'allow_partial_joints_goal'
NONZERO_END_FIELD = 'allow_nonzero_velocity_at_trajectory_end'
# A knot this close after the start is taken as at the start (float stamps).
TIME_EPSILON = 1e-9
CONTROLLER_STATE = 'control_msgs/msg/JointTrajectoryControllerState'
QUERY_STATE = 'control_msgs/srv/QueryTrajectoryState'
# ros2_controllers' texts for a query_state it cannot answer.
NOT_ACTIVE_TEXT = "Can't sample trajectory. Controller is not active."
NO_TRAJECTORY_TEXT = 'Currently there is no valid trajectory instance.'
BEFORE_START_TEXT = 'Requested sample time is earlier than the current trajectory start time.'
AFTER_END_TEXT = 'Requested sample time precedes the current trajectory end time.'
# What ~/controller_state's sink takes: time (s), then the reference (positions, velocities,
# accelerations), feedback (positions, velocities), error (positions, velocities) and output
# (positions, efforts), per joint; an empty list is a field the message leaves empty.
StateSink = Callable[[float, tuple[list[float], list[float], list[float]],
                      tuple[list[float], list[float]], tuple[list[float], list[float]],
                      tuple[list[float], list[float]]], None]


def command_interfaces_problem(interfaces: Sequence[str]) -> str | None:
    """Return what is wrong with a combination of command interfaces, as upstream says; or None.

    ros2_controllers (jazzy) takes ``position``, ``velocity`` or ``effort``
    alone, or ``position`` with ``velocity``, ``acceleration`` or both, or
    with ``effort``; its texts for the others are returned.
    """
    if 'velocity' in interfaces and len(interfaces) > 1 and 'position' not in interfaces:
        return ("'velocity' command interface can be used either alone or 'position' "
                'command interface has to be present')
    if 'acceleration' in interfaces and not {'velocity', 'position'} & set(interfaces):
        return ("'acceleration' command interface can only be used if 'velocity' and "
                "'position' command interfaces are present")
    if 'effort' in interfaces and not (len(interfaces) == 1 or (
            len(interfaces) == 2 and 'position' in interfaces)):
        return "'effort' command interface has to be used alone or with a 'position' interface"
    return None


# The spec's check of command_interfaces: a combination jazzy's controller accepts.
COMBINATIONS = Validator('a combination ros2_controllers accepts', lambda interfaces: (
    None if (problem := command_interfaces_problem(interfaces)) is None
    else f'{list(interfaces)!r}: {problem}'))


class JointTrajectoryController(MultiJointController):
    """Follows trajectories and FollowJointTrajectory goals in sim time, as ros2_controllers."""

    type_names = ('joint_trajectory_controller/JointTrajectoryController',)
    parameters = MultiJointController.parameters.extend(
        Param(COMMAND_INTERFACES_FIELD, STRING_ARRAY, [], 'The command interfaces of every '
              'joint; empty: position through the ideal actuator.',
              (unique(), one_of(*COMMAND_INTERFACES), COMBINATIONS), read_only=True),
        Param(STATE_INTERFACES_FIELD, STRING_ARRAY, list(DEFAULT_STATE_INTERFACES),
              'The state interfaces read from every joint.',
              (unique(), one_of(*STATE_INTERFACES)), read_only=True),
        Param(PARTIAL_FIELD, BOOL, False, 'Accept goals that name only some of the joints.'),
        Param(NONZERO_END_FIELD, BOOL, False,
              'Accept trajectories whose last point has a non-zero velocity.'),
        Param(MONITOR_RATE_FIELD, DOUBLE, DEFAULT_MONITOR_RATE,
              'Rate (Hz) of FollowJointTrajectory feedback.', (gt_eq(0.1),)),
        Param(f'{CONSTRAINTS_FIELD}.goal_time', DOUBLE, DEFAULT_GOAL_TIME,
              'Time (s) after the end a goal may take to reach its tolerances; 0: forever.',
              (gt_eq(0.0),)),
        Param(f'{CONSTRAINTS_FIELD}.stopped_velocity_tolerance', DOUBLE,
              DEFAULT_STOPPED_VELOCITY_TOLERANCE,
              'Goal velocity tolerance of every joint (rad/s or m/s).', (gt_eq(0.0),)),
        Param(f'{CONSTRAINTS_FIELD}.__map_joints.trajectory', DOUBLE, 0.0,
              'Path position tolerance; 0: not checked.', (gt_eq(0.0),)),
        Param(f'{CONSTRAINTS_FIELD}.__map_joints.goal', DOUBLE, 0.0,
              'Goal position tolerance; 0: not checked.', (gt_eq(0.0),)),
        *joint_gains(),
        Param('command_joints', STRING_ARRAY, [], 'Joints commanded in place of joints '
              '(chaining).', simulated=False),
        Param('interpolation_method', STRING, 'splines', 'How points are interpolated.',
              (one_of('splines', 'none'),), simulated=False),
        Param('open_loop_control', BOOL, False, 'Plan from the last command, not the '
              'measured state.', simulated=False),
        Param('allow_integration_in_goal_trajectories', BOOL, False,
              'Integrate missing positions from velocities.', simulated=False),
        Param('cmd_timeout', DOUBLE, 0.0, 'Hold position if no new command comes within this '
              'time (s); 0: never.', (gt_eq(0.0),), simulated=False),
    )
    command_topic = 'joint_trajectory'
    command_kind = CommandKind.JOINT_TRAJECTORY

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        interfaces = self.params[COMMAND_INTERFACES_FIELD]
        self._effort_interface = EFFORT_INTERFACE in interfaces
        self._command_interfaces = tuple(interfaces)
        states = self.params[STATE_INTERFACES_FIELD] or list(DEFAULT_STATE_INTERFACES)
        self._state_interfaces = tuple(states)
        # ros2_controllers measures the velocity error only in this case.
        self._velocity_error = 'velocity' in states and bool(
            {'velocity', 'effort'} & set(self._command_interfaces))
        self._flags = {field: self.params[field] for field in (PARTIAL_FIELD, NONZERO_END_FIELD)}
        self.monitor_period = 1.0 / self.params[MONITOR_RATE_FIELD]
        self.default_tolerances = default_tolerances(self, self.params, self._joint_names)
        gains = joint_gains_from_params(self, self._joint_names)
        self._gains = [gains.get(joint) for joint in self._joint_names]
        scales = feedforward_scales(self, self._joint_names)
        self._feedforward = [scales[joint] for joint in self._joint_names]
        self._goal: TrajectoryGoal | None = None
        self._state_sink: StateSink | None = None
        # ~/controller_state's optional fields, as upstream fills them.
        self._velocity_feedback = 'velocity' in states
        self._position_output = not interfaces or 'position' in interfaces
        self._effort_output = self._effort_interface

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return upstream's surface.

        The ``~/joint_trajectory`` topic, the FollowJointTrajectory action,
        ``~/controller_state`` (see :meth:`connect_state`) and ``~/query_state``
        (see :meth:`query_state`; refused while inactive, as upstream).
        """
        inactive = TrajectoryStateAnswer(False, NOT_ACTIVE_TEXT, (), (), (), ())
        return (*super().ros_surface(),
                ActionServer('~/follow_joint_trajectory',
                             'control_msgs/action/FollowJointTrajectory'),
                StateTopic('~/controller_state', CONTROLLER_STATE, self.connect_state,
                           {'joint_names': list(self._joint_names)}),
                Service('~/query_state', QUERY_STATE, self.query_state, inactive))

    def connect_state(self, sink: StateSink | None) -> None:
        """Take the ``~/controller_state`` sink (None: nobody listens, take no samples).

        Every update then hands it a sample (see :data:`StateSink`), as
        ros2_controllers publishes its state every update: the desired
        state; the measured positions, and velocities with a ``velocity``
        state interface; desired minus measured (wrapped on continuous
        joints); and the commands -- the desired positions on a ``position``
        command interface (or none listed: the ideal actuator's), the efforts
        on an ``effort`` one.  The velocities commanded on a ``velocity``
        interface are left out: the joints are driven by the ideal actuator
        or a PID's effort, not by that command.
        """
        self._state_sink = sink

    def query_state(self, time: float) -> TrajectoryStateAnswer:
        """Answer ``~/query_state``: the desired state at sim ``time`` (s), as upstream.

        Within the trajectory being followed (from its start, before its last
        point): success, the desired positions, velocities and accelerations.
        Otherwise failure with upstream's text: without a trajectory (before
        the first, or holding position) the measured state; before its start
        or from its last point on, the state it holds there.
        """
        names = tuple(self._joint_names)
        plan = self._plan
        if plan is None:
            return TrajectoryStateAnswer(
                False, NO_TRAJECTORY_TEXT, names,
                tuple(handle.position for handle in self._handles),
                tuple(handle.velocity for handle in self._handles), (0.0,) * len(names))
        positions, velocities, accelerations = plan.at(time)
        if time < plan.times[0]:
            success, text = False, BEFORE_START_TEXT
        elif time >= plan.end_time:
            success, text = False, AFTER_END_TEXT
        else:
            success, text = True, ''
        return TrajectoryStateAnswer(success, text, names, tuple(positions), tuple(velocities),
                                     tuple(accelerations))

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the ``command_interfaces`` listed, for every joint."""
        return {joint: self._command_interfaces for joint in self._joint_names}

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the ``state_interfaces`` listed, for every joint."""
        return {joint: self._state_interfaces for joint in self._joint_names}

    @property
    def goal(self) -> TrajectoryGoal | None:
        """The goal being executed, if any (None once it has ended)."""
        return self._goal

    @property
    def following(self) -> bool:
        """Whether the latest trajectory has started (not waiting for its stamp or next step)."""
        return self._pending is None

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
        self._wraps = [handle.spec.kind is JointKind.CONTINUOUS for handle in self._handles]
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
        """Hold every joint where it is; forget trajectories and integrals.

        A goal still running is aborted (INVALID_GOAL): the simulation was reset.
        """
        self._end_goal(GoalStatus.ABORTED, INVALID_GOAL, RESET_TEXT)
        for index, handle in enumerate(self._handles):
            self._desired_positions[index] = handle.position
            self._desired_velocities[index] = 0.0
            pid = self._pids[index]
            if pid is not None:
                pid.reset()
        self._plan: TrajectoryPlan | None = None
        self._pending: JointTrajectory | None = None
        self._start_time = 0.0
        self._tolerances = self.default_tolerances
        self._checking = False
        self._first_sample = False

    def deactivate(self) -> None:
        """Abort a running goal (INVALID_GOAL), as ros2_controllers does on deactivation."""
        self._end_goal(GoalStatus.ABORTED, INVALID_GOAL, DEACTIVATED_TEXT)

    def check_goal(self, trajectory: JointTrajectory, now: float) -> tuple[int, str] | None:
        """Return ``(error code, text)`` of the first reason to reject a goal, or None.

        ros2_controllers' checks in its order (joints, points, end velocity,
        a start stamp ending in the past, strictly increasing times, sizes,
        effort without an effort interface), then this controller's own (finite
        values; velocities in every point or in none).  ``now`` is sim time.
        """
        names = trajectory.joint_names
        if not self._flags[PARTIAL_FIELD] and len(names) != len(self._joint_names):
            return INVALID_JOINTS, (
                "Joints on incoming trajectory don't match the controller joints "
                f"({', '.join(self._joint_names)}); allow_partial_joints_goal is false")
        if not names:
            return INVALID_JOINTS, 'Empty joint names on incoming trajectory.'
        if not trajectory.points:
            return INVALID_GOAL, 'Empty trajectory received.'
        for name in names:
            if name not in self._joint_names:
                return INVALID_JOINTS, (
                    f"Incoming joint {name} doesn't match the controller's joints "
                    f"({', '.join(self._joint_names)}).")
        if len(set(names)) != len(names):
            return INVALID_JOINTS, 'A joint is named more than once in the incoming trajectory.'
        last = trajectory.points[-1]
        if not self._flags[NONZERO_END_FIELD]:
            for name, velocity in zip(names, last.velocities, strict=False):
                if abs(velocity) > FLOAT_EPSILON:
                    return INVALID_GOAL, (f'Velocity of last trajectory point of joint {name} '
                                          f'is not zero: {velocity:.15f}')
        start = trajectory.start_time
        if start is not None and start + last.time_from_start < now:
            return OLD_HEADER_TIMESTAMP, (
                f'Received trajectory with non-zero start time ({start:f}) that ends in the '
                f'past ({start + last.time_from_start:f})')
        with_velocities = bool(trajectory.points[0].velocities)
        previous = -math.inf
        for number, point in enumerate(trajectory.points):
            when = point.time_from_start
            if not (math.isfinite(when) and when >= 0.0 and when > previous):
                return INVALID_GOAL, (
                    f'Time between points {number - 1} and {number} is not strictly '
                    f'increasing, it is {previous:f} and {when:f} respectively'
                    if number else f'Time of point 0 is {when}: it must be a time >= 0')
            previous = when
            for field, values, required in (('positions', point.positions, True),
                                            ('velocities', point.velocities, False),
                                            ('accelerations', point.accelerations, False)):
                if (values or required) and len(values) != len(names):
                    return INVALID_GOAL, (
                        f'Mismatch between joint_names size ({len(names)}) and {field} '
                        f'({len(values)}) at point #{number}.')
            if bool(point.velocities) != with_velocities:
                return INVALID_GOAL, ('Velocities must be given in every point or in none '
                                      f'(point #{number} differs from point #0).')
            if point.efforts and 'effort' not in self._command_interfaces:
                return INVALID_GOAL, ("Trajectories with effort fields are only supported for "
                                      "controllers using the 'effort' command interface.")
            if not all(map(is_sane_number, (*point.positions, *point.velocities,
                                            *point.accelerations))):
                return INVALID_GOAL, (
                    f'Point #{number}: a position, velocity or acceleration is not a finite '
                    f'number (within +-{MAX_COMMAND_MAGNITUDE:g}).')
        return None

    def start_goal(self, trajectory: JointTrajectory, tolerances: Tolerances) -> TrajectoryGoal:
        """Run ``trajectory`` (checked by :meth:`check_goal`) as a goal; return the goal.

        A goal still running is aborted: preempted (INVALID_GOAL).  Joints the
        trajectory leaves out (``allow_partial_joints_goal``) hold their
        present setpoints.
        """
        self._end_goal(GoalStatus.ABORTED, INVALID_GOAL, PREEMPTED_TEXT)
        goal = TrajectoryGoal(tolerances)
        if self.set_command(self._completed(trajectory)) is CommandResult.REJECTED:
            goal.end(GoalStatus.ABORTED, INVALID_GOAL, self._problem)
            return goal
        self._goal = goal
        self._tolerances = tolerances
        self._checking = False  # until its trajectory starts (at its stamp)
        return goal

    def cancel_goal(self, goal: TrajectoryGoal) -> bool:
        """Cancel ``goal`` if it is the one running: the joints hold where they are.

        Returns whether it was running (a cancel of another goal changes nothing).
        """
        if goal is not self._goal:
            return False
        self._end_goal(GoalStatus.CANCELED)
        self._hold_measured()
        return True

    def feedback(self) -> tuple[list[float], list[float], list[float], list[float], float]:
        """Return desired and measured positions and velocities, and the trajectory's start."""
        return (list(self._desired_positions), list(self._desired_velocities),
                [handle.position for handle in self._handles],
                [handle.velocity for handle in self._handles], self._start_time)

    def position_errors(self) -> list[float]:
        """Return desired minus measured position per joint (wrapped for continuous joints)."""
        return [self._position_error(index) for index in self._indices]

    @property
    def measures_velocity_error(self) -> bool:
        """Whether tolerances see a velocity error (velocity state, velocity/effort command)."""
        return self._velocity_error

    def _position_error(self, index: int) -> float:
        desired, measured = self._desired_positions[index], self._handles[index].position
        if self._wraps[index]:
            return shortest_angular_distance(measured, desired)
        return desired - measured

    def _end_goal(self, status: GoalStatus, code: int = 0, text: str = '') -> None:
        goal = getattr(self, '_goal', None)
        if goal is not None:
            goal.end(status, code, text)
            self._goal = None
            self._tolerances = self.default_tolerances

    def _hold_measured(self) -> None:
        """Hold every joint where it is now, at rest (ros2_controllers' set_hold_position)."""
        for index, handle in enumerate(self._handles):
            self._desired_positions[index] = handle.position
            self._desired_velocities[index] = 0.0
        self._plan = None
        self._pending = None
        self._checking = False

    def _completed(self, trajectory: JointTrajectory) -> JointTrajectory:
        """Fill the joints a partial trajectory leaves out with their present setpoints."""
        missing = [index for index, joint in enumerate(self._joint_names)
                   if joint not in trajectory.joint_names]
        if not missing:
            return trajectory
        names = trajectory.joint_names + tuple(self._joint_names[i] for i in missing)
        held = tuple(self._desired_positions[i] for i in missing)
        rest = (0.0,) * len(missing)
        points = tuple(dataclasses.replace(
            point, positions=point.positions + held,
            velocities=point.velocities + rest if point.velocities else (),
            accelerations=point.accelerations + rest if point.accelerations else ())
            for point in trajectory.points)
        return JointTrajectory(names, points, trajectory.start_time)

    def set_command(self, value: JointTrajectory) -> CommandResult:
        """Check a trajectory, put it in the controller's joint order and queue it.

        A running goal goes on against it (ros2_controllers' topic override).
        """
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

    def actuation(self) -> Callable[[float], None] | None:
        """For joints without gains: the ideal actuator tracking the held desired state."""
        ideal = [index for index in self._indices if self._pids[index] is None]
        if not ideal:
            return None

        def track(time_step: float) -> None:
            handles, positions = self._handles, self._desired_positions
            velocities, gains = self._desired_velocities, self._tracking_gains
            for index in ideal:
                handle = handles[index]
                target = velocities[index] + gains[index] / time_step * (
                    positions[index] - handle.position)
                limit = self._max_velocities[index]
                handle.velocity_target = (limit if target > limit else
                                          -limit if target < -limit else target)

        return track

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
            if self._checking:
                self._check_tolerances(time)
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
        if self._state_sink is not None:
            self._publish_state(time)

    def _publish_state(self, time: float) -> None:
        """Hand ``~/controller_state``'s sink this update's sample (see :meth:`connect_state`)."""
        handles = self._handles
        desired_positions = list(self._desired_positions)
        desired_velocities = list(self._desired_velocities)
        accelerations = (self._plan.at(time)[2] if self._plan is not None
                         else [0.0] * len(handles))
        measured = [handle.position for handle in handles]
        errors = [self._position_error(index) for index in self._indices]
        if self._velocity_feedback:
            speeds = [handle.velocity for handle in handles]
            speed_errors = [desired - speed
                            for desired, speed in zip(desired_velocities, speeds, strict=True)]
        else:
            speeds, speed_errors = [], []
        output = (desired_positions if self._position_output else [],
                  [handle.effort for handle in handles] if self._effort_output else [])
        self._state_sink(time, (desired_positions, desired_velocities, accelerations),
                         (measured, speeds), (errors, speed_errors), output)

    def _start(self, trajectory: JointTrajectory, time: float) -> None:
        """Replace the plan by ``trajectory``, from the desired state at ``time``.

        The first knot is the desired state now -- or a point that falls due
        exactly now; points already past are skipped.
        """
        self._pending = None
        if self._plan is not None:
            self._plan.sample(time, self._desired_positions, self._desired_velocities)
        start = time if trajectory.start_time is None else trajectory.start_time
        self._start_time = start
        self._first_sample = True
        self._checking = self._goal is not None or self._tolerances.checks_anything
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

    def _check_tolerances(self, time: float) -> None:
        """Compare desired and measured state with the active tolerances; end or hold.

        ros2_controllers' update(): path tolerances before the last point (and
        on the first sample), goal tolerances after it.
        """
        tolerances = self._tolerances
        end_time = self._plan.end_time
        before_last = time < end_time - TIME_EPSILON
        if before_last and not self._first_sample and not tolerances.checks_path:
            return  # before the last point only path tolerances count, and none is set
        first, self._first_sample = self._first_sample, False
        handles, velocities = self._handles, self._desired_velocities
        path_broken = outside_goal = False
        for index in self._indices:
            position_error = self._position_error(index)
            velocity_error = (velocities[index] - handles[index].velocity
                              if self._velocity_error else 0.0)
            if (before_last or first) and not tolerances.path[index].holds(
                    position_error, velocity_error):
                path_broken = True
            if not before_last and not tolerances.goal[index].holds(
                    position_error, velocity_error):
                outside_goal = True
        late = time - end_time
        goal_time_out = (outside_goal and tolerances.goal_time != 0.0
                         and late > tolerances.goal_time)
        goal = self._goal
        if path_broken:
            if goal is not None:
                self._end_goal(GoalStatus.ABORTED, PATH_TOLERANCE_VIOLATED, PATH_VIOLATED_TEXT)
            else:
                self.notices.append(
                    f'path tolerance broken at sim time {time:.3f} s (errors '
                    f'{_rounded(self.position_errors())}): holding position')
            self._hold_measured()
        elif not before_last:
            if goal is not None and not outside_goal:
                self._end_goal(GoalStatus.SUCCEEDED, 0, SUCCEEDED_TEXT)
                self._checking = False  # the last point is held
            elif goal_time_out:
                if goal is not None:
                    self._end_goal(GoalStatus.ABORTED, GOAL_TOLERANCE_VIOLATED,
                                   GOAL_TIME_TEXT.format(late))
                else:
                    self.notices.append(
                        f'goal_time_tolerance exceeded at sim time {time:.3f} s (errors '
                        f'{_rounded(self.position_errors())}): holding position')
                self._hold_measured()
            elif goal is None and not outside_goal:
                self._checking = False  # a topic trajectory ended within its goal tolerances

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



def _rounded(values: list[float]) -> str:
    return '[' + ', '.join(f'{value:.4f}' for value in values) + ']'
