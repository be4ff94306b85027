"""In-process harness for node tests: the node under test and a probe on one executor.

Waiting is always bounded: :meth:`NodeHarness.spin_until` spins the shared
executor until a condition holds or a wall-clock budget runs out, and
reports which.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import QoSHistoryPolicy, QoSProfile

SPIN_SLICE_S = 0.05
DEFAULT_BUDGET_S = 30.0
# Deep queues: at real_time_factor 0 the node publishes faster than one
# executor iteration takes a message, so the probe must be able to lag.
PROBE_QUEUE = QoSProfile(depth=20000, history=QoSHistoryPolicy.KEEP_LAST)


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
        """Spin ``node`` on the shared executor; it is destroyed with the harness."""
        self.executor.add_node(node)
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

    def close(self) -> None:
        """Destroy every node and shut the context down."""
        for node in reversed(self._nodes):
            self.executor.remove_node(node)
            node.destroy_node()
        self.executor.shutdown()
        rclpy.try_shutdown(context=self.context)
