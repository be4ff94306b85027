"""A closed loop through DDS for the determinism tests: a user's node steers the rover from odom.

:func:`trajectory` runs it on a fresh ``sim`` handle and returns the wheel
joints' positions and the base's true pose after every turn, as floats to
compare bit for bit; :func:`digest` condenses one run into a line of text.
"""

from __future__ import annotations

import hashlib
import struct

from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.node import Node

ROVER = 'package://pan_tilt_sim/urdf/diff_drive_rover.urdf'
ROOM = 'package://pan_tilt_sim/config/worlds/room.yaml'
SECONDS = 3.0


class Steering(Node):
    """Answers each odometry message with a command that depends on it (a feedback loop)."""

    def __init__(self) -> None:
        super().__init__('steering')
        self._cmd = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(Odometry, 'odom', self._steer, 10)

    def _steer(self, odom: Odometry) -> None:
        command = Twist()
        command.linear.x = 0.4 - 0.2 * odom.pose.pose.position.x
        command.angular.z = 1.2 * odom.pose.pose.position.y - 0.8 * odom.twist.twist.linear.x + 0.6
        self._cmd.publish(command)


def trajectory(sim) -> list[tuple[float, ...]]:
    """Run the loop for SECONDS of sim time; the wheels and the base after every turn."""
    s = sim(robot=ROVER, world=ROOM)
    s.add_node(Steering())
    samples: list[tuple[float, ...]] = []

    def sample() -> bool:
        wheels = s.joint_positions()
        pose = s.entity_pose(s.robot_name)
        samples.append((s.time, *(wheels[name] for name in sorted(wheels)),
                        pose.position.x, pose.position.y, pose.orientation.z,
                        pose.orientation.w))
        return s.time >= SECONDS

    s.run_until(sample, timeout=SECONDS + 1.0)
    return samples


def digest(samples: list[tuple[float, ...]]) -> str:
    """The samples' count and the SHA-256 of their exact bits."""
    bits = b''.join(struct.pack(f'<{len(row)}d', *row) for row in samples)
    return f'{len(samples)} {hashlib.sha256(bits).hexdigest()}'
