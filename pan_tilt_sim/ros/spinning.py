"""Spinning sim_node until its context shuts down.

The program spins sim_node on a :class:`~pan_tilt_sim.ros.physics_thread.TurnTakingExecutor`
(the physics runs in its own paced thread; see :mod:`pan_tilt_sim.ros.physics_thread`);
:func:`spin` takes the executor to use, rclpy's SingleThreadedExecutor by default.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext

from rclpy.context import Context
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node

ExecutorFactory = Callable[[Context], Executor]


def single_threaded(context: Context) -> Executor:
    """Return rclpy's SingleThreadedExecutor on ``context``."""
    return SingleThreadedExecutor(context=context)


def spin(node: Node, on_ready: Callable[[], None] | None = None,
         make_executor: ExecutorFactory = single_threaded, *,
         interrupts: AbstractContextManager | None = None) -> None:
    """Spin ``node`` on ``make_executor(node.context)`` until its context shuts down.

    The nodes in ``node.companion_nodes`` (sim_node's controller_manager), if
    any, spin on the same executor.

    ``on_ready`` is called once the executor exists, just before spinning
    starts: a signal that shuts the context down while the executor is being
    built leaves a half-built executor whose ``__del__`` prints a traceback,
    so "running" is announced only after that window.  A shut-down during the
    build ends the spin like any other.  Ctrl-C raises KeyboardInterrupt as
    usual.  The executor is shut down and released here, before the caller
    destroys the node.

    ``interrupts`` (the program's
    :func:`~pan_tilt_sim.ros.runner.interruptible_spin`) is entered around
    the loop alone, so that a stop signal raises there.  Relying on
    the context's shutdown is not enough: rclpy's signal thread wakes the
    executor first and shuts the context down after, without waking it, so
    an executor that woke in between and saw the context still up went back
    to waiting with no timeout, and for good.
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
        with interrupts if interrupts is not None else nullcontext():
            while node.context.ok():
                # No timeout: the executor sleeps until there is work.  rclpy
                # wakes it when SIGINT/SIGTERM arrives (its handler runs ours
                # too, which raises in ``interrupts``) and when Python shuts the
                # context down.  No wake-ups "just in case": each one rebuilds
                # the executor's wait set over every service, in Python.
                executor.spin_once()
    except ExternalShutdownException:
        pass  # the context shut down while waiting: the normal end
    finally:
        for each in nodes:
            executor.remove_node(each)
        executor.shutdown()
        # Also when an exception propagates: its traceback keeps this frame,
        # and so the executor, alive until after the node is destroyed.
        del executor
