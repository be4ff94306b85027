"""controller_bindings: the declared surface on the node, and its tables."""


import pytest
from node_harness import sim_node
from rcl_interfaces.msg import Log
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile

from pan_tilt_sim.controllers.framework.registry import CONTROLLER_CLASSES
from pan_tilt_sim.controllers.framework.surface import CommandTopic, StateTopic
from pan_tilt_sim.ros.controller_bindings import STATE_SINKS
from pan_tilt_sim.ros.ros_interfaces import COMMAND_MESSAGES
from pan_tilt_sim.ros.state_sinks import HeldSample
from pan_tilt_sim.tools.controller_reference import example_controller

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


@pytest.mark.parametrize('cls', CONTROLLER_CLASSES, ids=lambda cls: cls.type_names[0])
def test_every_topic_a_registered_type_declares_has_its_message_type_in_the_tables(cls):
    for endpoint in example_controller(cls).ros_surface():
        if isinstance(endpoint, CommandTopic):
            assert endpoint.message in COMMAND_MESSAGES
        elif isinstance(endpoint, StateTopic):
            assert endpoint.message in STATE_SINKS


class NoPublisher:
    def publish(self, message) -> None:
        raise AssertionError('nothing was taken')


ODOMETRY_FIELDS = {'frame_id': 'odom', 'child_frame_id': 'base_link',
                   'pose_covariance_diagonal': [0.0] * 6,
                   'twist_covariance_diagonal': [0.0] * 6}


@pytest.mark.parametrize('message_type', sorted(STATE_SINKS))
def test_every_state_sink_holds_its_samples_the_one_way(message_type):
    _message_class, sink = STATE_SINKS[message_type]
    if isinstance(sink, type):
        assert issubclass(sink, HeldSample)
    else:  # a factory choosing among sinks by the fields
        for spatial in (False, True):
            made = sink(NoPublisher(), {**ODOMETRY_FIELDS, 'spatial': spatial})
            assert isinstance(made, HeldSample)
            made.flush()
