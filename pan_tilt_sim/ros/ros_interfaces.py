"""Conversions between ROS messages and the simulator's plain values."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from typing import Any

from builtin_interfaces.msg import Duration, Time
from geometry_msgs.msg import Twist, TwistStamped
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray
from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMessage

from pan_tilt_sim.controllers import CommandKind
from pan_tilt_sim.controllers.framework.surface import StampedTwist
from pan_tilt_sim.controllers.trajectory.trajectory import JointTrajectory, TrajectoryPoint

try:
    from control_msgs.msg import MultiDOFCommand
except ImportError:  # an optional interface package (see optional_interfaces)
    MultiDOFCommand = None

NANOSECONDS_PER_SECOND = 1_000_000_000
# Requests a service of the node holds while it is busy (a batch of physics steps, other
# callbacks).  rclpy's default keeps the last 10 and silently drops older ones, so 20
# callers at once lost requests for good; parameter services keep 1000 for that reason.
SERVICE_QUEUE_DEPTH = 1000
SERVICE_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=SERVICE_QUEUE_DEPTH,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.VOLATILE)


def seconds(time: Time | Duration) -> float:
    """Return a ``builtin_interfaces`` Time or Duration in seconds."""
    return time.sec + time.nanosec / NANOSECONDS_PER_SECOND


def joint_trajectory(message: JointTrajectoryMessage) -> JointTrajectory:
    """Return a ``trajectory_msgs/JointTrajectory`` as a plain value (zero stamp: start now)."""
    stamp_ = message.header.stamp
    return JointTrajectory(
        joint_names=tuple(message.joint_names),
        points=tuple(
            TrajectoryPoint(seconds(point.time_from_start), tuple(point.positions),
                            tuple(point.velocities), tuple(point.accelerations),
                            tuple(point.effort))
            for point in message.points),
        start_time=seconds(stamp_) if stamp_.sec or stamp_.nanosec else None)


def stamped_twist(message: TwistStamped) -> StampedTwist:
    """Return a ``geometry_msgs/TwistStamped`` as a plain value (stamp in s; 0: unstamped)."""
    linear, angular = message.twist.linear, message.twist.angular
    return StampedTwist(seconds(message.header.stamp), (linear.x, linear.y, linear.z),
                        (angular.x, angular.y, angular.z))


def twist(message: Twist) -> StampedTwist:
    """Return a ``geometry_msgs/Twist`` as an unstamped :class:`StampedTwist` (stamp 0)."""
    linear, angular = message.linear, message.angular
    return StampedTwist(0.0, (linear.x, linear.y, linear.z), (angular.x, angular.y, angular.z))


def group_values(message: Any) -> tuple[list[str], list[tuple[list[str], list[float]]]]:
    """Return a ``control_msgs/DynamicInterfaceGroupValues`` as plain lists.

    ``(interface_groups, [(interface_names, values) per interface_values entry])``,
    as the gpio controller takes a command.
    """
    return (list(message.interface_groups),
            [(list(entry.interface_names), list(entry.values))
             for entry in message.interface_values])


def optional_message(name: str) -> type | None:
    """Return the message class ``<package>/msg/<Type>``, or None if its package is missing."""
    package, _, type_name = name.split('/')
    try:
        return getattr(importlib.import_module(f'{package}.msg'), type_name)
    except (ImportError, AttributeError):
        return None


GROUP_VALUES = 'control_msgs/msg/DynamicInterfaceGroupValues'
# Each command message type (by its ROS name), and how to get the command value out of it.
# The class is None where its interface package is not installed (no such topics then).
COMMAND_MESSAGES: dict[str, tuple[type | None, Callable[[Any], Any]]] = {
    CommandKind.FLOAT64.value: (Float64, lambda msg: msg.data),
    CommandKind.FLOAT64_ARRAY.value: (Float64MultiArray, lambda msg: list(msg.data)),
    CommandKind.JOINT_TRAJECTORY.value: (JointTrajectoryMessage, joint_trajectory),
    # (dof_names, values, values_dot), as lists.
    CommandKind.MULTI_DOF_COMMAND.value: (MultiDOFCommand, lambda msg: (
        list(msg.dof_names), list(msg.values), list(msg.values_dot))),
    CommandKind.TWIST_STAMPED.value: (TwistStamped, stamped_twist),
    CommandKind.TWIST.value: (Twist, twist),
}
if (_group_values := optional_message(GROUP_VALUES)) is not None:
    COMMAND_MESSAGES[GROUP_VALUES] = (_group_values, group_values)


def stamp(seconds: float, into: Time | None = None) -> Time:
    """Return sim time in seconds as a ``builtin_interfaces/Time`` (filled in place if given)."""
    nanoseconds = round(seconds * NANOSECONDS_PER_SECOND)
    message = Time() if into is None else into
    message.sec, message.nanosec = divmod(nanoseconds, NANOSECONDS_PER_SECOND)
    return message


def clock_message(seconds: float, into: Clock | None = None) -> Clock:
    """Return a ``rosgraph_msgs/Clock`` for sim time ``seconds``."""
    message = Clock() if into is None else into
    stamp(seconds, message.clock)
    return message


def joint_state_message(time: float, positions: Sequence[float], velocities: Sequence[float],
                        efforts: Sequence[float], into: JointState) -> JointState:
    """Fill ``into`` (whose ``name`` is set) with sim time and the joint values; return it."""
    message = into
    stamp(time, message.header.stamp)
    message.position = positions
    message.velocity = velocities
    message.effort = efforts
    return message
