"""``omni_wheel_drive_controller/OmniWheelDriveController``: a twist in, n omni wheel speeds out.

As ros2_controllers' (jazzy branch), parameters by their names there (see the design notes).

Design notes: docs/design/controllers.md#omni_wheel_drive_controllerpy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
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
    STRING_ARRAY,
    Param,
    ParameterSpec,
    gt,
    gt_eq,
    names,
    not_empty,
    unique,
)
from pan_tilt_sim.controllers.framework.shared_parameters import (
    UPDATE_RATE,
    check_odometry_frames,
    odometry_frames,
    prefixed_frames,
    tf_frame_prefix,
    update_period,
)
from pan_tilt_sim.controllers.framework.surface import (
    CommandTopic,
    Endpoint,
    StampedTwist,
    StateTopic,
)
from pan_tilt_sim.controllers.toolbox.odometry_outputs import (
    OdometryOutputs,
    SpatialOdometrySink,
    TfSink,
)
from pan_tilt_sim.controllers.toolbox.twist_command import (
    TwistCommand,
    TwistCommanded,
    twist_references,
)
from pan_tilt_sim.controllers.toolbox.wheel_sides import feedback_interfaces, velocity_targets
from pan_tilt_sim.schedule import DUE_EPSILON, PeriodicSchedule

WHEEL_NAMES = 'wheel_names'
VELOCITY = 'velocity'
MIN_WHEELS = 3
OMNI_ROLLERS = math.pi / 2.0  # rad: an omni wheel's rollers roll along its axis
MIN_INTERVAL = 1e-6  # s: odometry updates closer together than this are skipped, as upstream
STRAIGHT = 1e-6  # rad: a smaller turn per update is integrated as a straight step


class OmniOdometry:
    """The base's pose in odom and twist in the base frame from n omni wheels (upstream's).

    Wheel ``i`` at ``2 pi i / n + offset`` rad, ``robot_radius`` m from the
    centre.  The twist is the least-squares solution of the wheels'
    kinematics, in closed form: for n >= 3 evenly spaced wheels the normal
    matrix is diagonal, (n/2, n/2, n R^2).
    """

    def __init__(self, count: int, robot_radius: float, wheel_radius: float,
                 offset: float) -> None:
        self.robot_radius = robot_radius
        self.wheel_radius = wheel_radius
        step = 2.0 * math.pi / count
        self._directions = [(math.sin(step * i + offset), -math.cos(step * i + offset))
                            for i in range(count)]
        self.reset(0.0, [0.0] * count)

    def reset(self, time: float, positions: Sequence[float]) -> None:
        """Back to the origin at sim ``time``; the wheels' ``positions`` (rad) are the reference."""
        self.x = self.y = self.heading = 0.0
        self.linear_x = self.linear_y = self.angular = 0.0
        self._time = time
        self._positions = list(positions)

    def body_twist(self, wheel_velocities: Sequence[float]) -> tuple[float, float, float]:
        """Return the base's twist (m/s, m/s, rad/s) that best explains the wheels' (rad/s)."""
        count = len(wheel_velocities)
        radius = self.wheel_radius
        vx = vy = turn = 0.0
        for (sin, minus_cos), velocity in zip(self._directions, wheel_velocities, strict=True):
            speed = velocity * radius
            vx += sin * speed
            vy += minus_cos * speed
            turn += speed
        return (2.0 * vx / count, 2.0 * vy / count, -turn / (count * self.robot_radius))

    def update_from_positions(self, positions: Sequence[float], time: float) -> bool:
        """Integrate the wheels' turn (rad) since the last update; False if too soon."""
        dt = time - self._time
        if abs(dt) < MIN_INTERVAL:
            return False
        velocities = [(now - before) / dt
                      for now, before in zip(positions, self._positions, strict=True)]
        self._positions = list(positions)
        return self.update_from_velocities(velocities, time)

    def update_from_velocities(self, velocities: Sequence[float], time: float) -> bool:
        """Integrate the wheels' velocities (rad/s) over the time since the last update."""
        dt = time - self._time
        self.linear_x, self.linear_y, self.angular = self.body_twist(velocities)
        self._integrate(self.linear_x * dt, self.linear_y * dt, self.angular * dt)
        self._time = time
        return True

    def update_open_loop(self, linear_x: float, linear_y: float, angular: float,
                         time: float) -> bool:
        """Integrate the commanded twist over the time since the last update."""
        dt = time - self._time
        self._integrate(linear_x * dt, linear_y * dt, angular * dt)
        self._time = time
        self.linear_x, self.linear_y, self.angular = linear_x, linear_y, angular
        return True

    def _integrate(self, dx: float, dy: float, turn: float) -> None:
        """Move by (dx, dy) in the base frame while turning ``turn`` rad (exact along an arc)."""
        before = self.heading
        if abs(turn) < STRAIGHT:
            cos, sin = math.cos(before), math.sin(before)
            self.x += dx * cos - dy * sin
            self.y += dx * sin + dy * cos
            self.heading += turn
            return
        self.heading += turn
        after = self.heading
        self.x += (dx / turn) * (math.sin(after) - math.sin(before)) + (dy / turn) * (
            math.cos(after) - math.cos(before))
        self.y += -(dx / turn) * (math.cos(after) - math.cos(before)) + (dy / turn) * (
            math.sin(after) - math.sin(before))


