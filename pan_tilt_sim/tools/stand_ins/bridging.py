"""What ``parameter_bridge`` and ``image_bridge`` share: hand the entries to sim_node, then stay.

The simulation is the node serving simulation_interfaces' ``spawn_entity`` (sim_node
started by gz_sim.launch.py); the entries go into its ``gz_bridge`` parameter
(:mod:`pan_tilt_sim.ros.bridged_topics`).  The stand-in then spins until stopped,
as the bridge runs until stopped.
"""

from __future__ import annotations

import sys

from rclpy.node import Node

from pan_tilt_sim.model.gz_bridge import BridgeEntry, encode
from pan_tilt_sim.tools.stand_ins.spawning import find_spawn_service, spin_for, spin_once

EXIT_REFUSED = 2
SPIN_PERIOD_S = 1.0


def absolute(node: Node, entry: BridgeEntry, expand_gz_names: bool) -> BridgeEntry:
    """Return the entry with its ROS name resolved in the node's namespace, its gz name absolute.

    gz topic names are not ROS names: ``odom`` is ``/odom`` to gz, unless
    ``expand_gz_topic_names`` expands them as ROS names of the bridge node.
    """
    import dataclasses

    gz_topic = (node.resolve_topic_name(entry.gz_topic) if expand_gz_names
                else '/' + entry.gz_topic.lstrip('/'))
    return dataclasses.replace(entry, ros_topic=node.resolve_topic_name(entry.ros_topic),
                               gz_topic=gz_topic)


def announce(node: Node) -> object:
    """Say in the graph that a bridge is coming (sim_node waits for it before a robot)."""
    from std_msgs.msg import Empty

    from pan_tilt_sim.ros.bridged_topics import ANNOUNCE_TOPIC

    return node.create_publisher(Empty, ANNOUNCE_TOPIC, 1)


def hand_over(node: Node, entries: list[BridgeEntry]) -> int | None:
    """Give sim_node the entries; spin until stopped.  An exit code if it refused them."""
    import rclpy
    from rclpy.parameter import Parameter
    from rclpy.parameter_client import AsyncParameterClient

    logger = node.get_logger()
    for entry in entries:
        logger.info(f'Creating {entry.direction} Bridge: [{entry.gz_topic} ({entry.gz_type}) '
                    f'<-> {entry.ros_topic} ({entry.ros_type})] (Lazy {int(entry.lazy)})')
    said = False
    service = None
    while rclpy.ok(context=node.context) and service is None:
        service = find_spawn_service(node)
        if service is None:
            if not said:
                logger.info('waiting for the simulation (a sim_node started by '
                            "gz_sim.launch.py, serving 'spawn_entity')")
                said = True
            spin_for(node, SPIN_PERIOD_S, lambda: find_spawn_service(node) is not None)
    if service is None:
        return 0
    simulation = service.rsplit('/', 1)[0]
    client = AsyncParameterClient(node, simulation)
    if not spin_for(node, 30.0, client.services_are_ready):
        if not rclpy.ok(context=node.context):
            return 0  # stopped while waiting, as the bridge exits when interrupted
        logger.error(f'{simulation} has no parameter services: nothing bridged')
        return EXIT_REFUSED
    future = client.set_parameters([Parameter(
        'gz_bridge', Parameter.Type.STRING_ARRAY,
        encode(node.get_fully_qualified_name(), entries))])
    if not spin_for(node, 30.0, future.done) and not rclpy.ok(context=node.context):
        return 0
    results = future.result().results if future.done() and future.result() else []
    if not results or not results[0].successful:
        reason = results[0].reason if results else 'no answer'
        sys.stderr.write(f'{node.get_name()}: {simulation} refused the bridge: {reason}\n')
        return EXIT_REFUSED
    logger.info(f'{len(entries)} topics bridged by {simulation} itself')
    stay_until_stopped(node)
    return None


def stay_until_stopped(node: Node) -> None:
    """Spin ``node`` until its context is shut down (SIGINT), as the bridge's ``rclcpp::spin``."""
    while spin_once(node, SPIN_PERIOD_S):
        pass
