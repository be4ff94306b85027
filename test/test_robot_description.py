"""robot_description (transient local) and TF, as robot_state_publisher would publish them."""

import importlib.util
import math

import pytest
from geometry_msgs.msg import TransformStamped
from node_harness import sim_node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from pan_tilt_sim.description import Mimic, load_description
from pan_tilt_sim.kinematics import (
    Transform,
    parse_kinematics,
    quaternion_from_axis_angle,
    rotate,
)
from pan_tilt_sim.robot_state import (
    joint_position,
    moving_transforms,
    static_transforms,
    transform_message,
)
from pan_tilt_sim.share import DEFAULT_DESCRIPTION, package_share

HAS_TF2_MSGS = importlib.util.find_spec('tf2_msgs') is not None
LATE_SUBSCRIBER_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                                 durability=DurabilityPolicy.TRANSIENT_LOCAL)
TF_OFF_LINE = 'TF is off: tf2_msgs is not installed'


def test_robot_description_reaches_a_subscriber_that_comes_late():
    with sim_node() as harness:
        harness.run_until_sim_time(0.5)  # the node has long published it
        received = harness.collect(String, harness.node.topic('robot_description'),
                                   LATE_SUBSCRIBER_QOS)
        assert harness.spin_until(lambda: received, budget_s=10.0)
        urdf = harness.simulation.description.urdf_xml
    assert harness.node.topic('robot_description') == '/ex_urdf_pan_tilt/robot_description'
    assert received[0].data == urdf
    assert '<robot name="ex_urdf_pan_tilt"' in urdf and 'xacro:' not in urdf


def test_tf_has_one_edge_per_moving_joint_following_the_joint_positions():
    tree = parse_kinematics(load_description(package_share() / DEFAULT_DESCRIPTION).urdf_xml)
    frames = moving_transforms(tree, {'pan_joint': math.pi / 2, 'tilt_joint': -math.pi})
    assert [(parent, child) for parent, child, _ in frames] == [
        ('base_link', 'pan_link'), ('pan_link', 'tilt_link')]
    pan, tilt = frames[0][2], frames[1][2]
    assert pan.translation == pytest.approx((0.0, 0.0, 0.1))  # the joint origin
    assert rotate(pan.rotation, (1, 0, 0)) == pytest.approx((0, 1, 0), abs=1e-12)
    assert tilt.translation == pytest.approx((0.0, 0.0, 0.2))
    assert rotate(tilt.rotation, (0, 0, 1)) == pytest.approx((0, 0, -1), abs=1e-12)


def test_tf_static_has_the_fixed_joints_and_the_extra_frames():
    tree = parse_kinematics("""<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="bolt" type="fixed"><parent link="a"/><child link="b"/>
        <origin xyz="1 2 3"/></joint>
      <joint name="hinge" type="revolute"><parent link="b"/><child link="c"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
    </robot>""")
    optical = ('c', 'c_optical', Transform((0.0, 0.0, 0.5)))
    frames = static_transforms(tree, [optical])
    assert [(parent, child) for parent, child, _ in frames] == [('a', 'b'), ('c', 'c_optical')]
    assert frames[0][2].translation == (1.0, 2.0, 3.0)


def test_a_mimic_joint_follows_its_leader_in_tf():
    mimics = {'finger_right': Mimic('finger_left', multiplier=-1.0, offset=0.1)}
    assert joint_position({'finger_left': 0.3}, 'finger_right', mimics) == pytest.approx(-0.2)
    assert joint_position({'finger_left': 0.3}, 'finger_left', mimics) == 0.3


def test_the_node_puts_the_camera_optical_frame_on_tf_static():
    with sim_node() as harness:
        frames = harness.node.features.robot_state.static_frames
        mount = harness.node.features.camera.mount
    assert frames == [('tilt_link', 'tilt_link_optical', mount)]


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
