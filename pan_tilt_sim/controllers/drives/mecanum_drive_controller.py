"""``mecanum_drive_controller/MecanumDriveController``: a body twist in, four wheel speeds out.

As ros2_controllers' (jazzy), parameters by their names there (see the design notes).

Design notes: docs/design/controllers.md#mecanum_drive_controllerpy.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any, ClassVar

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
    REQUIRED,
    STRING,
    Param,
    ParameterSpec,
    gt,
    gt_eq,
    not_empty,
)
from pan_tilt_sim.controllers.framework.shared_parameters import (
    COVARIANCE_SIZE,
    UPDATE_RATE,
    check_odometry_frames,
    odometry_frames,
    prefixed_frames,
    tf_frame_prefix,
    update_period,
    velocity_limit_params,
    velocity_limiter,
)
from pan_tilt_sim.controllers.framework.surface import CommandTopic, Endpoint, StateTopic
from pan_tilt_sim.controllers.toolbox.odometry_outputs import (
    OdometryOutputs,
    SpatialOdometrySink,
    TfSink,
)
from pan_tilt_sim.controllers.toolbox.rate_limiter import InvalidLimitsError
from pan_tilt_sim.controllers.toolbox.twist_command import (
    TwistCommand,
    TwistCommanded,
    twist_references,
)
from pan_tilt_sim.controllers.toolbox.wheel_sides import velocity_targets
from pan_tilt_sim.schedule import DUE_EPSILON, PeriodicSchedule

VELOCITY = 'velocity'
# The wheels in upstream's order of the command interfaces.
WHEELS = ('front_left', 'front_right', 'rear_right', 'rear_left')
LIMIT_GROUPS = ('linear.x', 'linear.y', 'angular.z')
# The angle (rad) between each wheel's rolling direction and its rollers' free direction in
# the ground plane, towards the wheel's axis (see pan_tilt_sim.sim.roller_wheels): rollers
# seen from above as an X, the front left and rear right wheels' one way, the others' the other.
ROLLER_ANGLES = {'front_left': math.pi / 4.0, 'front_right': -math.pi / 4.0,
                 'rear_right': math.pi / 4.0, 'rear_left': -math.pi / 4.0}
MIN_INTERVAL = 1e-4  # s: odometry updates closer together than this are skipped, as upstream
# Sinks besides odometry and tf (toolbox.odometry_outputs): state(time, wheel velocities in
# WHEELS order, reference (vx, vy, wz)).
StateSink = Callable[[float, Sequence[float], Sequence[float]], None]
# Upstream's defaults: 0.1 on both covariance diagonals; the frames fixed once configured.
FRAMES = odometry_frames(covariance=(0.1,) * COVARIANCE_SIZE, read_only=True)



def _wheel_params(position: str) -> tuple[Param, Param]:
    text = position.replace('_', ' ')
    example = f'joint{WHEELS.index(position) + 1}'
    return (Param(f'{position}_wheel_command_joint_name', STRING, REQUIRED,
                  f'The joint commanding the {text} wheel.', (not_empty(),), read_only=True,
                  example=example),
            Param(f'{position}_wheel_state_joint_name', STRING, '',
                  f'The joint the {text} wheel is read by; empty: the command joint.',
                  read_only=True))


class MecanumOdometry:
    """The base's pose in odom and twist in the base frame from four wheel velocities (upstream).

    ``offset`` is ``kinematics.base_frame_offset`` (x m, y m, theta rad).
    """

    def __init__(self, wheel_radius: float, projection_sum: float,
                 offset: tuple[float, float, float]) -> None:
        self.wheel_radius = wheel_radius
        self.projection_sum = projection_sum
        self.offset = offset
        self.reset()

    def reset(self) -> None:
        """Back to the origin, at rest."""
        self.x = self.y = self.heading = 0.0
        self.linear_x = self.linear_y = self.angular = 0.0

    def body_twist(self, front_left: float, front_right: float, rear_right: float,
                   rear_left: float) -> tuple[float, float, float]:
        """Return the base frame's twist (m/s, m/s, rad/s) from the wheels' velocities (rad/s)."""
        quarter = 0.25 * self.wheel_radius
        center_x = quarter * (front_left + rear_left + rear_right + front_right)
        center_y = quarter * (-front_left + rear_left - rear_right + front_right)
        angular = quarter / self.projection_sum * (
            -front_left - rear_left + rear_right + front_right)
        offset_x, offset_y, theta = self.offset
        cos, sin = math.cos(-theta), math.sin(-theta)
        linear_x = cos * center_x - sin * center_y
        linear_y = sin * center_x + cos * center_y
        shift_x = cos * -offset_x - sin * -offset_y
        shift_y = sin * -offset_x + cos * -offset_y
        return linear_x + shift_y * angular, linear_y - shift_x * angular, angular

    def update(self, wheel_velocities: Sequence[float], dt: float) -> bool:
        """Integrate ``dt`` s at the wheels' velocities (WHEELS order); False if too short."""
        if dt < MIN_INTERVAL:
            return False
        self.linear_x, self.linear_y, self.angular = self.body_twist(*wheel_velocities)
        self.heading += self.angular * dt
        cos, sin = math.cos(self.heading), math.sin(self.heading)
        self.x += (cos * self.linear_x - sin * self.linear_y) * dt
        self.y += (sin * self.linear_x + cos * self.linear_y) * dt
        return True


