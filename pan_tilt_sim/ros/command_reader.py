"""Command topics read by a thread of their own, not by rclpy's executor.

Each time rclpy's Python executor wakes it rebuilds its wait set, in
Python, over every entity of sim_node and its controller_manager (all their
services, parameter services included), so a command stream that woke it
for every message would cost CPU in proportion to the message rate.
Commands are the one thing that arrives that often, so in the
sim_node program (the physics in its own thread, see
:mod:`pan_tilt_sim.ros.physics_thread`) a :class:`CommandReader` waits on
the command subscriptions alone, takes every message that arrived, and runs
their callbacks in their turn -- between two batches of steps, as the
executor would have run them.

Design notes: docs/design/ros.md#command_readerpy.
"""

from __future__ import annotations

import contextlib
import threading
from typing import Any

from rclpy.callback_groups import CallbackGroup
from rclpy.context import Context
from rclpy.exceptions import InvalidHandle
from rclpy.guard_condition import GuardCondition
from rclpy.subscription import Subscription

try:
    from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
except ImportError:  # moved or gone: available() says no
    _rclpy = None

from pan_tilt_sim.ros.physics_thread import JOIN_TIMEOUT_S, Turns

WAIT_FOREVER = -1  # ns, for the wait set
DONT_WAIT = 0  # ns
# What wait_and_take uses of rclpy's private subscription handle.
_HANDLE_API = ('take_message', 'pointer')


def wait_and_take(subscriptions: list[Subscription], guard: GuardCondition, context: Context,
                  timeout_ns: int = WAIT_FOREVER) -> list[tuple[Subscription, Any]]:
    """Wait for a message on ``subscriptions`` or a trigger of ``guard``; take every message.

    Returns (subscription, message) pairs, in the order of ``subscriptions``
    and, for each, of arrival; subscriptions destroyed meanwhile are skipped.
    ``timeout_ns`` < 0 waits without end.  Built on rclpy's private API
    (see the module's design notes): AttributeError or TypeError where rclpy
    changed it.
    """
    with contextlib.ExitStack() as held:
        usable = []
        for subscription in subscriptions:
            try:
                held.enter_context(subscription.handle)
            except InvalidHandle:  # destroyed meanwhile
                continue
            usable.append(subscription)
        held.enter_context(guard.handle)
        wait_set = _rclpy.WaitSet(len(usable), 1, 0, 0, 0, 0, context.handle)
        wait_set.clear_entities()
        for subscription in usable:
            wait_set.add_subscription(subscription.handle)
        wait_set.add_guard_condition(guard.handle)
        wait_set.wait(timeout_ns)
        ready = wait_set.get_ready_entities('subscription')
        taken = []
        for subscription in usable:
            if subscription.handle.pointer not in ready:
                continue
            while (message := subscription.handle.take_message(
                    subscription.msg_type, subscription.raw)) is not None:
                taken.append((subscription, message[0]))
        return taken


def available(context: Context) -> bool:
    """Whether :func:`wait_and_take` works with the rclpy installed.

    It waits for a guard condition triggered beforehand, which must end the
    wait at once, and checks that subscription handles have what it uses.
    """
    guard = GuardCondition(None, None, context=context)
    try:
        guard.trigger()
        taken = wait_and_take([], guard, context, DONT_WAIT)
        subscription_type = getattr(_rclpy, 'Subscription', None)
        return taken == [] and all(hasattr(subscription_type, name) for name in _HANDLE_API)
    except (AttributeError, TypeError):
        return False
    finally:
        guard.destroy()


class ReaderGroup(CallbackGroup):
    """A callback group no executor runs: its subscriptions are a :class:`CommandReader`'s."""

    def can_execute(self, entity: Any) -> bool:
        """Never: the executor leaves the entity out of its wait set."""
        return False

    def beginning_execution(self, entity: Any) -> bool:
        """Never (see :meth:`can_execute`)."""
        return False

    def ending_execution(self, entity: Any) -> None:
        """Nothing began, so nothing ends."""


class CommandReader:
    """Waits on its subscriptions in a thread; runs their callbacks in their turn.

    Create each subscription with :attr:`group` as its callback group, then
    :meth:`add` it; :meth:`remove` it before destroying it.
    """

    def __init__(self, context: Context, turns: Turns, name: str = 'commands') -> None:
        self.group = ReaderGroup()
        self._context = context
        self._turns = turns
        self._guard = GuardCondition(None, None, context=context)
        self._lock = threading.Lock()
        self._subscriptions: list[Subscription] = []
        self._stopping = False
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    def add(self, subscription: Subscription) -> None:
        """Read ``subscription`` (made with :attr:`group`) from now on."""
        with self._lock:
            self._subscriptions.append(subscription)
        self._guard.trigger()

    def remove(self, subscription: Subscription) -> None:
        """Stop reading ``subscription``; messages taken but not yet handed over are dropped."""
        with self._lock:
            if subscription in self._subscriptions:
                self._subscriptions.remove(subscription)
        self._guard.trigger()

    def start(self) -> None:
        """Start reading."""
        self._thread.start()

    def stop(self) -> None:
        """Stop reading and wait for the thread to end (it lets go of the subscriptions)."""
        with self._lock:
            self._stopping = True
        with contextlib.suppress(InvalidHandle):
            self._guard.trigger()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(JOIN_TIMEOUT_S)
        if not self._thread.is_alive():
            self._guard.destroy()

    @property
    def alive(self) -> bool:
        """Whether the thread is running."""
        return self._thread.is_alive()

    def _run(self) -> None:
        try:
            while True:
                with self._lock:
                    if self._stopping:
                        return
                    subscriptions = list(self._subscriptions)
                taken = wait_and_take(subscriptions, self._guard, self._context)
                if taken:
                    self._hand_over(taken)
        except BaseException as error:
            with self._lock:
                stopping = self._stopping
            if stopping or not self._context.ok():  # the program is ending anyway
                return
            self._turns.fail(error)

    def _hand_over(self, taken: list[tuple[Subscription, Any]]) -> None:
        """Run the callbacks of the messages taken, in order, in one turn."""
        with self._turns.callback():
            for subscription, message in taken:
                with self._lock:
                    wanted = subscription in self._subscriptions and not self._stopping
                if wanted:
                    subscription.callback(message)
