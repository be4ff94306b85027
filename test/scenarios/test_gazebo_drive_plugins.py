"""A robot driven by Gazebo's drive plugins on sim_node: cmd_vel, odom and TF, no controllers.

The rover of test/support/mobile_fixtures.py with a ``libgazebo_ros_diff_drive.so``
plugin (or planar move, or gz-sim's DiffDrive system), a
``libgazebo_ros_p3d.so`` on ``/ground_truth`` and a lidar,
in-process, paused, at real_time_factor 0; each test drives it closed loop
from the probe: it reads ``/odom``, decides the next Twist on ``/cmd_vel``,
and steps one plugin update period at a time.  The
true pose comes from simulation_interfaces' GetEntityState.
"""

from __future__ import annotations

import contextlib
import math
import textwrap
from collections.abc import Iterator

import pytest
from geometry_msgs.msg import PoseStamped, Twist
from mobile_fixtures import (
    GZ_DIFF_DRIVE,
    GZ_JOINT_STATES,
    GZ_ODOMETRY,
    P3D,
    PLANAR_MOVE,
    REST_HEIGHT,
    ROS1_DIFF_DRIVE,
    ROS2_DIFF_DRIVE,
    plugin_rover_urdf,
)
from nav_msgs.msg import Odometry
from node_harness import PROBE_QUEUE, sim_node
from rcl_interfaces.msg import Log
from sensor_msgs.msg import JointState, LaserScan
from sim_interfaces_client import OK, SimInterfaces, position
from tf2_msgs.msg import TFMessage

TIME_STEP = 0.001
PERIOD_STEPS = 10  # one update of the plugin at its update rate of 100 Hz
# m past 1 m once stopped: braking from 0.2 m/s at the fixture's 1 m/s^2 wheel acceleration
# takes 0.02 m, plus up to one update at speed.
OVERRUN = 0.02 + 0.2 * 0.01
MAX_PERIODS = 1000  # 10 s of sim time: twice what 1 m at 0.2 m/s takes
ROBOT = 'rover'
# gz-sim's DiffDrive of the rover: its default topics, as ros_gz_bridge would carry them.
GZ_COMMAND, GZ_ODOMETRY_TOPIC, GZ_TF = ('/model/rover/cmd_vel', '/model/rover/odometry',
                                        '/model/rover/tf')


class PluginRover:
    """The plugin-driven rover on sim_node, driven from the probe one update at a time."""

    def __init__(self, sim, command: str = '/cmd_vel', odometry: str = '/odom',
                 tf: str = '/tf') -> None:
        self.sim = sim
        self.node = sim.node
        self.odometry: list[Odometry] = sim.collect(Odometry, odometry)
        self.tf: list[TFMessage] = sim.collect(TFMessage, tf)
        self.interfaces = SimInterfaces(sim)
        self.twist = sim.probe.create_publisher(Twist, command, 10)
        sim.wait_for_subscribers(odometry)
        sim.wait_for_subscribers(tf)
        assert sim.spin_until(lambda: self.twist.get_subscription_count() > 0), (
            f'sim_node does not subscribe {command}')
        self.node.step(1)  # from here on each period() holds one of the plugin's updates

    def command(self, linear: float, angular: float, sideways: float = 0.0) -> None:
        """Publish a Twist on the command topic; return once the plugin took it."""
        counts = self.node.commands_received
        name = self.node.simulation.plugins[0].name
        before = counts[name]
        message = Twist()
        message.linear.x, message.linear.y, message.angular.z = linear, sideways, angular
        self.twist.publish(message)
        assert self.sim.spin_until(lambda: counts[name] > before), 'cmd_vel never arrived'

    def period(self) -> Odometry:
        """Step one plugin update; return the odometry it published."""
        count = len(self.odometry)
        self.node.step(PERIOD_STEPS)
        assert self.sim.spin_until(lambda: len(self.odometry) > count), 'no odometry came'
        return self.odometry[-1]

    def true_pose(self) -> tuple[tuple[float, float, float], float]:
        """Return the base's true position and heading (GetEntityState)."""
        state = self.interfaces.entity_state(ROBOT)
        q = state.pose.orientation
        return position(state), 2.0 * math.atan2(q.z, q.w)

    def drive_one_metre(self) -> Odometry:
        """Drive at 0.2 m/s until the odometry says 1 m, then stop and settle."""
        odometry = self.period()
        self.command(0.2, 0.0)
        for _ in range(MAX_PERIODS):
            if odometry.pose.pose.position.x >= 1.0:
                break
            odometry = self.period()
        else:
            raise AssertionError(f'the odometry never reached 1 m: {odometry.pose.pose}')
        self.command(0.0, 0.0)
        for _ in range(30):
            odometry = self.period()
        return odometry


