#!/usr/bin/env python3
"""Command one joint of a running sim_node and print its motion: a client without ros2cli.

    python examples/move_joint.py /ex_urdf_pan_tilt/joint1_position_controller/command 1.0

does what ``ros2 topic pub --once <topic> std_msgs/msg/Float64 "{data: 1.0}"`` followed by
``ros2 topic echo <ns>/joint_states`` does, for machines where only the rclpy wheels are
installed.  It stops when the joint is within ``--tolerance`` of the target, or after
``--timeout`` wall seconds.
"""

import argparse
import os
import sys
import time

import rclpy
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64


def main(argv: list[str] | None = None) -> int:
    """Publish the command and watch the joint; 0 when it arrived, 1 on timeout."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('topic', help='a Float64 command topic, e.g. '
                        '/ex_urdf_pan_tilt/joint1_position_controller/command')
    parser.add_argument('value', type=float, help='the command (rad for position controllers)')
    parser.add_argument('--joint', default='pan_joint', help='joint to watch (default pan_joint)')
    parser.add_argument('--joint-states', default=None,
                        help='JointState topic (default: <namespace of topic>/joint_states)')
    parser.add_argument('--tolerance', type=float, default=0.015)
    parser.add_argument('--timeout', type=float, default=60.0, help='wall seconds')
    args = parser.parse_args(argv)
    namespace = args.topic.rsplit('/', 2)[0]
    states_topic = args.joint_states or f'{namespace}/joint_states'

    # Talk to a sim_node started by scripts/run_sim.sh, which keeps DDS on loopback.
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    rclpy.init()
    node = Node('move_joint')
    latest = {}
    node.create_subscription(JointState, states_topic, lambda m: latest.update(
        zip(m.name, m.position, strict=False)), 10)
    publisher = node.create_publisher(Float64, args.topic, 10)
    deadline = time.monotonic() + args.timeout
    reached = False
    try:
        while publisher.get_subscription_count() == 0 and time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=0.1)
        publisher.publish(Float64(data=args.value))
        last_print = 0.0
        while time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=0.1)
            position = latest.get(args.joint)
            if position is None:
                continue
            if time.monotonic() - last_print > 0.5:
                print(f'{args.joint}: {position:+.4f}', flush=True)
                last_print = time.monotonic()
            if abs(position - args.value) <= args.tolerance:
                print(f'{args.joint}: {position:+.4f} (reached)')
                reached = True
                break
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0 if reached else 1


if __name__ == '__main__':
    sys.exit(main())
