"""The physics in a thread of its own, taking turns with the executor's callbacks."""

import os
import signal
import threading
import time

import pytest
import rclpy
from rclpy.executors import Executor
from rclpy.parameter import Parameter
from rclpy.task import Future
from std_msgs.msg import Float64
from waiting import BUDGET_S, wait_for

from pan_tilt_sim.ros import command_reader, physics_thread
from pan_tilt_sim.ros.command_reader import ReaderGroup
from pan_tilt_sim.ros.physics_thread import PhysicsThread, Turns, TurnTakingExecutor, Wakeup
from pan_tilt_sim.ros.runner import StopRequested, StopSignals
from pan_tilt_sim.ros.sim_node import SimNode

# --- Turns and the thread, without ROS -------------------------------------------------

def test_a_wakeup_is_a_flag_a_wait_takes_down_or_times_out_without():
    wakeup = Wakeup()
    assert wakeup.wait(0.0) is False
    wakeup.set()
    wakeup.set()  # a flag, not a count
    assert wakeup.wait(BUDGET_S) is True
    started = time.monotonic()
    assert wakeup.wait(0.05) is False
    assert time.monotonic() - started >= 0.05


def test_a_wakeup_ends_a_wait_without_end_from_another_thread():
    wakeup, woken = Wakeup(), []
    waiter = threading.Thread(target=lambda: woken.append(wakeup.wait(None)), daemon=True)
    waiter.start()
    waiter.join(0.05)
    assert waiter.is_alive() and woken == []  # still waiting
    wakeup.set()
    waiter.join(BUDGET_S)
    assert woken == [True]


def test_a_waiting_callback_goes_before_the_next_batch():
    turns, order = Turns(), []
    in_batch = threading.Event()

    def tick():
        order.append('batch')
        in_batch.set()
        time.sleep(0.02)  # a batch of steps in progress

    thread = PhysicsThread(tick, lambda: 0.0, turns)
    thread.start()
    try:
        assert in_batch.wait(BUDGET_S)
        with turns.callback():  # waits for the batch in progress, not for more
            order.append('callback')
        assert wait_for(lambda: order.count('batch') >= 3)
    finally:
        thread.stop()
    assert order.index('callback') <= 2


def test_a_callback_stopped_while_it_waits_for_its_turn_does_not_hold_up_the_physics():
    # A stop signal ends the main thread's wait for its turn with StopRequested;
    # the physics thread must still get its next turns (and so stop when asked).
    turns, batches = Turns(), []
    in_batch, release = threading.Event(), threading.Event()

    def tick():
        batches.append(time.monotonic())
        in_batch.set()
        release.wait(BUDGET_S)  # the first batch holds the turn until released

    def signal_the_waiting_callback():
        if wait_for(lambda: turns._callbacks_waiting == 1):
            os.kill(os.getpid(), signal.SIGINT)  # handled in the main thread, as in the program

    thread = PhysicsThread(tick, lambda: 0.0, turns)
    thread.start()
    try:
        assert in_batch.wait(BUDGET_S)
        threading.Thread(target=signal_the_waiting_callback, daemon=True).start()
        with StopSignals() as stop, stop.interruptible(), pytest.raises(StopRequested):
            with turns.callback():
                pytest.fail('the callback ran: its wait was not cut short')
        release.set()  # the batch in progress ends only now
        count = len(batches)
        assert wait_for(lambda: len(batches) > count + 3, budget_s=2.0), \
            'the physics waits for a callback that will never come'
    finally:
        release.set()
        thread.stop()
    assert not thread.alive


def test_ticks_keep_their_period_and_a_paused_thread_waits_until_woken():
    ticks, period = [], [0.02]
    thread = PhysicsThread(lambda: ticks.append(time.monotonic()), lambda: period[0], Turns())
    thread.start()
    try:
        assert wait_for(lambda: len(ticks) >= 26)
        gaps = [b - a for a, b in zip(ticks[1:26], ticks[2:26], strict=False)]
        period[0] = None  # paused
        thread.wake()
        time.sleep(0.1)
        held = len(ticks)
        time.sleep(0.2)
        assert len(ticks) == held  # no tick while paused
        period[0] = 0.02
        thread.wake()
        assert wait_for(lambda: len(ticks) > held)
    finally:
        thread.stop()
    assert 0.018 < sum(gaps) / len(gaps) < 0.022  # the grid does not drift
    assert not thread.alive