@contextlib.contextmanager
def running(folder, plugin: str, world: str = 'ground', *, ground_truth: str = P3D,
            joint_states: str | None = None, **topics: str) -> Iterator[PluginRover]:
    """Run the plugin rover on sim_node (no controllers file) in ``world``.

    ``topics``: the drive's command, odometry and tf topics (see :class:`PluginRover`).
    """
    description = folder / 'rover.urdf'
    extra = {} if joint_states is None else {'joint_states': joint_states}
    description.write_text(plugin_rover_urdf(plugin, ground_truth=ground_truth, **extra),
                           encoding='utf-8')
    with sim_node(paused=True, time_step=TIME_STEP, robot_description_file=str(description),
                  world=world) as sim:
        yield PluginRover(sim, **topics)


def test_the_plugin_frees_the_base_and_gives_the_plugins_topics(tmp_path):
    with running(tmp_path, ROS2_DIFF_DRIVE) as rover:
        assert not rover.node.simulation.physics.fixed_base
        where, _ = rover.true_pose()
        assert where == pytest.approx((0.0, 0.0, REST_HEIGHT), abs=1e-3)
        published, subscribed = rover.sim.own_topics()
        assert subscribed['/cmd_vel'] == 'geometry_msgs/msg/Twist'
        assert published['/odom'] == 'nav_msgs/msg/Odometry'
        assert published['/tf'] == 'tf2_msgs/msg/TFMessage'
        assert published['/scan'] == 'sensor_msgs/msg/LaserScan'


@pytest.mark.parametrize('plugin', [ROS2_DIFF_DRIVE, ROS1_DIFF_DRIVE], ids=['ros2', 'ros1'])
def test_one_metre_straight_at_0_2_m_s_the_encoder_odometry_agrees_with_the_true_pose(
        tmp_path, plugin):
    with running(tmp_path, plugin) as rover:
        odometry = rover.drive_one_metre()
        where, yaw = rover.true_pose()
        assert 1.0 * 0.98 <= where[0] <= 1.02 + OVERRUN
        assert odometry.pose.pose.position.x == pytest.approx(where[0], rel=0.02)
        assert odometry.pose.pose.position.y == pytest.approx(where[1], abs=0.02)
        assert odometry.header.frame_id == 'odom' and odometry.child_frame_id == 'base_link'
        rover.sim.drain()
        transform = [message.transforms[0] for message in rover.tf
                     if message.transforms[0].header.frame_id == 'odom'][-1]
        assert transform.child_frame_id == 'base_link'
        assert transform.transform.translation.x == pytest.approx(
            odometry.pose.pose.position.x, abs=0.01)


def test_world_odometry_is_the_true_pose(tmp_path):
    plugin = ROS2_DIFF_DRIVE.replace('<odometry_source>0', '<odometry_source>1')
    with running(tmp_path, plugin) as rover:
        odometry = rover.drive_one_metre()
        where, _ = rover.true_pose()
        assert odometry.pose.pose.position.x == pytest.approx(where[0], abs=1e-3)
        assert odometry.pose.pose.position.y == pytest.approx(where[1], abs=1e-3)


def test_the_wheel_acceleration_limit_ramps_the_speed(tmp_path):
    with running(tmp_path, ROS2_DIFF_DRIVE) as rover:  # max_wheel_acceleration 1 m/s^2
        rover.period()
        rover.command(0.2, 0.0)
        speeds = [rover.period().twist.twist.linear.x for _ in range(10)]
        assert speeds[0] < 0.05  # 0.01 m/s per update, not at once
        assert speeds[-1] == pytest.approx(0.1, abs=0.03)


