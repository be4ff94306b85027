"""A bare rclpy JointState publisher in a process of its own: the start-up floor.

``python -m pan_tilt_sim.tools.bare_publisher TOPIC`` starts rclpy, makes one
node with one publisher and publishes an empty JointState on ``TOPIC`` every
20 ms (sim_node's pace at real_time_factor 1) until SIGINT/SIGTERM.  Nothing
else is imported first, so the wall time from its start to its first message
at a fresh subscriber is what Python, rclpy and DDS discovery alone cost on
the machine: the floor under ``bench``'s ``startup_s``.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING

os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')  # as sim_node does (pan_tilt_sim.__main__)

import rclpy  # noqa: E402 (after the line above: the message package loads numpy)
from rclpy.qos import QoSProfile  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402

if TYPE_CHECKING:
    from rclpy.node import Node
    from rclpy.publisher import Publisher

PERIOD_S = 0.02


def main(argv: Sequence[str] | None = None) -> None:
    """Publish an empty JointState on the topic every PERIOD_S until stopped."""
    parser = argparse.ArgumentParser(prog='bare_publisher', description=__doc__)
    parser.add_argument('topic')
    args = parser.parse_args(argv)
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    rclpy.init(args=[])
    node = rclpy.create_node('pan_tilt_bench_bare_publisher')
    publisher = node.create_publisher(JointState, args.topic, QoSProfile(depth=1))
    try:
        publish_until_stopped(node, publisher, JointState())
    except KeyboardInterrupt:
        pass
    finally:
        from pan_tilt_sim.ros.runner import shut_down_ros  # not before the first message

        node.destroy_node()
        shut_down_ros()  # rclpy's signal handler may have shut the context down meanwhile


def publish_until_stopped(node: Node, publisher: Publisher, message: JointState) -> None:
    """Publish ``message`` every PERIOD_S until ``node``'s context is shut down (SIGINT).

    rclpy's SIGINT handler shuts the context down from its own thread: a publish that
    comes right after it fails with RCLError, which is the stop, not an error.
    """
    from rclpy.impl.implementation_singleton import rclpy_implementation

    while rclpy.ok(context=node.context):
        try:
            publisher.publish(message)
        except rclpy_implementation.RCLError:
            if rclpy.ok(context=node.context):
                raise
            return
        time.sleep(PERIOD_S)


if __name__ == '__main__':
    main(sys.argv[1:])
