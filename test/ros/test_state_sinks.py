"""state_sinks: the controllers' state samples as messages, one held-sample sink per type.

Each message is built from the state topic's fields, filled with a sample
and held until the node flushes (or the next sample comes first).
"""

import importlib.util
import math

import pytest
from control_msgs.msg import DynamicInterfaceGroupValues
from geometry_msgs.msg import PoseStamped, WrenchStamped
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import Imu, Range

from pan_tilt_sim.ros.state_sinks import (
    DofStateSink,
    DynamicJointStateSink,
    GroupValuesSink,
    ImuSink,
    JointStateSink,
    PoseSink,
    RangeSink,
    TrajectoryStateSink,
    WrenchSink,
)


class RecordingPublisher:
    """Keeps a copy of every message published."""

    def __init__(self):
        self.sent = []

    def publish(self, message):
        self.sent.append(deserialize_message(serialize_message(message), type(message)))


def seconds(stamp):
    return stamp.sec + stamp.nanosec * 1e-9


def test_a_wrench_is_held_until_flushed_or_pushed_out_by_the_next():
    publisher = RecordingPublisher()
    sink = WrenchSink(publisher, {'frame_id': 'tool0'})
    sink(0.01, [1.0, 2.0, -19.62], [0.0, 0.5, 0.0])
    assert publisher.sent == []
    sink(0.02, [1.0, 2.0, -19.0], [0.0, 0.5, 0.0])
    sink.flush()
    sink.flush()
    assert [seconds(m.header.stamp) for m in publisher.sent] == [0.01, 0.02]
    first = publisher.sent[0]
    assert isinstance(first, WrenchStamped) and first.header.frame_id == 'tool0'
    assert (first.wrench.force.z, first.wrench.torque.y) == (-19.62, 0.5)


def test_an_imu_sample_carries_the_covariances_given():
    publisher = RecordingPublisher()
    covariance = (0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01)
    sink = ImuSink(publisher, {'frame_id': 'imu_link',
                               'covariances': ((0.0,) * 9, covariance, (0.0,) * 9)})
    sink(0.5, [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.1], [0.0, 0.0, 9.81])
    sink.flush()
    (message,) = publisher.sent
    assert isinstance(message, Imu) and message.header.frame_id == 'imu_link'
    assert (message.orientation.w, message.angular_velocity.z,
            message.linear_acceleration.z) == (1.0, 0.1, 9.81)
    assert list(message.angular_velocity_covariance) == list(covariance)


def test_a_range_has_the_fields_limits_and_the_sampled_distance():
    publisher = RecordingPublisher()
    sink = RangeSink(publisher, {'frame_id': 'sonar', 'radiation_type': 1,
                                 'field_of_view': 0.3, 'min_range': 0.1, 'max_range': 2.0,
                                 'variance': 0.01})
    sink(0.1, math.inf)
    sink.flush()
    (message,) = publisher.sent
    assert isinstance(message, Range)
    # float32 fields on the wire
    assert (message.radiation_type, message.max_range) == (1, 2.0)
    assert (message.field_of_view, message.variance) == (pytest.approx(0.3),
                                                         pytest.approx(0.01))
    assert math.isinf(message.range)


def test_a_pose():
    poses = RecordingPublisher()
    pose = PoseSink(poses, {'frame_id': 'world'})
    pose(0.2, [0.1, 0.2, 0.3], [0.0, 0.0, 0.0, 1.0])
    pose.flush()
    (stamped,) = poses.sent
    assert isinstance(stamped, PoseStamped) and stamped.pose.position.z == 0.3
    assert stamped.header.frame_id == 'world' and seconds(stamped.header.stamp) == 0.2


def test_gpio_states_name_the_groups_and_interfaces_once_and_copy_the_values():
    publisher = RecordingPublisher()
    sink = GroupValuesSink(publisher, {'groups': ('io', 'vac'),
                                       'interface_names': (('out', 'in'), ('vacuum',))})
    values = [[1.0, math.nan], [0.0]]
    sink(0.1, values)
    values[1][0] = 1.0  # the controller reuses its lists
    sink.flush()
    (message,) = publisher.sent
    assert isinstance(message, DynamicInterfaceGroupValues)
    assert list(message.interface_groups) == ['io', 'vac']
    assert [list(entry.interface_names) for entry in message.interface_values] == [
        ['out', 'in'], ['vacuum']]
    assert message.interface_values[1].values[0] == 0.0
    assert math.isnan(message.interface_values[0].values[1])


class PositionsPublisher:
    """Keeps what each publish() sent, as it was at that moment."""

    def __init__(self) -> None:
        self.sent: list[tuple[float, list[float]]] = []

    def publish(self, message) -> None:
        stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
        self.sent.append((round(stamp, 9), list(message.position)))


def sample(sink: JointStateSink, time: float, position: float) -> None:
    sink(time, ['a'], [position], [0.0], [0.0])


def test_a_sample_leaves_only_when_flushed_and_only_once():
    publisher = PositionsPublisher()
    sink = JointStateSink(publisher, {'names': ['a']})
    sample(sink, 0.02, 1.5)
    assert publisher.sent == []
    sink.flush()
    sink.flush()
    assert publisher.sent == [(0.02, [1.5])]


def test_a_sample_taken_before_the_flush_pushes_out_the_one_held():
    publisher = PositionsPublisher()
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


def test_a_trajectory_state_sample_leaves_with_every_field_and_empty_ones_left_empty():
    pytest.importorskip('control_msgs.msg', reason='control_msgs is not installed')
    sent = []

    class Publisher:
        def publish(self, message) -> None:
            stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
            sent.append((round(stamp, 9), list(message.joint_names), [
                [list(values) for values in (point.positions, point.velocities,
                                             point.accelerations, point.effort)]
                for point in (message.reference, message.feedback, message.error,
                              message.output)], message.speed_scaling_factor))

    sink = TrajectoryStateSink(Publisher(), {'joint_names': ['a', 'b']})
    sink(0.25, ([1.0, 2.0], [0.1, 0.2], [0.0, -1.0]), ([0.5, 1.5], [0.3, 0.4]),
         ([0.5, 0.5], [-0.2, -0.2]), ([], [7.0, 8.0]))
    assert sent == []
    sink.flush()
    sink.flush()
    assert sent == [(0.25, ['a', 'b'], [
        [[1.0, 2.0], [0.1, 0.2], [0.0, -1.0], []],
        [[0.5, 1.5], [0.3, 0.4], [], []],
        [[0.5, 0.5], [-0.2, -0.2], [], []],
        [[], [], [], [7.0, 8.0]]], 1.0)]