def test_the_lidar_on_the_plugin_robot_publishes_a_scan(tmp_path):
    with running(tmp_path, ROS2_DIFF_DRIVE) as rover:
        scans = rover.sim.collect(LaserScan, '/scan')
        rover.sim.wait_for_subscribers('/scan')
        for _ in range(20):
            rover.period()
        assert rover.sim.spin_until(lambda: scans), 'no scan came'
        assert len(scans[-1].ranges) == 90 and scans[-1].header.frame_id == 'lidar_link'


def test_p3d_publishes_the_true_pose_of_its_link(tmp_path):
    with running(tmp_path, ROS2_DIFF_DRIVE) as rover:
        truth = rover.sim.collect(Odometry, '/ground_truth')
        rover.sim.wait_for_subscribers('/ground_truth')
        rover.drive_one_metre()
        where, yaw = rover.true_pose()
        assert rover.sim.spin_until(lambda: truth), 'no ground truth came'
        rover.sim.drain()
        last = truth[-1]
        assert last.header.frame_id == 'world' and last.child_frame_id == 'base_link'
        position_ = last.pose.pose.position
        assert (position_.x, position_.y, position_.z) == pytest.approx(where, abs=1e-3)
        assert 2.0 * math.atan2(last.pose.pose.orientation.z,
                                last.pose.pose.orientation.w) == pytest.approx(yaw, abs=1e-3)


WALL_FACE = 0.8  # m: the near face of the wall ahead, on the x axis
FRONT = 0.15  # m: the rover's front (its base box) ahead of its base frame
LIDAR_X = 0.1  # m: the lidar ahead of the base frame


def test_driving_at_a_wall_the_scan_sees_it_approach_and_the_contact_stops_the_robot(tmp_path):
    world = tmp_path / 'wall.yaml'
    world.write_text(textwrap.dedent(f'''\
        entities:
          - name: wall
            shape: box
            size: [0.1, 2.0, 0.5]
            pose: {{position: [{WALL_FACE + 0.05}, 0.0, 0.25]}}
        '''), encoding='utf-8')
    with running(tmp_path, ROS2_DIFF_DRIVE, world=str(world)) as rover:
        scans = rover.sim.collect(LaserScan, '/scan')
        rover.sim.wait_for_subscribers('/scan')
        rover.period()
        rover.command(0.2, 0.0)
        ahead = []  # (true x, range straight ahead) at each scan
        for _ in range(60):  # 6 s: 1.2 m at 0.2 m/s, were there no wall
            for _ in range(10):
                rover.period()
            assert rover.sim.spin_until(lambda: scans), 'no scan came'
            rover.sim.drain()
            middle = len(scans[-1].ranges) // 2
            ahead.append((rover.true_pose()[0][0], min(scans[-1].ranges[middle - 1:middle + 1])))
        first_x, first_range = ahead[0]
        assert first_range == pytest.approx(WALL_FACE - LIDAR_X - first_x, abs=0.02)
        ranges = [measured for _, measured in ahead]
        assert all(later <= earlier + 0.005
                   for earlier, later in zip(ranges, ranges[1:], strict=False))
        last_x, last_range = ahead[-1]
        assert last_x == pytest.approx(WALL_FACE - FRONT, abs=0.02)  # at the wall, not through
        assert ahead[-10][0] == pytest.approx(last_x, abs=0.005)  # and stopped there
        assert last_range == pytest.approx(WALL_FACE - LIDAR_X - last_x, abs=0.02)


def test_the_joint_state_publisher_publishes_the_wheels(tmp_path):
    with running(tmp_path, ROS2_DIFF_DRIVE) as rover:
        states = rover.sim.collect(JointState, '/joint_states')
        rover.sim.wait_for_subscribers('/joint_states')
        rover.period()
        rover.command(0.2, 0.0)
        for _ in range(50):  # 0.5 s
            rover.period()
        assert rover.sim.spin_until(lambda: states), 'no joint states came'
        rover.sim.drain()
        last = states[-1]
        assert list(last.name) == ['left_wheel_joint', 'right_wheel_joint']
        positions = rover.node.simulation.joint_positions()
        assert last.position[0] == pytest.approx(positions['left_wheel_joint'], abs=0.1)
        assert last.position[0] > 0.5  # the wheels turned: 0.2 m/s for most of 0.5 s
        assert len(states) == pytest.approx(0.5 * 50, abs=2)  # at the plugin's 50 Hz


