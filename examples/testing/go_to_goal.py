"""A user's node to test: drive a differential-drive base to a goal, stopping for obstacles.

Reads ``odom`` (nav_msgs/Odometry) and ``scan`` (sensor_msgs/LaserScan), takes goals on
``goal_pose`` (geometry_msgs/PoseStamped, x and y in the odometry frame) and writes
``cmd_vel`` (geometry_msgs/Twist).  It reacts to each odometry message, so it needs no
timer and runs the same at any speed of the simulation.
"""

from __future__ import annotations

import math

import rclpy
from geometry_msgs.msg import PoseStamped, Twist
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import LaserScan

TOLERANCE = 0.02  # m: closer than this to the goal counts as arrived
MAX_SPEED = 0.4  # m/s
MAX_TURN = 1.0  # rad/s
SPEED_GAIN = 1.0  # (m/s) per m of distance left
TURN_GAIN = 2.0  # (rad/s) per rad of heading error
STOP_DISTANCE = 0.4  # m: an obstacle nearer than this ahead stops the robot
AHEAD = math.radians(20.0)  # the scan's sector counted as "ahead", either side


def yaw_of(quaternion) -> float:
    """Return the rotation about z of a quaternion (rad)."""
    q = quaternion
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def wrapped(angle: float) -> float:
    """Return ``angle`` wrapped into [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


class GoToGoal(Node):
    """Turns toward the goal and drives to it; ``arrived`` and ``blocked`` say how it ended."""

    def __init__(self, **kwargs) -> None:
        super().__init__('go_to_goal', **kwargs)
        self.goal: tuple[float, float] | None = None
        self.arrived = False
        self.blocked = False
        self._nearest_ahead = math.inf
        self._cmd = self.create_publisher(Twist, 'cmd_vel', 10)
        self.create_subscription(PoseStamped, 'goal_pose', self._on_goal, 10)
        self.create_subscription(Odometry, 'odom', self._on_odom, 10)
        self.create_subscription(LaserScan, 'scan', self._on_scan, qos_profile_sensor_data)

    def _on_goal(self, message: PoseStamped) -> None:
        self.goal = (message.pose.position.x, message.pose.position.y)
        self.arrived = self.blocked = False

    def _on_scan(self, scan: LaserScan) -> None:
        ahead = [r for i, r in enumerate(scan.ranges)
                 if abs(scan.angle_min + i * scan.angle_increment) <= AHEAD
                 and scan.range_min <= r <= scan.range_max]
        self._nearest_ahead = min(ahead, default=math.inf)

    def _on_odom(self, odom: Odometry) -> None:
        if self.goal is None:
            return
        pose = odom.pose.pose
        dx = self.goal[0] - pose.position.x
        dy = self.goal[1] - pose.position.y
        distance = math.hypot(dx, dy)
        command = Twist()
        self.arrived = distance < TOLERANCE
        self.blocked = not self.arrived and self._nearest_ahead < STOP_DISTANCE
        if not (self.arrived or self.blocked):
            error = wrapped(math.atan2(dy, dx) - yaw_of(pose.orientation))
            command.angular.z = max(-MAX_TURN, min(MAX_TURN, TURN_GAIN * error))
            # Forward only when roughly facing the goal.
            command.linear.x = min(MAX_SPEED, SPEED_GAIN * distance) * max(0.0, math.cos(error))
        self._cmd.publish(command)


def main() -> None:
    """Run the node until interrupted (``ros2 run``-style entry point)."""
    rclpy.init()
    node = GoToGoal()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
