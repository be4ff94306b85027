"""What ``create`` and ``spawn_entity.py`` share: a description from a topic, and the spawn call.

The simulation is found by its service: the ``spawn_entity`` service of type
simulation_interfaces/srv/SpawnEntity in the graph (sim_node's, ``~/spawn_entity``),
the first by name if several simulations run, or the one under a namespace given
(:func:`find_spawn_service`).  Its ``get_entities`` and ``delete_entity`` are beside it.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

SPAWN_TYPE = 'simulation_interfaces/srv/SpawnEntity'
SPAWN_LEAF = 'spawn_entity'
DESCRIPTION_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
SPIN_SLICE_S = 0.1


def spin_once(node: Node, timeout_sec: float) -> bool:
    """Spin ``node`` once (up to ``timeout_sec`` s); False once its context is shut down.

    On the node's executor if it has one (a node of a context of its own), else rclpy's.

    rclpy's SIGINT handler shuts the context down from its own thread, so it can land
    between an ``ok()`` check and the wait; rclpy then raises ExternalShutdownException
    or RCLError (context not valid).  Either is the stop, not an error.
    """
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.impl.implementation_singleton import rclpy_implementation

    if not rclpy.ok(context=node.context):
        return False
    try:
        rclpy.spin_once(node, executor=node.executor, timeout_sec=timeout_sec)
    except (ExternalShutdownException, rclpy_implementation.RCLError):
        if rclpy.ok(context=node.context):
            raise
        return False
    return True


def spin_for(node: Node, seconds: float, done: Callable[[], bool]) -> bool:
    """Spin ``node`` until ``done()``, ``seconds`` passed or it is stopped; return ``done()``."""
    deadline = time.monotonic() + seconds
    while not done() and time.monotonic() < deadline:
        if not spin_once(node, min(SPIN_SLICE_S, max(0.0, deadline - time.monotonic()))):
            break
    return done()


def description_from_topic(node: Node, topic: str, timeout: float | None,
                           waiting: Callable[[str], None]) -> str | None:
    """Return the first String on ``topic`` (transient local), or None after ``timeout`` s.

    ``waiting(topic)`` is called before each one-second wait, as create logs it.
    """
    received: list[str] = []
    subscription = node.create_subscription(
        String, topic, lambda message: received.append(message.data), DESCRIPTION_QOS)
    deadline = math.inf if timeout is None else time.monotonic() + timeout
    try:
        while not received and time.monotonic() < deadline:
            waiting(subscription.topic_name)
            if not spin_for(node, min(1.0, max(0.0, deadline - time.monotonic())),
                            lambda: bool(received)):
                import rclpy

                if not rclpy.ok(context=node.context):
                    return None
    finally:
        node.destroy_subscription(subscription)
    return received[0] if received else None


def find_spawn_service(node: Node, namespace: str = '') -> str | None:
    """Return the name of a simulation's SpawnEntity service in the graph, if any.

    ``namespace`` (absolute) narrows it to ``<namespace>/spawn_entity`` or the
    ``~/spawn_entity`` of a simulation node in ``namespace``; '' takes any.
    """
    prefix = namespace.rstrip('/')

    def under(name: str) -> bool:
        parent = name.rsplit('/', 1)[0]
        return not namespace or prefix in (parent, parent.rsplit('/', 1)[0])

    names = sorted(name for name, types in node.get_service_names_and_types()
                   if SPAWN_TYPE in types and name.rsplit('/', 1)[-1] == SPAWN_LEAF
                   and under(name))
    return names[0] if names else None


def beside(spawn_service: str, leaf: str) -> str:
    """Return the simulation's service ``leaf`` next to its ``spawn_service``."""
    return spawn_service.rsplit('/', 1)[0] + '/' + leaf


def call_spawn(node: Node, request, timeout: float | None,
               waiting: Callable[[], None], period: float = 5.0, namespace: str = ''):
    """Call the simulation's SpawnEntity with ``request``; return its response.

    Waits for the service (``waiting()`` every ``period`` s) up to ``timeout``
    s (None: for good); None if it never came or rclpy shut down.  ``namespace``
    as :func:`find_spawn_service`'s.
    """
    from simulation_interfaces.srv import SpawnEntity

    deadline = math.inf if timeout is None else time.monotonic() + timeout
    name = None
    while name is None:
        name = find_spawn_service(node, namespace)
        if name is not None:
            break
        waiting()
        spin_for(node, min(period, max(0.0, deadline - time.monotonic())),
                 lambda: find_spawn_service(node, namespace) is not None)
        import rclpy

        if time.monotonic() >= deadline or not rclpy.ok(context=node.context):
            name = find_spawn_service(node, namespace)
            if name is None:
                return None
    client = node.create_client(SpawnEntity, name)
    try:
        if not client.wait_for_service(timeout_sec=max(1.0, min(30.0, deadline
                                                                  - time.monotonic()))):
            return None
        future = client.call_async(request)
        # The answer comes once the robot is built (seconds for a big one).  A server
        # that has not matched this client's reader yet drops it (DDS discovery): then
        # the robot's name among the entities says it is in.
        while not future.done():
            if spin_for(node, min(period, max(0.0, deadline - time.monotonic())),
                        future.done):
                break
            if _present(node, beside(name, 'get_entities'), request.name):
                return _ok(SpawnEntity.Response(entity_name=request.name))
            import rclpy

            if time.monotonic() >= deadline or not rclpy.ok(context=node.context):
                return None
        return future.result()
    finally:
        node.destroy_client(client)


def _ok(response):
    response.result.result = 1  # RESULT_OK
    return response


def _present(node: Node, get_entities: str, name: str) -> bool:
    """Whether ``name`` is among the entities, asked through a client made for the question."""
    if not name:
        return False
    entities = EntityList(node, get_entities)
    try:
        return name in (entities.names() or ())
    finally:
        entities.close()


class EntityList:
    """The names of the entities in the simulation, through its GetEntities service."""

    def __init__(self, node: Node, service: str) -> None:
        from simulation_interfaces.srv import GetEntities

        self._node = node
        self._client = node.create_client(GetEntities, service)

    def names(self, answer_within: float = 2.0) -> list[str] | None:
        """Return the entities' names; None if the service is not there or did not answer."""
        from simulation_interfaces.srv import GetEntities

        if not self._client.service_is_ready():
            return None
        future = self._client.call_async(GetEntities.Request())
        if not spin_for(self._node, answer_within, future.done) or future.result() is None:
            return None
        return list(future.result().entities)

    def close(self) -> None:
        """Destroy the client."""
        self._node.destroy_client(self._client)
