"""The physics in a paced thread of its own, taking turns with the executor's callbacks.

Each wake-up of rclpy's Python executor rebuilds its wait set of every
subscription, service and timer, so waking it 50 times a second only to step
the physics would cost more than the physics at real_time_factor 1, and more
with every service added.  So the sim_node
program steps the physics from a :class:`PhysicsThread`, which sleeps
between ticks, and the executor wakes only for messages, services and
parameters (the command topics have a reader of their own:
:mod:`pan_tilt_sim.ros.command_reader`).

Design notes: docs/design/ros.md#physics_threadpy.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING

from rclpy.context import Context
from rclpy.executors import (
    ConditionReachedException,
    ShutdownException,
    SingleThreadedExecutor,
    TimeoutException,
)

if TYPE_CHECKING:
    from rclpy.executors import TimeoutObject
    from rclpy.task import Future, Task

JOIN_TIMEOUT_S = 5.0
# Wall seconds of callbacks one turn may run when more are ready, before the physics
# gets its batch: about one batch at real_time_factor 0 (pacing.FAST_TICK_S), so under
# a flood of requests the two share the time, and a request waits for at most one batch.
CALLBACK_TURN_S = 0.005


class Turns:
    """A lock the physics and the callbacks take in turns; waiting callbacks go first."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._condition = threading.Condition()
        self._callbacks_waiting = 0
        self._on_failure: list[Callable[[], None]] = []
        self.failure: BaseException | None = None

    def on_failure(self, wake: Callable[[], None]) -> None:
        """Have ``wake()`` called (from the physics thread) when the physics fails."""
        self._on_failure.append(wake)

    def fail(self, error: BaseException) -> None:
        """Record why the physics stopped and wake whoever waits to hear of it."""
        self.failure = error
        for wake in self._on_failure:
            wake()

    @contextlib.contextmanager
    def callback(self) -> Iterator[None]:
        """Hold the simulation for one executor callback."""
        with self._condition:
            self._callbacks_waiting += 1
        try:
            # A stop signal can end this wait with StopRequested (in the main
            # thread): the physics must not wait for this callback then.
            self._lock.acquire()
        finally:
            with self._condition:
                self._callbacks_waiting -= 1
                self._condition.notify_all()
        try:
            yield
        finally:
            self._lock.release()

    @contextlib.contextmanager
    def physics(self) -> Iterator[None]:
        """Hold the simulation for one batch of steps, once no callback is waiting."""
        # Read without the condition first (nearly always 0): a callback that
        # registers just after waits for this batch, as it would a moment later.
        if self._callbacks_waiting:
            with self._condition:
                self._condition.wait_for(lambda: self._callbacks_waiting == 0)
        self._lock.acquire()
        try:
            yield
        finally:
            self._lock.release()