@pytest.mark.parametrize(('joint_states', 'warned'), [('', True), (None, False)],
                         ids=['no publisher', 'a joint state publisher'])
def test_start_up_warns_of_empty_joint_states_only_without_a_joint_state_publisher(
        tmp_path, capfd, joint_states, warned):
    with running(tmp_path, ROS2_DIFF_DRIVE, joint_states=joint_states):
        pass
    said = 'nothing will be published on /joint_states' in capfd.readouterr().err
    assert said is warned


GZ_TOPICS = {'command': GZ_COMMAND, 'odometry': GZ_ODOMETRY_TOPIC, 'tf': GZ_TF}


def test_planar_move_one_metre_its_odometry_is_the_true_pose(tmp_path):
    with running(tmp_path, PLANAR_MOVE) as rover:
        published, subscribed = rover.sim.own_topics()
        assert subscribed['/cmd_vel'] == 'geometry_msgs/msg/Twist'
        assert published['/odom'] == 'nav_msgs/msg/Odometry'
        odometry = rover.drive_one_metre()
        where, yaw = rover.true_pose()
        assert 0.98 <= where[0] <= 1.02 + OVERRUN
        assert odometry.pose.pose.position.x == pytest.approx(where[0], rel=0.02)
        assert odometry.pose.pose.position.y == pytest.approx(where[1], abs=0.02)
        assert (odometry.header.frame_id, odometry.child_frame_id) == ('odom', 'base_link')
        assert odometry.pose.covariance[0] == pytest.approx(1e-5)
        assert odometry.pose.covariance[35] == pytest.approx(1e-3)


def test_planar_move_strafes_sideways_as_the_twist_says(tmp_path):
    # Set every step (update_rate 0): between two updates the wheels' friction brakes a
    # sideways slide, in Gazebo as here.
    every_step = PLANAR_MOVE.replace('<update_rate>100<', '<update_rate>0<')
    with running(tmp_path, every_step) as rover:
        rover.period()
        rover.command(0.0, 0.0, sideways=0.2)
        for _ in range(100):  # 1 s
            odometry = rover.period()
        where, yaw = rover.true_pose()
        assert where[1] == pytest.approx(0.2, abs=0.02)
        assert abs(where[0]) < 0.01 and abs(yaw) < 0.05
        assert odometry.twist.twist.linear.y == pytest.approx(0.2, abs=0.01)


def test_gz_diff_drive_one_metre_the_wheel_odometry_agrees_with_the_true_pose(tmp_path):
    with running(tmp_path, GZ_DIFF_DRIVE, ground_truth=GZ_ODOMETRY,
                 joint_states=GZ_JOINT_STATES, **GZ_TOPICS) as rover:
        published, subscribed = rover.sim.own_topics()
        assert subscribed[GZ_COMMAND] == 'geometry_msgs/msg/Twist'
        assert published[GZ_ODOMETRY_TOPIC] == 'nav_msgs/msg/Odometry'
        assert published[GZ_TF] == 'tf2_msgs/msg/TFMessage'
        assert published['/ground_truth'] == 'nav_msgs/msg/Odometry'  # OdometryPublisher
        assert published['/joint_states'] == 'sensor_msgs/msg/JointState'
        odometry = rover.drive_one_metre()
        where, yaw = rover.true_pose()
        assert 0.98 <= where[0] <= 1.02 + OVERRUN
        assert odometry.pose.pose.position.x == pytest.approx(where[0], rel=0.02)
        assert odometry.pose.pose.position.y == pytest.approx(where[1], abs=0.02)
        assert (odometry.header.frame_id, odometry.child_frame_id) == ('rover/odom',
                                                                       'rover/base_link')
        rover.sim.drain()
        transform = rover.tf[-1].transforms[0]
        assert (transform.header.frame_id, transform.child_frame_id) == ('rover/odom',
                                                                         'rover/base_link')
        assert transform.transform.translation.x == pytest.approx(
            odometry.pose.pose.position.x, abs=0.01)


