"""The plugin's ``sim`` fixture: a paused sim_node in the test's process, stepped in sim time."""

from __future__ import annotations

import gc
import math
import os
import resource
import sys

import pytest
import rclpy
from geometry_msgs.msg import Twist
from gripper_fixtures import FINGER_JOINT, write_gripper_arm
from nav_msgs.msg import Odometry
from rclpy.action import ActionClient
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from pan_tilt_sim.share import package_share
from pan_tilt_sim.tools.pytest_plugin import SimFactory
from pan_tilt_sim.tools.sim_helpers import MissingInterfaceError, SimTimeoutError

PAN_COMMAND = '/ex_urdf_pan_tilt/joint1_position_controller/command'
JOINT_STATES = '/ex_urdf_pan_tilt/joint_states'
JOINT_STATE_PERIOD = 0.02  # s: the pan/tilt example's joint_state_controller (50 Hz)
ARM = 'package://pan_tilt_sim/urdf/three_joint_arm.xacro'
ARM_CONTROLLERS = 'package://pan_tilt_sim/config/three_joint_arm_controllers.yaml'
ARM_JOINTS = ('shoulder_joint', 'extend_joint', 'wrist_joint')
ROVER = 'package://pan_tilt_sim/urdf/diff_drive_rover.urdf'
GRIPPER_GOAL_TOLERANCE = 0.01  # m: the gripper action controller's default goal_tolerance
LEAK_CHECK_SIMS = 40
LEAK_CHECK_RSS_MB = 5.0  # over 30 simulations: well under a megabyte each
BOX = ('<robot name="box"><link name="box"><inertial><mass value="1"/><inertia ixx="0.01" '
       'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>'
       '<box size="0.2 0.2 0.2"/></geometry></collision></link></robot>')


class StampCounter(Node):
    """A user's node: keeps the stamps of the joint states it receives."""

    def __init__(self) -> None:
        super().__init__('stamp_counter')
        self.stamps: list[float] = []
        self.create_subscription(JointState, JOINT_STATES, self._take, 10)

    def _take(self, message: JointState) -> None:
        self.stamps.append(message.header.stamp.sec + message.header.stamp.nanosec * 1e-9)


def test_with_no_arguments_it_is_the_pan_tilt_example_paused_at_zero(sim):
    s = sim()
    s.executor.spin_once(timeout_sec=0.1)  # the node's own ticks do not move it
    assert s.node.paused
    assert s.time == 0.0
    assert set(s.joint_positions()) == {'pan_joint', 'tilt_joint'}


def test_step_runs_exactly_that_much_sim_time(sim):
    s = sim()
    s.step(0.5)
    assert s.time == pytest.approx(0.5, abs=1e-12)
    s.step(0.0123)  # whole steps of 1 ms: 12 of them
    assert s.time == pytest.approx(0.512, abs=1e-12)


def test_a_published_command_moves_the_joint(sim):
    s = sim()
    s.publish(PAN_COMMAND, Float64(data=0.2))  # the pan turns at 0.1 rad/s at most
    s.run_until(lambda: s.joint_positions()['pan_joint'] > 0.15, timeout=5.0)
    assert 1.0 < s.time < 5.0


def test_run_until_times_out_in_sim_time_naming_the_time_and_the_latest_messages(sim):
    s = sim()
    s.messages(JOINT_STATES, JointState)
    with pytest.raises(SimTimeoutError) as raised:
        s.run_until(lambda: False, timeout=0.25)
    assert s.time == pytest.approx(0.25, abs=1e-12)
    report = str(raised.value)
    assert 'sim time now 0.250 s' in report
    assert f'{JOINT_STATES} (' in report and 'pan_joint' in report


def test_the_tests_nodes_see_every_message_in_order(sim):
    s = sim()
    counter = s.add_node(StampCounter())
    seen_by_probe = s.messages(JOINT_STATES, JointState)
    s.step(1.0)
    expected = round(1.0 / JOINT_STATE_PERIOD)
    assert len(counter.stamps) == len(seen_by_probe) == expected
    assert counter.stamps == sorted(counter.stamps)
    assert all(b - a == pytest.approx(JOINT_STATE_PERIOD) for a, b in
               zip(counter.stamps, counter.stamps[1:], strict=False))


def test_latest_is_none_before_the_first_message_then_the_newest(sim):
    s = sim()
    assert s.latest(JOINT_STATES, JointState) is None
    s.step(0.1)
    newest = s.latest(JOINT_STATES, JointState)
    # Sampled as each step starts: the one of 0.1 s comes with the next step.
    assert newest.header.stamp.nanosec == pytest.approx(8e7, abs=1)


def test_spawned_objects_fall_and_reset_takes_them_away(sim):
    s = sim()
    name = s.spawn(name='box', resource_string=BOX, position=(1.0, 0.0, 1.0))
    assert s.entity_pose(name).position.z == pytest.approx(1.0)
    s.step(1.0)
    assert s.entity_pose(name).position.z == pytest.approx(0.1, abs=0.01)
    s.reset()
    assert s.time == 0.0
    with pytest.raises(KeyError):
        s.entity_pose(name)


def test_follow_joint_trajectory_runs_the_arm_to_the_last_point(sim):
    s = sim(robot=ARM, controllers=ARM_CONTROLLERS)
    result = s.follow_joint_trajectory('arm_controller', [(1.0, (0.3, 0.05, 0.4)),
                                                          (2.0, (0.6, 0.1, 1.0))])
    assert result.error_code == 0, result.error_string
    reached = s.joint_positions()
    assert [reached[j] for j in ARM_JOINTS] == pytest.approx((0.6, 0.1, 1.0), abs=0.02)
    assert s.time == pytest.approx(2.0, abs=0.1)


