"""controller_bindings: state samples leave as JointStates or per-DoF states, held until flushed."""

import pytest

from pan_tilt_sim.ros.controller_bindings import DofStateSink, JointStateSink


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


def test_a_dof_state_sample_leaves_as_multi_dof_state_stamped_with_every_field():
    pytest.importorskip('control_msgs.msg', reason='control_msgs is not installed')
    sent = []

    class Publisher:
        def publish(self, message) -> None:
            stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
            sent.append((round(stamp, 9), [
                (s.name, s.reference, s.feedback, s.feedback_dot, s.error, s.error_dot,
                 s.time_step, s.output) for s in message.dof_states]))

    sink = DofStateSink(Publisher(), {'names': ['a', 'b']})
    sink(0.5, [(1.0, 2.0, 3.0, 4.0, 5.0, 0.001, 7.0), (8.0, 9.0, 0.0, -1.0, 0.0, 0.001, 2.5)])
    assert sent == []
    sink(0.501, [(1.5, 2.0, 3.0, 4.0, 5.0, 0.001, 7.0)] * 2)
    sink.flush()
    sink.flush()
    assert sent == [
        (0.5, [('a', 1.0, 2.0, 3.0, 4.0, 5.0, 0.001, 7.0),
               ('b', 8.0, 9.0, 0.0, -1.0, 0.0, 0.001, 2.5)]),
        (0.501, [('a', 1.5, 2.0, 3.0, 4.0, 5.0, 0.001, 7.0),
                 ('b', 1.5, 2.0, 3.0, 4.0, 5.0, 0.001, 7.0)])]
