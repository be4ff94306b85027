"""sim_node's messages agree with the world: /scan, /odom, /tf and GetEntityState, in sim time.

The robots and world of :mod:`consistency_fixtures` on sim_node, in-process,
paused and stepped from the probe, driven through their ROS command topics.
At each checkpoint (a lidar due time, so the last scan is of this instant):

* the last LaserScan's ranges are within 1 cm of the analytic distances
  (:mod:`world_truth`) from the lidar's true pose -- the robot entity's pose
  from simulation_interfaces' GetEntityState, carried to the lidar by the
  URDF's joints (the mast's from /joint_states);
* /tf's odom -> base transform is the last /odom pose (1 mm, 0.1 degree), and
  the odometry stays within 5 % of the distance driven from the true pose;
  the mast's /tf edges are its joint positions;
* every stamp is sim time (no later than /clock), and the newest sample of
  each stream is no older than one period of it.
"""

from __future__ import annotations

import math

import numpy
import pytest
from consistency_fixtures import (
    BASE_MOUNTS,
    DRIVES,
    LIDAR_MAX_ANGLE,
    LIDAR_MIN_ANGLE,
    LIDAR_RANGE,
    LIDAR_RATE,
    LIDAR_SAMPLES,
    MAST_CONTROLLER,
    MAST_JOINTS,
    MAST_MOUNTS,
    MAST_PAN_ORIGIN,
    MAST_TILT_ORIGIN,
    SHAPES,
    write_robot,
)
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from node_harness import PROBE_QUEUE, sim_node, stamp_s
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from sim_interfaces_client import SimInterfaces
from std_msgs.msg import Float64MultiArray
from tf2_msgs.msg import TFMessage
from world_truth import about_y, about_z, angle_between, first_hits, pose, quaternion_matrix

TIME_STEP = 0.001
SCAN_STEPS = round(1.0 / LIDAR_RATE / TIME_STEP)  # one lidar period
RANGE_TOLERANCE = 0.01  # m
EDGE = 0.005  # m: beams that hit something else in a world this much bigger or smaller graze
POSE_TOLERANCE = (0.001, math.radians(0.1))
ODOMETRY_DRIFT = 0.05  # of the distance driven
# s: each drive's odometry period: the plugin's 100 Hz, diff_drive_controller's publish_rate 50 Hz
ODOMETRY_PERIODS = {'gazebo_ros_diff_drive': 0.01, 'diff_drive_controller': 0.02}
CLOCK_PERIOD = 0.01  # s: sim_node's /clock at 100 Hz of sim time


def _matrix(message_pose) -> numpy.ndarray:
    p, q = message_pose.position, message_pose.orientation
    return pose((p.x, p.y, p.z), quaternion_matrix((q.x, q.y, q.z, q.w)))


def _transform(message) -> numpy.ndarray:
    t, q = message.transform.translation, message.transform.rotation
    return pose((t.x, t.y, t.z), quaternion_matrix((q.x, q.y, q.z, q.w)))