def test_gripper_moves_the_finger_to_within_the_goal_tolerance(sim, tmp_path):
    urdf, controllers = write_gripper_arm(tmp_path)
    s = sim(robot=urdf, controllers=controllers)
    result = s.gripper('gripper_controller', 0.03, 10.0)
    assert result.reached_goal
    finger = s.joint_positions()[FINGER_JOINT]
    assert finger == pytest.approx(0.03, abs=GRIPPER_GOAL_TOLERANCE)
    # Upstream's rule: the goal succeeds once the finger is within the tolerance.
    assert result.position == pytest.approx(0.03, abs=GRIPPER_GOAL_TOLERANCE)


def test_drive_returns_the_true_pose_and_the_odometry(sim):
    s = sim(robot=ROVER)
    end = s.drive('cmd_vel', 0.3, 0.0, 2.0)
    assert s.time == pytest.approx(2.0, abs=1e-9)
    assert isinstance(end.odometry, Odometry)
    assert 0.4 < end.pose.position.x < 0.62
    assert end.odometry.pose.pose.position.x == pytest.approx(end.pose.position.x, abs=0.03)
    s.step(1.0)  # then it stops
    assert s.entity_pose('diff_drive_rover').position.x == pytest.approx(
        end.pose.position.x, abs=0.1)


def test_drive_turns_with_w(sim):
    s = sim(robot=ROVER)
    end = s.drive('/cmd_vel', 0.0, 1.0, 1.5)
    q = end.pose.orientation
    yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
    assert 0.5 < yaw < 1.5


def test_drive_names_what_it_cannot_drive(sim):
    s = sim()
    with pytest.raises(ValueError, match='neither a drive controller nor a topic'):
        s.drive('no_such_base', 0.1, 0.0, 1.0)


def test_a_helper_whose_interface_package_is_missing_names_it_and_how_to_install_it(
        sim, monkeypatch):
    s = sim()
    monkeypatch.setitem(sys.modules, 'control_msgs.action', None)
    with pytest.raises(MissingInterfaceError,
                       match=r'follow_joint_trajectory\(\) needs the ROS interface package '
                             r'control_msgs.*apt install ros-\$ROS_DISTRO-control-msgs'):
        s.follow_joint_trajectory('arm_controller', [(1.0, (0.0,))])


def test_publish_says_when_nobody_subscribes(sim, monkeypatch):
    from pan_tilt_sim.tools import sim_helpers

    monkeypatch.setattr(sim_helpers, 'DISCOVERY_BUDGET_S', 0.2)
    s = sim()
    with pytest.raises(SimTimeoutError, match='nobody subscribes to /nobody_listens'):
        s.publish('nobody_listens', Float64(data=1.0))


def test_robot_and_world_take_paths_and_package_uris(sim):
    rover = package_share() / 'urdf' / 'diff_drive_rover.urdf'
    s = sim(robot=str(rover), world='package://pan_tilt_sim/config/worlds/room.yaml')
    assert s.entity_pose('wall_east').position.x == pytest.approx(2.05)
    assert s.robot_name == 'diff_drive_rover'


def test_teardown_destroys_the_tests_nodes_their_action_clients_and_the_context(request):
    factory = SimFactory(request)
    s = factory()
    user = s.add_node(Node('user'))
    client = ActionClient(user, _fjt(), '/arm_controller/follow_joint_trajectory')
    publisher = user.create_publisher(Twist, 'cmd_vel', 10)
    factory.close()
    assert not rclpy.ok()
    # ActionClient.destroy() takes it off its node; destroy_node() alone leaves it there.
    assert client not in list(user.waitables)
    with pytest.raises(Exception):  # noqa: B017 -- rclpy's InvalidHandle, not exported
        publisher.get_subscription_count()
    assert s.node.simulation is None or _pybullet_released(s)


def test_a_context_the_test_initialised_is_left_to_the_test(request):
    rclpy.init()
    try:
        factory = SimFactory(request)
        factory().step(0.01)
        factory.close()
        assert rclpy.ok()
    finally:
        rclpy.try_shutdown()


def _fjt():
    from control_msgs.action import FollowJointTrajectory

    return FollowJointTrajectory


def _pybullet_released(s) -> bool:
    import pybullet

    return not pybullet.isConnected(physicsClientId=s.node.simulation.physics.client_id)


def _open_fds() -> int:
    return len(os.listdir('/proc/self/fd'))


def _rss_mb() -> float:
    with open('/proc/self/statm') as statm:
        return int(statm.read().split()[1]) * resource.getpagesize() / 1e6


def test_fresh_simulations_one_after_another_leak_no_file_descriptors_or_memory(request):
    fds, rss = [], []
    for _ in range(LEAK_CHECK_SIMS):
        factory = SimFactory(request)
        s = factory()
        s.add_node(StampCounter())
        s.step(0.05)
        factory.close()
        gc.collect()
        fds.append(_open_fds())
        rss.append(_rss_mb())
    warmed = LEAK_CHECK_SIMS // 4  # caches and first imports fill up first
    assert fds[-1] <= fds[warmed], fds
    assert rss[-1] - rss[warmed] < LEAK_CHECK_RSS_MB, rss
