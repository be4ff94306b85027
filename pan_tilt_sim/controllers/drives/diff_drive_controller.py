"""``diff_drive_controller/DiffDriveController``: a twist in, wheel velocities out, odometry back.

As ros2_controllers' (jazzy), parameters by their names there (see the design notes).

Design notes: docs/design/controllers.md#diff_drive_controllerpy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
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
    INT,
    REQUIRED,
    STRING_ARRAY,
    Param,
    ParameterSpec,
    gt,
    gt_eq,
    not_empty,
    rate,
    unique,
)
from pan_tilt_sim.controllers.framework.shared_parameters import (
    check_odometry_frames,
    odometry_frames,
    prefixed_frames,
    tf_frame_prefix,
    velocity_limit_params,
    velocity_limiter,
)
from pan_tilt_sim.controllers.framework.surface import CommandTopic, Endpoint, StateTopic
from pan_tilt_sim.controllers.toolbox.odometry import Odometry
from pan_tilt_sim.controllers.toolbox.odometry_outputs import (
    OdometryOutputs,
    OdometrySink,
    TfSink,
    TwistSink,
)
from pan_tilt_sim.controllers.toolbox.rate_limiter import InvalidLimitsError, RateLimiter
from pan_tilt_sim.controllers.toolbox.twist_command import (
    TwistCommand,
    TwistCommanded,
    planar_references,
)
from pan_tilt_sim.controllers.toolbox.wheel_sides import feedback_interfaces
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model import ros1_diff_drive
from pan_tilt_sim.schedule import PeriodicSchedule

LEFT, RIGHT = 'left_wheel_names', 'right_wheel_names'
VELOCITY = 'velocity'
LIMIT_GROUPS = ('linear.x', 'angular.z')


class DiffDriveController(OdometryOutputs, TwistCommanded, CommandController):
    """Drives a differential base from a twist and publishes its odometry, as ros2_controllers."""

    type_names = ('diff_drive_controller/DiffDriveController',)
    chainable = True
    drives_base: ClassVar[bool] = True
    command_topic = 'cmd_vel'
    command_kind = CommandKind.TWIST_STAMPED
    parameters = ParameterSpec([
        Param(LEFT, STRING_ARRAY, REQUIRED, "The left side wheels' joints.",
              (not_empty(), unique()), example=['joint1']),
        Param(RIGHT, STRING_ARRAY, REQUIRED, "The right side wheels' joints (as many).",
              (not_empty(), unique()), example=['joint2']),
        Param('wheel_separation', DOUBLE, REQUIRED, 'Distance between the left and right '
              'wheels (m).', (gt(0.0),), example=0.3),
        Param('wheel_radius', DOUBLE, REQUIRED, 'Radius of the wheels (m).', (gt(0.0),),
              example=0.05),
        Param('wheel_separation_multiplier', DOUBLE, 1.0,
              'Correction factor of wheel_separation.', (gt(0.0),)),
        Param('left_wheel_radius_multiplier', DOUBLE, 1.0,
              'Correction factor of wheel_radius for the left wheels.', (gt(0.0),)),
        Param('right_wheel_radius_multiplier', DOUBLE, 1.0,
              'Correction factor of wheel_radius for the right wheels.', (gt(0.0),)),
        *tf_frame_prefix(),
        *odometry_frames(),
        Param('open_loop', BOOL, False, 'Odometry from the limited command, not the wheels.'),
        Param('position_feedback', BOOL, True, "Odometry from the wheels' positions (else "
              'their velocities).'),
        Param('enable_odom_tf', BOOL, True, 'Publish odom_frame_id -> base_frame_id on /tf.'),
        Param('cmd_vel_timeout', DOUBLE, 0.5, 'Seconds of sim time after which the last '
              'command is stale and the robot brakes; 0: never.', (gt_eq(0.0),)),
        Param('publish_limited_velocity', BOOL, False, 'Publish the limited twist on '
              '~/cmd_vel_out.'),
        Param('velocity_rolling_window_size', INT, 10, "Updates in the odometry twist's "
              'rolling mean.', (gt_eq(1),)),
        Param('publish_rate', DOUBLE, 50.0, 'Odometry and TF messages per second of sim time.',
              (rate(),)),
        Param('update_rate', DOUBLE, None, "The controller's update rate (Hz): the rate of "
              '~/cmd_vel_out.', (rate(),)),
        *velocity_limit_params('linear.x', deprecated_switches=True),
        *velocity_limit_params('angular.z', deprecated_switches=True),
    ])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        # ROS 1's layout (gazebo_ros_control YAML): its names and defaults, an unstamped Twist.
        self.ros1 = isinstance(params, Mapping) and ros1_diff_drive.is_ros1_layout(params)
        if self.ros1:
            params = ros1_diff_drive.jazzy_params(params)
            self.command_kind = CommandKind.TWIST
        try:
            super().__init__(name, params, source)
        except ControllerConfigError as err:
            if not self.ros1:
                raise
            raise ControllerConfigError(ros1_diff_drive.ros1_message(str(err))) from None
        left, right = list(self.params[LEFT]), list(self.params[RIGHT])
        if len(left) != len(right):
            raise self.error(RIGHT, f'{len(right)} wheels, but {LEFT} names {len(left)}: '
                                    'each side needs as many')
        both = [wheel for wheel in left if wheel in right]
        if both:
            raise self.error(RIGHT, f"'{both[0]}' is also one of {LEFT}")
        check_odometry_frames(self)
        self._left_names, self._right_names = tuple(left), tuple(right)
        self._limiters = tuple(self._limiter(group) for group in LIMIT_GROUPS)
        self._references = planar_references(name)
        self._linear_reference, self._angular_reference = self._references.values()
        self._odometry = Odometry(*self._geometry(), self.params['velocity_rolling_window_size'])
        self._publishing = PeriodicSchedule(1.0 / self.params['publish_rate'])
        self._limited_publishing = PeriodicSchedule(
            1.0 / (self.params.get('update_rate') or self.params['publish_rate']))
        # What each wheel's velocity is written to: its joint, or a reference (chained).
        self._left_outputs: list[JointHandle | Reference] = []
        self._right_outputs: list[JointHandle | Reference] = []
        # Where each wheel's feedback is read (empty in open loop for chained wheels).
        self._left: list[JointHandle] = []
        self._right: list[JointHandle] = []
        self._odometry_sink: OdometrySink | None = None
        self._tf_sink: TfSink | None = None
        self._twist_sink: TwistSink | None = None
        self._command = TwistCommand('cmd_vel', timeout_field='cmd_vel_timeout',
                                     stale_at_timeout=True)
        self.reset()

    def error(self, field: str, problem: str) -> ControllerConfigError:
        """Return a configuration error naming ``field``; in noetic's names for a ROS 1 file."""
        err = super().error(field, problem)
        return ControllerConfigError(ros1_diff_drive.ros1_message(str(err))) if self.ros1 else err

    def _limiter(self, group: str) -> RateLimiter:
        try:
            return velocity_limiter(self.params, group)
        except InvalidLimitsError as err:
            raise self.error(group, f'invalid limits: {err}') from None

    def _geometry(self) -> tuple[float, float, float]:
        """Return the wheel separation and the left and right radii, multipliers applied (m)."""
        params = self.params
        radius = params['wheel_radius']
        return (params['wheel_separation_multiplier'] * params['wheel_separation'],
                params['left_wheel_radius_multiplier'] * radius,
                params['right_wheel_radius_multiplier'] * radius)

    # --- what it claims and exports --------------------------------------------------------

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The wheels, left then right."""
        return self._left_names + self._right_names

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the velocity interface of every wheel."""
        return {wheel: (VELOCITY,) for wheel in self.joint_names}

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the feedback each wheel is read by (none in open loop)."""
        return feedback_interfaces(self.joint_names, self.params)

    def actuators(self) -> dict[str, Actuator]:
        """Return the ideal velocity actuator for every wheel that is a joint (not a reference)."""
        return {output.name: Actuator(ActuatorKind.IDEAL_VELOCITY, self.name)
                for output in self._left_outputs + self._right_outputs
                if isinstance(output, JointHandle)}

    def reference_interfaces(self) -> Mapping[str, Reference]:
        """Return ``<name>/linear/velocity`` and ``<name>/angular/velocity``."""
        return self._references

    # --- ROS surface -----------------------------------------------------------------------

    def frame_ids(self) -> tuple[str, str]:
        """Return the odometry frame and the base frame, prefixed as upstream prefixes them."""
        return prefixed_frames(self.params, self.node_namespace)

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return ``~/cmd_vel`` in; ``~/odom``, ``/tf`` and ``~/cmd_vel_out`` out as configured."""
        odom, base = self.frame_ids()
        params = self.params
        endpoints: list[Endpoint] = [
            CommandTopic(f'~/{self.command_topic}', self.command_kind.value, self.set_command,
                         self.command_problem),
            self.odometry_topic('~/odom', (odom, base), params['pose_covariance_diagonal'],
                                params['twist_covariance_diagonal'])]
        if params['enable_odom_tf']:
            endpoints.append(StateTopic('/tf', 'tf2_msgs/msg/TFMessage', self.set_tf_sink))
        if params['publish_limited_velocity']:
            endpoints.append(StateTopic('~/cmd_vel_out', CommandKind.TWIST_STAMPED.value,
                                        self.set_limited_velocity_sink))
        return tuple(endpoints)

    def set_limited_velocity_sink(self, sink: TwistSink | None) -> None:
        """Where the limited twist goes: ``sink(time, linear, angular)``."""
        self._twist_sink = sink

    # --- lifecycle -------------------------------------------------------------------------

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind each wheel's joint or reference and its feedback, then reset.

        An unknown wheel names its parameter and what exists.
        """
        sides = []
        for names, field in ((self._left_names, LEFT), (self._right_names, RIGHT)):
            outputs = [self.command_target(joints, wheel, VELOCITY, field) for wheel in names]
            feedback = [self._feedback(joints, wheel, output, field)
                        for wheel, output in zip(names, outputs, strict=True)]
            sides.append((outputs, [handle for handle in feedback if handle is not None]))
        (self._left_outputs, self._left), (self._right_outputs, self._right) = sides
        self.reset()

    def _feedback(self, joints: Mapping[str, JointHandle], wheel: str,
                  output: JointHandle | Reference, field: str) -> JointHandle | None:
        """Return the handle a wheel's feedback is read from (None: chained, in open loop)."""
        if isinstance(output, JointHandle):
            return output
        dof = wheel.partition('/')[2]
        handle = joints.get(dof)
        if handle is None and not self.params['open_loop']:
            raise self.error(field, f"'{wheel}' is a reference interface, and '{dof}' is not a "
                             'joint of the robot whose state could be its feedback: set '
                             'open_loop to true')
        return None if self.params['open_loop'] else handle

    def reset(self) -> None:
        """No command, references NaN, odometry at the origin, wheel joints asked to stand."""
        self._command.latest = None
        self._timed_out = False
        self._time = 0.0
        self._linear_reference.value = math.nan
        self._angular_reference.value = math.nan
        # The last two limited commands (upstream fills them with zeros, not NaN).
        self._history = [(0.0, 0.0), (0.0, 0.0)]
        self._publishing.reset()
        self._limited_publishing.reset()
        self._linear_command = self._angular_command = 0.0
        self._odometry.reset(0.0, *self._side_positions())
        # The joints are asked to stand; a reference is written only while active (a
        # configured, inactive controller must not touch an active chained controller's).
        for output in self._left_outputs + self._right_outputs:
            if isinstance(output, JointHandle):
                output.velocity_target = 0.0

    def deactivate(self) -> None:
        """Stop the wheels (upstream's halt)."""
        self._drive(0.0, 0.0)

    def _drive(self, left: float, right: float) -> None:
        """Command each side's wheels ``left`` and ``right`` rad/s (joints or references)."""
        for outputs, velocity in ((self._left_outputs, left), (self._right_outputs, right)):
            for output in outputs:
                if isinstance(output, Reference):
                    output.value = velocity
                else:
                    output.velocity_target = velocity

    # --- commands (set_command, command_problem: TwistCommanded) ----------------------------

    def setpoints(self) -> dict[str, float]:
        """Return each wheel's commanded velocity (rad/s), by wheel name."""
        outputs = self._left_outputs + self._right_outputs
        return {wheel: output.value if isinstance(output, Reference) else output.velocity_target
                for wheel, output in zip(self.joint_names, outputs, strict=True)}

    @property
    def limited_command(self) -> tuple[float, float]:
        """The last limited command: linear (m/s) and angular (rad/s) velocity."""
        return self._linear_command, self._angular_command

    @property
    def odometry(self) -> Odometry:
        """The odometry (pose and twist in the odom frame)."""
        return self._odometry

    # --- the step ---------------------------------------------------------------------------

    def update(self, time: float, period: float) -> None:
        """Take the command (or the references), limit it, integrate odometry, drive the wheels."""
        self._time = time
        if not self.is_chained:
            self._update_references(time)
        linear, angular = self._linear_reference.value, self._angular_reference.value
        if not (math.isfinite(linear) and math.isfinite(angular)):
            # Nothing commanded yet: the wheels stand, the odometry still runs and is published.
            self._update_odometry(0.0, 0.0, time, period)
            self._publish(time)
            return
        (before_linear, before_angular), (last_linear, last_angular) = self._history
        linear = self._limiters[0].limit(linear, last_linear, before_linear, period)
        angular = self._limiters[1].limit(angular, last_angular, before_angular, period)
        self._history = [self._history[1], (linear, angular)]
        self._linear_command, self._angular_command = linear, angular
        self._update_odometry(linear, angular, time, period)
        self._publish(time)
        separation, left_radius, right_radius = self._geometry()
        self._drive((linear - angular * separation / 2.0) / left_radius,
                    (linear + angular * separation / 2.0) / right_radius)

    def _update_references(self, time: float) -> None:
        """Write the newest command to the references; zeros once it is stale (braking)."""
        command = self._command.latest
        if command is None:
            return
        timeout = self.params['cmd_vel_timeout']
        if timeout > 0.0 and time - command.stamp > timeout:
            self._linear_reference.value = 0.0
            self._angular_reference.value = 0.0
            if not self._timed_out:
                self._timed_out = True
                self.notices.append(f'velocity command timed out ({timeout:g} s without one at '
                                    f'sim time {time:.3f} s): braking')
            return
        self._timed_out = False
        self._linear_reference.value = command.linear[0]
        self._angular_reference.value = command.angular[2]

    def _side_positions(self) -> tuple[float, float]:
        """Return each side's mean wheel position (rad); zeros before configure."""
        if not self._left:
            return 0.0, 0.0
        return (sum(handle.position for handle in self._left) / len(self._left),
                sum(handle.position for handle in self._right) / len(self._right))

    def _update_odometry(self, linear: float, angular: float, time: float,
                         period: float) -> None:
        odometry = self._odometry
        if self.params['open_loop']:
            odometry.update_open_loop(linear, angular, time)
        elif self.params['position_feedback']:
            odometry.update(*self._side_positions(), time)
        else:
            left = sum(handle.velocity for handle in self._left) / len(self._left)
            right = sum(handle.velocity for handle in self._right) / len(self._right)
            odometry.update_from_travel(left * odometry.left_radius * period,
                                        right * odometry.right_radius * period, time)

    def _publish(self, time: float) -> None:
        if self._limited_publishing.take(time) and self._twist_sink is not None:
            self._twist_sink(time, self._linear_command, self._angular_command)
        if not self._publishing.take(time):
            return
        odometry = self._odometry
        self.publish_planar(time, odometry.x, odometry.y, odometry.heading, odometry.linear,
                            odometry.angular, self.frame_ids())
