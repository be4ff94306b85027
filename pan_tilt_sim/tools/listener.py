"""A subscriber in a process of its own, for the benchmark: it only takes messages.

``python -m pan_tilt_sim.tools.listener TOPIC TYPE [--best-effort] [--depth N]``
subscribes to ``TOPIC`` (``TYPE`` like ``rosgraph_msgs/msg/Clock``) and spins
until SIGINT/SIGTERM, then prints the number of messages it took.  With the
default reliable QoS it is what ``ros2 topic echo`` is; ``--best-effort
--depth 1`` is what rclpy's use_sim_time TimeSource creates on /clock.
"""

from __future__ import annotations

import argparse
import importlib
import signal
import sys
from collections.abc import Sequence

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.qos import QoSProfile, ReliabilityPolicy

from pan_tilt_sim.ros.runner import shut_down_ros


def message_type(name: str) -> type:
    """Return the message class for ``pkg/msg/Type``."""
    package, _, type_name = name.replace('/msg/', '/').partition('/')
    return getattr(importlib.import_module(f'{package}.msg'), type_name)


def main(argv: Sequence[str] | None = None) -> None:
    """Subscribe and count until stopped."""
    parser = argparse.ArgumentParser(prog='listener', description=__doc__)
    parser.add_argument('topic')
    parser.add_argument('type')
    parser.add_argument('--best-effort', action='store_true')
    parser.add_argument('--depth', type=int, default=10)
    args = parser.parse_args(argv)
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    rclpy.init(args=[])
    node = rclpy.create_node('pan_tilt_bench_listener')
    count = [0]
    reliability = (ReliabilityPolicy.BEST_EFFORT if args.best_effort
                   else ReliabilityPolicy.RELIABLE)
    node.create_subscription(
        message_type(args.type), args.topic, lambda message: count.__setitem__(0, count[0] + 1),
        QoSProfile(depth=args.depth, reliability=reliability))
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        shut_down_ros()  # rclpy's signal handler may have shut the context down meanwhile
    print(count[0], flush=True)


if __name__ == '__main__':
    main(sys.argv[1:])
