"""ros2_controllers' ``steering_controllers_library`` (jazzy): what the steering types share.

The Ackermann, bicycle and tricycle steering controllers
(:mod:`.ackermann_steering_controller`, :mod:`.bicycle_steering_controller`,
:mod:`.tricycle_steering_controller`) differ only in their geometry
parameters and their kinematics (:mod:`.steering_odometry`); the rest is
here, parameters by their upstream names (see the design notes).

Design notes: docs/design/controllers.md#steering_controllerspy.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Mapping, Sequence
from typing import Any, ClassVar

from pan_tilt_sim.controllers.drives.steering.steering_odometry import (
    Configuration,
    SteeringKinematics,
)
from pan_tilt_sim.controllers.framework.base import (
    Actuator,
    ActuatorKind,
    CommandController,
    CommandKind,
    JointHandle,
    Reference,
)
from pan_tilt_sim.controllers.framework.parameter_spec import (
    BOOL,
    DOUBLE,
    INT,
    STRING_ARRAY,
    Param,
    Validator,
    gt,
    gt_eq,
    unique,
)
from pan_tilt_sim.controllers.framework.shared_parameters import (
    UNSET_OR_LENGTH,
    UPDATE_RATE,
    check_odometry_frames,
    odometry_frames,
    update_period,
)
from pan_tilt_sim.controllers.framework.surface import (
    CommandTopic,
    Endpoint,
    StateTopic,
)
from pan_tilt_sim.controllers.toolbox.actuator import ARRIVED, SETPOINT_ACCELERATION, ramp
from pan_tilt_sim.controllers.toolbox.limits import PositionLimits
from pan_tilt_sim.controllers.toolbox.odometry_outputs import OdometryOutputs, OdometrySink, TfSink
from pan_tilt_sim.controllers.toolbox.twist_command import (
    TwistCommand,
    TwistCommanded,
    planar_references,
)
from pan_tilt_sim.schedule import PeriodicSchedule

VELOCITY, POSITION = 'velocity', 'position'
TRACTION, STEERING = 'traction_joints_names', 'steering_joints_names'
TRACTION_STATE, STEERING_STATE = 'traction_joints_state_names', 'steering_joints_state_names'
# upstream's default covariance diagonals
FRAMES = odometry_frames(covariance=(0.0, 7.0, 14.0, 21.0, 28.0, 35.0))
MAX_JOINTS = 4  # upstream's size_lt<5> on every joint list
EPSILON = sys.float_info.epsilon  # a length at most this is "not set", as upstream
STATUS_MESSAGE = 'control_msgs/msg/SteeringControllerStatus'
# Sinks besides the planar odometry and tf (toolbox.odometry_outputs): status(time,
# traction positions, traction velocities, traction commands, steering positions, steering
# commands) -- the lists of control_msgs/SteeringControllerStatus.
StatusSink = Callable[[float, list[float], list[float], list[float], list[float],
                       list[float]], None]


def _at_most(size: int) -> Validator:
    return Validator(f'at most {size} elements', lambda value: None if len(value) <= size else
                     f'must have at most {size} elements, has {len(value)}')


def _joint_list(name: str, description: str, **extra: Any) -> Param:
    return Param(name, STRING_ARRAY, [], description, (_at_most(MAX_JOINTS), unique()),
                 read_only=True, **extra)


def library_parameters(traction: list[str], steering: list[str]) -> tuple[Param, ...]:
    """Return the library's parameters (steering_controllers_library.yaml).

    ``traction`` and ``steering`` are the joint lists' examples (as many as the type needs).
    """
    return (
        Param('reference_timeout', DOUBLE, 1.0, 'Seconds of sim time after which a reference '
              'is dropped (the traction wheels stop); 0: each reference is used for one update.',
              (gt_eq(0.0),)),
        Param('front_steering', BOOL, True, 'Deprecated: whether front_wheels_names are the '
              'steering joints (else rear_wheels_names are); use the joints_names parameters.',
              read_only=True),
        _joint_list('rear_wheels_names', 'Deprecated: the rear joints (traction with '
                    'front_steering, else steering).'),
        _joint_list('front_wheels_names', 'Deprecated: the front joints (steering with '
                    'front_steering, else traction).'),
        _joint_list(TRACTION, 'The traction joints, driven in velocity (two: right, then left).',
                    example=list(traction)),
        _joint_list(STEERING, 'The steering joints, driven in position (two: right, then left); '
                    'a positive angle turns the robot about +z.', example=list(steering)),
        _joint_list(TRACTION_STATE, 'The joints whose state stands for the traction joints; '
                    'empty: the traction joints.'),
        _joint_list('rear_wheels_state_names', 'Deprecated: use traction_joints_state_names or '
                    'steering_joints_state_names.'),
        _joint_list(STEERING_STATE, 'The joints whose state stands for the steering joints; '
                    'empty: the steering joints.'),
        _joint_list('front_wheels_state_names', 'Deprecated: use traction_joints_state_names or '
                    'steering_joints_state_names.'),
        Param('open_loop', BOOL, False, 'Odometry from the reference, not the joints.'),
        Param('reduce_wheel_speed_until_steering_reached', BOOL, False, 'Slow the traction '
              'wheels while the steering is more than 30 degrees from its command.'),
        Param('velocity_rolling_window_size', INT, 10, "Updates in the odometry twist's rolling "
              'mean.', (gt(0),)),
        FRAMES.base,
        FRAMES.odom,
        Param('enable_odom_tf', BOOL, True, 'Publish odom_frame_id -> base_frame_id on '
              '~/tf_odometry.'),
        FRAMES.twist_covariance,
        FRAMES.pose_covariance,
        Param('position_feedback', BOOL, False, "Odometry from the traction joints' positions "
              '(else their velocities).'),
        UPDATE_RATE,    )


# The Ackermann and tricycle types declare these alike upstream; the bicycle type's radius
# entries are singular and read-only, its own.
TRACTION_TRACK_WIDTH = Param('traction_track_width', DOUBLE, 0.0, 'Distance between the '
                             'traction wheels (m).', example=0.3, validators=UNSET_OR_LENGTH)
WHEELS_RADIUS = 'traction_wheels_radius'
WHEELS_RADIUS_DEPRECATED = ('front_wheels_radius', 'rear_wheels_radius')


def wheels_radius_parameters() -> tuple[Param, ...]:
    """Return ``traction_wheels_radius`` and its deprecated ``front_``/``rear_wheels_radius``."""
    return (Param(WHEELS_RADIUS, DOUBLE, 0.0, 'Radius of the traction wheels (m).',
                  example=0.05, validators=UNSET_OR_LENGTH),
            *(Param(name, DOUBLE, 0.0, f"Deprecated: use '{WHEELS_RADIUS}'.",
                    validators=UNSET_OR_LENGTH) for name in WHEELS_RADIUS_DEPRECATED))


# (deprecated name, the name it stands for with front_steering, without it)
DEPRECATED_JOINTS = (
    ('front_wheels_names', STEERING, TRACTION),
    ('rear_wheels_names', TRACTION, STEERING),
    ('front_wheels_state_names', STEERING_STATE, TRACTION_STATE),
    ('rear_wheels_state_names', TRACTION_STATE, STEERING_STATE),
)


class SteeringJoints:
    """Steering joints driven through their ``position`` command interface, tracked every step.

    A command (rad) is clamped to the joint's limits and becomes a setpoint
    that moves toward it within the joint's velocity limit and
    :data:`~pan_tilt_sim.controllers.toolbox.actuator.SETPOINT_ACCELERATION`; the
    ideal position actuator's velocity target follows the setpoint (as a
    position command interface under gz_ros2_control).  Until the first
    command (NaN) each joint holds where it was.
    """

    def __init__(self, handles: Sequence[JointHandle] = ()) -> None:
        self.handles = list(handles)
        self._limits = [PositionLimits(handle.spec) for handle in self.handles]
        self.hold()

    def hold(self) -> None:
        """Hold each joint where it is: setpoint there, at rest, no command."""
        self.setpoints = [handle.position for handle in self.handles]
        self._rates = [0.0] * len(self.handles)
        self.commands = [math.nan] * len(self.handles)
        for handle in self.handles:
            handle.velocity_target = 0.0

    def command(self, angles: Sequence[float]) -> None:
        """Take one angle per joint (rad), clamped to the joint's limits."""
        self.commands = [min(max(angle, limits.lower), limits.upper)
                         for angle, limits in zip(angles, self._limits, strict=True)]

    def track(self, period: float) -> None:
        """Move each setpoint toward its command; set each joint's velocity target."""
        for index, handle in enumerate(self.handles):
            command = self.commands[index]
            setpoint, rate = self.setpoints[index], self._rates[index]
            limits = self._limits[index]
            if not math.isnan(command) and (rate != 0.0 or not -ARRIVED < command - setpoint
                                            < ARRIVED):
                setpoint, rate = ramp(setpoint, rate, command, period, limits.max_velocity,
                                      SETPOINT_ACCELERATION)
                self.setpoints[index], self._rates[index] = setpoint, rate
            target = rate + handle.tracking_gain / period * (setpoint - handle.position)
            limit = limits.max_velocity
            handle.velocity_target = limit if target > limit else (
                -limit if target < -limit else target)


