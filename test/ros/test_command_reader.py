"""Command topics read by a thread of their own, their callbacks run in their turn."""

import threading
import time

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from std_msgs.msg import Float64
from waiting import BUDGET_S, wait_for

from pan_tilt_sim.ros import command_reader
from pan_tilt_sim.ros.command_reader import CommandReader
from pan_tilt_sim.ros.physics_thread import PhysicsThread, Turns, TurnTakingExecutor

TOPIC = '/reader_test/command'


@pytest.fixture
def reader_setup(context):
    """A node, a reader on its context, and a publisher in a node of its own."""
    node = rclpy.create_node('reader_test', context=context)
    sender = rclpy.create_node('reader_test_sender', context=context)
    turns = Turns()
    reader = CommandReader(context, turns)
    yield node, sender, turns, reader
    reader.stop()
    sender.destroy_node()
    node.destroy_node()


def read(node, reader, topic, on_message):
    """Create a subscription read by ``reader``; return it."""
    subscription = node.create_subscription(Float64, topic, on_message, 10,
                                            callback_group=reader.group)
    reader.add(subscription)
    return subscription


def connected_publisher(sender, topic, subscribers=1):
    publisher = sender.create_publisher(Float64, topic, 10)
    assert wait_for(lambda: publisher.get_subscription_count() >= subscribers)
    return publisher


def test_every_message_reaches_its_callback_in_order_on_the_readers_thread(reader_setup):
    node, sender, _, reader = reader_setup
    received = []
    read(node, reader, TOPIC,
         lambda message: received.append((message.data, threading.current_thread().name)))
    reader.start()
    publisher = connected_publisher(sender, TOPIC)
    for value in range(5):
        publisher.publish(Float64(data=float(value)))
    assert wait_for(lambda: len(received) == 5)
    assert received == [(float(value), 'commands') for value in range(5)]


def test_the_executor_leaves_a_readers_subscription_alone(reader_setup):
    # The same message reaches a subscription of the executor's and not the reader's own,
    # which the executor does not even wait on, while the reader does not run.
    node, sender, _, reader = reader_setup
    by_reader, by_executor = [], []
    read(node, reader, TOPIC, by_reader.append)
    node.create_subscription(Float64, TOPIC, by_executor.append, 10)
    executor = SingleThreadedExecutor(context=node.context)
    executor.add_node(node)
    try:
        publisher = connected_publisher(sender, TOPIC, subscribers=2)
        publisher.publish(Float64(data=1.0))
        deadline = time.monotonic() + BUDGET_S
        while not by_executor and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.01)
        assert by_executor and not by_reader
        # Nor does it wake for the message waiting there for the reader: for 0.2 s each
        # spin_once waits its whole timeout (the executor's own subscription has nothing).
        spins, end = 0, time.monotonic() + 0.2
        while time.monotonic() < end:
            executor.spin_once(timeout_sec=0.05)
            spins += 1
        assert spins <= 6 and len(by_executor) == 1
        reader.start()
        assert wait_for(lambda: len(by_reader) == 1)  # it waited for the reader
    finally:
        executor.shutdown()


def test_a_callback_never_runs_during_a_batch_of_steps(reader_setup):
    node, sender, turns, reader = reader_setup
    in_batch, overlaps, received = [False], [], []

    def tick():  # back to back, as at real_time_factor 0
        in_batch[0] = True
        time.sleep(0.002)
        in_batch[0] = False

    def on_message(message):
        overlaps.append(in_batch[0])
        received.append(message.data)

    read(node, reader, TOPIC, on_message)
    physics = PhysicsThread(tick, lambda: 0.0, turns)
    physics.start()
    reader.start()
    try:
        publisher = connected_publisher(sender, TOPIC)
        for value in range(30):
            publisher.publish(Float64(data=float(value)))
            time.sleep(0.001)  # spread over many batches
        assert wait_for(lambda: len(received) == 30)
    finally:
        physics.stop()
    assert not any(overlaps)


def test_a_removed_subscription_is_read_no_more_and_can_be_destroyed(reader_setup):
    node, sender, _, reader = reader_setup
    first, second = [], []
    removed = read(node, reader, TOPIC, lambda message: first.append(message.data))
    read(node, reader, '/reader_test/other', lambda message: second.append(message.data))
    reader.start()
    publisher = connected_publisher(sender, TOPIC)
    other = connected_publisher(sender, '/reader_test/other')
    publisher.publish(Float64(data=1.0))
    assert wait_for(lambda: first == [1.0])
    reader.remove(removed)
    publisher.publish(Float64(data=2.0))  # sent before the ten below, and never read
    for value in range(10):
        other.publish(Float64(data=float(value)))
    assert wait_for(lambda: len(second) == 10)  # still reading the other
    assert first == [1.0]
    assert node.destroy_subscription(removed)  # the reader let go of it: no hang, no error
    assert wait_for(lambda: publisher.get_subscription_count() == 0)


def test_a_message_taken_before_its_subscription_was_removed_is_dropped(reader_setup):
    # As controller_manager unloads a controller while the reader waits for its turn
    # with a command for it in hand.
    node, sender, turns, reader = reader_setup
    received = []
    subscription = read(node, reader, TOPIC, lambda message: received.append(message.data))
    reader.start()
    publisher = connected_publisher(sender, TOPIC)
    with turns.physics():
        publisher.publish(Float64(data=1.0))
        assert wait_for(lambda: turns._callbacks_waiting == 1)  # taken, waiting for its turn
        reader.remove(subscription)
    with turns.physics():  # the next batch comes after the reader's turn
        pass
    assert received == []


def test_stop_ends_a_thread_that_waits_for_messages(reader_setup):
    node, _, _, reader = reader_setup
    read(node, reader, TOPIC, lambda message: None)
    reader.start()
    assert reader.alive
    started = time.monotonic()
    reader.stop()
    assert not reader.alive and time.monotonic() - started < 1.0


def test_a_callback_that_raises_makes_the_executor_raise_it(reader_setup):
    node, sender, turns, reader = reader_setup

    def on_message(message):
        raise RuntimeError(f'bad command {message.data}')

    read(node, reader, TOPIC, on_message)
    executor = TurnTakingExecutor(turns, context=node.context)
    executor.add_node(node)
    reader.start()
    try:
        connected_publisher(sender, TOPIC).publish(Float64(data=7.0))
        assert wait_for(lambda: not reader.alive)
        with pytest.raises(RuntimeError, match='bad command 7.0'):
            executor.spin_once(timeout_sec=0.01)
    finally:
        executor.shutdown()


def test_rclpys_private_wait_set_still_works_as_the_reader_needs_it(context):
    # Fails when rclpy changes the private API wait_and_take builds on: sim_node then
    # reads its command topics by its executor (see the next test), at more CPU.
    assert command_reader.available(context), (
        "rclpy's private WaitSet or subscription handle changed: update "
        'pan_tilt_sim.ros.command_reader.wait_and_take')


def test_without_rclpys_private_wait_set_the_reader_is_not_available(context, monkeypatch):
    monkeypatch.setattr(command_reader, '_rclpy', None)
    assert not command_reader.available(context)
