"""The executor sim_node spins on: rclpy's C++ EventsExecutor where rclpy has it.

rclpy's Python executors rebuild a wait set of every entity on each wake-up:
~0.2 ms of CPU for an idle node, ~0.35 ms for sim_node with its parameter
services and QoS event handlers, cache misses included.  At
real_time_factor 1 the node wakes 100 times a second, so that alone was
~3.5 % of a core.  The EventsExecutor (``rclpy.experimental``, in Jazzy's
rclpy since 7.1) reacts to events instead and costs ~0.05 ms per wake-up.

Set ``PAN_TILT_SIM_EXECUTOR=single_threaded`` to use rclpy's
SingleThreadedExecutor instead (as where the EventsExecutor is missing).
"""

from __future__ import annotations

import os

from rclpy.context import Context
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node

EXECUTOR_VARIABLE = 'PAN_TILT_SIM_EXECUTOR'
EVENTS = 'events'
SINGLE_THREADED = 'single_threaded'
# The EventsExecutor waits in C++, where Python's SIGINT handler cannot run:
# spin in slices this long so that Ctrl-C is seen (its own spin() and
# rclpy.spin() would not stop, or would busy-loop).
SPIN_SLICE_S = 0.1


def make_executor(context: Context | None = None) -> Executor:
    """Return an EventsExecutor where rclpy has one and not told otherwise, else a plain one."""
    if os.environ.get(EXECUTOR_VARIABLE, EVENTS) != SINGLE_THREADED:
        try:
            from rclpy.experimental import EventsExecutor
        except ImportError:
            pass
        else:
            return EventsExecutor(context=context)
    return SingleThreadedExecutor(context=context)


def spin(node: Node) -> None:
    """Spin ``node`` on :func:`make_executor`'s executor until its context shuts down.

    Ctrl-C raises KeyboardInterrupt as usual.  The executor is shut down and
    released here, before the caller destroys the node: an EventsExecutor
    destroyed after the node's timers and subscriptions aborted the process
    (SIGABRT at exit, in 6 of 16 runs of test_signals' "SIGINT started
    ignored" case; 0 of 200 runs of test_signals with this order).
    """
    executor = make_executor(node.context)
    executor.add_node(node)
    try:
        while node.context.ok():
            executor.spin_once(timeout_sec=SPIN_SLICE_S)
    except ExternalShutdownException:
        pass  # the context shut down while waiting: the normal end
    finally:
        executor.remove_node(node)
        executor.shutdown()
        # Also when an exception propagates: its traceback keeps this frame,
        # and so the executor, alive until after the node is destroyed.
        del executor
