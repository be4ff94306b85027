"""The executor sim_node spins on, and spinning until shutdown."""

import time

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor

from pan_tilt_sim.ros import spinning

SPIN_BUDGET_S = 10.0


def test_the_single_threaded_executor_is_the_default(context, monkeypatch):
    monkeypatch.delenv(spinning.EXECUTOR_VARIABLE, raising=False)
    executor = spinning.make_executor(context)
    try:
        assert isinstance(executor, SingleThreadedExecutor)
    finally:
        executor.shutdown()


def test_the_environment_can_ask_for_the_events_executor(context, monkeypatch):
    pytest.importorskip('rclpy.experimental')
    monkeypatch.setenv(spinning.EXECUTOR_VARIABLE, spinning.EVENTS)
    executor = spinning.make_executor(context)
    try:
        assert not isinstance(executor, SingleThreadedExecutor)
        assert type(executor).__name__ == 'EventsExecutor'
    finally:
        executor.shutdown()


@pytest.mark.parametrize('kind', [spinning.EVENTS, spinning.SINGLE_THREADED])
def test_spin_runs_timers_and_returns_once_the_context_shuts_down(context, monkeypatch, kind):
    monkeypatch.setenv(spinning.EXECUTOR_VARIABLE, kind)
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
