"""The executor sim_node spins on: rclpy's SingleThreadedExecutor, or the EventsExecutor.

rclpy's Python executors rebuild a wait set of every entity on each wake-up:
~0.35 ms of CPU for sim_node with its parameter services and QoS event
handlers, cache misses included.  sim_node therefore wakes only every 20 ms
at real_time_factor 1 (see sim_node.TICK_PERIOD_S), which keeps it under 5 %
of a core.  rclpy's C++ EventsExecutor (``rclpy.experimental``, in Jazzy's
rclpy since 7.1) costs ~0.05 ms per wake-up, but it is experimental: in our
signal tests it aborted the process (SIGABRT) now and then, even with the
shut-down order :func:`spin` uses.  So it is opt-in:
``PAN_TILT_SIM_EXECUTOR=events`` selects it where rclpy has it.
"""

from __future__ import annotations

import os
from collections.abc import Callable

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
    """Return a SingleThreadedExecutor, or an EventsExecutor if asked for and available."""
    if os.environ.get(EXECUTOR_VARIABLE, SINGLE_THREADED) == EVENTS:
        try:
            from rclpy.experimental import EventsExecutor
        except ImportError:
            pass
        else:
            return EventsExecutor(context=context)
    return SingleThreadedExecutor(context=context)


def spin(node: Node, on_ready: Callable[[], None] | None = None) -> None:
    """Spin ``node`` on :func:`make_executor`'s executor until its context shuts down.

    The nodes in ``node.companion_nodes`` (sim_node's controller_manager), if
    any, spin on the same executor.

    ``on_ready`` is called once the executor exists, just before spinning
    starts: a signal that shuts the context down while the executor is being
    built leaves a half-built executor whose ``__del__`` prints a traceback,
    so "running" is announced only after that window.  A shut-down during the
    build ends the spin like any other.  Ctrl-C raises KeyboardInterrupt as
    usual.  The executor is shut down and released here, before the caller
    destroys the node (an EventsExecutor destroyed after the node's timers
    and subscriptions aborted the process).
    """
    try:
        executor = make_executor(node.context)
    except Exception:
        if node.context.ok():
            raise
        return  # a signal shut the context down while the executor was built
    nodes = [node, *getattr(node, 'companion_nodes', ())]
    for each in nodes:
        executor.add_node(each)
    try:
        if on_ready is not None:
            on_ready()
        while node.context.ok():
            executor.spin_once(timeout_sec=SPIN_SLICE_S)
    except ExternalShutdownException:
        pass  # the context shut down while waiting: the normal end
    finally:
        for each in nodes:
            executor.remove_node(each)
        executor.shutdown()
        # Also when an exception propagates: its traceback keeps this frame,
        # and so the executor, alive until after the node is destroyed.
        del executor
