"""``tricycle_controller/TricycleController``: one wheel that steers and drives.

As ros2_controllers' (jazzy), parameters by their names there (see the design notes).

Design notes: docs/design/controllers.md#tricycle_controllerpy.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from pan_tilt_sim.controllers.drives.steering.steering_controllers import (
    SteeredOnOwnClock,
    SteeringJoints,
)
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
)
from pan_tilt_sim.controllers.framework.parameter_spec import (
    BOOL,
    DOUBLE,
    INT,
    REQUIRED,
    STRING,
    Param,
    ParameterSpec,
    gt,
    gt_eq,
    not_empty,
)
from pan_tilt_sim.controllers.framework.shared_parameters import (
    UPDATE_RATE,
    check_odometry_frames,
    odometry_frames,
    update_period,
)
from pan_tilt_sim.controllers.framework.surface import (
    CommandTopic,
    Endpoint,
    Service,
    StateTopic,
)
from pan_tilt_sim.controllers.toolbox.odometry_outputs import OdometryOutputs, OdometrySink, TfSink
from pan_tilt_sim.controllers.toolbox.twist_command import TwistCommand, TwistCommanded
from pan_tilt_sim.schedule import PeriodicSchedule

TRACTION, STEERING = 'traction_joint_name', 'steering_joint_name'
VELOCITY, POSITION = 'velocity', 'position'
UNBOUNDED = 1000.0  # upstream's "arbitrarily big" upper bound where only a lower one is given
ACKERMANN_MESSAGE = 'ackermann_msgs/msg/AckermannDrive'
# Steering further than this from its command scales the wheel speed by the cosine of the
# difference; beyond SLOW_ERROR the scale is SLOWEST.
FULL_SPEED_ERROR = math.pi / 6.0
SLOW_ERROR = math.pi / 2.0
SLOWEST = 0.01
AckermannSink = Callable[[float, float, float], None]  # sink(time, speed, steering angle)


def _given(value: float) -> bool:
    return not math.isnan(value)


def _clamp(value: float, lower: float, upper: float) -> float:
    return lower if value < lower else upper if value > upper else value


def _signed(magnitude: float, change: float) -> float:
    return magnitude if change >= 0.0 else -magnitude


class LimitsError(ValueError):
    """Limits upstream refuses (negative, or a floor above its ceiling)."""


def _pair(low: float, high: float, name: str, low_default: float = 0.0) -> tuple[float, float]:
    """Complete a (min, max) magnitude pair as upstream; refuse negative or crossed ones."""
    if _given(low) and not _given(high):
        high = UNBOUNDED
    if _given(high) and not _given(low):
        low = low_default
    if low < 0.0 or high < 0.0:
        raise LimitsError(f'{name} limits cannot be negative (one magnitude for both '
                          'directions)')
    if low > high:
        raise LimitsError(f'min_{name} {low:g} > max_{name} {high:g}')
    return low, high


class TractionLimiter:
    """The wheel speed's limits (rad/s, per s, per s^2): magnitudes, in both directions."""

    def __init__(self, limits: Mapping[str, float]) -> None:
        self.velocity = _pair(limits['min_velocity'], limits['max_velocity'], 'velocity')
        self.acceleration = _pair(limits['min_acceleration'], limits['max_acceleration'],
                                  'acceleration')
        self.deceleration = _pair(limits['min_deceleration'], limits['max_deceleration'],
                                  'deceleration')
        self.jerk = _pair(limits['min_jerk'], limits['max_jerk'], 'jerk')

    def limit(self, value: float, previous: float, before: float, dt: float) -> float:
        """Return ``value`` limited: jerk, acceleration, then velocity (upstream's order)."""
        low, high = self.jerk
        if _given(low):
            change, last_change = value - previous, previous - before
            step = 2.0 * dt * dt
            value = previous + last_change + _signed(
                _clamp(abs(change - last_change), low * step, high * step), change - last_change)
        growing = abs(value) >= abs(previous)
        low, high = self.acceleration if growing else self.deceleration
        if _given(low):
            value = previous + _signed(_clamp(abs(value - previous), low * dt, high * dt),
                                       value - previous)
        low, high = self.velocity
        if _given(low):
            value = _signed(_clamp(abs(value), low, high), value)
        return value