class OmniWheelDriveController(OdometryOutputs, TwistCommanded, CommandController):
    """Drives a base on three or more omni wheels from a twist, as ros2_controllers."""

    type_names = ('omni_wheel_drive_controller/OmniWheelDriveController',)
    chainable = True
    drives_base: ClassVar[bool] = True
    command_topic = 'cmd_vel'
    command_kind = CommandKind.TWIST_STAMPED
    parameters = ParameterSpec([
        Param('wheel_offset', DOUBLE, REQUIRED, 'Angle of the first wheel from the x axis '
              '(rad).', read_only=True, example=0.0),
        Param(WHEEL_NAMES, STRING_ARRAY, REQUIRED, "The wheels' joints, anticlockwise from the "
              'one at wheel_offset; at least three.', (not_empty(), names(), unique()),
              read_only=True, example=['joint1', 'joint2', 'joint3']),
        Param('robot_radius', DOUBLE, REQUIRED, "Distance from the base's centre to the wheels "
              '(m).', (gt(0.0),), read_only=True, example=0.15),
        Param('wheel_radius', DOUBLE, REQUIRED, "The wheels' radius (m).", (gt(0.0),),
              read_only=True, example=0.05),
        *tf_frame_prefix(enable_read_only=True, prefix_read_only=True),
        *odometry_frames(pose_name='diagonal_covariance.pose',
                         twist_name='diagonal_covariance.twist', read_only=True),
        Param('open_loop', BOOL, False, 'Odometry from the command, not the wheels.',
              read_only=True),
        Param('position_feedback', BOOL, True, "Odometry from the wheels' positions (else their "
              'velocities).', read_only=True),
        Param('enable_odom_tf', BOOL, True, 'Publish odom_frame_id -> base_frame_id on /tf.',
              read_only=True),
        Param('cmd_vel_timeout', DOUBLE, 0.5, 'Seconds of sim time after which the last '
              'command is stale and the wheels brake.', (gt_eq(0.0),), read_only=True),
        UPDATE_RATE,
    ])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        check_odometry_frames(self)
        params = self.params
        self._wheel_names = tuple(params[WHEEL_NAMES])
        if len(self._wheel_names) < MIN_WHEELS:
            raise self.error(WHEEL_NAMES, f'{len(self._wheel_names)} wheels: the number of '
                                          'wheels is less than 3 (name them all, or use '
                                          'another controller for this wheel layout)')
        self._references = twist_references(name)
        self._reference_list = tuple(self._references.values())
        self._odometry = OmniOdometry(len(self._wheel_names), params['robot_radius'],
                                      params['wheel_radius'], params['wheel_offset'])
        step = 2.0 * math.pi / len(self._wheel_names)
        self._directions = [(math.sin(step * i + params['wheel_offset']),
                             math.cos(step * i + params['wheel_offset']))
                            for i in range(len(self._wheel_names))]
        self._schedule = PeriodicSchedule(update_period(params))
        self._wheels: list[JointHandle] = []
        self._odometry_sink: SpatialOdometrySink | None = None
        self._tf_sink: TfSink | None = None
        self._command = TwistCommand('cmd_vel', sideways=True, timeout_field='cmd_vel_timeout',
                                     stale_at_timeout=True)
        self.reset()

    # --- what it claims and exports --------------------------------------------------------

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The wheels, in ``wheel_names`` order."""
        return self._wheel_names

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the velocity interface of every wheel."""
        return {wheel: (VELOCITY,) for wheel in self._wheel_names}

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the feedback each wheel is read by (none in open loop)."""
        return feedback_interfaces(self._wheel_names, self.params)

    def actuators(self) -> dict[str, Actuator]:
        """Return the ideal velocity actuator for every wheel."""
        return {wheel: Actuator(ActuatorKind.IDEAL_VELOCITY, self.name)
                for wheel in self._wheel_names}

    def reference_interfaces(self) -> Mapping[str, Reference]:
        """Return ``<name>/linear/x/velocity``, ``.../linear/y/...`` and ``.../angular/z/...``."""
        return self._references

    def roller_wheels(self) -> dict[str, float]:
        """Return every wheel with its rollers' angle: pi / 2, free along the wheel's axis."""
        return {wheel: OMNI_ROLLERS for wheel in self._wheel_names}

    def schedule(self) -> PeriodicSchedule:
        """Return the update schedule: every ``1 / update_rate`` s of sim time."""
        return self._schedule

    # --- ROS surface -----------------------------------------------------------------------

    def frame_ids(self) -> tuple[str, str]:
        """Return the odometry frame and the base frame, prefixed as upstream prefixes them."""
        return prefixed_frames(self.params, self.node_namespace)

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return ``~/cmd_vel`` in; ``~/odom`` and, with ``enable_odom_tf``, ``/tf`` out."""
        odom, base = self.frame_ids()
        covariance = self.params['diagonal_covariance']
        endpoints: list[Endpoint] = [
            CommandTopic(f'~/{self.command_topic}', self.command_kind.value, self.set_command,
                         self.command_problem),
            self.odometry_topic('~/odom', (odom, base), covariance['pose'], covariance['twist'],
                                spatial=True)]
        if self.params['enable_odom_tf']:
            endpoints.append(StateTopic('/tf', 'tf2_msgs/msg/TFMessage', self.set_tf_sink))
        return tuple(endpoints)

    # --- lifecycle -------------------------------------------------------------------------

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the wheels' handles (an unknown wheel names ``wheel_names``), then reset."""
        self._wheels = [self.handle(joints, wheel, WHEEL_NAMES) for wheel in self._wheel_names]
        self.reset()

    def reset(self) -> None:
        """Forget the command (an empty one at time 0), references NaN, odometry at the origin."""
        self._time = 0.0
        self._command.latest = StampedTwist(0.0, (math.nan, math.nan, 0.0),
                                            (0.0, 0.0, math.nan))
        self._timed_out = False
        for reference in self._reference_list:
            reference.value = math.nan
        self._schedule.reset()
        self._odometry.reset(0.0, [handle.position for handle in self._wheels])
        for handle in self._wheels:
            handle.velocity_target = 0.0

    def deactivate(self) -> None:
        """Stop the wheels (upstream's halt)."""
        for handle in self._wheels:
            handle.velocity_target = 0.0

    # --- commands (set_command, command_problem: TwistCommanded) ----------------------------

    def setpoints(self) -> dict[str, float]:
        """Return each wheel's commanded velocity (rad/s)."""
        return velocity_targets(self._wheels)

    @property
    def odometry(self) -> OmniOdometry:
        """The odometry (pose in the odom frame, twist in the base frame)."""
        return self._odometry

    def wheel_velocities(self, linear_x: float, linear_y: float,
                         angular: float) -> list[float]:
        """Return the inverse kinematics: each wheel's velocity (rad/s) for a twist."""
        params = self.params
        turn = angular * params['robot_radius']
        radius = params['wheel_radius']
        return [(sin * linear_x - cos * linear_y - turn) / radius
                for sin, cos in self._directions]

    # --- the step ---------------------------------------------------------------------------

    def update(self, time: float, period: float) -> None:
        """When due: the command to the references, odometry, then the wheels."""
        self._time = time
        schedule = self._schedule
        if time + DUE_EPSILON < schedule.next_due:
            return
        schedule.advance(time)
        if not self.is_chained:
            self._update_references(time)
        linear_x, linear_y, angular = (reference.value for reference in self._reference_list)
        if not (math.isfinite(linear_x) and math.isfinite(linear_y) and math.isfinite(angular)):
            return  # nothing commanded yet, as upstream
        odometry = self._odometry
        if self.params['open_loop']:
            odometry.update_open_loop(linear_x, linear_y, angular, time)
        elif self.params['position_feedback']:
            odometry.update_from_positions([handle.position for handle in self._wheels], time)
        else:
            odometry.update_from_velocities([handle.velocity for handle in self._wheels], time)
        self._publish(time)
        for handle, velocity in zip(self._wheels, self.wheel_velocities(
                linear_x, linear_y, angular), strict=False):
            handle.velocity_target = velocity

    def _update_references(self, time: float) -> None:
        """Write the command to the references, or zeros once it is stale (braking)."""
        command = self._command.latest
        timeout = self.params['cmd_vel_timeout']
        if time - command.stamp > timeout:
            for reference in self._reference_list:
                reference.value = 0.0
            if not self._timed_out and math.isfinite(command.linear[0]) and timeout > 0.0:
                self.notices.append(f'velocity command timed out ({timeout:g} s without one at '
                                    f'sim time {time:.3f} s): braking')
            self._timed_out = True
            return
        self._timed_out = False
        values = (command.linear[0], command.linear[1], command.angular[2])
        if all(math.isfinite(value) for value in values):
            for reference, value in zip(self._reference_list, values, strict=True):
                reference.value = value

    def _publish(self, time: float) -> None:
        odometry = self._odometry
        self.publish_spatial(time, odometry.x, odometry.y, odometry.heading,
                             (odometry.linear_x, odometry.linear_y), odometry.angular,
                             self.frame_ids())
