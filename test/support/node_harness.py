"""In-process harness for node tests: the node under test and a probe on one executor.

Waiting is always bounded: :meth:`NodeHarness.spin_until` spins the shared
executor until a condition holds or a wall-clock budget runs out, and
reports which.

:func:`sim_node` runs a SimNode (real_time_factor 0 unless given) on such a
harness and hands the test a :class:`SimUnderTest`: the node, the
JointStates it published, and the probe's ways to command and watch it.
"""

from __future__ import annotations

import contextlib
import pathlib
import time
from collections.abc import Callable, Iterator
from typing import Any

import rclpy
from rclpy.action import ActionClient
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.qos import QoSHistoryPolicy, QoSProfile
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from pan_tilt_sim.ros.sim_node import SimNode

SPIN_SLICE_S = 0.05
# A service request still unanswered after this long is sent again (see call()).
RESEND_AFTER_S = 2.0
DEFAULT_BUDGET_S = 30.0
QUEUE_DEPTH = 10
# Deep queues: at real_time_factor 0 the node publishes faster than one
# executor iteration takes a message, so the probe must be able to lag.
PROBE_QUEUE = QoSProfile(depth=20000, history=QoSHistoryPolicy.KEEP_LAST)
SAME_STAMP_S = 1e-6  # two stamps this close are the same instant
SIM_TIME_EPSILON_S = 1e-9
# Where sim_node() records its runs while a test may want them kept (record_failed.py).
_recording: dict[str, object] = {'folder': None, 'made': 0}


def interface_name(interface: type) -> str:
    """ROS's name of a message or service class, as the graph gives it: ``std_msgs/msg/Float64``."""
    package, kind, _module = interface.__module__.split('.')
    return f'{package}/{kind}/{interface.__name__}'


def stamp_s(message) -> float:
    """Return a message's time in seconds: a Clock's ``clock``, else its header stamp."""
    stamp = message.clock if isinstance(message, Clock) else message.header.stamp
    return stamp.sec + stamp.nanosec * 1e-9


class NodeHarness:
    """A fresh rclpy context with an executor, a probe node and the node(s) under test."""

    def __init__(self) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.probe = Node('probe', context=self.context)
        self.executor.add_node(self.probe)
        self._nodes: list[Node] = [self.probe]

    def add(self, node: Node) -> Node:
        """Spin ``node`` (and its ``companion_nodes``) on the shared executor until closed.

        The node is destroyed with the harness (and destroys its companions).
        """
        for each in (node, *getattr(node, 'companion_nodes', ())):
            self.executor.add_node(each)
        self._nodes.append(node)
        return node

    def spin_until(self, condition: Callable[[], bool],
                   budget_s: float = DEFAULT_BUDGET_S) -> bool:
        """Spin until ``condition()`` holds; False if the budget ran out first."""
        deadline = time.monotonic() + budget_s
        while not condition():
            if time.monotonic() > deadline:
                return False
            self.executor.spin_once(timeout_sec=SPIN_SLICE_S)
        return True

    def spin_for(self, seconds: float) -> None:
        """Keep spinning for ``seconds`` of wall time (to show that something does not happen)."""
        self.spin_until(lambda: False, budget_s=seconds)

    def drain(self, count: Callable[[], int], quiet_spins: int = 20,
              budget_s: float = DEFAULT_BUDGET_S) -> bool:
        """Spin until ``count()`` has not grown for ``quiet_spins`` spins in a row.

        Use it after pausing a publisher, to take the messages still queued.
        """
        deadline = time.monotonic() + budget_s
        last, quiet = count(), 0
        while quiet < quiet_spins:
            if time.monotonic() > deadline:
                return False
            self.executor.spin_once(timeout_sec=SPIN_SLICE_S / 10)
            now = count()
            quiet = quiet + 1 if now == last else 0
            last = now
        return True

    def call(self, service_type: type, name: str, request: Any = None,
             budget_s: float = DEFAULT_BUDGET_S) -> Any:
        """Call service ``name`` from the probe once it is there; return the response.

        Fast DDS may report the service ready before the server has matched the
        client's response reader; the server then drops the response ("failed
        to send response (timeout)").  So an unanswered request is sent again
        after RESEND_AFTER_S -- the services tested here are idempotent.
        """
        client = self.probe.create_client(service_type, name)
        try:
            assert self.spin_until(client.service_is_ready, budget_s), f'no service {name}'
            deadline = time.monotonic() + budget_s
            while True:
                future = client.call_async(
                    service_type.Request() if request is None else request)
                if self.spin_until(future.done, RESEND_AFTER_S):
                    break
                client.remove_pending_request(future)
                assert time.monotonic() < deadline, f'{name} did not answer'
            response = future.result()
            assert response is not None, f'{name} failed: {future.exception()!r}'
            return response
        finally:
            self.probe.destroy_client(client)

    def close(self) -> None:
        """Destroy every node, and the tests' action clients; shut the context down.

        rclpy's destroy_node leaves a node's action clients alone, and they keep
        the node -- and its DDS participant, with its endpoints -- alive until
        garbage collection, where the next test's nodes would still meet them.
        (sim_node destroys its own action servers.)
        """
        for node in reversed(self._nodes):
            for each in (*getattr(node, 'companion_nodes', ()), node):
                self.executor.remove_node(each)
                for waitable in list(each.waitables):
                    if isinstance(waitable, ActionClient):
                        waitable.destroy()
            node.destroy_node()
        self.executor.shutdown()
        rclpy.try_shutdown(context=self.context)