class SteeringLimiter:
    """The steering angle's limits (rad, rad/s, rad/s^2): position range, rate magnitudes."""

    def __init__(self, limits: Mapping[str, float]) -> None:
        low, high = limits['min_position'], limits['max_position']
        if _given(low) and not _given(high):
            high = -low
        if _given(high) and not _given(low):
            low = -high
        self.position = (low, high)
        self.velocity = _pair(limits['min_velocity'], limits['max_velocity'], 'velocity')
        self.acceleration = _pair(limits['min_acceleration'], limits['max_acceleration'],
                                  'acceleration')

    def limit(self, value: float, previous: float, before: float, dt: float) -> float:
        """Return ``value`` limited: acceleration, velocity, then position (upstream's order)."""
        low, high = self.acceleration
        if _given(low):
            change, last_change = value - previous, previous - before
            step = 2.0 * dt * dt
            value = previous + last_change + _signed(
                _clamp(abs(change - last_change), low * step, high * step), change - last_change)
        low, high = self.velocity
        if _given(low):
            value = previous + _signed(_clamp(abs(value - previous), low * dt, high * dt),
                                       value - previous)
        low, high = self.position
        if _given(low):
            value = _clamp(value, low, high)
        return value


def _limit(group: str, name: str, unit: str) -> Param:
    return Param(f'{group}.{name}', DOUBLE, math.nan, f'{name.replace("_", " ").capitalize()} '
                 f'({unit}, a magnitude for both directions); NaN: none.', finite=False)