def test_gz_odometry_publisher_gives_the_true_planar_pose(tmp_path):
    with running(tmp_path, GZ_DIFF_DRIVE, ground_truth=GZ_ODOMETRY, **GZ_TOPICS) as rover:
        truth = rover.sim.collect(Odometry, '/ground_truth')
        rover.sim.wait_for_subscribers('/ground_truth')
        rover.drive_one_metre()
        where, yaw = rover.true_pose()
        assert rover.sim.spin_until(lambda: truth), 'no odometry came from OdometryPublisher'
        rover.sim.drain()
        last = truth[-1]
        assert (last.header.frame_id, last.child_frame_id) == ('odom', 'base_link')
        position_ = last.pose.pose.position
        assert (position_.x, position_.y) == pytest.approx(where[:2], abs=1e-3)
        assert position_.z == 0.0  # dimensions 2


def _base_warnings(log: list[Log], what: str) -> list[str]:
    return [entry.msg for entry in log
            if entry.name == 'sim_node' and entry.level == Log.WARN and what in entry.msg]


def test_a_robot_turned_upside_down_keeps_simulating_and_says_it_tipped_over(tmp_path):
    with running(tmp_path, ROS2_DIFF_DRIVE) as rover:
        log = rover.sim.collect(Log, '/rosout', PROBE_QUEUE)
        states = rover.sim.collect(JointState, '/joint_states')
        rover.sim.wait_for_subscribers('/joint_states')
        rover.period()
        rover.command(0.2, 0.0)
        upside_down = PoseStamped()
        upside_down.header.frame_id = 'world'
        upside_down.pose.position.z = 0.3
        upside_down.pose.orientation.x, upside_down.pose.orientation.w = 1.0, 0.0
        assert rover.interfaces.set_entity_state(ROBOT, upside_down).result == OK
        before = rover.node.simulation.steps
        for _ in range(100):  # 1 s on its back, wheels spinning in the air
            odometry = rover.period()
        assert rover.node.simulation.steps == before + 100 * PERIOD_STEPS
        assert math.isfinite(odometry.pose.pose.position.x)
        count = len(states)
        rover.period()
        assert rover.sim.spin_until(lambda: len(states) > count), 'joint states stopped'
        rover.sim.drain()
        warnings = _base_warnings(log, 'tipped over')
        assert warnings, 'no warning that the robot tipped over'
        assert "robot 'rover' has tipped over" in warnings[0]
        assert len(warnings) <= 2  # throttled, not one per step


def test_far_out_on_the_ground_plane_the_robot_keeps_driving_the_ground_is_infinite(tmp_path):
    with running(tmp_path, ROS2_DIFF_DRIVE) as rover:
        log = rover.sim.collect(Log, '/rosout', PROBE_QUEUE)
        far = PoseStamped()
        far.header.frame_id = 'world'
        far.pose.position.x, far.pose.position.z = 5000.0, REST_HEIGHT
        assert rover.interfaces.set_entity_state(ROBOT, far).result == OK
        rover.period()
        rover.command(0.2, 0.0)
        for _ in range(200):  # 2 s
            odometry = rover.period()
        where, _ = rover.true_pose()
        assert where[0] == pytest.approx(5000.0 + 0.4 - 0.02, abs=0.03)  # 2 s, less the ramp
        assert where[2] == pytest.approx(REST_HEIGHT, abs=0.01)  # on the ground, not falling
        assert odometry.twist.twist.linear.x == pytest.approx(0.2, abs=0.01)
        rover.sim.drain()
        assert not (_base_warnings(log, 'tipped over') or _base_warnings(log, 'fell below')), (
            'a healthy robot far out got a warning')


def test_gz_joint_state_publisher_publishes_every_step_on_its_topic(tmp_path):
    with running(tmp_path, GZ_DIFF_DRIVE, ground_truth=GZ_ODOMETRY,
                 joint_states=GZ_JOINT_STATES, **GZ_TOPICS) as rover:
        states = rover.sim.collect(JointState, '/joint_states', PROBE_QUEUE)
        rover.sim.wait_for_subscribers('/joint_states')
        rover.period()
        rover.command(0.2, 0.0)
        for _ in range(5):
            rover.period()
        assert rover.sim.spin_until(lambda: len(states) >= 5 * PERIOD_STEPS), (
            f'{len(states)} joint states for {5 * PERIOD_STEPS} steps')
        assert list(states[-1].name) == ['left_wheel_joint', 'right_wheel_joint']
        assert states[-1].velocity[0] > 0.0