class Robot:
    """A matrix robot on sim_node, the probe's subscriptions and its truths."""

    def __init__(self, sim, drive: str, root: str, mount: str) -> None:
        self.sim, self.drive, self.root, self.mount = sim, drive, root, mount
        self.node = sim.node
        self.interfaces = SimInterfaces(sim)
        self.scans: list[LaserScan] = sim.collect(LaserScan, '/scan', PROBE_QUEUE)
        self.clock: list[Clock] = sim.collect(Clock, '/clock', PROBE_QUEUE)
        self.tf: list[TFMessage] = sim.collect(TFMessage, '/tf', PROBE_QUEUE)
        controller = DRIVES[drive].controller
        odometry = '/odom' if controller is None else f'/{controller}/odom'
        self.command_topic = '/cmd_vel' if controller is None else f'/{controller}/cmd_vel'
        self.odometry: list[Odometry] = sim.collect(Odometry, odometry, PROBE_QUEUE)
        for topic in ('/scan', odometry, '/tf'):
            sim.wait_for_subscribers(topic)
        stamped = controller is not None  # diff_drive_controller takes TwistStamped
        self.twist = sim.probe.create_publisher(TwistStamped if stamped else Twist,
                                                self.command_topic, 10)
        assert sim.spin_until(lambda: self.twist.get_subscription_count() > 0)
        self.mast = None
        if mount == 'mast':
            self.mast = sim.probe.create_publisher(
                Float64MultiArray, f'/{MAST_CONTROLLER}/commands', 10)
            assert sim.spin_until(lambda: self.mast.get_subscription_count() > 0)
        self.start = self.base_link_pose()
        self.driven = 0.0

    # --- truth ------------------------------------------------------------------------------------

    def root_pose(self) -> numpy.ndarray:
        """The robot entity's pose, from GetEntityState."""
        return _matrix(self.interfaces.entity_state(self.node.simulation.description.model.name)
                       .pose)

    def base_link_pose(self) -> numpy.ndarray:
        root = self.root_pose()
        if self.root == 'base_footprint':
            return root @ pose((0.0, 0.0, DRIVES[self.drive].rest_height))
        return root

    def mast_positions(self) -> tuple[float, float]:
        """The mast's joint positions, from the last /joint_states."""
        self.sim.drain()
        return tuple(self.sim.position(joint) for joint in MAST_JOINTS)

    def lidar_pose(self) -> numpy.ndarray:
        base = self.base_link_pose()
        if self.mount == 'base':
            return base @ pose(BASE_MOUNTS['lidar_link'])
        pan, tilt = self.mast_positions()
        return (base @ pose(MAST_PAN_ORIGIN, about_z(pan)) @ pose(MAST_TILT_ORIGIN, about_y(tilt))
                @ pose(MAST_MOUNTS['lidar_link']))

    # --- driving ----------------------------------------------------------------------------------

    def command(self, forward: float, turn: float) -> None:
        """Publish a twist; return once the drive took it."""
        counts = self.node.commands_received
        controller = DRIVES[self.drive].controller
        name = self.node.simulation.plugins[0].name if controller is None else controller
        before = counts[name]
        message = TwistStamped() if controller is not None else Twist()
        twist = message.twist if controller is not None else message
        twist.linear.x, twist.angular.z = forward, turn
        self.twist.publish(message)
        assert self.sim.spin_until(lambda: counts[name] > before), 'the twist never arrived'

    def point_mast(self, pan: float, tilt: float) -> None:
        counts = self.node.commands_received
        before = counts[MAST_CONTROLLER]
        self.mast.publish(Float64MultiArray(data=[pan, tilt]))
        assert self.sim.spin_until(lambda: counts[MAST_CONTROLLER] > before)

    def scan_periods(self, count: int, forward: float = 0.0, turn: float = 0.0) -> None:
        """Run ``count`` lidar periods, the twist sent again every 0.1 s (a teleop's pace)."""
        for _ in range(count):
            before = self.base_link_pose()[:3, 3]
            for _ in range(2):
                self.command(forward, turn)
                self.node.step(SCAN_STEPS // 2)
            self.driven += float(numpy.linalg.norm(self.base_link_pose()[:3, 3] - before))
        self.sim.drain()

    # --- checks -----------------------------------------------------------------------------------

    def check(self, where: str) -> list[str]:
        failures = []
        now = self.node.simulation.time
        scan = self.scans[-1]
        clock = stamp_s(self.clock[-1])
        if abs(clock - now) > CLOCK_PERIOD + 1e-9:
            failures.append(f'{where}: /clock says {clock} s at sim time {now} s')
        for name, stream, period in (('/scan', self.scans, 1.0 / LIDAR_RATE),
                                     ('odometry', self.odometry, ODOMETRY_PERIODS[self.drive])):
            newest = stamp_s(stream[-1])
            if not now - period - 1e-9 <= newest <= now + 1e-9:
                failures.append(f'{where}: the newest {name} is stamped {newest} s at sim time '
                                f'{now} s (period {period} s)')
        failures += self._check_scan(where, scan)
        failures += self._check_odometry(where)
        return failures

    def _check_scan(self, where: str, scan: LaserScan) -> list[str]:
        lidar = self.lidar_pose()
        angles = numpy.linspace(LIDAR_MIN_ANGLE, LIDAR_MAX_ANGLE, LIDAR_SAMPLES)
        directions = numpy.stack([numpy.cos(angles), numpy.sin(angles),
                                  numpy.zeros_like(angles)], axis=-1) @ lidar[:3, :3].T
        origin = lidar[:3, 3]
        low, high = LIDAR_RANGE

        def truth(grow: float):
            hits, which = first_hits(origin, directions, SHAPES, grow)
            seen = (hits >= low) & (hits <= high)
            return numpy.where(seen, hits, numpy.inf), numpy.where(seen, which, -2)

        (exact, _), (_, bigger), (_, smaller) = truth(0.0), truth(EDGE), truth(-EDGE)
        measured = numpy.array(scan.ranges, dtype=float)
        with numpy.errstate(invalid='ignore'):
            right = (measured == exact) | (numpy.abs(measured - exact) <= RANGE_TOLERANCE)
        wrong = numpy.flatnonzero(~right & (bigger == smaller))
        if not wrong.size:
            return []
        beam = wrong[0]
        return [f'{where}: {wrong.size} beams of /scan wrong, e.g. beam {beam} reads '
                f'{measured[beam]:.3f} m where {exact[beam]:.3f} m is right (lidar at '
                f'{numpy.round(origin, 3).tolist()})']

    def _check_odometry(self, where: str) -> list[str]:
        failures = []
        odometry = self.odometry[-1]
        found = _matrix(odometry.pose.pose)
        edges = [transform for message in self.tf for transform in message.transforms
                 if transform.header.frame_id == odometry.header.frame_id
                 and transform.child_frame_id == odometry.child_frame_id]
        if not edges:
            failures.append(f'{where}: no /tf {odometry.header.frame_id} -> '
                            f'{odometry.child_frame_id}')
        else:
            transform = _transform(edges[-1])
            offset = float(numpy.linalg.norm(transform[:3, 3] - found[:3, 3]))
            if offset > POSE_TOLERANCE[0] or angle_between(transform, found) > POSE_TOLERANCE[1]:
                failures.append(f'{where}: /tf odom edge is {offset * 1000:.1f} mm from /odom')
            if stamp_s(edges[-1]) != stamp_s(odometry):
                failures.append(f'{where}: /tf odom edge stamped {stamp_s(edges[-1])} s, '
                                f'/odom {stamp_s(odometry)} s')
        point = pose((DRIVES[self.drive].odometry_point, 0.0, 0.0))
        truth = numpy.linalg.inv(self.start @ point) @ self.base_link_pose() @ point
        drift = float(numpy.linalg.norm(truth[:2, 3] - found[:2, 3]))
        if drift > max(0.01, ODOMETRY_DRIFT * self.driven):
            failures.append(f'{where}: /odom {numpy.round(found[:2, 3], 3)} is {drift:.3f} m from '
                            f'the true pose {numpy.round(truth[:2, 3], 3)}')
        if self.mount == 'mast':
            pan, tilt = self.mast_positions()
            mast = {transform.child_frame_id: _transform(transform)
                    for message in self.tf for transform in message.transforms}
            for link, expected in (('mast_pan_link', pose(MAST_PAN_ORIGIN, about_z(pan))),
                                   ('mast_tilt_link', pose(MAST_TILT_ORIGIN, about_y(tilt)))):
                if link not in mast or angle_between(mast[link], expected) > POSE_TOLERANCE[1]:
                    failures.append(f'{where}: /tf {link} is not where /joint_states puts it')
        return failures


@pytest.mark.parametrize(('drive', 'root', 'mount'), [
    ('gazebo_ros_diff_drive', 'base_footprint', 'base'),  # the TurtleBot3-style rover
    ('diff_drive_controller', 'base_link', 'mast'),
], ids=['turtlebot_style', 'ros2_control_mast'])
def test_scan_odom_tf_and_the_true_pose_agree_driving_out_and_back(tmp_path, drive, root, mount):
    urdf, controllers, world = write_robot(tmp_path, drive, root, mount)
    parameters = {'controllers_file': str(controllers)} if controllers else {}
    with sim_node(paused=True, time_step=TIME_STEP, robot_description_file=str(urdf),
                  world=str(world), **parameters) as sim:
        robot = Robot(sim, drive, root, mount)
        robot.scan_periods(1)
        failures = robot.check('start')
        if robot.mast is not None:
            robot.point_mast(0.7, -0.05)
        robot.scan_periods(10, forward=0.2)  # 2 s out
        failures += robot.check('driving out')
        robot.scan_periods(5, forward=0.2, turn=0.5)
        failures += robot.check('arc')
        robot.scan_periods(8, forward=-0.2)  # and back
        failures += robot.check('driving back')
        robot.scan_periods(3)
        failures += robot.check('stopped')
        assert not failures, '\n'.join(failures)