class SimUnderTest:
    """A running SimNode beside the harness's probe node.

    ``states`` collects the JointStates on the robot's ``joint_states`` topic
    from the start; :meth:`collect` watches more topics.  :meth:`run_for` and
    :meth:`drain` take every message still queued on all of them.
    """

    def __init__(self, harness: NodeHarness, node: SimNode) -> None:
        self.harness = harness
        self.node = node
        self.probe = harness.probe
        self.spin_until = harness.spin_until
        self.spin_for = harness.spin_for
        self.call = harness.call
        self._collected: list[list] = []
        self._publishers: dict[str, Any] = {}
        self.states: list[JointState] = self.collect(
            JointState, node.topic('joint_states'), PROBE_QUEUE)

    @property
    def simulation(self):
        """The node's Simulation."""
        return self.node.simulation

    # --- watching ---------------------------------------------------------------------------

    def collect(self, message_type: type, topic: str, qos: Any = QUEUE_DEPTH) -> list:
        """Subscribe the probe to ``topic``; return the list messages are appended to."""
        received: list = []
        self.probe.create_subscription(message_type, topic, received.append, qos)
        self._collected.append(received)
        return received

    def topics_once_seen(self, *names: str) -> dict[str, list[str]]:
        """The ROS graph's topics, once ``names`` are all in it.

        The graph learns even the node's own topics through DDS discovery, which
        lags under load: wait for them (bounded) rather than read it once.
        """
        return self._graph_once_seen(self.node.get_topic_names_and_types, names)

    def services_once_seen(self, *names: str) -> dict[str, list[str]]:
        """The ROS graph's services, once ``names`` are all in it.

        The whole graph, not the node's share of it looked up by node name: a
        second node of the same name in the domain would make that look-up
        answer for the other one.
        """
        return self._graph_once_seen(self.node.get_service_names_and_types, names)

    def own_topics(self) -> tuple[dict[str, str], dict[str, str]]:
        """The topics the node publishes and subscribes to, from its own endpoints.

        What the node created, with no DDS discovery in between: a negative
        check ("no camera topic") on the discovered graph would pass while
        discovery lags.
        """
        def named(endpoints) -> dict[str, str]:
            return {e.topic_name: interface_name(e.msg_type) for e in endpoints}
        return named(self.node.publishers), named(self.node.subscriptions)

    def own_services(self) -> dict[str, str]:
        """The services the node serves (actions aside), from its own endpoints, no discovery."""
        return {service.service_name: interface_name(service.srv_type)
                for service in self.node.services}

    def _graph_once_seen(self, read: Callable[[], list], names: tuple[str, ...]) -> dict:
        graph: dict[str, list[str]] = {}

        def seen() -> bool:
            graph.clear()
            graph.update(read())
            return all(name in graph for name in names)

        assert self.spin_until(seen), (
            f'not in the ROS graph: {[name for name in names if name not in graph]}')
        return dict(graph)

    def wait_for_subscribers(self, topic: str, count: int = 1) -> None:
        """Spin until the node sees ``count`` subscribers on ``topic``."""
        assert self.spin_until(lambda: self.node.count_subscribers(topic) >= count), (
            f'no subscriber discovered on {topic}')

    def drain(self) -> None:
        """Hold the physics and take every message still queued on the collected topics."""
        held = self.node.paused
        self.node.set_paused(True)
        assert self.harness.drain(lambda: sum(len(received) for received in self._collected)), (
            'messages kept coming while the physics was held')
        self.node.set_paused(held)

    # --- running ----------------------------------------------------------------------------

    def run_for(self, seconds: float) -> None:
        """Let sim time advance by ``seconds``, then :meth:`drain`."""
        target = self.simulation.time + seconds
        assert self.spin_until(lambda: self.simulation.time >= target), (
            f'sim time stuck at {self.simulation.time} s, wanted {target} s')
        self.drain()

    def run_until_sim_time(self, seconds: float, budget_s: float = DEFAULT_BUDGET_S) -> None:
        """Spin until sim time reaches ``seconds``; fail the test if it does not."""
        assert self.spin_until(
            lambda: self.simulation.time >= seconds - SIM_TIME_EPSILON_S, budget_s), (
            f'sim time stuck at {self.simulation.time} s, wanted {seconds} s')

    # --- commanding -------------------------------------------------------------------------

    def command(self, controller: str, message: Any) -> None:
        """Publish ``message`` on the controller's command topic; return once the node took it."""
        publisher = self._command_publisher(controller, type(message))
        counts = self.node.commands_received
        before = counts[controller]
        publisher.publish(message)
        assert self.spin_until(lambda: counts[controller] > before), (
            f'{controller} never received {message}')

    def send_paused(self, controller: str, message: Any) -> float:
        """Command while the physics is held, so it takes effect at a known time; return it."""
        self.node.set_paused(True)
        self.command(controller, message)
        self.node.set_paused(False)
        return self.simulation.time

    def command_position(self, controller: str, value: float) -> float:
        """Command a position controller; return the sim time once its setpoint moved.

        The command landed at most one batch of steps before that time.
        """
        taken = self.simulation.controller(controller)
        before = taken.setpoints()
        self.command(controller, Float64(data=value))
        assert self.spin_until(lambda: taken.setpoints() != before), (
            f'command {value} to {controller} never moved the setpoint')
        return self.simulation.time

    def set_parameters(self, **values: Any) -> list:
        """Set sim_node parameters through its set_parameters service; return the results."""
        client = AsyncParameterClient(self.probe, self.node.get_name())
        assert self.spin_until(client.services_are_ready), 'parameter services not ready'
        future = client.set_parameters([Parameter(name, value=value)
                                        for name, value in values.items()])
        assert self.spin_until(future.done), 'set_parameters did not answer'
        return list(future.result().results)

    def _command_publisher(self, controller: str, message_type: type):
        topic = self.node.topic(controller, self.simulation.controller(controller).command_topic)
        publisher = self._publishers.get(topic)
        if publisher is None:
            publisher = self.probe.create_publisher(message_type, topic, QUEUE_DEPTH)
            self._publishers[topic] = publisher
            assert self.spin_until(lambda: publisher.get_subscription_count() > 0), (
                f'sim_node does not subscribe {topic}')
        return publisher

    # --- reading ----------------------------------------------------------------------------

    def position(self, joint: str, message: JointState | None = None) -> float:
        """Return ``joint``'s position in ``message`` (default: the last JointState)."""
        message = message or self.states[-1]
        return message.position[list(message.name).index(joint)]

    def series(self, joint: str, field: str, since: float = 0.0) -> list[float]:
        """Return ``joint``'s ``field`` (position, velocity or effort) from ``since`` on."""
        return [getattr(m, field)[list(m.name).index(joint)] for m in self.states
                if stamp_s(m) >= since]

    def state_at(self, seconds: float) -> JointState:
        """Return the JointState stamped at ``seconds`` of sim time."""
        return next(m for m in self.states if abs(stamp_s(m) - seconds) < SAME_STAMP_S)

    def setpoints(self, controller: str) -> list[float]:
        """Return the controller's setpoints, one per joint."""
        found = self.simulation.controller(controller)
        return list(found.setpoints().values())


@contextlib.contextmanager
def recording_into(folder: pathlib.Path) -> Iterator[None]:
    """Have every :func:`sim_node` started meanwhile record into ``folder/sim_node_<n>``."""
    _recording.update(folder=folder, made=0)
    try:
        yield
    finally:
        _recording.update(folder=None, made=0)


@contextlib.contextmanager
def sim_node(*, node_namespace: str | None = None, **parameters: Any) -> Iterator[SimUnderTest]:
    """Run a SimNode (real_time_factor 0 unless given) with ``parameters`` as overrides.

    Inside :func:`recording_into` (``PAN_TILT_SIM_RECORD_FAILED``), the node
    records its run unless the test gives ``record`` itself.
    """
    parameters.setdefault('real_time_factor', 0.0)
    folder = _recording['folder']
    if folder is not None and 'record' not in parameters:
        parameters['record'] = str(folder / f"sim_node_{_recording['made']}")
        _recording['made'] += 1
    harness = NodeHarness()
    try:
        node = harness.add(SimNode(
            context=harness.context, namespace=node_namespace,
            parameter_overrides=[Parameter(name, value=value)
                                 for name, value in parameters.items()]))
        yield SimUnderTest(harness, node)
    finally:
        harness.close()
