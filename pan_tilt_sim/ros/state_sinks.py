"""Sinks of the sensor broadcasters' and the gpio controller's samples: one per message type.

Each sink builds its message once from the state topic's ``fields`` (frame,
covariances, names...), fills it in place with each sample and holds it
until the node flushes, as
:class:`~pan_tilt_sim.ros.controller_bindings.JointStateSink` does for
JointStates: a sample leaves at the flush after the batch of steps it was
taken in, or when the next sample comes first, stamped with the sim time it
was taken at.  :mod:`pan_tilt_sim.ros.controller_bindings` picks the sink by
message type (its ``STATE_SINKS`` table).

control_msgs and tf2_msgs are optional (:mod:`.optional_interfaces`): their
sinks import them only when created.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from geometry_msgs.msg import PoseStamped, WrenchStamped
from sensor_msgs.msg import Imu, Range

from pan_tilt_sim.ros.ros_interfaces import stamp
from pan_tilt_sim.ros.sensor_messages import imu_message, wrench_message


class HeldSample:
    """One reused message, published at :meth:`flush` (or when the next sample comes first)."""

    def __init__(self, publisher: Any, message: Any) -> None:
        self._publisher = publisher
        self.message = message
        self._pending = False

    def take(self, fill: Callable[[], object]) -> None:
        """Publish a sample still held, then ``fill()`` the message with the new one and hold it."""
        if self._pending:
            self._publisher.publish(self.message)
        fill()
        self._pending = True

    def flush(self) -> None:
        """Publish the sample taken since the last flush, if any."""
        if self._pending:
            self._pending = False
            self._publisher.publish(self.message)


class WrenchSink(HeldSample):
    """``geometry_msgs/msg/WrenchStamped`` from ``sink(time, force, torque)``."""

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        message = WrenchStamped()
        message.header.frame_id = fields['frame_id']
        super().__init__(publisher, message)

    def __call__(self, time: float, force: Sequence[float], torque: Sequence[float]) -> None:
        """Take a sample (N, N m)."""
        self.take(lambda: wrench_message(force, torque, self.message.header.frame_id, time,
                                         self.message))


class ImuSink(HeldSample):
    """``sensor_msgs/msg/Imu`` from ``sink(time, orientation, angular_velocity, acceleration)``."""

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        super().__init__(publisher, Imu())
        self._frame = fields['frame_id']
        self._covariances = fields['covariances']

    def __call__(self, time: float, orientation: Sequence[float],
                 angular_velocity: Sequence[float],
                 linear_acceleration: Sequence[float]) -> None:
        """Take a sample (quaternion x y z w, rad/s, m/s^2)."""
        self.take(lambda: imu_message(
            orientation, angular_velocity, linear_acceleration, self._covariances, self._frame,
            time, self.message))


class RangeSink(HeldSample):
    """``sensor_msgs/msg/Range`` from ``sink(time, range)``; the rest comes from the fields."""

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        message = Range()
        message.header.frame_id = fields['frame_id']
        message.radiation_type = int(fields['radiation_type'])
        message.field_of_view = float(fields['field_of_view'])
        message.min_range = float(fields['min_range'])
        message.max_range = float(fields['max_range'])
        message.variance = float(fields['variance'])
        super().__init__(publisher, message)

    def __call__(self, time: float, distance: float) -> None:
        """Take a sample (m; +inf: nothing within reach)."""
        def fill() -> None:
            stamp(time, self.message.header.stamp)
            self.message.range = float(distance)
        self.take(fill)


class PoseSink(HeldSample):
    """``geometry_msgs/msg/PoseStamped`` from ``sink(time, position, orientation)``."""

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        message = PoseStamped()
        message.header.frame_id = fields['frame_id']
        super().__init__(publisher, message)

    def __call__(self, time: float, position: Sequence[float],
                 orientation: Sequence[float]) -> None:
        """Take a sample (m; quaternion x y z w)."""
        def fill() -> None:
            stamp(time, self.message.header.stamp)
            pose = self.message.pose
            pose.position.x, pose.position.y, pose.position.z = (float(v) for v in position)
            q = pose.orientation
            q.x, q.y, q.z, q.w = (float(v) for v in orientation)
        self.take(fill)


class GroupValuesSink(HeldSample):
    """``control_msgs/msg/DynamicInterfaceGroupValues`` from ``sink(time, values per group)``.

    The groups and their interface names are the fields' (they never change);
    the values are copied from the controller's lists.
    """

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        module = importlib.import_module('control_msgs.msg')
        message = module.DynamicInterfaceGroupValues()
        message.interface_groups = list(fields['groups'])
        message.interface_values = [module.InterfaceValue(interface_names=list(names))
                                    for names in fields['interface_names']]
        super().__init__(publisher, message)

    def __call__(self, time: float, values: Sequence[Sequence[float]]) -> None:
        """Take a sample: per group, its interfaces' values in the names' order."""
        def fill() -> None:
            stamp(time, self.message.header.stamp)
            for entry, row in zip(self.message.interface_values, values, strict=True):
                entry.values = row  # the message keeps a copy (an array of doubles)
        self.take(fill)



class SteeringStatusSink(HeldSample):
    """``control_msgs/msg/SteeringControllerStatus`` from a steering controller's samples.

    Field ``frame_id`` (the odometry frame, as upstream's header); a sample is
    ``sink(time, traction positions, traction velocities, traction commands,
    steering positions, steering commands)`` in rad, rad/s, rad/s, rad, rad
    (an empty list leaves its field empty).
    """

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        message = importlib.import_module('control_msgs.msg').SteeringControllerStatus()
        message.header.frame_id = fields['frame_id']
        super().__init__(publisher, message)

    def __call__(self, time: float, traction_positions: Sequence[float],
                 traction_velocities: Sequence[float], traction_commands: Sequence[float],
                 steering_positions: Sequence[float], steering_commands: Sequence[float]) -> None:
        """Take a sample (see the class)."""
        def fill() -> None:
            message = self.message
            stamp(time, message.header.stamp)
            message.traction_wheels_position = list(traction_positions)
            message.traction_wheels_velocity = list(traction_velocities)
            message.linear_velocity_command = list(traction_commands)
            message.steer_positions = list(steering_positions)
            message.steering_angle_command = list(steering_commands)
        self.take(fill)


class AckermannDriveSink(HeldSample):
    """``ackermann_msgs/msg/AckermannDrive`` from ``sink(time, speed, steering angle)``.

    The tricycle controller's limited command, as upstream fills it: ``speed``
    is the wheel's (rad/s), ``steering_angle`` in rad.  ackermann_msgs is
    optional: the sink imports it only when created.
    """

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        super().__init__(publisher, importlib.import_module('ackermann_msgs.msg').AckermannDrive())

    def __call__(self, time: float, speed: float, steering_angle: float) -> None:
        """Take a sample (the message has no stamp)."""
        def fill() -> None:
            self.message.speed = speed
            self.message.steering_angle = steering_angle
        self.take(fill)