def test_a_failing_tick_makes_the_executor_raise_it(context):
    turns = Turns()

    def tick():
        raise RuntimeError('the physics broke')

    thread = PhysicsThread(tick, lambda: 0.0, turns)
    executor = TurnTakingExecutor(turns, context=context)
    thread.start()
    try:
        assert wait_for(lambda: not thread.alive)
        with pytest.raises(RuntimeError, match='the physics broke'):
            executor.spin_once(timeout_sec=0.01)
    finally:
        executor.shutdown()


def test_a_failing_tick_wakes_an_executor_that_waits_without_a_timeout(context):
    """sim_node's executor waits with no timeout, so the physics thread must wake it."""
    turns, waiting, raised = Turns(), threading.Event(), []

    class Observed(TurnTakingExecutor):
        def wait_for_ready_callbacks(self, *args, **kwargs):
            waiting.set()
            return super().wait_for_ready_callbacks(*args, **kwargs)

    def tick():
        assert waiting.wait(BUDGET_S)
        raise RuntimeError('the physics broke')

    def spin():
        try:
            executor.spin_once()  # nothing else will ever end this wait
        except RuntimeError as error:
            raised.append(error)

    executor = Observed(turns, context=context)
    spinner = threading.Thread(target=spin, daemon=True)
    thread = PhysicsThread(tick, lambda: 0.0, turns)
    spinner.start()
    thread.start()
    try:
        spinner.join(BUDGET_S)
        assert not spinner.is_alive(), 'the executor slept through the failure'
        assert [str(error) for error in raised] == ['the physics broke']
    finally:
        thread.stop()
        executor.shutdown()


def test_callbacks_ready_together_are_served_in_one_turn_not_one_per_batch(
        context, monkeypatch):
    # The per-turn cap is lifted so that a loaded machine's slower callbacks
    # cannot split the turn.  Guard conditions are ready the moment they are
    # triggered, so what is measured is the executor's turn-taking, not the
    # middleware's delivery.
    monkeypatch.setattr(physics_thread, 'CALLBACK_TURN_S', BUDGET_S)
    turns_taken, served = [], []

    class CountedTurns(Turns):
        def callback(self):
            turns_taken.append(1)
            return super().callback()

    turns = CountedTurns()
    node = rclpy.create_node('server', context=context)
    guards = [node.create_guard_condition(lambda: served.append(1)) for _ in range(30)]
    executor = TurnTakingExecutor(turns, context=context)
    executor.add_node(node)
    thread = PhysicsThread(lambda: time.sleep(0.02), lambda: 0.0, turns)
    try:
        for guard in guards:
            guard.trigger()
        thread.start()
        deadline = time.monotonic() + BUDGET_S
        while len(served) < len(guards) and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.05)
    finally:
        thread.stop()
        executor.shutdown()
        node.destroy_node()
    assert len(served) == len(guards)
    assert len(turns_taken) == 1, f'{len(served)} callbacks took {len(turns_taken)} turns'


class FinishedError(Exception):
    """Raised by the test's callback: it ends every way of spinning, spin() included."""


SPIN_PATHS = {
    'spin': lambda executor, node, future: executor.spin(),
    'spin_once': lambda executor, node, future: executor.spin_once(),
    'spin_until_future_complete': lambda executor, node, future: (
        executor.spin_until_future_complete(future)),
    'spin_until_future_complete with a timeout': lambda executor, node, future: (
        executor.spin_until_future_complete(future, timeout_sec=BUDGET_S)),
    'spin_once_until_future_complete': lambda executor, node, future: (
        executor.spin_once_until_future_complete(future, timeout_sec=BUDGET_S)),
    'rclpy.spin': lambda executor, node, future: rclpy.spin(node, executor=executor),
    'rclpy.spin_once': lambda executor, node, future: rclpy.spin_once(node, executor=executor),
    'rclpy.spin_until_future_complete': lambda executor, node, future: (
        rclpy.spin_until_future_complete(node, future, executor=executor)),
}


