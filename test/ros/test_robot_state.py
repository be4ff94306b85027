"""robot_description (transient local) and TF, as robot_state_publisher would publish them."""

import importlib.util
import math
import os
import pathlib

import mesh_fixtures as mf
import pytest
from builtin_interfaces.msg import Duration
from geometry_msgs.msg import TransformStamped
from node_harness import PROBE_QUEUE, sim_node, stamp_s
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64MultiArray, String
from std_srvs.srv import Empty
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.transforms import Transform, quaternion_from_axis_angle, rotate
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.ros import robot_state
from pan_tilt_sim.ros.robot_state import (
    moving_transforms,
    static_transforms,
    transform_message,
)
from pan_tilt_sim.share import DEFAULT_DESCRIPTION, package_share

HAS_TF2_MSGS = importlib.util.find_spec('tf2_msgs') is not None
LATE_SUBSCRIBER_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                                 durability=DurabilityPolicy.TRANSIENT_LOCAL)
TF_OFF_LINE = 'off, for want of their interface packages: TF (/tf, /tf_static'


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


MESH_ROBOT = """<robot name="meshy">
  <link name="base"><visual><geometry>
    <mesh filename="package://meshy_pkg/meshes/base.dae" scale="0.001 0.001 0.001"/>
  </geometry><material name="orange"><color rgba="1 0.5 0 1"/></material></visual></link>
  <link name="arm"><inertial><mass value="1"/>
      <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><mesh filename="package://meshy_pkg/meshes/arm.stl"/></geometry>
    </collision></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
"""
JOINT_STATE_ONLY = 'jsb:\n  type: joint_state_broadcaster/JointStateBroadcaster\n'


@pytest.fixture
def mesh_robot(tmp_path, monkeypatch):
    """A robot whose meshes are package:// URIs of a package in a temporary ament prefix."""
    prefix = mf.make_ament_prefix(tmp_path, 'meshy_pkg', {
        'meshes/base.dae': mf.dae_text((100.0, 100.0, 100.0)),
        'meshes/arm.stl': mf.binary_stl_bytes((0.1, 0.1, 0.5)),
        'urdf/meshy.urdf': MESH_ROBOT,
        'config/controllers.yaml': JOINT_STATE_ONLY})
    monkeypatch.setenv('AMENT_PREFIX_PATH', os.pathsep.join(
        [str(prefix), os.environ.get('AMENT_PREFIX_PATH', '')]))
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path / 'cache'))
    return prefix / 'share' / 'meshy_pkg'


def test_robot_description_is_the_urdf_as_written_and_pybullet_gets_local_files(mesh_robot):
    # RViz and robot_state_publisher need the package:// URIs (and the DAE's
    # colours); only PyBullet's own copy points at loadable local files.
    with sim_node(robot_description_file=str(mesh_robot / 'urdf' / 'meshy.urdf'),
                  controllers_file=str(mesh_robot / 'config' / 'controllers.yaml')) as harness:
        received = harness.collect(String, harness.node.topic('robot_description'),
                                   LATE_SUBSCRIBER_QOS)
        assert harness.spin_until(lambda: received, budget_s=10.0)
        description = harness.simulation.description
    assert received[0].data == MESH_ROBOT
    assert description.urdf_xml == MESH_ROBOT
    assert 'package://' not in description.physics_urdf
    local = [pathlib.Path(part.split('"')[0]) for part in
             description.physics_urdf.split('filename="')[1:]]
    assert len(local) == 2 and all(path.is_file() for path in local), local


def test_tf_has_one_edge_per_moving_joint_following_the_joint_positions():
    tree = load_description(package_share() / DEFAULT_DESCRIPTION).model
    frames = moving_transforms(tree, {'pan_joint': math.pi / 2, 'tilt_joint': -math.pi})
    assert [(parent, child) for parent, child, _ in frames] == [
        ('base_link', 'pan_link'), ('pan_link', 'tilt_link')]
    pan, tilt = frames[0][2], frames[1][2]
    assert pan.translation == pytest.approx((0.0, 0.0, 0.1))  # the joint origin
    assert rotate(pan.rotation, (1, 0, 0)) == pytest.approx((0, 1, 0), abs=1e-12)
    assert tilt.translation == pytest.approx((0.0, 0.0, 0.2))
    assert rotate(tilt.rotation, (0, 0, 1)) == pytest.approx((0, 0, -1), abs=1e-12)


