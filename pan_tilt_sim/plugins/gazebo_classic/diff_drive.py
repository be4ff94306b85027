"""``libgazebo_ros_diff_drive.so`` as a unit of the simulation: the plugin's semantics, no ROS.

Not a ros2_control controller: no controller_manager loads, lists or
switches it.  The simulation creates one per plugin the URDF declares
(:mod:`pan_tilt_sim.model.drive_plugins`) and updates it every physics
step, before the controllers; it is always active.  As the plugin:

* **Command**: ``geometry_msgs/Twist`` on its command topic; only
  ``linear.x`` (m/s) and ``angular.z`` (rad/s) count, and the last one holds
  until the next (the plugin has no timeout).  A twist with a NaN or
  infinite value is refused (a throttled warning names it).
* **Wheels**: every ``1 / update_rate`` s of sim time each pair's wheel
  speeds ``v -+ w * separation / 2`` (m/s) are set as joint velocity
  targets (divided by the radius), reached by a motor of at most
  ``max_wheel_torque`` (N m).  With ``max_wheel_acceleration`` (m/s^2, 0:
  none) and a wheel not yet within 0.01 m/s of its speed, the target moves
  from the wheel's measured speed toward it by at most
  ``max_wheel_acceleration / update_rate`` per update, as the plugin does.
* **Odometry**: ``encoder`` integrates the first pair's wheel velocities
  every step (:class:`~.odometry.Odometry`); ``world`` is the base's true
  planar pose and its twist in the base frame (read through the source the
  simulation hands in: :meth:`set_base_state`).  Published at
  ``update_rate`` on the odometry topic (``publish_odom``) and as
  ``odometry_frame -> robot_base_frame`` on ``/tf`` (``publish_odom_tf``).

A reset (``reset_simulation``) drops the command and puts the encoder
odometry back at the origin, as the plugin's Reset.  Pure Python.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from pan_tilt_sim.controllers.base import (
    Actuator,
    ActuatorKind,
    CommandController,
    CommandKind,
    CommandResult,
    JointHandle,
)
from pan_tilt_sim.controllers.diff_drive_controller import OdometrySink, TfSink
from pan_tilt_sim.controllers.odometry import Odometry
from pan_tilt_sim.controllers.odometry_outputs import OdometryOutputs
from pan_tilt_sim.controllers.surface import CommandTopic, Endpoint, StampedTwist, StateTopic
from pan_tilt_sim.model.drive_plugins import ENCODER, DiffDrivePlugin
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.schedule import DUE_EPSILON

REACHED = 0.01  # m/s: a wheel this close to its speed is set to it directly (the plugin's)
# The base's state: (x, y, heading) in the world (m, rad) and its twist in the base frame
# (forward m/s, sideways m/s, yaw rate rad/s).
BaseState = tuple[tuple[float, float, float], tuple[float, float, float]]


class GazeboDiffDrive(OdometryOutputs, CommandController):
    """One ``gazebo_ros_diff_drive`` plugin: a Twist in, wheel velocities out, odometry back."""

    drives_base: ClassVar[bool] = True
    command_kind = CommandKind.TWIST

    def __init__(self, plugin: DiffDrivePlugin, source: str = '') -> None:
        super().__init__(plugin.name, {}, source)
        self.plugin = plugin
        self._period = 1.0 / plugin.update_rate if plugin.update_rate > 0.0 else 0.0
        self._odometry = Odometry(plugin.wheel_separation[0], plugin.wheel_diameter[0] / 2.0,
                                  plugin.wheel_diameter[0] / 2.0, window=1)
        self._left: list[JointHandle] = []
        self._right: list[JointHandle] = []
        self._odometry_sink: OdometrySink | None = None
        self._tf_sink: TfSink | None = None
        self._base_state: Callable[[], BaseState] | None = None
        self._problem = ''
        self.reset()

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The wheels, left then right."""
        return self.plugin.joint_names

    def actuators(self) -> dict[str, Actuator]:
        """Return the ideal velocity actuator, its force limit the wheel torque, per wheel."""
        plugin = self.plugin
        element = 'wheelTorque' if plugin.convention == 'ros1' else 'max_wheel_torque'
        text = f"at most {plugin.max_wheel_torque:g} N*m (the plugin's {element})"
        return {wheel: Actuator(ActuatorKind.IDEAL_VELOCITY, self.name,
                                force_from_controller=True, force_text=text)
                for wheel in self.joint_names}

    def set_base_state(self, source: Callable[[], BaseState]) -> None:
        """Where the ``world`` odometry reads the base's true pose and twist."""
        self._base_state = source

    # --- ROS surface -----------------------------------------------------------------------

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the command topic in; odometry and ``/tf`` out, as the plugin publishes."""
        plugin = self.plugin
        override = self.node_namespace.strip('/')
        command, odometry = plugin.topics(override)
        endpoints: list[Endpoint] = [
            CommandTopic(command, self.command_kind.value, self.set_command,
                         self.command_problem)]
        if plugin.publish_odom:
            endpoints.append(StateTopic(odometry, 'nav_msgs/msg/Odometry', self.set_odometry_sink,
                                        {'frame_id': plugin.odometry_frame,
                                         'child_frame_id': plugin.robot_base_frame,
                                         'pose_covariance_diagonal': plugin.pose_covariance,
                                         'twist_covariance_diagonal': plugin.twist_covariance}))
        if plugin.publish_odom_tf:
            endpoints.append(StateTopic('/tf', 'tf2_msgs/msg/TFMessage', self.set_tf_sink))
        return tuple(endpoints)

    # --- lifecycle -------------------------------------------------------------------------

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the wheels' handles, then reset."""
        self._left = [self.handle(joints, wheel, 'left_joint')
                      for wheel in self.plugin.left_joints]
        self._right = [self.handle(joints, wheel, 'right_joint')
                       for wheel in self.plugin.right_joints]
        self.reset()

    def reset(self) -> None:
        """No command, the encoder odometry at the origin, the wheels asked to stand."""
        self._linear = self._angular = 0.0
        self._last_update = 0.0
        self._odometry.reset(0.0)
        self._instructed = [0.0] * len(self._left + self._right)
        for handle in self._left + self._right:
            handle.velocity_target = 0.0
            handle.force_limit = self.plugin.max_wheel_torque

    # --- commands --------------------------------------------------------------------------

    def set_command(self, value: StampedTwist) -> CommandResult:
        """Take a twist (from the subscription; cheap): refuse non-finite ones."""
        linear, angular = value.linear[0], value.angular[2]
        if not (math.isfinite(linear) and math.isfinite(angular)):
            self._problem = (f'ignored cmd_vel (linear.x {linear!r}, angular.z {angular!r}): '
                             'not finite numbers')
            return CommandResult.REJECTED
        self._linear, self._angular = linear, angular
        return CommandResult.ACCEPTED

    def command_problem(self, value: Any, result: CommandResult) -> str:
        """Describe the last refused twist."""
        return self._problem

    def setpoints(self) -> dict[str, float]:
        """Return each wheel's velocity target (rad/s)."""
        return {handle.name: handle.velocity_target for handle in self._left + self._right}

    @property
    def odometry(self) -> Odometry:
        """The encoder odometry (pose and twist in the odometry frame)."""
        return self._odometry

    # --- the step ---------------------------------------------------------------------------

    def update(self, time: float, period: float) -> None:
        """Integrate the encoders; at the update rate publish and set the wheels' targets."""
        plugin = self.plugin
        radius = plugin.wheel_diameter[0] / 2.0
        if plugin.odometry_source == ENCODER and self._left:
            self._odometry.update_from_travel(self._left[0].velocity * radius * period,
                                              self._right[0].velocity * radius * period, time)
        for handle in self._left + self._right:
            handle.force_limit = plugin.max_wheel_torque
        since = time - self._last_update
        if since + DUE_EPSILON < self._period:
            return
        self._publish(time)
        self._drive(since)
        self._last_update = time

    def _drive(self, since: float) -> None:
        """Set each wheel's velocity target as the plugin does, its ramp included."""
        plugin = self.plugin
        accel = plugin.max_wheel_acceleration
        for pair, (left, right) in enumerate(zip(self._left, self._right, strict=True)):
            radius = plugin.wheel_diameter[pair] / 2.0
            half = self._angular * plugin.wheel_separation[pair] / 2.0
            desired = (self._linear - half, self._linear + half)
            current = (left.velocity * radius, right.velocity * radius)
            reached = all(abs(want - have) < REACHED
                          for want, have in zip(desired, current, strict=True))
            for side, handle in enumerate((left, right)):
                slot = 2 * pair + side
                if accel == 0.0 or reached:
                    self._instructed[slot] = desired[side]
                else:
                    step = desired[side] - current[side]
                    self._instructed[slot] += max(-accel * since, min(accel * since, step))
                handle.velocity_target = self._instructed[slot] / radius

    def _pose_and_twist(self) -> tuple[float, float, float, float, float]:
        """Return (x, y, heading, forward speed, yaw rate) from the odometry source."""
        if self.plugin.odometry_source == ENCODER or self._base_state is None:
            odometry = self._odometry
            return odometry.x, odometry.y, odometry.heading, odometry.linear, odometry.angular
        (x, y, heading), (forward, _sideways, yaw_rate) = self._base_state()
        return x, y, heading, forward, yaw_rate

    def _publish(self, time: float) -> None:
        if self._odometry_sink is None and self._tf_sink is None:
            return
        x, y, heading, linear, angular = self._pose_and_twist()
        if self._odometry_sink is not None:
            self._odometry_sink(time, x, y, heading, linear, angular)
        if self._tf_sink is not None:
            pose = Transform((x, y, 0.0), (0.0, 0.0, math.sin(heading / 2.0),
                                           math.cos(heading / 2.0)))
            self._tf_sink(time, [(self.plugin.odometry_frame, self.plugin.robot_base_frame,
                                  pose)])
