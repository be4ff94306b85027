"""Sinks of the controllers' state samples: one class per message type, one way of holding.

Every sink is a :class:`HeldSample`: it builds its message once from the state
topic's ``fields`` (names, frame, covariances...), fills it in place with each
sample and holds it until the node flushes -- after the batch of steps the
sample was taken in, or where a chunk of it ends -- or until the next sample
comes first.  Every sample leaves, in order, stamped with the sim time it was
taken at; only the moment changes, by at most a batch.
:mod:`pan_tilt_sim.ros.controller_bindings` picks the sink by message type
(its ``STATE_SINKS`` table).

control_msgs, tf2_msgs and ackermann_msgs are optional
(:mod:`.optional_interfaces`): their sinks import them only when created.
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, JointState, Range

from pan_tilt_sim.ros.robot_state import tf_message_type, transform_message
from pan_tilt_sim.ros.ros_interfaces import joint_state_message, stamp
from pan_tilt_sim.ros.sensor_messages import imu_message, wrench_message


def _control_msgs() -> Any:
    """Return the module control_msgs.msg (optional: imported by the sinks that need it)."""
    return importlib.import_module('control_msgs.msg')


class HeldSample:
    """One reused message, published at :meth:`flush` (or when the next sample comes first).

    Published with the node's other messages, while DDS's code is warm: right
    after a sleep the first publish costs several times what the next ones cost.
    """

    def __init__(self, publisher: Any, message: Any) -> None:
        self._publisher = publisher
        self.message = message
        self._pending = False

    def take(self) -> Any:
        """Return the message to fill with a new sample (a sample still held leaves first)."""
        if self._pending:
            self._publisher.publish(self.message)
        self._pending = True
        return self.message

    def flush(self) -> None:
        """Publish the sample taken since the last flush, if any."""
        if self._pending:
            self._pending = False
            self._publisher.publish(self.message)


class JointStateSink(HeldSample):
    """A broadcaster's samples as ``sensor_msgs/msg/JointState`` (field ``names``, once)."""

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        names: Iterable[str] = fields['names']
        message = JointState()
        message.name = list(names)  # once: the names never change
        super().__init__(publisher, message)

    def __call__(self, time: float, names: Any, positions: Any, velocities: Any,
                 efforts: Any) -> None:
        """Take a sample (the broadcaster's lists are copied into the message)."""
        joint_state_message(time, positions, velocities, efforts, self.take())


class DynamicJointStateSink(HeldSample):
    """A broadcaster's samples as ``control_msgs/msg/DynamicJointState``.

    The topic's fields name the joints (``joint_names``) and each joint's
    interfaces (``interface_names``), once; a sample is a list of values per
    joint, copied into the message.
    """

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        module = _control_msgs()
        message = module.DynamicJointState()
        message.joint_names = list(fields['joint_names'])
        message.interface_values = [module.InterfaceValue(interface_names=list(names))
                                    for names in fields['interface_names']]
        super().__init__(publisher, message)

    def __call__(self, time: float, values: Sequence[Sequence[float]]) -> None:
        """Take a sample: ``values[i]`` are joint i's interface values."""
        message = self.take()
        stamp(time, message.header.stamp)
        for interface_value, joint_values in zip(message.interface_values, values, strict=True):
            interface_value.values = joint_values


class DofStateSink(HeldSample):
    """A controller's per-DoF samples as ``control_msgs/msg/MultiDOFStateStamped``.

    A sample is the time and, per DoF of ``fields['names']``, ``(reference,
    feedback, feedback_dot, error, error_dot, time_step, output)``.
    """

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        module = _control_msgs()
        super().__init__(publisher, module.MultiDOFStateStamped(
            dof_states=[module.SingleDOFState(name=name) for name in fields['names']]))

    def __call__(self, time: float, rows: Iterable[Iterable[float]]) -> None:
        """Take a sample."""
        message = self.take()
        stamp(time, message.header.stamp)
        for state, row in zip(message.dof_states, rows, strict=True):
            (state.reference, state.feedback, state.feedback_dot, state.error, state.error_dot,
             state.time_step, state.output) = row