class TricycleController(SteeredOnOwnClock, OdometryOutputs, TwistCommanded, CommandController):
    """Drives a tricycle's steered and driven wheel from a twist; publishes its odometry."""

    type_names = ('tricycle_controller/TricycleController',)
    drives_base: ClassVar[bool] = True
    command_topic = 'cmd_vel'
    command_kind = CommandKind.TWIST_STAMPED
    parameters = ParameterSpec([
        Param(TRACTION, STRING, REQUIRED, 'The joint of the wheel that drives.', (not_empty(),),
              example='joint1'),
        Param(STEERING, STRING, REQUIRED, 'The joint that steers that wheel.', (not_empty(),),
              example='joint2'),
        Param('wheelbase', DOUBLE, REQUIRED, 'Distance from the steered wheel to the rear axle '
              '(m).', (gt(0.0),), example=0.5),
        Param('wheel_radius', DOUBLE, REQUIRED, 'Radius of the driven wheel (m).', (gt(0.0),),
              example=0.05),
        *odometry_frames(),
        Param('open_loop', BOOL, False, 'Odometry from the command, not the joints.'),
        Param('enable_odom_tf', BOOL, False, 'Publish odom_frame_id -> base_frame_id on /tf.'),
        Param('odom_only_twist', BOOL, False, "Publish only the odometry's twist (its pose "
              'stays zero).'),
        Param('cmd_vel_timeout', INT, 500, 'Milliseconds of sim time after which a command is '
              'stale and the wheel stops.', (gt_eq(0),)),
        Param('publish_ackermann_command', BOOL, False, 'Publish the limited command on '
              '~/cmd_ackermann.'),
        Param('velocity_rolling_window_size', INT, 10, "Updates in the odometry twist's rolling "
              'mean.', (gt(0),)),
        *(_limit('traction', name, unit) for name, unit in (
            ('max_velocity', 'rad/s'), ('min_velocity', 'rad/s'),
            ('max_acceleration', 'rad/s^2'), ('min_acceleration', 'rad/s^2'),
            ('max_deceleration', 'rad/s^2'), ('min_deceleration', 'rad/s^2'),
            ('max_jerk', 'rad/s^3'), ('min_jerk', 'rad/s^3'))),
        *(_limit('steering', name, unit) for name, unit in (
            ('max_position', 'rad'), ('min_position', 'rad'), ('max_velocity', 'rad/s'),
            ('min_velocity', 'rad/s'), ('max_acceleration', 'rad/s^2'),
            ('min_acceleration', 'rad/s^2'))),
        UPDATE_RATE,
    ])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        check_odometry_frames(self)
        params = self.params
        try:
            self._traction_limiter = TractionLimiter(params['traction'])
        except LimitsError as err:
            raise self.error('traction', f'invalid limits: {err}') from None
        try:
            self._steering_limiter = SteeringLimiter(params['steering'])
        except LimitsError as err:
            raise self.error('steering', f'invalid limits: {err}') from None
        if params[TRACTION] == params[STEERING]:
            raise self.error(STEERING, f"'{params[STEERING]}' is also the {TRACTION}: a joint "
                                       'either steers or drives')
        self._odometry = SteeringKinematics(Configuration.BICYCLE, params['wheelbase'],
                                            params['wheel_radius'],
                                            window=params['velocity_rolling_window_size'])
        self._updates = PeriodicSchedule(update_period(params))
        self._traction: JointHandle | None = None
        self._steering = SteeringJoints()
        self._odometry_sink: OdometrySink | None = None
        self._tf_sink: TfSink | None = None
        self._ackermann_sink: AckermannSink | None = None
        self._command = TwistCommand('cmd_vel')
        self.reset()

    # --- what it claims ---------------------------------------------------------------------

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The driven joint, then the steering joint."""
        return self.params[TRACTION], self.params[STEERING]

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return ``velocity`` for the driven joint, ``position`` for the steering joint."""
        return {self.params[TRACTION]: (VELOCITY,), self.params[STEERING]: (POSITION,)}

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the driven joint's velocity and the steering joint's position."""
        return {self.params[TRACTION]: (VELOCITY,), self.params[STEERING]: (POSITION,)}

    def actuators(self) -> dict[str, Actuator]:
        """Return the ideal velocity actuator for the wheel, position for the steering."""
        return {self.params[TRACTION]: Actuator(ActuatorKind.IDEAL_VELOCITY, self.name),
                self.params[STEERING]: Actuator(ActuatorKind.IDEAL_POSITION, self.name)}

    # --- ROS surface -----------------------------------------------------------------------

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return ``~/cmd_vel`` in; ``~/odom``, ``/tf``, ``~/cmd_ackermann`` as configured."""
        params = self.params
        odom, base = params['odom_frame_id'], params['base_frame_id']
        endpoints: list[Endpoint] = [
            CommandTopic(f'~/{self.command_topic}', self.command_kind.value, self.set_command,
                         self.command_problem),
            self.odometry_topic('~/odom', (odom, base), params['pose_covariance_diagonal'],
                                params['twist_covariance_diagonal']),
            Service('~/reset_odometry', 'std_srvs/srv/Empty', self.reset_odometry)]
        if params['enable_odom_tf']:
            endpoints.append(StateTopic('/tf', 'tf2_msgs/msg/TFMessage', self.set_tf_sink))
        if params['publish_ackermann_command']:
            endpoints.append(StateTopic('~/cmd_ackermann', ACKERMANN_MESSAGE,
                                        self.set_ackermann_sink))
        return tuple(endpoints)

    def set_ackermann_sink(self, sink: AckermannSink | None) -> None:
        """Where the limited command goes: ``sink(time, speed, steering angle)``."""
        self._ackermann_sink = sink

    def reset_odometry(self, value: Any = None) -> None:
        """Put the odometry back at the origin (the ``~/reset_odometry`` service)."""
        self._odometry.reset()

    # --- lifecycle -------------------------------------------------------------------------

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the joints' handles (an unknown joint names its parameter), then reset."""
        self._traction = self.handle(joints, self.params[TRACTION], TRACTION)
        self._steering = SteeringJoints([self.handle(joints, self.params[STEERING], STEERING)])
        self.reset()

    def reset(self) -> None:
        """No command, odometry at the origin, the wheel asked to stand, the steering held."""
        self._command.latest = None
        self._timed_out = False
        self._time = 0.0
        self._last_update: float | None = None
        # The last two limited commands, (wheel speed, steering angle); upstream starts at zero.
        self._history = [(0.0, 0.0), (0.0, 0.0)]
        self._updates.reset()
        self._odometry.reset()
        if self._traction is not None:
            self._traction.velocity_target = 0.0
        self._steering.hold()

    def deactivate(self) -> None:
        """Stop the wheel and steer it straight (upstream's halt)."""
        if self._traction is not None:
            self._traction.velocity_target = 0.0
        self._steering.command([0.0])

    # --- commands (set_command, command_problem: TwistCommanded) ----------------------------

    def setpoints(self) -> dict[str, float]:
        """Return the wheel's commanded velocity (rad/s) and the steering setpoint (rad)."""
        wanted = {}
        if self._traction is not None:
            wanted[self._traction.name] = self._traction.velocity_target
        for handle, setpoint in zip(self._steering.handles, self._steering.setpoints,
                                    strict=True):
            wanted[handle.name] = setpoint
        return wanted

    @property
    def odometry(self) -> SteeringKinematics:
        """The odometry (pose and twist in the odom frame)."""
        return self._odometry

    @property
    def limited_command(self) -> tuple[float, float]:
        """The last limited command: wheel speed (rad/s) and steering angle (rad)."""
        return self._history[1]

    @property
    def steering_command(self) -> float:
        """The angle the steering joint's position interface was last sent (rad; NaN: none)."""
        return self._steering.commands[0] if self._steering.commands else math.nan

    def twist_to_ackermann(self, linear: float, angular: float) -> tuple[float, float]:
        """Return the steering angle (rad) and wheel speed (rad/s) of a twist, as upstream."""
        wheelbase, radius = self.params['wheelbase'], self.params['wheel_radius']
        if linear == 0.0 and angular != 0.0:  # on the spot
            return math.copysign(math.pi / 2.0, angular), abs(angular) * wheelbase / radius
        alpha = 0.0 if angular == 0.0 or linear == 0.0 else math.atan(
            angular * wheelbase / linear)
        return alpha, linear / (radius * math.cos(alpha))

    # --- the step ---------------------------------------------------------------------------

    # update(): SteeredOnOwnClock; one upstream update: command, odometry, limits, joints.

    def _control(self, time: float, period: float) -> None:
        linear, angular = self._current_command(time)
        wheel, steering = self._traction, self._steering.handles[0]
        odometry = self._odometry
        if self.params['open_loop']:
            odometry.update_open_loop(linear, angular, period)
        else:
            speed = wheel.velocity * self.params['wheel_radius']
            alpha = steering.position
            odometry.update_from_twist(speed * math.cos(alpha),
                                       speed * math.sin(alpha) / self.params['wheelbase'], period)
        self._publish(time)
        alpha, speed = self.twist_to_ackermann(linear, angular)
        error = abs(alpha - steering.position)
        if error > SLOW_ERROR:
            speed *= SLOWEST
        elif error >= FULL_SPEED_ERROR:
            speed *= math.cos(error)
        (before_speed, before_angle), (last_speed, last_angle) = self._history
        speed = self._traction_limiter.limit(speed, last_speed, before_speed, period)
        alpha = self._steering_limiter.limit(alpha, last_angle, before_angle, period)
        self._history = [self._history[1], (speed, alpha)]
        if self._ackermann_sink is not None:
            self._ackermann_sink(time, speed, alpha)
        wheel.velocity_target = speed
        self._steering.command([alpha])

    def _current_command(self, time: float) -> tuple[float, float]:
        """Return the command's (linear, angular); zero before the first and once stale."""
        command = self._command.latest
        if command is None:
            return 0.0, 0.0
        timeout = self.params['cmd_vel_timeout'] / 1000.0
        if time - command.stamp > timeout:
            if not self._timed_out:
                self._timed_out = True
                self.notices.append(f'velocity command timed out ({timeout:g} s without one at '
                                    f'sim time {time:.3f} s): stopping')
            return 0.0, 0.0
        return command.linear[0], command.angular[2]

    def _publish(self, time: float) -> None:
        odometry, params = self._odometry, self.params
        self.publish_planar(time, odometry.x, odometry.y, odometry.heading, odometry.linear,
                            odometry.angular, (params['odom_frame_id'], params['base_frame_id']),
                            twist_only=params['odom_only_twist'])
