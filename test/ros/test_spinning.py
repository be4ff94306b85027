"""The executor sim_node spins on, and spinning until shutdown."""

import os
import signal
import time

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor

from pan_tilt_sim.ros import spinning
from pan_tilt_sim.ros.runner import StopRequested, StopSignals

SPIN_BUDGET_S = 10.0
STOP_MISSED_S = 3.0  # a spin that misses the stop signal ends only then


def test_spin_runs_timers_and_returns_once_the_context_shuts_down(context):
    node = rclpy.create_node('spinning_test', context=context)
    ticks = []

    def tick():
        ticks.append(time.monotonic())
        if len(ticks) == 5:
            rclpy.try_shutdown(context=context)

    node.create_timer(0.01, tick)
    started = time.monotonic()
    try:
        spinning.spin(node)
    finally:
        node.destroy_node()
    assert len(ticks) == 5
    assert time.monotonic() - started < SPIN_BUDGET_S


def test_spin_uses_the_executor_it_is_given(context):
    node = rclpy.create_node('spinning_test', context=context)
    made = []

    def make(executor_context):
        made.append(SingleThreadedExecutor(context=executor_context))
        return made[-1]

    node.create_timer(0.01, lambda: rclpy.try_shutdown(context=context))
    try:
        spinning.spin(node, make_executor=make)
    finally:
        node.destroy_node()
    assert len(made) == 1


def test_spin_lets_keyboard_interrupt_through(context):
    node = rclpy.create_node('spinning_test', context=context)

    def interrupt():
        raise KeyboardInterrupt

    node.create_timer(0.01, interrupt)
    try:
        with pytest.raises(KeyboardInterrupt):
            spinning.spin(node)
        # The node is free again: another executor can take it.
        executor = SingleThreadedExecutor(context=context)
        assert executor.add_node(node)
        executor.shutdown()
    finally:
        node.destroy_node()


def test_an_idle_spin_sleeps_until_there_is_work(context):
    """No wake-ups "just in case": each one rebuilds the wait set over every service."""
    node = rclpy.create_node('spinning_test', context=context)
    waits = []

    class Counting(SingleThreadedExecutor):
        def spin_once(self, timeout_sec=None):
            waits.append(timeout_sec)
            super().spin_once(timeout_sec)

    node.create_timer(0.5, lambda: rclpy.try_shutdown(context=context))
    try:
        spinning.spin(node, make_executor=lambda spin_context: Counting(context=spin_context))
    finally:
        node.destroy_node()
    assert 1 <= len(waits) <= 2  # the wait that the timer ends, perhaps one more


def test_a_stop_signal_ends_the_spin_though_nobody_shuts_the_context_down(context):
    # As when rclpy's signal thread has woken the executor but not yet shut the
    # context down: the executor must not go back to waiting for good.
    node = rclpy.create_node('spinning_test', context=context)
    node.create_timer(0.01, lambda: os.kill(os.getpid(), signal.SIGINT))
    # Bounds the test if the signal is missed: the spin would then end here, normally.
    node.create_timer(STOP_MISSED_S, lambda: rclpy.try_shutdown(context=context))
    started = time.monotonic()
    try:
        with StopSignals() as stop, pytest.raises(StopRequested):
            spinning.spin(node, interrupts=stop.interruptible())
    finally:
        node.destroy_node()
    assert time.monotonic() - started < STOP_MISSED_S
    assert context.ok()  # nothing shut it down: the signal alone ended the spin


def test_a_stop_signal_before_the_loop_ends_the_spin_at_once(context):
    node = rclpy.create_node('spinning_test', context=context)
    node.create_timer(STOP_MISSED_S, lambda: rclpy.try_shutdown(context=context))
    try:
        with StopSignals() as stop, pytest.raises(StopRequested):
            spinning.spin(node, on_ready=lambda: os.kill(os.getpid(), signal.SIGINT),
                          interrupts=stop.interruptible())
    finally:
        node.destroy_node()
    assert context.ok()