class OdometrySink(HeldSample):
    """Planar odometry samples as ``nav_msgs/msg/Odometry``.

    Fields: ``frame_id``, ``child_frame_id`` and the six-element
    ``pose_covariance_diagonal`` and ``twist_covariance_diagonal``.
    """

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        message = Odometry()
        message.header.frame_id = fields['frame_id']
        message.child_frame_id = fields['child_frame_id']
        size = len(fields['pose_covariance_diagonal'])
        pose_covariance, twist_covariance = [0.0] * size * size, [0.0] * size * size
        for index in range(size):
            pose_covariance[index * (size + 1)] = fields['pose_covariance_diagonal'][index]
            twist_covariance[index * (size + 1)] = fields['twist_covariance_diagonal'][index]
        message.pose.covariance = pose_covariance
        message.twist.covariance = twist_covariance
        super().__init__(publisher, message)

    def __call__(self, time: float, x: float, y: float, heading: float, linear: float,
                 angular: float) -> None:
        """Take a sample: the pose (m, rad) in the odometry frame, the twist (m/s, rad/s)."""
        message = self.take()
        stamp(time, message.header.stamp)
        pose = message.pose.pose
        pose.position.x, pose.position.y = x, y
        pose.orientation.z, pose.orientation.w = math.sin(heading / 2.0), math.cos(heading / 2.0)
        message.twist.twist.linear.x = linear
        message.twist.twist.angular.z = angular


class TrajectoryStateSink(HeldSample):
    """A trajectory controller's samples as ``control_msgs/msg/JointTrajectoryControllerState``.

    Field ``joint_names``, once.  A sample is the time and the reference
    (positions, velocities, accelerations), feedback (positions, velocities),
    error (positions, velocities) and output (positions, efforts) per joint;
    an empty list leaves its field empty.  No multi-DOF joints; the speed
    scaling factor is 1 (no scaling here).
    """

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        message = _control_msgs().JointTrajectoryControllerState(
            joint_names=list(fields['joint_names']), speed_scaling_factor=1.0)
        super().__init__(publisher, message)

    def __call__(self, time: float, reference: Sequence[list[float]],
                 feedback: Sequence[list[float]], error: Sequence[list[float]],
                 output: Sequence[list[float]]) -> None:
        """Take a sample (see the class)."""
        message = self.take()
        stamp(time, message.header.stamp)
        (message.reference.positions, message.reference.velocities,
         message.reference.accelerations) = reference
        message.feedback.positions, message.feedback.velocities = feedback
        message.error.positions, message.error.velocities = error
        message.output.positions, message.output.effort = output


class SpatialOdometryMessageSink(OdometrySink):
    """Odometry samples in 3-D: ``sink(time, pose, linear, angular)``.

    ``pose`` a Transform (m, quaternion), ``linear`` and ``angular`` the
    twist's (x, y, z) in m/s and rad/s.  The fields are the planar sink's.
    """

    def __call__(self, time: float, pose: Any, linear: Sequence[float],
                 angular: Sequence[float]) -> None:
        """Take a sample."""
        message = self.take()
        stamp(time, message.header.stamp)
        position, orientation = message.pose.pose.position, message.pose.pose.orientation
        position.x, position.y, position.z = pose.translation
        orientation.x, orientation.y, orientation.z, orientation.w = pose.rotation
        twist = message.twist.twist
        twist.linear.x, twist.linear.y, twist.linear.z = linear
        twist.angular.x, twist.angular.y, twist.angular.z = angular


def odometry_sink(publisher: Any, fields: Mapping[str, Any]) -> OdometrySink:
    """Return the odometry sink ``fields`` ask for: planar, or 3-D with ``spatial``."""
    kind = SpatialOdometryMessageSink if fields.get('spatial') else OdometrySink
    return kind(publisher, fields)


class TfMessageSink(HeldSample):
    """Transforms as ``tf2_msgs/msg/TFMessage``: ``sink(time, [(parent, child, transform)])``."""

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        super().__init__(publisher, tf_message_type()())

    def __call__(self, time: float, frames: Iterable[tuple[str, str, Any]]) -> None:
        """Take a sample of the frames (parent, child, Transform), stamped ``time``."""
        message = self.take()
        message.transforms = [transform_message(parent, child, transform, time)
                              for parent, child, transform in frames]


class TwistSink(HeldSample):
    """Planar twists as ``geometry_msgs/msg/TwistStamped`` (frame id ``frame_id``, default '')."""

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        message = TwistStamped()
        message.header.frame_id = fields.get('frame_id', '')
        super().__init__(publisher, message)

    def __call__(self, time: float, linear: float, angular: float) -> None:
        """Take a sample: linear.x (m/s) and angular.z (rad/s)."""
        message = self.take()
        stamp(time, message.header.stamp)
        message.twist.linear.x = linear
        message.twist.angular.z = angular


