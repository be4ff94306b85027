"""gazebo_ros's ``spawn_entity.py`` (classic): hand a robot to sim_node; exit 0 once it is in.

Its arguments (argparse, single dashes): one of ``-file -topic -database -stdin``,
``-entity`` (required), ``-robot_namespace``, ``-reference_frame``, ``-timeout`` (for the
service; ``-spawn_service_timeout`` its old name), ``-unpause``, ``-x -y -z -R -P -Y``,
``-package_to_model`` (nothing to do: sim_node resolves ``package://``).
``-gazebo_namespace``, ``-wait`` and ``-b`` are named in a warning (not honoured).
Exit 0 spawned, 1 not, as spawn_entity.py.
"""

from __future__ import annotations

import argparse
import sys
import xml.etree.ElementTree as ElementTree

from pan_tilt_sim.tools.stand_ins.create import quaternion
from pan_tilt_sim.tools.stand_ins.launcher import exit_with, run_node
from pan_tilt_sim.tools.stand_ins.spawning import call_spawn, description_from_topic, spin_for

NODE_NAME = 'spawn_entity'
EXIT_FAILED = 1


def parser() -> argparse.ArgumentParser:
    """spawn_entity.py's arguments."""
    parsed = argparse.ArgumentParser(prog='spawn_entity.py',
                                     description='Spawn an entity in the simulation.')
    source = parsed.add_mutually_exclusive_group(required=True)
    source.add_argument('-file', type=str, metavar='FILE_NAME')
    source.add_argument('-topic', type=str, metavar='TOPIC_NAME')
    source.add_argument('-database', type=str, metavar='ENTITY_NAME')
    source.add_argument('-stdin', action='store_true')
    parsed.add_argument('-entity', required=True, type=str, metavar='ENTITY_NAME')
    parsed.add_argument('-reference_frame', type=str, default='')
    parsed.add_argument('-gazebo_namespace', type=str, default='')
    parsed.add_argument('-robot_namespace', type=str, default='')
    parsed.add_argument('-timeout', type=float, default=30.0)
    parsed.add_argument('-unpause', action='store_true')
    parsed.add_argument('-wait', type=str, metavar='ENTITY_NAME')
    parsed.add_argument('-spawn_service_timeout', type=float, metavar='TIMEOUT')
    for axis in ('x', 'y', 'z', 'R', 'P', 'Y'):
        parsed.add_argument(f'-{axis}', type=float, default=0)
    parsed.add_argument('-package_to_model', action='store_true')
    parsed.add_argument('-b', dest='bond', action='store_true')
    return parsed


def main(argv: list[str] | None = None) -> None:
    """Run spawn_entity.py with ``argv`` (program name first); exit 0 spawned, 1 not."""
    exit_with(run, argv)


def run(argv: list[str]) -> int:
    """Spawn as spawn_entity.py does; return the exit code."""
    from rclpy.utilities import remove_ros_args

    args = parser().parse_args(remove_ros_args(argv)[1:])  # exits 2 on bad arguments
    return run_node(argv, NODE_NAME, lambda node, _words: _spawn(node, args))


def _spawn(node, args: argparse.Namespace) -> int:
    from simulation_interfaces.srv import SpawnEntity

    logger = node.get_logger()
    logger.info('Spawn Entity started')
    for name, given in (('-gazebo_namespace', args.gazebo_namespace), ('-wait', args.wait),
                        ('-b', args.bond)):
        if given:
            logger.warning(f'{name} is not honoured: sim_node has one spawn service and no '
                           'bond')
    request = SpawnEntity.Request(name=args.entity, entity_namespace=args.robot_namespace)
    if args.file:
        logger.info(f'Loading entity XML from file {args.file}')
        request.uri = args.file
    elif args.topic:
        logger.info(f'Loading entity published on topic {args.topic}')
        request.resource_string = description_from_topic(
            node, args.topic, None,
            lambda topic: logger.info(f'Waiting for entity xml on {topic}')) or ''
        if not request.resource_string:
            return 0
    elif args.database:
        from pan_tilt_sim.model.sdf_resources import find_model_folder, model_sdf_file

        logger.info('Loading entity XML from Gazebo Model Database')
        folder = find_model_folder(args.database)
        if folder is None:
            logger.error(f"model '{args.database}' is in no model path (GAZEBO_MODEL_PATH, "
                         'GZ_SIM_RESOURCE_PATH); nothing is downloaded')
            return EXIT_FAILED
        request.uri = str(model_sdf_file(folder))
    else:
        logger.info('Loading entity XML from stdin')
        request.resource_string = sys.stdin.read()
        if not request.resource_string:
            logger.error('Error: stdin buffer was empty')
            return EXIT_FAILED
    if request.resource_string:
        try:
            ElementTree.fromstring(request.resource_string)
        except ElementTree.ParseError as err:
            logger.error(f'Invalid XML: {err}')
            return EXIT_FAILED
    pose = request.initial_pose
    pose.header.frame_id = args.reference_frame
    pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = args.x, args.y, args.z
    (pose.pose.orientation.x, pose.pose.orientation.y, pose.pose.orientation.z,
     pose.pose.orientation.w) = quaternion(args.R, args.P, args.Y)
    timeout = args.timeout
    if args.spawn_service_timeout is not None:
        logger.warning("'-spawn_service_timeout' is deprecated, use '-timeout' instead")
        timeout = args.spawn_service_timeout
    if timeout < 0:
        logger.error('spawn_entity timeout must be greater than zero')
        return EXIT_FAILED
    logger.info(f'Waiting for service spawn_entity, timeout = {timeout:.0f}')
    response = call_spawn(node, request, timeout, lambda: None)
    if response is None:
        logger.error('Service spawn_entity unavailable. Was sim_node started by '
                     "pan_tilt_sim's gazebo.launch.py?")
        logger.error('Spawn service failed. Exiting.')
        return EXIT_FAILED
    status = response.result.error_message or (
        f'SpawnEntity: Successfully spawned entity [{response.entity_name}]')
    logger.info(f'Spawn status: {status}')
    if response.result.result != 1:
        logger.error('Spawn service failed. Exiting.')
        return EXIT_FAILED
    if args.unpause:
        _unpause(node)
    return 0


def _unpause(node) -> None:
    """Call the simulation's gazebo_ros ``unpause_physics`` (std_srvs/srv/Empty)."""
    from std_srvs.srv import Empty

    names = sorted(name for name, types in node.get_service_names_and_types()
                   if 'std_srvs/srv/Empty' in types and name.endswith('/unpause_physics'))
    if not names:
        node.get_logger().error('Service unpause_physics unavailable.')
        return
    client = node.create_client(Empty, names[0])
    node.get_logger().info(f'Calling service {names[0]}')
    if client.wait_for_service(timeout_sec=5.0):
        spin_for(node, 5.0, client.call_async(Empty.Request()).done)
