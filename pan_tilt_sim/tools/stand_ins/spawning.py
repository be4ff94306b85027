"""What ``create`` and ``spawn_entity.py`` share: a description from a topic, and the spawn call.

The simulation is found by its service: the ``spawn_entity`` service of type
simulation_interfaces/srv/SpawnEntity in the graph (sim_node's, ``~/spawn_entity``),
the first by name if several simulations run.
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
        rclpy.spin_once(node, timeout_sec=timeout_sec)
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


def find_spawn_service(node: Node) -> str | None:
    """Return the name of a simulation's SpawnEntity service in the graph, if any."""
    names = sorted(name for name, types in node.get_service_names_and_types()
                   if SPAWN_TYPE in types and name.rsplit('/', 1)[-1] == SPAWN_LEAF)
    return names[0] if names else None


def call_spawn(node: Node, request, timeout: float | None,
               waiting: Callable[[], None], period: float = 5.0):
    """Call the simulation's SpawnEntity with ``request``; return its response.

    Waits for the service (``waiting()`` every ``period`` s) up to ``timeout``
    s (None: for good); None if it never came or rclpy shut down.
    """
    from simulation_interfaces.srv import SpawnEntity

    deadline = math.inf if timeout is None else time.monotonic() + timeout
    name = None
    while name is None:
        name = find_spawn_service(node)
        if name is not None:
            break
        waiting()
        spin_for(node, min(period, max(0.0, deadline - time.monotonic())),
                 lambda: find_spawn_service(node) is not None)
        import rclpy

        if time.monotonic() >= deadline or not rclpy.ok(context=node.context):
            name = find_spawn_service(node)
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
        checker = _EntityCheck(node, name, request.name)
        while not future.done():
            if spin_for(node, min(period, max(0.0, deadline - time.monotonic())),
                        future.done):
                break
            if checker.present():
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


class _EntityCheck:
    """Whether an entity of a name is in the simulation (its GetEntities beside the spawn)."""

    def __init__(self, node: Node, spawn_service: str, name: str) -> None:
        self._node, self._name = node, name
        self._service = spawn_service.rsplit('/', 1)[0] + '/get_entities'

    def present(self) -> bool:
        if not self._name:
            return False
        from simulation_interfaces.srv import GetEntities

        client = self._node.create_client(GetEntities, self._service)
        try:
            if not client.service_is_ready():
                return False
            future = client.call_async(GetEntities.Request())
            spin_for(self._node, 2.0, future.done)
            return future.done() and future.result() is not None and self._name in (
                future.result().entities)
        finally:
            self._node.destroy_client(client)
