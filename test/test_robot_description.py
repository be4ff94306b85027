"""robot_description (transient local) and TF, as robot_state_publisher would publish them."""

import importlib.util
import math

import pytest
from geometry_msgs.msg import TransformStamped
from node_harness import sim_node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from pan_tilt_sim.kinematics import Transform, quaternion_from_axis_angle
from pan_tilt_sim.robot_state import transform_message

HAS_TF2_MSGS = importlib.util.find_spec('tf2_msgs') is not None
LATE_SUBSCRIBER_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                                 durability=DurabilityPolicy.TRANSIENT_LOCAL)
TF_OFF_LINE = 'TF is off: tf2_msgs is not installed'


def test_robot_description_reaches_a_subscriber_that_comes_late():
    with sim_node() as harness:
        harness.run_until_sim_time(0.5)  # the node has long published it
        received = harness.collect(String, harness.node.topic('robot_description'),
                                   LATE_SUBSCRIBER_QOS)
        assert harness.spin_until(lambda: received, timeout_s=10.0)
        urdf = harness.simulation.description.urdf_xml
    assert harness.node.topic('robot_description') == '/ex_urdf_pan_tilt/robot_description'
    assert received[0].data == urdf
    assert '<robot name="ex_urdf_pan_tilt"' in urdf and 'xacro:' not in urdf


def test_transform_message_carries_parent_child_and_pose():
    rotation = quaternion_from_axis_angle((0, 0, 1), math.pi / 2)
    message = transform_message('base_link', 'pan_link', Transform((0.0, 0.0, 0.1), rotation),
                                12.5, TransformStamped())
    assert (message.header.frame_id, message.child_frame_id) == ('base_link', 'pan_link')
    assert (message.header.stamp.sec, message.header.stamp.nanosec) == (12, 500_000_000)
    assert message.transform.translation.z == pytest.approx(0.1)
    assert (message.transform.rotation.z, message.transform.rotation.w) == pytest.approx(
        (math.sqrt(0.5), math.sqrt(0.5)))


@pytest.mark.skipif(HAS_TF2_MSGS, reason='tf2_msgs is installed: TF is on here')
def test_without_tf2_msgs_tf_is_off_and_said_so_once(capfd):
    with sim_node() as harness:
        harness.run_until_sim_time(0.5)
        publishers = dict(harness.node.get_publisher_names_and_types_by_node(
            harness.node.get_name(), harness.node.get_namespace()))
        assert not harness.node.features.robot_state.publishes_tf
    assert '/tf' not in publishers and '/tf_static' not in publishers
    assert capfd.readouterr().err.count(TF_OFF_LINE) == 1


@pytest.mark.skipif(HAS_TF2_MSGS, reason='tf2_msgs is installed: TF is on here')
def test_with_publish_tf_false_nothing_is_said_about_tf(capfd):
    with sim_node(publish_tf=False) as harness:
        harness.run_until_sim_time(0.1)
    assert TF_OFF_LINE not in capfd.readouterr().err


@pytest.mark.skipif(not HAS_TF2_MSGS, reason='tf2_msgs is not installed')
def test_with_tf2_msgs_tf_has_the_joints_and_tf_static_the_camera_frame():
    from tf2_msgs.msg import TFMessage

    with sim_node() as harness:
        static = harness.collect(TFMessage, '/tf_static', LATE_SUBSCRIBER_QOS)
        moving = harness.collect(TFMessage, '/tf')
        assert harness.spin_until(lambda: static and moving)
    children = {t.child_frame_id: t for t in moving[-1].transforms}
    assert set(children) == {'pan_link', 'tilt_link'}
    assert children['tilt_link'].header.frame_id == 'pan_link'
    optical = {t.child_frame_id: t for t in static[0].transforms}['tilt_link_optical']
    assert optical.header.frame_id == 'tilt_link'
    assert optical.transform.translation.z == pytest.approx(0.2)
