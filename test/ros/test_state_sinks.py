"""state_sinks: the sensor broadcasters' and gpio controller's samples as messages.

Each message is built from the state topic's fields, filled with a sample
and held until the node flushes (or the next sample comes first).
"""

import math

import pytest
from control_msgs.msg import DynamicInterfaceGroupValues
from geometry_msgs.msg import PoseStamped, WrenchStamped
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import Imu, Range

from pan_tilt_sim.ros.state_sinks import (
    GroupValuesSink,
    ImuSink,
    PoseSink,
    RangeSink,
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
