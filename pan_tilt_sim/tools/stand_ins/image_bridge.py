"""ros_gz_image's ``image_bridge``: gz image topics as sensor_msgs/msg/Image, by sim_node itself.

``image_bridge TOPIC [TOPIC ...]`` (node ``ros_gz_image``, parameter ``qos``): each
gz image topic appears on ROS under the same name (:mod:`.bridging`); the stand-in
stays until stopped.  image_transport's compressed topics are not made, nor is a
``qos`` other than ``default`` applied (a warning each).
"""

from __future__ import annotations

import sys

from pan_tilt_sim.model.gz_bridge import GZ_TO_ROS, BridgeEntry
from pan_tilt_sim.tools.stand_ins.launcher import exit_with, run_node

NODE_NAME = 'ros_gz_image'
EXIT_USAGE = 255
QOS_CHOICES = ('default', 'system_default', 'sensor_data')
USAGE = ('Bridge a collection of Gazebo Transport image topics to ROS using image_transport.\n\n'
         '  image_bridge <topic> <topic> ..\n\nE.g.: image_bridge /camera/front/image_raw\n')


def main(argv: list[str] | None = None) -> None:
    """Run image_bridge with ``argv`` (program name first)."""
    exit_with(run, argv)


def run(argv: list[str]) -> int:
    """Bridge as image_bridge does; return the exit code (0 when stopped)."""
    if len(argv) < 2:
        sys.stderr.write(USAGE)
        return EXIT_USAGE
    return run_node(argv, NODE_NAME, _bridge)


def _bridge(node, topics: list[str]) -> int:
    from pan_tilt_sim.tools.stand_ins.bridging import absolute, announce, hand_over

    announce(node)

    qos = node.declare_parameter('qos', 'default').value
    if qos not in QOS_CHOICES:
        node.get_logger().error(
            f'Invalid QoS profile {qos} specified. Using default profile.')
    elif qos != 'default':
        node.get_logger().warning(
            f"qos '{qos}' is not honoured: sim_node publishes the images reliable, which "
            'reliable and best-effort subscribers both receive')
    node.get_logger().warning(
        "image_transport's compressed and theora topics are not made: raw images only")
    entries = [absolute(node, BridgeEntry(topic, topic, 'sensor_msgs/msg/Image',
                                          'gz.msgs.Image', GZ_TO_ROS), False)
               for topic in topics]
    code = hand_over(node, entries)
    return 0 if code is None else code
