"""A small stand-in for robot_state_publisher: its ``robot_description`` parameter on its topic.

robot_state_publisher (not on the standalone path) publishes the URDF it is
given as its ``robot_description`` parameter -- a launch file's xacro
output -- on ``robot_description`` (relative: in its namespace), reliable and
transient local with depth 1, so a controller_manager that starts later
still gets it.  That is all a controller_manager reads of it, and all this
stand-in does (no TF).  In-process as :class:`RobotStatePublisherStandIn`,
or as a program: ``python robot_state_publisher_stand_in.py --ros-args -p
robot_description:=...``.
"""

from __future__ import annotations

import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

NODE_NAME = 'robot_state_publisher'
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


class RobotStatePublisherStandIn(Node):
    """Publishes its ``robot_description`` parameter once, latched, on ``robot_description``."""

    def __init__(self, robot_description: str | None = None, **kwargs) -> None:
        super().__init__(NODE_NAME, **kwargs)
        text = self.declare_parameter('robot_description', robot_description or '').value
        self.publisher = self.create_publisher(String, 'robot_description', LATCHED)
        self.publisher.publish(String(data=text))


def main() -> None:
    """Run the stand-in until SIGINT/SIGTERM."""
    rclpy.init(args=sys.argv)
    node = RobotStatePublisherStandIn()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