class MecanumStateSink(HeldSample):
    """A mecanum drive's state as ``control_msgs/msg/MecanumDriveControllerState``.

    Field ``frame_id`` (the odometry frame, as upstream).  A sample is the
    time, the measured wheel velocities (rad/s: front left, front right,
    rear right, rear left) and the reference (vx m/s, vy m/s, wz rad/s).
    """

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        message = _control_msgs().MecanumDriveControllerState()
        message.header.frame_id = fields['frame_id']
        super().__init__(publisher, message)

    def __call__(self, time: float, wheels: Sequence[float], reference: Sequence[float]) -> None:
        """Take a sample (see the class)."""
        message = self.take()
        stamp(time, message.header.stamp)
        (message.front_left_wheel_velocity, message.front_right_wheel_velocity,
         message.back_right_wheel_velocity, message.back_left_wheel_velocity) = wheels
        twist = message.reference_velocity
        twist.linear.x, twist.linear.y, twist.angular.z = reference


class WrenchSink(HeldSample):
    """``geometry_msgs/msg/WrenchStamped`` from ``sink(time, force, torque)``."""

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        message = WrenchStamped()
        message.header.frame_id = fields['frame_id']
        super().__init__(publisher, message)

    def __call__(self, time: float, force: Sequence[float], torque: Sequence[float]) -> None:
        """Take a sample (N, N m)."""
        message = self.take()
        wrench_message(force, torque, message.header.frame_id, time, message)


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
        imu_message(orientation, angular_velocity, linear_acceleration, self._covariances,
                    self._frame, time, self.take())


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
        message = self.take()
        stamp(time, message.header.stamp)
        message.range = float(distance)


class PoseSink(HeldSample):
    """``geometry_msgs/msg/PoseStamped`` from ``sink(time, position, orientation)``."""

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        message = PoseStamped()
        message.header.frame_id = fields['frame_id']
        super().__init__(publisher, message)

    def __call__(self, time: float, position: Sequence[float],
                 orientation: Sequence[float]) -> None:
        """Take a sample (m; quaternion x y z w)."""
        message = self.take()
        stamp(time, message.header.stamp)
        pose = message.pose
        pose.position.x, pose.position.y, pose.position.z = (float(v) for v in position)
        q = pose.orientation
        q.x, q.y, q.z, q.w = (float(v) for v in orientation)


class GroupValuesSink(HeldSample):
    """``control_msgs/msg/DynamicInterfaceGroupValues`` from ``sink(time, values per group)``.

    The groups and their interface names are the fields' (they never change);
    the values are copied from the controller's lists.
    """

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        module = _control_msgs()
        message = module.DynamicInterfaceGroupValues()
        message.interface_groups = list(fields['groups'])
        message.interface_values = [module.InterfaceValue(interface_names=list(names))
                                    for names in fields['interface_names']]
        super().__init__(publisher, message)

    def __call__(self, time: float, values: Sequence[Sequence[float]]) -> None:
        """Take a sample: per group, its interfaces' values in the names' order."""
        message = self.take()
        stamp(time, message.header.stamp)
        for entry, row in zip(message.interface_values, values, strict=True):
            entry.values = row  # the message keeps a copy (an array of doubles)


class SteeringStatusSink(HeldSample):
    """``control_msgs/msg/SteeringControllerStatus`` from a steering controller's samples.

    Field ``frame_id`` (the odometry frame, as upstream's header); a sample is
    ``sink(time, traction positions, traction velocities, traction commands,
    steering positions, steering commands)`` in rad, rad/s, rad/s, rad, rad
    (an empty list leaves its field empty).
    """

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        message = _control_msgs().SteeringControllerStatus()
        message.header.frame_id = fields['frame_id']
        super().__init__(publisher, message)

    def __call__(self, time: float, traction_positions: Sequence[float],
                 traction_velocities: Sequence[float], traction_commands: Sequence[float],
                 steering_positions: Sequence[float], steering_commands: Sequence[float]) -> None:
        """Take a sample (see the class)."""
        message = self.take()
        stamp(time, message.header.stamp)
        message.traction_wheels_position = list(traction_positions)
        message.traction_wheels_velocity = list(traction_velocities)
        message.linear_velocity_command = list(traction_commands)
        message.steer_positions = list(steering_positions)
        message.steering_angle_command = list(steering_commands)


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
        message = self.take()
        message.speed = speed
        message.steering_angle = steering_angle