class TurnTakingExecutor(SingleThreadedExecutor):
    """rclpy's SingleThreadedExecutor, running each callback in its turn (see :class:`Turns`).

    Whichever way it is spun -- ``spin``, ``spin_once``, ``spin_until_future_complete``,
    ``spin_once_until_future_complete``, or rclpy's functions of those names
    -- no callback runs during a batch of steps.
    """

    def __init__(self, turns: Turns, *, context: Context | None = None) -> None:
        super().__init__(context=context)
        self._turns = turns
        turns.on_failure(self._wake_for_failure)

    def _physics_failed(self) -> bool:
        return self._turns.failure is not None

    def _wake_for_failure(self) -> None:
        # Shut down meanwhile (its guard condition destroyed): nobody is left to tell.
        with contextlib.suppress(RuntimeError):
            self.wake()

    def spin_once(self, timeout_sec: float | None = None) -> None:
        """Wait for a ready callback (without holding the turn), then run it in its turn.

        Callbacks that are ready by then run in the same turn, up to
        :data:`CALLBACK_TURN_S` of wall time: a queue of requests is served
        between two batches of steps, not one request per batch.
        """
        self._take_turn(timeout_sec, self._physics_failed)

    def spin_once_until_future_complete(
            self, future: Future, timeout_sec: float | TimeoutObject | None = None) -> None:
        """As :meth:`spin_once`, but the wait also ends when ``future`` is done.

        rclpy's ``spin_until_future_complete`` (the executor's and
        ``rclpy.spin_until_future_complete``) loops over this method, and
        ``spin`` over :meth:`spin_once`: every way to spin this executor runs
        its callbacks in their turn.
        """
        future.add_done_callback(lambda _future: self.wake())
        self._take_turn(timeout_sec, lambda: self._physics_failed() or future.done())

    def _take_turn(self, timeout_sec: float | TimeoutObject | None,
                   condition: Callable[[], bool]) -> None:
        """Run the next ready callback, and those ready with it, in one turn."""
        handler = self._next_ready(timeout_sec, condition)
        if handler is None:
            return
        with self._turns.callback():
            deadline = time.perf_counter() + CALLBACK_TURN_S
            while handler is not None:
                handler()
                if handler.exception() is not None:
                    raise handler.exception()
                handler.result()
                handler = (self._next_ready(0.0, condition) if time.perf_counter() < deadline
                           else None)

    def _next_ready(self, timeout_sec: float | TimeoutObject | None,
                    condition: Callable[[], bool]) -> Task | None:
        """Return the next ready callback, waiting up to ``timeout_sec``.

        None when none came in time or ``condition()`` ended the wait; the
        physics' failure, if it failed, is raised instead.
        """
        if self._turns.failure is not None:
            raise self._turns.failure
        try:
            handler, _entity, _node = self.wait_for_ready_callbacks(
                timeout_sec, condition=condition)
        except (ShutdownException, TimeoutException):
            return None
        except ConditionReachedException:  # the physics failed, or the future is done
            if self._turns.failure is not None:
                raise self._turns.failure from None
            return None
        return handler


class Wakeup:
    """A wake-up call one thread makes and another waits for, with a timeout.

    As :class:`threading.Event` set/wait/clear, but a wait is one lock
    acquisition: Event's runs a Condition in Python and makes a lock per call,
    Python work the paced thread would do twice per tick with cold caches.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._lock.acquire()  # held while nobody has called: a wait blocks

    def set(self) -> None:
        """Wake the present wait, or the next one."""
        with contextlib.suppress(RuntimeError):  # already set
            self._lock.release()

    def wait(self, seconds: float | None) -> bool:
        """Wait up to ``seconds`` (None: without end); return whether set() was called."""
        return self._lock.acquire(timeout=-1 if seconds is None else max(seconds, 0.0))


class PhysicsThread:
    """Calls ``tick()`` in its turn, then waits ``period()`` s: 0 = at once, None = until woken.

    ``wake()`` cuts a wait short (the pace or the pause state changed); the
    next tick then starts a fresh schedule.  Ticks are scheduled on a fixed
    grid of wall time, so sleeping does not make the period drift.
    """

    def __init__(self, tick: Callable[[], None], period: Callable[[], float | None],
                 turns: Turns, name: str = 'physics') -> None:
        self._tick = tick
        self._period = period
        self._turns = turns
        self._wake = Wakeup()
        self._stopping = False
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    def start(self) -> None:
        """Start ticking."""
        self._thread.start()

    def wake(self) -> None:
        """End the present wait now (the pace or the pause state changed)."""
        self._wake.set()

    def stop(self) -> None:
        """Stop after the batch in progress and wait for the thread to end."""
        self._stopping = True
        self._wake.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(JOIN_TIMEOUT_S)

    @property
    def alive(self) -> bool:
        """Whether the thread is running."""
        return self._thread.is_alive()

    def _run(self) -> None:
        try:
            self._loop()
        except BaseException as error:  # handed to the executor, which raises it
            self._turns.fail(error)

    def _loop(self) -> None:
        next_tick = time.monotonic()
        while not self._stopping:
            with self._turns.physics():
                if self._stopping:
                    return
                self._tick()
            period = self._period()
            if period is None:
                self._wait(None)
                next_tick = time.monotonic()
                continue
            next_tick += period
            now = time.monotonic()
            if next_tick < now - period:  # far behind (a stall): restart the grid
                next_tick = now
            if next_tick > now and self._wait(next_tick - now):
                next_tick = time.monotonic()

    def _wait(self, seconds: float | None) -> bool:
        """Wait ``seconds`` (None: until woken); return whether ``wake()`` ended it."""
        return self._wake.wait(seconds)
