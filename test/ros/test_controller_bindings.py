"""controller_bindings: the declared surface on the node; samples held until flushed."""

import importlib.util

import pytest
from node_harness import sim_node
from rcl_interfaces.msg import Log
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile

from pan_tilt_sim.controllers.framework.registry import CONTROLLER_CLASSES
from pan_tilt_sim.controllers.framework.surface import CommandTopic, StateTopic
from pan_tilt_sim.ros.controller_bindings import (
    STATE_SINKS,
    DofStateSink,
    DynamicJointStateSink,
    JointStateSink,
    TrajectoryStateSink,
)
from pan_tilt_sim.ros.ros_interfaces import COMMAND_MESSAGES
from pan_tilt_sim.tools.controller_reference import example_controller


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


MISSPELT_YAML = '''controller_manager:
  ros__parameters:
    update_rate: 100
    joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
    arm: {type: joint_trajectory_controller/JointTrajectoryController}
arm:
  ros__parameters:
    joints: [pan_joint, tilt_joint]
    alow_partial_joints_goal: true
'''


def test_a_misspelt_controller_parameter_is_logged_with_the_closest_known_one(tmp_path):
    config = tmp_path / 'misspelt.yaml'
    config.write_text(MISSPELT_YAML)
    # /rosout keeps its history for late joiners (transient local), so start-up lines arrive.
    history = QoSProfile(depth=1000, history=HistoryPolicy.KEEP_LAST,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
    with sim_node(controllers_file=str(config)) as sim:
        log = sim.collect(Log, '/rosout', history)
        wanted = (f"{config}: arm.alow_partial_joints_goal: unknown parameter, ignored "
                  "(did you mean 'allow_partial_joints_goal'?)")
        assert sim.harness.spin_until(
            lambda: any(entry.level == Log.WARN and entry.msg == wanted for entry in log)), \
            [entry.msg for entry in log]
        assert not sim.node.simulation.manager.controller('arm')._flags[
            'allow_partial_joints_goal']


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


@pytest.mark.parametrize('cls', CONTROLLER_CLASSES, ids=lambda cls: cls.type_names[0])
def test_every_topic_a_registered_type_declares_has_its_message_type_in_the_tables(cls):
    for endpoint in example_controller(cls).ros_surface():
        if isinstance(endpoint, CommandTopic):
            assert endpoint.message in COMMAND_MESSAGES
        elif isinstance(endpoint, StateTopic):
            assert endpoint.message in STATE_SINKS
