"""controller_bindings: a broadcaster's samples leave as messages, held until flushed."""

import importlib.util

import pytest

from pan_tilt_sim.ros.controller_bindings import DynamicJointStateSink, JointStateSink


class RecordingPublisher:
    """Keeps what each publish() sent, as it was at that moment."""

    def __init__(self) -> None:
        self.sent: list[tuple[float, list[float]]] = []

    def publish(self, message) -> None:
        stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
        self.sent.append((round(stamp, 9), list(message.position)))


def sample(sink: JointStateSink, time: float, position: float) -> None:
    sink(time, ['a'], [position], [0.0], [0.0])


def test_a_sample_leaves_only_when_flushed_and_only_once():
    publisher = RecordingPublisher()
    sink = JointStateSink(publisher, {'names': ['a']})
    sample(sink, 0.02, 1.5)
    assert publisher.sent == []
    sink.flush()
    sink.flush()
    assert publisher.sent == [(0.02, [1.5])]


def test_a_sample_taken_before_the_flush_pushes_out_the_one_held():
    publisher = RecordingPublisher()
    sink = JointStateSink(publisher, {'names': ['a']})
    sample(sink, 0.02, 1.0)
    sample(sink, 0.04, 2.0)
    sample(sink, 0.06, 3.0)
    sink.flush()
    assert publisher.sent == [(0.02, [1.0]), (0.04, [2.0]), (0.06, [3.0])]


class RecordingDynamicPublisher:
    """Keeps each DynamicJointState sent, as it was at that moment."""

    def __init__(self) -> None:
        self.sent: list[tuple] = []

    def publish(self, message) -> None:
        stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
        self.sent.append((round(stamp, 9), list(message.joint_names),
                          [(list(value.interface_names), list(value.values))
                           for value in message.interface_values]))


@pytest.mark.skipif(importlib.util.find_spec('control_msgs') is None,
                    reason='control_msgs is not installed')
def test_a_dynamic_sample_is_copied_and_held_until_flushed():
    publisher = RecordingDynamicPublisher()
    sink = DynamicJointStateSink(publisher, {'joint_names': ('a', 'b'), 'interface_names': (
        ('position', 'temperature'), ('position',))})
    values = [[0.5, 21.5], [-0.25]]
    sink(0.02, values)
    values[0][0] = 9.0  # the broadcaster reuses its lists
    sink(0.04, values)
    assert len(publisher.sent) == 1
    sink.flush()
    sink.flush()
    assert publisher.sent == [
        (0.02, ['a', 'b'], [(['position', 'temperature'], [0.5, 21.5]), (['position'], [-0.25])]),
        (0.04, ['a', 'b'], [(['position', 'temperature'], [9.0, 21.5]), (['position'], [-0.25])])]