def test_tf_static_has_the_fixed_joints_and_the_extra_frames():
    tree = parse_urdf("""<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="bolt" type="fixed"><parent link="a"/><child link="b"/>
        <origin xyz="1 2 3"/></joint>
      <joint name="hinge" type="revolute"><parent link="b"/><child link="c"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
    </robot>""", pathlib.Path('r.urdf'))
    optical = ('c', 'c_optical', Transform((0.0, 0.0, 0.5)))
    frames = static_transforms(tree, [optical])
    assert [(parent, child) for parent, child, _ in frames] == [('a', 'b'), ('c', 'c_optical')]
    assert frames[0][2].translation == (1.0, 2.0, 3.0)


def test_a_mimic_joint_follows_its_leader_in_tf():
    model = parse_urdf("""<robot name="r"><link name="a"/><link name="l"/><link name="r"/>
      <joint name="finger_left" type="prismatic"><parent link="a"/><child link="l"/>
        <limit lower="0" upper="1" effort="1" velocity="1"/></joint>
      <joint name="finger_right" type="prismatic"><parent link="a"/><child link="r"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/>
        <mimic joint="finger_left" multiplier="-1" offset="0.1"/></joint>
    </robot>""", pathlib.Path('r.urdf'))
    frames = {child: transform for _, child, transform in
              moving_transforms(model, {'finger_left': 0.3})}
    assert frames['l'].translation == pytest.approx((0.3, 0.0, 0.0))
    assert frames['r'].translation == pytest.approx((-0.2, 0.0, 0.0))


ARM = package_share() / 'urdf' / 'three_joint_arm.xacro'
ARM_CONTROLLERS = package_share() / 'config' / 'three_joint_arm_controllers.yaml'
ARM_JOINTS = ('shoulder_joint', 'extend_joint', 'wrist_joint')
needs_tf2_msgs = pytest.mark.skipif(not HAS_TF2_MSGS, reason='tf2_msgs is not installed')


def _edge(message: TransformStamped) -> Transform:
    t, r = message.transform.translation, message.transform.rotation
    return Transform((t.x, t.y, t.z), (r.x, r.y, r.z, r.w))


def tf_link_poses(static_messages, moving_message) -> dict[str, Transform]:
    """Chain the TF edges from the root: every link's pose in the root frame, as tf2 would."""
    edges = {t.child_frame_id: (t.header.frame_id, _edge(t))
             for message in (*static_messages, moving_message) for t in message.transforms}
    poses: dict[str, Transform] = {}

    def pose(frame: str) -> Transform:
        if frame not in poses:
            parent, edge = edges[frame] if frame in edges else (None, Transform())
            poses[frame] = edge if parent is None else pose(parent).then(edge)
        return poses[frame]
    for frame in edges:
        pose(frame)
    return poses


def assert_same_pose(got: Transform, expected: Transform, label: str) -> None:
    assert got.translation == pytest.approx(expected.translation, abs=1e-4), label
    dot = abs(sum(a * b for a, b in zip(got.rotation, expected.rotation, strict=True)))
    assert dot == pytest.approx(1.0, abs=1e-6), label


