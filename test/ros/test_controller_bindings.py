"""controller_bindings: a broadcaster's samples leave as JointStates, held until flushed."""

from pan_tilt_sim.ros.controller_bindings import JointStateSink


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
