"""An SDF robot in an SDF world on sim_node: gz-sim's topics, driving, and a lidar that sees.

The rover of test/support/sdf_fixtures.py (gz-sim's DiffDrive and JointStatePublisher,
a gpu_lidar, an IMU, a ball caster) in an SDF world of a ground plane and
static cylinders, in-process, paused, at real_time_factor 0.
"""

from __future__ import annotations

import math
import statistics

import pytest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from node_harness import PROBE_QUEUE, sim_node
from sdf_fixtures import LIDAR_RANGE, cylinders_world, rover_sdf, write
from sensor_msgs.msg import Imu, JointState, LaserScan
from sim_interfaces_client import SimInterfaces, position

from pan_tilt_sim.model.physics_settings import PhysicsSettings

CYLINDERS = [(2.0, 0.0, 0.3), (0.0, 1.5, 0.2), (-1.2, -1.2, 0.25)]
WORLD_STEP = 0.002  # s: the world's <max_step_size>
SCAN_TOLERANCE = 0.01  # m: the median beam's range against the analytic one
GRAZE = 0.01  # m


def expected_range(origin: tuple[float, float], heading: float, angle: float,
                   grow: float = 0.0) -> float:
    """The range along a beam from ``origin`` to the nearest cylinder, inf when none.

    ``grow`` (m) widens every cylinder: a beam that misses them all by that much misses.
    """
    direction = (math.cos(heading + angle), math.sin(heading + angle))
    best = math.inf
    for cx, cy, radius in CYLINDERS:
        # |o + t d - c| = r, the smaller root t > 0
        ox, oy = origin[0] - cx, origin[1] - cy
        b = ox * direction[0] + oy * direction[1]
        c = ox * ox + oy * oy - (radius + grow) ** 2
        disc = b * b - c
        if disc < 0.0:
            continue
        t = -b - math.sqrt(disc)
        if t > 0.0:
            best = min(best, t)
    return best


@pytest.fixture
def rover(tmp_path):
    robot = write(tmp_path / 'rover.sdf', rover_sdf())
    world = write(tmp_path / 'pillars.sdf', cylinders_world(CYLINDERS, step=WORLD_STEP))
    with sim_node(paused=True, robot_description_file=str(robot), world=str(world)) as sim:
        yield sim


def test_the_worlds_step_and_the_sdfs_topics(rover):
    assert rover.node.settings.time_step == WORLD_STEP
    assert rover.node.get_parameter('time_step').value == WORLD_STEP
    published, subscribed = rover.own_topics()
    assert subscribed['/cmd_vel'] == 'geometry_msgs/msg/Twist'
    for topic, kind in (('/odom', 'nav_msgs/msg/Odometry'), ('/tf', 'tf2_msgs/msg/TFMessage'),
                        ('/scan', 'sensor_msgs/msg/LaserScan'), ('/imu', 'sensor_msgs/msg/Imu'),
                        ('/joint_states', 'sensor_msgs/msg/JointState')):
        assert published[topic] == kind, topic


def test_a_parameter_wins_over_the_worlds_physics(tmp_path):
    robot = write(tmp_path / 'rover.sdf', rover_sdf())
    world = write(tmp_path / 'pillars.sdf', cylinders_world(CYLINDERS, step=WORLD_STEP))
    with sim_node(paused=True, robot_description_file=str(robot), world=str(world),
                  time_step=0.001) as sim:
        assert sim.node.settings.time_step == 0.001


def test_it_drives_on_cmd_vel_and_its_scan_sees_the_cylinders_where_they_are(rover):
    scans = rover.collect(LaserScan, '/scan', PROBE_QUEUE)
    odometry = rover.collect(Odometry, '/odom', PROBE_QUEUE)
    imu = rover.collect(Imu, '/imu', PROBE_QUEUE)
    states = rover.collect(JointState, '/joint_states', PROBE_QUEUE)
    twist = rover.probe.create_publisher(Twist, '/cmd_vel', 10)
    for topic in ('/scan', '/odom', '/imu', '/joint_states'):
        rover.wait_for_subscribers(topic)
    assert rover.spin_until(lambda: twist.get_subscription_count() > 0)

    def send(linear: float, angular: float) -> None:
        before = sum(rover.node.commands_received.values())
        command = Twist()
        command.linear.x, command.angular.z = linear, angular
        twist.publish(command)
        assert rover.spin_until(lambda: sum(rover.node.commands_received.values()) > before)

    send(0.3, 0.4)
    for _ in range(20):  # 2 s, a tenth of a second at a time
        rover.node.step(50)
        rover.spin_until(lambda: False, 0.02)
    assert rover.spin_until(lambda: odometry and imu and states and len(scans) >= 2)
    interfaces = SimInterfaces(rover)
    x, y, _z = position(interfaces.entity_state('sdf_rover'))
    assert math.hypot(x, y) > 0.3, 'the rover did not drive'
    assert odometry[-1].pose.pose.position.x > 0.3
    assert set(states[-1].name) == {'left_wheel_joint', 'right_wheel_joint'}
    # gz-sim's DiffDrive holds the last command: a zero twist stops the rover, and the
    # newest scan is compared with the cylinders from where it stands.
    send(0.0, 0.0)
    rover.node.step(500)
    count = len(scans)
    rover.node.step(150)
    assert rover.spin_until(lambda: len(scans) > count)
    scan = scans[-1]
    state = interfaces.entity_state('sdf_rover')
    q = state.pose.orientation
    heading = 2.0 * math.atan2(q.z, q.w)
    x, y, _z = position(state)
    assert scan.header.frame_id == 'lidar' and len(scan.ranges) == 360
    errors = []
    for index, measured in enumerate(scan.ranges):
        angle = scan.angle_min + index * scan.angle_increment
        # Beams within a centimetre of a cylinder's edge graze it: they count neither way.
        if math.isfinite(expected_range((x, y), heading, angle, -GRAZE)):
            errors.append(abs(measured - expected_range((x, y), heading, angle)))
        elif not math.isfinite(expected_range((x, y), heading, angle, GRAZE)):
            assert not math.isfinite(measured) or measured >= LIDAR_RANGE[1], (index, measured)
    assert len(errors) > 20
    assert statistics.median(errors) < SCAN_TOLERANCE


def test_the_worlds_constraints_set_the_solver_parameters_unless_they_are_given(tmp_path,
                                                                               capfd):
    world = write(tmp_path / 'solver.sdf', (
        '<sdf version="1.9"><world name="w"><physics type="ode"><ode><solver><iters>20</iters>'
        '<sor>1.3</sor></solver><constraints><erp>0.5</erp><cfm>0.00001</cfm>'
        '<contact_surface_layer>0.001</contact_surface_layer></constraints></ode></physics>'
        '</world></sdf>'))
    with sim_node(paused=True, world=str(world), cfm=0.0) as sim:
        assert sim.simulation.physics.settings == PhysicsSettings(
            solver_iterations=20, erp=0.5, contact_erp=0.5, cfm=0.0, contact_slop=0.001)
        assert sim.node.get_parameter('contact_erp').value == 0.5
    lines = [line for line in capfd.readouterr().err.splitlines() if 'physics: ' in line]
    assert len(lines) == 1
    assert lines[0].endswith(
        "physics: solver_iterations 20 (the world's <physics>); erp 0.5 (the world's "
        "<physics>); contact_erp 0.5 (the world's <physics>); cfm 0.0 (the parameter; the "
        "world's <physics> says 1e-05); contact_slop 0.001 (the world's <physics>); no "
        'PyBullet counterpart, not simulated: <ode><solver><sor>')