@needs_tf2_msgs
def test_tf_gives_every_link_where_forward_kinematics_puts_it_after_commands_mimic_included():
    from tf2_msgs.msg import TFMessage

    with sim_node(robot_description_file=str(ARM),
                  controllers_file=str(ARM_CONTROLLERS)) as harness:
        static = harness.collect(TFMessage, '/tf_static', LATE_SUBSCRIBER_QOS)
        moving = harness.collect(TFMessage, '/tf', PROBE_QUEUE)
        harness.wait_for_subscribers('/tf')
        harness.command('arm_controller', JointTrajectory(
            joint_names=list(ARM_JOINTS), points=[JointTrajectoryPoint(
                positions=[0.8, 0.12, 2.0], time_from_start=Duration(sec=1))]))
        harness.command('gripper_controller', Float64MultiArray(data=[0.02]))
        harness.run_for(1.5)
        model = harness.simulation.description.model
        assert static, 'nothing on /tf_static'
        # Named if the frames are wrong: a foreign node in this domain would show here.
        static_publishers = sorted(
            f'{info.node_namespace.rstrip("/")}/{info.node_name}'
            for info in harness.probe.get_publishers_info_by_topic('/tf_static'))
    # The newest /tf message whose JointState (same stamp) also arrived: under load the
    # probe's queues may drop a few of either at factor 0.
    stamped = {round(stamp_s(m), 6): m for m in harness.states}
    last = next((m for m in reversed(moving)
                 if round(stamp_s(m.transforms[0]), 6) in stamped), None)
    assert last is not None, 'no /tf message with a JointState of the same stamp'
    seconds = stamp_s(last.transforms[0])
    assert seconds >= 1.2, f'the newest matched /tf is from {seconds} s, before the move ended'
    assert all(stamp_s(t) == seconds for t in last.transforms)
    measured = stamped[round(seconds, 6)]
    positions = dict(zip(measured.name, measured.position, strict=True))
    assert positions['shoulder_joint'] == pytest.approx(0.8, abs=0.02)  # the robot did move
    assert positions['left_finger_joint'] == pytest.approx(0.02, abs=2e-3)
    # Forward kinematics from the commanded joints alone: the mimic follows its leader.
    leaders = {name: value for name, value in positions.items() if name != 'right_finger_joint'}
    expected = model.link_poses(leaders)
    got = tf_link_poses(static, last)
    # One frame per link: every joint, fixed or moving.
    assert set(got) == set(expected), f'/tf_static publishers: {static_publishers}'
    assert {t.child_frame_id for t in last.transforms} == {j.child for j in model.moving_joints}
    for link, pose in expected.items():
        assert_same_pose(got[link], pose, link)
    # The fingers' frames are 2 x 10 mm apart at rest; each moved 20 mm out, the mimic too.
    assert math.dist(got['left_finger_link'].translation,
                     got['right_finger_link'].translation) == pytest.approx(0.06, abs=2e-3)


@needs_tf2_msgs
def test_after_reset_simulation_tf_starts_again_at_zero_with_the_initial_pose():
    from tf2_msgs.msg import TFMessage

    with sim_node(robot_description_file=str(ARM),
                  controllers_file=str(ARM_CONTROLLERS)) as harness:
        static = harness.collect(TFMessage, '/tf_static', LATE_SUBSCRIBER_QOS)
        moving = harness.collect(TFMessage, '/tf', PROBE_QUEUE)
        harness.wait_for_subscribers('/tf')
        harness.command('gripper_controller', Float64MultiArray(data=[0.03]))
        harness.run_for(1.0)
        moved = tf_link_poses(static, moving[-1])
        harness.node.set_paused(True)
        harness.drain()  # every /tf from before the reset is in
        before = len(moving)
        harness.call(Empty, '/reset_simulation')
        harness.node.set_paused(False)
        harness.run_for(0.5)
        after = moving[before:]
        model = harness.simulation.description.model
        initial = {j.name: j.initial_position for j in model.actuated_joints
                   if j.mimic is None}
    stamps = [stamp_s(message.transforms[0]) for message in after]
    assert stamps[0] == 0.0 and stamps == sorted(stamps) and len(stamps) >= 25
    assert moved['left_finger_link'].translation != pytest.approx(
        model.link_poses(initial)['left_finger_link'].translation, abs=1e-3)
    got = tf_link_poses(static, after[0])
    for link, pose in model.link_poses(initial).items():
        assert_same_pose(got[link], pose, link)


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


@pytest.fixture
def without_tf2_msgs(monkeypatch):
    """Make the node see no tf2_msgs, as on a machine where it is not installed."""
    monkeypatch.setattr(robot_state, 'tf_message_type', lambda: None)


def test_without_tf2_msgs_tf_is_off_and_said_so_once(capfd, without_tf2_msgs):
    with sim_node() as harness:
        harness.run_until_sim_time(0.5)
        publishers, _subscribed = harness.own_topics()
        assert not harness.node.features.robot_state.publishes_tf
    assert '/tf' not in publishers and '/tf_static' not in publishers
    assert '/clock' in publishers  # the look-up does see the node's topics
    assert capfd.readouterr().err.count(TF_OFF_LINE) == 1


def test_with_publish_tf_false_nothing_is_said_about_tf(capfd, without_tf2_msgs):
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