def test_every_way_rclpy_offers_to_spin_an_executor_is_checked_below():
    # A way to spin that rclpy adds may bypass spin_once and run callbacks out of turn.
    spin_methods = {name for name in dir(Executor) if name.startswith('spin')}
    checked = {name for name in SPIN_PATHS if not name.startswith('rclpy.')}
    assert spin_methods <= checked, (
        f'rclpy has ways to spin an executor not known to take turns: '
        f'{sorted(spin_methods - checked)}')


@pytest.mark.parametrize('way', SPIN_PATHS)
def test_every_way_to_spin_runs_a_callback_only_in_its_turn(context, way):
    turns, ran, finished = Turns(), [], []
    node = rclpy.create_node('turn_taker', context=context)
    executor = TurnTakingExecutor(turns, context=context)
    future = Future(executor=executor)

    def on_trigger():
        ran.append(threading.current_thread().name)
        raise FinishedError

    node.create_guard_condition(on_trigger).trigger()
    executor.add_node(node)

    def spin():
        try:
            SPIN_PATHS[way](executor, node, future)
        except FinishedError:
            finished.append(way)

    spinner = threading.Thread(target=spin, name='spinner', daemon=True)
    try:
        with turns.physics():  # a batch of steps in progress
            spinner.start()
            assert wait_for(lambda: turns._callbacks_waiting == 1), 'it did not wait its turn'
            assert ran == []
        spinner.join(BUDGET_S)
        assert not spinner.is_alive() and ran == ['spinner'] and finished == [way]
    finally:
        executor.shutdown()
        node.destroy_node()


def test_spin_until_future_complete_returns_when_another_thread_completes_the_future(context):
    # A future of no executor's calls its done callbacks (the wake-up) in the thread that
    # completes it; nothing else ends the executor's wait, which has no timeout.
    executor = TurnTakingExecutor(Turns(), context=context)
    future, returned = Future(), threading.Event()

    def spin():
        executor.spin_until_future_complete(future)
        returned.set()

    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    try:
        assert not returned.wait(0.05)
        future.set_result('done')
        assert returned.wait(BUDGET_S), 'the executor slept through the completed future'
    finally:
        if returned.is_set():
            executor.shutdown()


def test_spin_until_future_complete_raises_the_physics_failure(context):
    turns, waiting = Turns(), threading.Event()

    class Observed(TurnTakingExecutor):
        def wait_for_ready_callbacks(self, *args, **kwargs):
            waiting.set()
            return super().wait_for_ready_callbacks(*args, **kwargs)

    def tick():
        assert waiting.wait(BUDGET_S)
        raise RuntimeError('the physics broke')

    executor = Observed(turns, context=context)
    thread = PhysicsThread(tick, lambda: 0.0, turns)
    thread.start()
    try:
        with pytest.raises(RuntimeError, match='the physics broke'):
            executor.spin_until_future_complete(Future(executor=executor), timeout_sec=BUDGET_S)
    finally:
        thread.stop()
        executor.shutdown()


# --- sim_node with its physics thread -------------------------------------------------

@pytest.fixture
def threaded(context):
    """A SimNode stepping in its own thread, spun by a TurnTakingExecutor in another."""
    node = SimNode(physics_thread=True, context=context,
                   parameter_overrides=[Parameter('real_time_factor', value=1.0)])
    probe = rclpy.create_node('probe', context=context)
    executor = TurnTakingExecutor(node.turns, context=context)
    executor.add_node(node)
    executor.add_node(probe)
    stop = threading.Event()

    def spin() -> None:
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.05)

    # Stopped by its own loop, not by executor.shutdown() from here: rclpy's
    # shutdown drops the guard condition a wait in the spinning thread may be using.
    spinning = threading.Thread(target=spin, daemon=True)
    spinning.start()
    yield node, probe
    stop.set()
    spinning.join(BUDGET_S)
    assert not spinning.is_alive(), 'the spinning thread did not stop'
    executor.shutdown()
    probe.destroy_node()
    node.destroy_node()