class MecanumDriveController(OdometryOutputs, TwistCommanded, CommandController):
    """Drives a four-wheel mecanum base from a body twist, as ros2_controllers."""

    type_names = ('mecanum_drive_controller/MecanumDriveController',)
    chainable = True
    drives_base: ClassVar[bool] = True
    command_topic = 'reference'
    command_kind = CommandKind.TWIST_STAMPED
    parameters = ParameterSpec([
        Param('reference_timeout', DOUBLE, 0.0, 'Seconds of sim time a reference is used; '
              '0: for one update only.', (gt_eq(0.0),)),
        *(param for position in WHEELS for param in _wheel_params(position)),
        Param('kinematics.base_frame_offset.x', DOUBLE, 0.0, 'Offset of base_frame_id from '
              "the wheels' centre along its x axis (m).", read_only=True),
        Param('kinematics.base_frame_offset.y', DOUBLE, 0.0, 'Offset along y (m).',
              read_only=True),
        Param('kinematics.base_frame_offset.theta', DOUBLE, 0.0, 'Rotation about z (rad).',
              read_only=True),
        Param('kinematics.wheels_radius', DOUBLE, 0.0, "The wheels' radius (m).",
              (gt(0.0),), read_only=True, example=0.05),
        Param('kinematics.sum_of_robot_center_projection_on_X_Y_axis', DOUBLE, 0.0,
              "lx + ly: the wheels' distances from the centre along x plus along y (m); "
              'upstream accepts 0, which its odometry divides by.', (gt(0.0),),
              read_only=True, example=0.3),
        *tf_frame_prefix(prefix_read_only=True),
        FRAMES.base,
        FRAMES.odom,
        Param('enable_odom_tf', BOOL, True, 'Publish odom_frame_id -> base_frame_id on '
              '~/tf_odometry.'),
        FRAMES.twist_covariance,
        FRAMES.pose_covariance,
        UPDATE_RATE,
        *(param for group in LIMIT_GROUPS for param in velocity_limit_params(group)),
    ])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        check_odometry_frames(self)
        params = self.params
        self._command_names = tuple(params[f'{wheel}_wheel_command_joint_name']
                                    for wheel in WHEELS)
        for index, joint in enumerate(self._command_names):
            if joint in self._command_names[:index]:
                raise self.error(f'{WHEELS[index]}_wheel_command_joint_name',
                                 f"'{joint}' is already the command joint of another wheel")
        self._state_names = tuple(params[f'{wheel}_wheel_state_joint_name'] or command
                                  for wheel, command in zip(WHEELS, self._command_names,
                                                            strict=True))
        limiters = []
        for group in LIMIT_GROUPS:
            try:
                limiters.append(velocity_limiter(params, group))
            except InvalidLimitsError as err:
                raise self.error(group, f'invalid limits: {err}') from None
        self._limiters = tuple(limiters)
        self._references = twist_references(name)
        self._reference_list = tuple(self._references.values())
        kinematics = params['kinematics']
        for field in ('wheels_radius', 'sum_of_robot_center_projection_on_X_Y_axis'):
            if not kinematics[field] > 0.0:  # the default 0 too: upstream validates it so
                raise self.error(f'kinematics.{field}', f'{kinematics[field]!r} must be > 0')
        offset = kinematics['base_frame_offset']
        self._offset = (offset['x'], offset['y'], offset['theta'])
        self._radius = kinematics['wheels_radius']
        self._projection_sum = kinematics['sum_of_robot_center_projection_on_X_Y_axis']
        self._odometry = MecanumOdometry(self._radius, self._projection_sum, self._offset)
        self._schedule = PeriodicSchedule(update_period(params))
        # Each wheel's command: a joint's handle, or a following controller's reference.
        self._commands: list[JointHandle | Reference] = []
        self._command_handles: list[JointHandle] = []
        self._states: list[JointHandle] = []
        self._odometry_sink: SpatialOdometrySink | None = None
        self._tf_sink: TfSink | None = None
        self._state_sink: StateSink | None = None
        self._command = TwistCommand('reference', sideways=True,
                                     timeout_field='reference_timeout')
        self.reset()

    # --- what it claims and exports --------------------------------------------------------

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The command joints, front left, front right, rear right, rear left."""
        return self._command_names

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the velocity interface of every command joint."""
        return {joint: (VELOCITY,) for joint in self._command_names}

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the velocity interface of every state joint."""
        return {joint: (VELOCITY,) for joint in self._state_names}

    def actuators(self) -> dict[str, Actuator]:
        """Return the ideal velocity actuator for every command joint (not references)."""
        return {handle.name: Actuator(ActuatorKind.IDEAL_VELOCITY, self.name)
                for handle in self._command_handles}

    def reference_interfaces(self) -> Mapping[str, Reference]:
        """Return ``<name>/linear/x/velocity``, ``.../linear/y/...`` and ``.../angular/z/...``."""
        return self._references

    def roller_wheels(self) -> dict[str, float]:
        """Return each wheel's roller angle (rad): 45 degrees, an X seen from above.

        The wheels are the state joints: the command joints unless a
        following controller drives them (then the state joints name them).
        """
        return {joint: ROLLER_ANGLES[wheel]
                for wheel, joint in zip(WHEELS, self._state_names, strict=True)}

    def schedule(self) -> PeriodicSchedule:
        """Return the update schedule: every ``1 / update_rate`` s of sim time."""
        return self._schedule

    # --- ROS surface -----------------------------------------------------------------------

    def frame_ids(self) -> tuple[str, str]:
        """Return the odometry frame and the base frame, prefixed as upstream prefixes them."""
        return prefixed_frames(self.params, self.node_namespace)

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return ``~/reference`` in; ``~/odometry``, ``~/tf_odometry``, ``~/controller_state``."""
        odom, base = self.frame_ids()
        params = self.params
        endpoints: list[Endpoint] = [
            CommandTopic(f'~/{self.command_topic}', self.command_kind.value, self.set_command,
                         self.command_problem),
            self.odometry_topic('~/odometry', (odom, base), params['pose_covariance_diagonal'],
                                params['twist_covariance_diagonal'], spatial=True)]
        if params['enable_odom_tf']:
            endpoints.append(StateTopic('~/tf_odometry', 'tf2_msgs/msg/TFMessage',
                                        self.set_tf_sink))
        endpoints.append(StateTopic('~/controller_state',
                                    'control_msgs/msg/MecanumDriveControllerState',
                                    self.set_state_sink, {'frame_id': odom}))
        return tuple(endpoints)

    def set_state_sink(self, sink: StateSink | None) -> None:
        """Where the state goes: ``sink(time, wheel velocities, (vx, vy, wz) reference)``."""
        self._state_sink = sink

    # --- lifecycle -------------------------------------------------------------------------

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the wheels (an unknown joint names its parameter), then reset."""
        self._commands = [self.command_target(joints, joint, VELOCITY,
                                              f'{wheel}_wheel_command_joint_name')
                          for wheel, joint in zip(WHEELS, self._command_names, strict=True)]
        self._command_handles = [target for target in self._commands
                                 if isinstance(target, JointHandle)]
        self._states = [self.handle(joints, joint, f'{wheel}_wheel_state_joint_name'
                                    if self.params[f'{wheel}_wheel_state_joint_name']
                                    else f'{wheel}_wheel_command_joint_name', commanded=False)
                        for wheel, joint in zip(WHEELS, self._state_names, strict=True)]
        self.reset()

    def reset(self) -> None:
        """No reference, references NaN, limiter history zero, odometry at the origin."""
        self._command.latest = None
        self._timed_out = False
        self._time = 0.0
        self._last_update: float | None = None
        for reference in self._reference_list:
            reference.value = math.nan
        self._history = [(0.0, 0.0, 0.0), (0.0, 0.0, 0.0)]
        self._schedule.reset()
        self._odometry.reset()
        self._wheel_commands = [0.0] * len(WHEELS)
        self._write(self._wheel_commands)

    def deactivate(self) -> None:
        """Stop the wheels; following controllers' references get NaN, as upstream writes.

        A joint's velocity interface cannot be driven at NaN: it gets 0.
        """
        for target in self._commands:
            if isinstance(target, Reference):
                target.value = math.nan
            else:
                target.velocity_target = 0.0

    # --- commands (set_command, command_problem: TwistCommanded) ----------------------------

    def setpoints(self) -> dict[str, float]:
        """Return each command joint's commanded velocity (rad/s)."""
        return velocity_targets(self._command_handles)

    @property
    def odometry(self) -> MecanumOdometry:
        """The odometry (pose in the odom frame, twist in the base frame)."""
        return self._odometry

    def wheel_velocities(self, linear_x: float, linear_y: float,
                         angular: float) -> tuple[float, float, float, float]:
        """Return the inverse kinematics: wheel velocities (rad/s, WHEELS order) for a twist."""
        offset_x, offset_y, theta = self._offset
        cos, sin = math.cos(theta), math.sin(theta)
        center_x = cos * linear_x - sin * linear_y + offset_y * angular
        center_y = sin * linear_x + cos * linear_y - offset_x * angular
        turn = self._projection_sum * angular
        radius = self._radius
        return ((center_x - center_y - turn) / radius, (center_x + center_y + turn) / radius,
                (center_x - center_y + turn) / radius, (center_x + center_y - turn) / radius)

    # --- the step ---------------------------------------------------------------------------

    def update(self, time: float, period: float) -> None:
        """When due: odometry from the wheels, then the references to wheel speeds."""
        self._time = time
        schedule = self._schedule
        if time + DUE_EPSILON < schedule.next_due:
            return
        schedule.advance(time)
        interval = period if self._last_update is None else time - self._last_update
        self._last_update = time
        if not self.is_chained:
            self._update_references(time)
        measured = [handle.velocity for handle in self._states]
        if all(math.isfinite(velocity) for velocity in measured):
            self._odometry.update(measured, interval)
        references = [reference.value for reference in self._reference_list]
        if any(math.isnan(value) for value in references):
            self._wheel_commands = [0.0] * len(WHEELS)
        else:
            limited = []
            for index, (limit, value) in enumerate(zip(self._limiters, references, strict=True)):
                limited.append(limit.limit(value, self._history[1][index],
                                           self._history[0][index], interval))
            self._history = [self._history[1], tuple(limited)]
            self._wheel_commands = list(self.wheel_velocities(*limited))
        self._write(self._wheel_commands)
        self._publish(time, measured, references)
        for reference in self._reference_list:
            reference.value = math.nan

    def _write(self, velocities: Sequence[float]) -> None:
        """Command the wheels' velocities (rad/s): to their joints or following references."""
        for target, velocity in zip(self._commands, velocities, strict=False):
            if isinstance(target, Reference):
                target.value = velocity
            else:
                target.velocity_target = velocity

    def _update_references(self, time: float) -> None:
        """Write the reference while it is fresh; zeros once, then nothing, when it is stale."""
        reference = self._command.latest
        if reference is None:
            return
        timeout = self.params['reference_timeout']
        values = (reference.linear[0], reference.linear[1], reference.angular[2])
        if timeout == 0.0 or time - reference.stamp <= timeout:
            for interface, value in zip(self._reference_list, values, strict=True):
                interface.value = value
            self._timed_out = False
            if timeout == 0.0:
                self._command.latest = None  # used once, as upstream's reset after each run
            return
        for interface in self._reference_list:
            interface.value = 0.0
        self._command.latest = None
        if not self._timed_out:
            self._timed_out = True
            self.notices.append(f'reference timed out ({timeout:g} s without one at sim time '
                                f'{time:.3f} s): stopping')

    def _publish(self, time: float, measured: Sequence[float],
                 references: Sequence[float]) -> None:
        odometry = self._odometry
        self.publish_spatial(time, odometry.x, odometry.y, odometry.heading,
                             (odometry.linear_x, odometry.linear_y), odometry.angular,
                             self.frame_ids())
        if self._state_sink is not None:
            self._state_sink(time, measured, references)
