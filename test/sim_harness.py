"""sim_node under test with conveniences for the camera, TF and gain tests.

Built on :class:`node_harness.NodeHarness` (own context, probe node, bounded
spins): ``with sim_node(**parameters) as harness`` runs a SimNode at
real_time_factor 0 unless told otherwise.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

from node_harness import DEFAULT_BUDGET_S, NodeHarness
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from std_msgs.msg import Float64

from pan_tilt_sim.sim_node import SimNode


class SimHarness:
    """A running SimNode beside the harness's probe node."""

    def __init__(self, harness: NodeHarness, node: SimNode) -> None:
        self.harness = harness
        self.node = node
        self.probe = harness.probe
        self.spin_until = harness.spin_until

    @property
    def simulation(self):
        """The node's Simulation."""
        return self.node.simulation

    def run_until_sim_time(self, seconds: float, budget_s: float = DEFAULT_BUDGET_S) -> None:
        """Spin until sim time reaches ``seconds``; fail the test if it does not."""
        assert self.spin_until(lambda: self.simulation.time >= seconds - 1e-9, budget_s), (
            f'sim time stuck at {self.simulation.time} s, wanted {seconds} s')

    def collect(self, message_type: type, topic: str, qos: Any = 10) -> list:
        """Subscribe the probe to ``topic``; return the list messages are appended to."""
        received: list = []
        self.probe.create_subscription(message_type, topic, received.append, qos)
        return received

    def wait_for_subscribers(self, topic: str, count: int = 1) -> None:
        """Spin until the node sees ``count`` subscribers on ``topic``."""
        assert self.spin_until(lambda: self.node.count_subscribers(topic) >= count), (
            f'no subscriber discovered on {topic}')

    def command_position(self, controller: str, value: float) -> float:
        """Publish one Float64 command to a position controller; return when it took effect.

        Waits until the controller's setpoint moves, and returns the sim time then
        (the command landed at most one batch of steps earlier).
        """
        topic = self.node.topic(controller, 'command')
        publisher = self.probe.create_publisher(Float64, topic, 10)
        assert self.spin_until(lambda: publisher.get_subscription_count() > 0), (
            f'sim_node does not subscribe {topic}')
        taken = self.simulation.controller(controller)
        before = taken.setpoint
        publisher.publish(Float64(data=value))
        assert self.spin_until(lambda: taken.setpoint != before), (
            f'command {value} on {topic} never moved the setpoint')
        return self.simulation.time

    def set_parameters(self, **values: Any) -> list:
        """Set sim_node parameters through its set_parameters service; return the results."""
        client = AsyncParameterClient(self.probe, self.node.get_name())
        assert self.spin_until(client.services_are_ready), 'parameter services not ready'
        future = client.set_parameters([Parameter(name, value=value)
                                        for name, value in values.items()])
        assert self.spin_until(future.done), 'set_parameters did not answer'
        return list(future.result().results)


@contextlib.contextmanager
def sim_node(**overrides: Any) -> Iterator[SimHarness]:
    """Run a SimNode (real_time_factor 0 unless given) with ``overrides`` as parameters."""
    overrides.setdefault('real_time_factor', 0.0)
    harness = NodeHarness()
    try:
        node = harness.add(SimNode(context=harness.context, parameter_overrides=[
            Parameter(name, value=value) for name, value in overrides.items()]))
        yield SimHarness(harness, node)
    finally:
        harness.close()
