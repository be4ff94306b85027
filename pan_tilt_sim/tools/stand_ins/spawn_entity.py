"""gazebo_ros's ``spawn_entity.py`` (classic): hand a robot to sim_node; exit 0 once it is in.

Its arguments (argparse, single dashes): one of ``-file -topic -database -stdin``,
``-entity`` (required), ``-robot_namespace``, ``-reference_frame``, ``-timeout`` (for the
service; ``-spawn_service_timeout`` its old name), ``-unpause``, ``-x -y -z -R -P -Y``,
``-package_to_model`` (nothing to do: sim_node resolves ``package://``).
``-gazebo_namespace NS``: the simulation serving ``NS/spawn_entity`` or running in
namespace NS.  ``-wait NAME``: spawn once NAME is among its entities (GetEntities).
``-b``: stay until stopped (SIGINT, SIGTERM), then delete the entity (DeleteEntity).
Exit 0 spawned, 1 not, as spawn_entity.py.
"""

from __future__ import annotations

import argparse
import sys
import time
import xml.etree.ElementTree as ElementTree

from pan_tilt_sim.tools.stand_ins.create import quaternion
from pan_tilt_sim.tools.stand_ins.launcher import exit_with, run_node
from pan_tilt_sim.tools.stand_ins.spawning import (
    EntityList,
    beside,
    call_spawn,
    description_from_topic,
    find_spawn_service,
    spin_for,
)

NODE_NAME = 'spawn_entity'
EXIT_FAILED = 1
POLL_PERIOD_S = 0.5  # how often -wait asks for the entities


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
    return run_node(argv, NODE_NAME, lambda node, _words: _spawn(node, args, argv))


def _spawn(node, args: argparse.Namespace, argv: list[str]) -> int:
    from simulation_interfaces.srv import SpawnEntity

    logger = node.get_logger()
    logger.info('Spawn Entity started')
    namespace = _namespace(node, args.gazebo_namespace)
    if args.wait and not _wait_for(node, args.wait, namespace):
        return 0  # stopped while waiting
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
    logger.info(f'Waiting for service {args.gazebo_namespace}/spawn_entity, '
                f'timeout = {timeout:.0f}')
    response = call_spawn(node, request, timeout, lambda: None, namespace=namespace)
    if response is None:
        logger.error(f'Service {args.gazebo_namespace}/spawn_entity unavailable. Was sim_node '
                     "started by pan_tilt_sim's gazebo.launch.py?")
        logger.error('Spawn service failed. Exiting.')
        return EXIT_FAILED
    status = response.result.error_message or (
        f'SpawnEntity: Successfully spawned entity [{response.entity_name}]')
    logger.info(f'Spawn status: {status}')
    if response.result.result != 1:
        logger.error('Spawn service failed. Exiting.')
        return EXIT_FAILED
    if args.unpause:
        _unpause(node, namespace)
    if args.bond:
        service = find_spawn_service(node, namespace)
        if service is not None:
            _bond(node, args.entity, beside(service, 'delete_entity'), timeout, argv)
    return 0


def _namespace(node, gazebo_namespace: str) -> str:
    """Return the absolute namespace ``-gazebo_namespace`` names ('' if none: any simulation)."""
    if not gazebo_namespace:
        return ''
    return node.resolve_service_name(gazebo_namespace.rstrip('/') + '/spawn_entity').rsplit(
        '/', 1)[0] or '/'


def _wait_for(node, wanted: str, namespace: str) -> bool:
    """Spin until ``wanted`` is among the simulation's entities; False if stopped first."""
    import rclpy

    node.get_logger().info(f'Waiting for entity {wanted} before proceeding.')
    entities = None
    try:
        while rclpy.ok(context=node.context):
            service = find_spawn_service(node, namespace)
            if entities is None and service is not None:
                entities = EntityList(node, beside(service, 'get_entities'))
            if entities is not None and wanted in (entities.names() or ()):
                return True
            spin_for(node, POLL_PERIOD_S, lambda: False)
        return False
    finally:
        if entities is not None:
            entities.close()


def _bond(node, entity: str, delete_service: str, timeout: float, argv: list[str]) -> None:
    """Spin until stopped, then delete ``entity`` as spawn_entity.py's bond does.

    A signal shuts the node's context down (rclpy's handlers), so the deletion
    runs on a node of a context of its own.
    """
    import rclpy
    from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor

    node.get_logger().info(f'Waiting for shutdown to delete entity [{entity}]')
    interrupted = False
    try:
        while rclpy.ok(context=node.context):
            rclpy.spin_once(node, timeout_sec=1.0)
    except KeyboardInterrupt:
        interrupted = True
    except ExternalShutdownException:
        pass
    node.destroy_node()  # its context is down; its name goes to the deleting node
    context = rclpy.Context()
    rclpy.init(args=argv, context=context)
    deleter = rclpy.create_node(NODE_NAME, context=context)
    executor = SingleThreadedExecutor(context=context)  # the node holds it weakly
    executor.add_node(deleter)
    try:
        if interrupted:
            deleter.get_logger().info('Ctrl-C detected')
        _delete(deleter, entity, delete_service, timeout)
    finally:
        executor.shutdown()
        deleter.destroy_node()
        if context.ok():
            rclpy.shutdown(context=context)


def _delete(node, entity: str, service: str, timeout: float) -> None:
    from simulation_interfaces.srv import DeleteEntity

    logger = node.get_logger()
    logger.info(f'Deleting entity [{entity}]')
    client = node.create_client(DeleteEntity, service)
    entities = EntityList(node, beside(service, 'get_entities'))
    try:
        if not client.wait_for_service(timeout_sec=timeout):
            logger.error(f'Service {service} unavailable. Was sim_node started by '
                         "pan_tilt_sim's gazebo.launch.py?")
            return
        logger.info(f'Calling service {service}')
        future = client.call_async(DeleteEntity.Request(entity=entity))
        # An answer can be lost while the server has not matched this new client (DDS
        # discovery): then the entity missing from the list says it is gone.
        gone = False
        deadline = time.monotonic() + timeout
        while not future.done() and not gone and time.monotonic() < deadline:
            if not spin_for(node, 1.0, future.done):
                names = entities.names()
                gone = names is not None and entity not in names
        if future.done() and future.result() is not None:
            result = future.result().result
            logger.info(f'Deleting status: {result.error_message or "deleted " + entity}')
        elif gone:
            logger.info(f'Deleting status: deleted {entity}')
        else:
            logger.error(f'{service} did not answer: [{entity}] may still be in')
    finally:
        entities.close()
        node.destroy_client(client)


def _unpause(node, namespace: str) -> None:
    """Call the simulation's gazebo_ros ``unpause_physics`` (std_srvs/srv/Empty)."""
    from std_srvs.srv import Empty

    spawn_service = find_spawn_service(node, namespace) if namespace else None
    if spawn_service is not None:
        # sim_node serves ~/spawn_entity and, as gazebo_ros, unpause_physics in its namespace.
        names = [spawn_service.rsplit('/', 2)[0] + '/unpause_physics']
    else:
        names = sorted(name for name, types in node.get_service_names_and_types()
                       if 'std_srvs/srv/Empty' in types and name.endswith('/unpause_physics'))
    if not names:
        node.get_logger().error('Service unpause_physics unavailable.')
        return
    client = node.create_client(Empty, names[0])
    node.get_logger().info(f'Calling service {names[0]}')
    if client.wait_for_service(timeout_sec=5.0):
        spin_for(node, 5.0, client.call_async(Empty.Request()).done)