class SteeredOnOwnClock:
    """Mixin of the controllers that steer: control at the update rate, steering every step.

    An instance has ``_updates`` (its update schedule), ``_last_update``
    (None before the first), ``_steering`` (:class:`SteeringJoints`),
    ``_timed_out`` and ``_control(time, interval)``: one upstream update over
    ``interval`` s (the schedule's period the first time).
    """

    own_clock: ClassVar[bool] = True
    _updates: PeriodicSchedule
    _last_update: float | None
    _steering: SteeringJoints
    _time: float
    _timed_out: bool

    def update(self, time: float, period: float) -> None:
        """At the update rate: one upstream update (``_control``); every step: the steering."""
        self._time = time
        if self._updates.take(time):
            last = self._last_update
            self._last_update = time
            self._control(time, self._updates.period if last is None else time - last)
        self._steering.track(period)

    def _control(self, time: float, period: float) -> None:
        raise NotImplementedError

    def twist_taken(self) -> None:
        """Let a new twist time out again (and say so)."""
        self._timed_out = False


class SteeringController(SteeredOnOwnClock, OdometryOutputs, TwistCommanded,
                         CommandController):
    """A steered base from a twist: steering angles and wheel speeds out, odometry back.

    Subclasses give :attr:`configuration` and build the kinematics from their
    own geometry parameters (:meth:`kinematics`).
    """

    chainable = True
    drives_base: ClassVar[bool] = True
    command_topic = 'reference'
    command_kind = CommandKind.TWIST_STAMPED
    configuration: ClassVar[Configuration]
    kind: ClassVar[str] = ''  # how upstream's errors name it: 'Bicycle', 'Tricycle'...

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        check_odometry_frames(self)
        self._names = self._joint_lists()
        self._kinematics = self.kinematics()
        self._references = planar_references(name)
        self._linear_reference, self._angular_reference = self._references.values()
        self._updates = PeriodicSchedule(update_period(self.params))
        self._traction: list[JointHandle] = []
        self._steering = SteeringJoints()
        self._traction_state: list[JointHandle] = []
        self._steering_state: list[JointHandle] = []
        self._odometry_sink: OdometrySink | None = None
        self._tf_sink: TfSink | None = None
        self._status_sink: StatusSink | None = None
        self._command = TwistCommand('reference', timeout_field='reference_timeout')
        self.reset()

    def _joint_lists(self) -> dict[str, tuple[str, ...]]:
        """Map the deprecated lists as upstream does; check each list's size for the type."""
        params = self.params
        lists = {field: tuple(params[field])
                 for field in (TRACTION, STEERING, TRACTION_STATE, STEERING_STATE)}
        front = params['front_steering']
        if not front:
            self.deprecated('front_steering', f"'{TRACTION}' or '{STEERING}'")
        for deprecated, with_front, without in DEPRECATED_JOINTS:
            if params[deprecated]:
                self.deprecated(deprecated, f"'{with_front}' or '{without}'")
                lists[with_front if front else without] = tuple(params[deprecated])
        configuration = self.configuration
        wanted = {TRACTION: configuration.traction_joints, STEERING: configuration.steering_joints,
                  TRACTION_STATE: configuration.traction_joints,
                  STEERING_STATE: configuration.steering_joints}
        for field, count in wanted.items():
            given = len(lists[field])
            if field in (TRACTION_STATE, STEERING_STATE) and not given:
                continue
            if given != count:
                role = 'traction' if field.startswith('traction') else 'steering'
                plural = 'joint' if count == 1 else 'joints'
                raise self.error(field, f'{self.kind} configuration requires exactly '
                                        f"{'one' if count == 1 else 'two'} {role} {plural}, "
                                        f'but {given} were provided')
        both = [joint for joint in lists[TRACTION] if joint in lists[STEERING]]
        if both:
            raise self.error(STEERING, f"'{both[0]}' is also one of {TRACTION}: a joint is "
                                       'either steered or driven')
        lists[TRACTION_STATE] = lists[TRACTION_STATE] or lists[TRACTION]
        lists[STEERING_STATE] = lists[STEERING_STATE] or lists[STEERING]
        return lists

    def deprecated(self, field: str, instead: str) -> None:
        """Warn (once, at start-up) that ``field`` is deprecated upstream; name what replaces it."""
        where = f'{self._source}: ' if self._source else ''
        self.config_warnings.append(f'{where}{self.name}.{field}: deprecated; set {instead} '
                                    'instead')

    def kinematics(self) -> SteeringKinematics:
        """Return the type's kinematics from its geometry parameters (subclasses)."""
        raise NotImplementedError

    def traction_radius(self, name: str = WHEELS_RADIUS,
                        deprecated: Sequence[str] = WHEELS_RADIUS_DEPRECATED) -> float:
        """Return the ``name`` radius (m), or a deprecated one that is set (with a warning)."""
        params = self.params
        radius = params[name]
        for field in deprecated:
            if params[field] > 0.0:
                self.deprecated(field, f"'{name}'")
                radius = params[field]
        return radius

    # --- what it claims and exports --------------------------------------------------------

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The traction joints, then the steering joints."""
        return self._names[TRACTION] + self._names[STEERING]

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return ``velocity`` for the traction joints, ``position`` for the steering joints."""
        claimed = {joint: (VELOCITY,) for joint in self._names[TRACTION]}
        claimed.update({joint: (POSITION,) for joint in self._names[STEERING]})
        return claimed

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the traction feedback and the steering positions read, by joint."""
        feedback = POSITION if self.params['position_feedback'] else VELOCITY
        read: dict[str, tuple[str, ...]] = {}
        for joint in self._names[TRACTION_STATE]:
            read[joint] = (feedback,)
        for joint in self._names[STEERING_STATE]:
            read[joint] = tuple(dict.fromkeys((*read.get(joint, ()), POSITION)))
        return read

    def actuators(self) -> dict[str, Actuator]:
        """Return the ideal velocity actuator per traction joint, position per steering joint."""
        driven = {joint: Actuator(ActuatorKind.IDEAL_VELOCITY, self.name)
                  for joint in self._names[TRACTION]}
        driven.update({joint: Actuator(ActuatorKind.IDEAL_POSITION, self.name)
                       for joint in self._names[STEERING]})
        return driven

    def reference_interfaces(self) -> Mapping[str, Reference]:
        """Return ``<name>/linear/velocity`` and ``<name>/angular/velocity``."""
        return self._references

    # --- ROS surface -----------------------------------------------------------------------

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return ``~/reference`` in; ``~/odometry``, ``~/tf_odometry``, ``~/controller_state``."""
        params = self.params
        odom, base = params['odom_frame_id'], params['base_frame_id']
        return (
            CommandTopic(f'~/{self.command_topic}', self.command_kind.value, self.set_command,
                         self.command_problem),
            self.odometry_topic('~/odometry', (odom, base), params['pose_covariance_diagonal'],
                                params['twist_covariance_diagonal']),
            StateTopic('~/tf_odometry', 'tf2_msgs/msg/TFMessage', self.set_tf_sink),
            StateTopic('~/controller_state', STATUS_MESSAGE, self.set_status_sink,
                       {'frame_id': odom}),
        )

    def set_status_sink(self, sink: StatusSink | None) -> None:
        """Where the controller's status goes (see :data:`StatusSink`)."""
        self._status_sink = sink

    # --- lifecycle -------------------------------------------------------------------------

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the joints' handles (an unknown joint names its parameter), then reset."""
        names = self._names
        self._traction = [self.handle(joints, joint, TRACTION) for joint in names[TRACTION]]
        self._steering = SteeringJoints([self.handle(joints, joint, STEERING)
                                         for joint in names[STEERING]])
        self._traction_state = [self.handle(joints, joint, TRACTION_STATE, commanded=False)
                                for joint in names[TRACTION_STATE]]
        self._steering_state = [self.handle(joints, joint, STEERING_STATE, commanded=False)
                                for joint in names[STEERING_STATE]]
        self.reset()

    def reset(self) -> None:
        """No reference, odometry at the origin, the wheels asked to stand, the steering held."""
        self._command.latest = None
        self._timed_out = False
        self._time = 0.0
        self._last_update: float | None = None
        self._linear_reference.value = math.nan
        self._angular_reference.value = math.nan
        self._last_linear = self._last_angular = 0.0
        self._updates.reset()
        self._kinematics.reset(self._traction_positions())
        for handle in self._traction:
            handle.velocity_target = 0.0
        self._steering.hold()

    def deactivate(self) -> None:
        """Stop the traction wheels and hold the steering where it is."""
        for handle in self._traction:
            handle.velocity_target = 0.0
        self._steering.hold()

    # --- commands (set_command, command_problem: TwistCommanded) ----------------------------

    def setpoints(self) -> dict[str, float]:
        """Return each traction joint's velocity (rad/s) and steering joint's setpoint (rad)."""
        wanted = {handle.name: handle.velocity_target for handle in self._traction}
        steering = self._steering
        wanted.update({handle.name: setpoint
                       for handle, setpoint in zip(steering.handles, steering.setpoints,
                                                   strict=True)})
        return wanted

    @property
    def odometry(self) -> SteeringKinematics:
        """The odometry (pose and twist in the odom frame) and the kinematics."""
        return self._kinematics

    @property
    def steering_commands(self) -> list[float]:
        """The steering angles last commanded (rad; NaN before the first command)."""
        return list(self._steering.commands)

    # --- the step ---------------------------------------------------------------------------

    # update(): SteeredOnOwnClock; one upstream update: reference, odometry, commands, messages.

    def _control(self, time: float, period: float) -> None:
        """One upstream update: take the reference, update odometry, command the joints."""
        if not self.is_chained:
            self._update_references(time)
        linear, angular = self._linear_reference.value, self._angular_reference.value
        self._last_linear = linear if math.isfinite(linear) else 0.0
        self._last_angular = angular if math.isfinite(angular) else 0.0
        self._update_odometry(period)
        if not (math.isnan(linear) or math.isnan(angular)):
            traction, steering = self._kinematics.commands(
                linear, angular, open_loop=self.params['open_loop'],
                slow_until_steered=self.params['reduce_wheel_speed_until_steering_reached'])
            for handle, velocity in zip(self._traction, traction, strict=True):
                handle.velocity_target = velocity
            self._steering.command(steering)
        else:
            for handle in self._traction:
                handle.velocity_target = 0.0
        self._publish(time)
        self._linear_reference.value = math.nan
        self._angular_reference.value = math.nan

    def _update_references(self, time: float) -> None:
        """Write the newest reference to the references; drop it once it is stale."""
        command = self._command.latest
        if command is None:
            return
        timeout = self.params['reference_timeout']
        if timeout == 0.0:
            self._command.latest = None
        elif time - command.stamp > timeout:
            self._command.latest = None
            if not self._timed_out:
                self._timed_out = True
                self.notices.append(f'reference timed out ({timeout:g} s without one at sim '
                                    f'time {time:.3f} s): the traction wheels stop')
            return
        self._linear_reference.value = command.linear[0]
        self._angular_reference.value = command.angular[2]

    def _traction_positions(self) -> list[float]:
        return [handle.position for handle in self._traction_state]

    def _update_odometry(self, period: float) -> None:
        kinematics = self._kinematics
        if self.params['open_loop']:
            kinematics.update_open_loop(self._last_linear, self._last_angular, period)
            return
        steering = [handle.position for handle in self._steering_state]
        if not self._traction_state:
            return
        if self.params['position_feedback']:
            kinematics.update_from_positions(self._traction_positions(), steering, period)
        else:
            kinematics.update_from_velocities(
                [handle.velocity for handle in self._traction_state], steering, period)

    def _publish(self, time: float) -> None:
        kinematics, params = self._kinematics, self.params
        self.publish_planar(time, kinematics.x, kinematics.y, kinematics.heading,
                            kinematics.linear, kinematics.angular,
                            (params['odom_frame_id'], params['base_frame_id']),
                            tf=params['enable_odom_tf'])
        if self._status_sink is not None:
            feedback = [handle.position if self.params['position_feedback'] else handle.velocity
                        for handle in self._traction_state]
            positions = feedback if self.params['position_feedback'] else []
            velocities = [] if self.params['position_feedback'] else feedback
            self._status_sink(time, positions, velocities,
                              [handle.velocity_target for handle in self._traction],
                              [handle.position for handle in self._steering_state],
                              list(self._steering.commands))

