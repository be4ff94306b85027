"""ros_gz_bridge's ``parameter_bridge``: its arguments and config_file, bridged by sim_node itself.

Arguments ``topic@ros_type(@|[|])gz_type`` and the node's parameters (``config_file``,
``expand_gz_topic_names``, ``lazy``, ``subscription_heartbeat``,
``override_timestamps_with_wall_time``), as ros_gz_bridge's (jazzy) node
``ros_gz_bridge`` reads them.  The entries go to the running sim_node
(:mod:`pan_tilt_sim.tools.stand_ins.bridging`); the stand-in stays until stopped.  A
malformed entry or a type pair ros_gz_bridge cannot convert exits 2 with one line
naming it.  Service bridges are named in a warning (not honoured).  ``lazy`` is
taken silently: sim_node's own endpoints are the ROS ends, so it changes nothing a ROS
node sees (docs/launch-files.md says why).
"""

from __future__ import annotations

import dataclasses
import pathlib
import sys

from pan_tilt_sim.model.gz_bridge import BridgeEntry, BridgeError, parse_argument, read_config
from pan_tilt_sim.tools.stand_ins.launcher import exit_with, run_node

NODE_NAME = 'ros_gz_bridge'
EXIT_USAGE = 255  # parameter_bridge's return -1
EXIT_BAD_ENTRY = 2
USAGE = ('Bridge a collection of ROS2 and Gazebo Transport topics and services.\n\n'
         '  parameter_bridge [<topic@ROS2_type@Ign_type> ..]  '
         '[<service@ROS2_srv_type[@Ign_req_type@Ign_rep_type]> ..]\n')


def main(argv: list[str] | None = None) -> None:
    """Run parameter_bridge with ``argv`` (program name first)."""
    exit_with(run, argv)


def run(argv: list[str]) -> int:
    """Bridge as parameter_bridge does; return the exit code (0 when stopped)."""
    if len(argv) < 2:
        sys.stdout.write(USAGE)
        return EXIT_USAGE
    return run_node(argv, NODE_NAME, _bridge)


def _bridge(node, arguments: list[str]) -> int:
    from pan_tilt_sim.tools.stand_ins.bridging import absolute, announce, hand_over

    announce(node)
    logger = node.get_logger()
    lazy = node.declare_parameter('lazy', False).value
    config_file = node.declare_parameter('config_file', '').value
    expand = node.declare_parameter('expand_gz_topic_names', False).value
    node.declare_parameter('subscription_heartbeat', 1000)
    if node.declare_parameter('override_timestamps_with_wall_time', False).value:
        logger.warning('override_timestamps_with_wall_time is not honoured: stamps stay sim time')
    entries: list[BridgeEntry] = []
    try:
        for argument in arguments:
            parsed = parse_argument(argument)
            if isinstance(parsed, str):
                logger.warning(f"service bridge '{argument}' is not honoured (sim_node serves "
                               'no gz services)')
                continue
            entries.append(dataclasses.replace(parsed, lazy=lazy))  # the node's, as upstream
        if config_file:
            entries += read_config(pathlib.Path(config_file))
    except BridgeError as err:
        sys.stderr.write(f'parameter_bridge: {err}\n')
        return EXIT_BAD_ENTRY
    code = hand_over(node, [absolute(node, entry, expand) for entry in entries])
    return 0 if code is None else code