def test_with_its_thread_sim_time_follows_wall_time_and_commands_arrive(threaded):
    node, probe = threaded
    assert wait_for(lambda: node.simulation.time > 0.1)
    sim_start, wall_start = node.simulation.time, time.monotonic()
    time.sleep(1.5)
    factor = (node.simulation.time - sim_start) / (time.monotonic() - wall_start)
    assert factor == pytest.approx(1.0, rel=0.2)
    publisher = probe.create_publisher(
        Float64, '/ex_urdf_pan_tilt/joint1_position_controller/command', 10)
    assert wait_for(lambda: publisher.get_subscription_count() > 0)
    publisher.publish(Float64(data=0.5))
    controller = node.simulation.controller('joint1_position_controller')
    assert wait_for(lambda: node.commands_received['joint1_position_controller'] > 0)
    assert wait_for(lambda: controller.setpoints()['pan_joint'] > 0.0)


def test_with_its_thread_a_paused_node_holds_and_destroying_it_stops_the_thread(threaded):
    node, _ = threaded
    assert wait_for(lambda: node.simulation.time > 0.05)
    with node.turns.callback():
        node.set_paused(True)
    held = node.simulation.time
    time.sleep(0.2)
    assert node.simulation.time == held
    thread = node._physics_thread
    node.destroy_node()
    assert not thread.alive


def test_with_its_thread_commands_come_by_their_own_reader_also_after_a_reconfigure(threaded):
    node, probe = threaded
    name = 'joint1_position_controller'
    publisher = probe.create_publisher(Float64, f'/ex_urdf_pan_tilt/{name}/command', 10)
    assert wait_for(lambda: publisher.get_subscription_count() > 0)
    commands = [s for s in node.subscriptions if s.topic_name.endswith('/command')]
    assert commands and all(isinstance(s.callback_group, ReaderGroup) for s in commands)
    with node.turns.callback():  # as controller_manager's services do it
        node.controllers.switch([], [name], strict=True)
        node.controllers.cleanup(name)
    assert wait_for(lambda: publisher.get_subscription_count() == 0)
    with node.turns.callback():
        node.controllers.configure(name)
        node.controllers.switch([name], [], strict=True)
    assert wait_for(lambda: publisher.get_subscription_count() > 0)
    controller = node.simulation.controller(name)
    publisher.publish(Float64(data=0.4))
    assert wait_for(lambda: controller.setpoints()['pan_joint'] > 0.0)
    assert node.commands_received[name] == 1


@pytest.fixture
def without_private_wait_set(monkeypatch):
    """An rclpy whose private wait set is not the one the command reader knows."""
    monkeypatch.setattr(command_reader, '_rclpy', None)


def test_without_rclpys_private_wait_set_the_executor_reads_commands_in_their_turn(
        without_private_wait_set, threaded):
    node, probe = threaded
    name = 'joint1_position_controller'
    commands = [s for s in node.subscriptions if s.topic_name.endswith('/command')]
    assert commands and not any(isinstance(s.callback_group, ReaderGroup) for s in commands)
    in_turn = []
    for subscription in commands:
        callback = subscription.callback
        subscription.callback = lambda message, callback=callback: (
            in_turn.append(node.turns._lock.locked()), callback(message))
    publisher = probe.create_publisher(Float64, f'/ex_urdf_pan_tilt/{name}/command', 10)
    assert wait_for(lambda: publisher.get_subscription_count() > 0)
    publisher.publish(Float64(data=0.4))
    controller = node.simulation.controller(name)
    assert wait_for(lambda: controller.setpoints()['pan_joint'] > 0.0)
    assert node.commands_received[name] == 1 and in_turn == [True]
