"""A robot driven by Gazebo's diff drive plugin on sim_node: cmd_vel, odom and TF, no controllers.

The rover of test/mobile_fixtures.py with a ``libgazebo_ros_diff_drive.so``
plugin, a ``libgazebo_ros_p3d.so`` on ``/ground_truth`` and a lidar,
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
from geometry_msgs.msg import Twist
from mobile_fixtures import REST_HEIGHT, ROS1_DIFF_DRIVE, ROS2_DIFF_DRIVE, plugin_rover_urdf
from nav_msgs.msg import Odometry
from node_harness import sim_node
from sensor_msgs.msg import JointState, LaserScan
from sim_interfaces_client import SimInterfaces, position
from tf2_msgs.msg import TFMessage

TIME_STEP = 0.001
PERIOD_STEPS = 10  # one update of the plugin at its update rate of 100 Hz
# m past 1 m once stopped: braking from 0.2 m/s at the fixture's 1 m/s^2 wheel acceleration
# takes 0.02 m, plus up to one update at speed.
OVERRUN = 0.02 + 0.2 * 0.01
MAX_PERIODS = 1000  # 10 s of sim time: twice what 1 m at 0.2 m/s takes
ROBOT = 'rover'


class PluginRover:
    """The plugin-driven rover on sim_node, driven from the probe one update at a time."""

    def __init__(self, sim) -> None:
        self.sim = sim
        self.node = sim.node
        self.odometry: list[Odometry] = sim.collect(Odometry, '/odom')
        self.tf: list[TFMessage] = sim.collect(TFMessage, '/tf')
        self.interfaces = SimInterfaces(sim)
        self.twist = sim.probe.create_publisher(Twist, '/cmd_vel', 10)
        sim.wait_for_subscribers('/odom')
        sim.wait_for_subscribers('/tf')
        assert sim.spin_until(lambda: self.twist.get_subscription_count() > 0), (
            'sim_node does not subscribe /cmd_vel')
        self.node.step(1)  # from here on each period() holds one of the plugin's updates

    def command(self, linear: float, angular: float) -> None:
        """Publish a Twist on ``/cmd_vel``; return once the plugin took it."""
        counts = self.node.commands_received
        name = self.node.simulation.plugins[0].name
        before = counts[name]
        message = Twist()
        message.linear.x, message.angular.z = linear, angular
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
def running(folder, plugin: str, world: str = 'ground') -> Iterator[PluginRover]:
    """Run the plugin rover on sim_node (no controllers file) in ``world``."""
    description = folder / 'rover.urdf'
    description.write_text(plugin_rover_urdf(plugin), encoding='utf-8')
    with sim_node(paused=True, time_step=TIME_STEP, robot_description_file=str(description),
                  world=world) as sim:
        yield PluginRover(sim)


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
