#!/usr/bin/env python3
"""Send the three-joint arm a trajectory and open its gripper: a client without ros2cli.

    python examples/arm_trajectory.py

does what these do on a ROS 2 install, against a sim_node running
``urdf/three_joint_arm.xacro`` with ``config/three_joint_arm_controllers.yaml``::

    ros2 topic pub --once /arm_controller/joint_trajectory \
        trajectory_msgs/msg/JointTrajectory "{joint_names: [...], points: [...]}"
    ros2 topic pub --once /gripper_controller/commands \
        std_msgs/msg/Float64MultiArray "{data: [0.03]}"
    ros2 topic echo /joint_states

It prints the joints until the last waypoint is reached within ``--tolerance``,
or ``--timeout`` wall seconds pass.
"""

import argparse
import math
import os
import sys
import time

import rclpy
from builtin_interfaces.msg import Duration
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

JOINTS = ['shoulder_joint', 'extend_joint', 'wrist_joint']
# (seconds from start, positions in JOINTS order: rad, m, rad)
WAYPOINTS = [(2.0, [0.5, 0.05, 1.0]), (4.0, [1.0, 0.15, 3.0]), (6.0, [-0.5, 0.1, 7.0])]
GRIPPER_OPENING = 0.03  # m, left finger; the right one mimics it


def trajectory_message():
    """Return the waypoints as a JointTrajectory starting on receipt (zero stamp)."""
    message = JointTrajectory(joint_names=JOINTS)
    message.points = [
        JointTrajectoryPoint(positions=positions,
                             time_from_start=Duration(sec=int(when),
                                                      nanosec=round(when % 1 * 1e9)))
        for when, positions in WAYPOINTS]
    return message


def follow(node, namespace, tolerance, deadline):
    """Send the commands, print joint_states; return whether the last waypoint was reached."""
    latest = {}
    node.create_subscription(JointState, f'{namespace}/joint_states', lambda m: latest.update(
        zip(m.name, m.position, strict=False)), 10)
    arm = node.create_publisher(JointTrajectory, f'{namespace}/arm_controller/joint_trajectory',
                                10)
    gripper = node.create_publisher(Float64MultiArray,
                                    f'{namespace}/gripper_controller/commands', 10)
    while not (arm.get_subscription_count() and gripper.get_subscription_count()):
        if time.monotonic() > deadline:
            return False
        rclpy.spin_once(node, timeout_sec=0.1)
    arm.publish(trajectory_message())
    gripper.publish(Float64MultiArray(data=[GRIPPER_OPENING]))
    target = dict(zip(JOINTS, WAYPOINTS[-1][1], strict=True))
    next_print = 0.0
    while time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.1)
        if latest and time.monotonic() >= next_print:
            print('  '.join(f'{name}: {value:+.3f}' for name, value in latest.items()),
                  flush=True)
            next_print = time.monotonic() + 0.5
        if all(abs(latest.get(name, math.inf) - value) <= tolerance
               for name, value in target.items()):
            print('last waypoint reached')
            return True
    return False


def main(argv=None):
    """Run :func:`follow` on a fresh node; exit status 0 once the last waypoint is reached."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--namespace', default='', help="the robot's namespace (default none)")
    parser.add_argument('--tolerance', type=float, default=0.02)
    parser.add_argument('--timeout', type=float, default=60.0, help='wall seconds')
    args = parser.parse_args(argv)
    # Talk to a sim_node started by scripts/run_sim.sh, which keeps DDS on loopback.
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    rclpy.init()
    node = Node('arm_trajectory')
    try:
        reached = follow(node, args.namespace.rstrip('/'), args.tolerance,
                         time.monotonic() + args.timeout)
    except KeyboardInterrupt:
        reached = False
    node.destroy_node()
    rclpy.try_shutdown()
    return 0 if reached else 1


if __name__ == '__main__':
    sys.exit(main())
