"""The rig's URDF sensors through sim_node: topics, frames, values, rates, cost while unwatched."""

import math

import numpy
import pytest
from geometry_msgs.msg import WrenchStamped
from node_harness import PROBE_QUEUE, sim_node, stamp_s
from sensor_fixtures import (
    DEPTH_FOV,
    DEPTH_HEIGHT,
    DEPTH_WIDTH,
    FRAMES,
    HANG_MASS,
    IMU_RATE,
    LIDAR_HALF_ANGLE,
    LIDAR_RESOLUTION,
    LIDAR_SAMPLES,
    TOPICS,
    WALL_X,
    write_sensor_rig,
)
from sensor_msgs.msg import CameraInfo, Image, Imu, LaserScan, PointCloud2
from std_msgs.msg import Float64

from pan_tilt_sim.model.sensors import OPTICAL_ROTATION
from pan_tilt_sim.sim.physics import STANDARD_GRAVITY

ONE_PERCENT = 0.01
SAME_TIME = 1e-6
MESSAGE_TYPES = {'depth': Image, 'depth_info': CameraInfo, 'image': Image,
                 'camera_info': CameraInfo, 'points': PointCloud2, 'scan': LaserScan,
                 'imu': Imu, 'wrench': WrenchStamped}


@pytest.fixture
def rig_files(tmp_path):
    return write_sensor_rig(tmp_path)


@pytest.fixture
def rig(rig_files):
    urdf, controllers = rig_files
    with sim_node(robot_description_file=str(urdf), controllers_file=str(controllers),
                  world='empty', **{'sensors.noise_seed': 1}) as sim:
        yield sim


def listen(sim, *roles):
    """Subscribe the probe to the rig's topics of ``roles``; wait until sim_node sees it."""
    received = {role: sim.collect(MESSAGE_TYPES[role], TOPICS[role], PROBE_QUEUE)
                for role in roles}
    for role in roles:
        sim.wait_for_subscribers(TOPICS[role])
    return received


def floats(message, rows: int, columns: int, channels: int = 1) -> numpy.ndarray:
    shape = (rows, columns, channels) if channels > 1 else (rows, columns)
    return numpy.frombuffer(bytes(message.data), '<f4').reshape(shape)


def test_depth_image_and_point_cloud_see_the_wall_at_its_distance(rig):
    got = listen(rig, 'depth', 'depth_info', 'points', 'image')
    rig.run_for(0.35)
    for role in ('depth', 'depth_info', 'points', 'image'):
        assert got[role], f'nothing on {TOPICS[role]}'
        assert {m.header.frame_id for m in got[role]} == {FRAMES['depth']}
    depth = got['depth'][-1]
    assert (depth.encoding, depth.width, depth.height) == ('32FC1', DEPTH_WIDTH, DEPTH_HEIGHT)
    assert depth.step == 4 * DEPTH_WIDTH and depth.is_bigendian == 0
    values = floats(depth, DEPTH_HEIGHT, DEPTH_WIDTH)
    assert numpy.abs(values - WALL_X).max() <= ONE_PERCENT * WALL_X
    info = got['depth_info'][-1]
    focal = (DEPTH_WIDTH / 2) / math.tan(DEPTH_FOV / 2)
    assert info.k[0] == pytest.approx(focal) and info.k[4] == pytest.approx(focal)
    cloud = got['points'][-1]
    assert [field.name for field in cloud.fields] == ['x', 'y', 'z', 'rgb']
    assert (cloud.height, cloud.width, cloud.point_step) == (DEPTH_HEIGHT, DEPTH_WIDTH, 16)
    points = floats(cloud, DEPTH_HEIGHT, DEPTH_WIDTH, 4)
    assert numpy.abs(points[:, :, 2] - WALL_X).max() <= ONE_PERCENT * WALL_X
    # x right, y down (REP 103 optical): the image's left column is at negative x.
    cx, cy = (DEPTH_WIDTH - 1) / 2, (DEPTH_HEIGHT - 1) / 2
    assert points[0, 0, 0] == pytest.approx(-cx / focal * WALL_X, rel=ONE_PERCENT)
    assert points[0, 0, 1] == pytest.approx(-cy / focal * WALL_X, rel=ONE_PERCENT)
    assert got['image'][-1].encoding == 'rgb8'
    # Frames on the 10 Hz grid of sim time.
    stamps = [stamp_s(m) for m in got['depth']]
    assert all(abs(s * 10 - round(s * 10)) < SAME_TIME for s in stamps)


def test_the_urdfs_depth_camera_turns_the_parameter_camera_off(rig):
    assert rig.node.features.camera is None


def test_lidar_scan_sees_the_wall_ahead_and_nothing_past_its_edges(rig):
    got = listen(rig, 'scan')
    rig.run_for(0.2)
    scan = got['scan'][-1]
    assert scan.header.frame_id == FRAMES['scan']
    assert (scan.angle_min, scan.angle_max) == pytest.approx((-LIDAR_HALF_ANGLE,
                                                              LIDAR_HALF_ANGLE))
    assert len(scan.ranges) == LIDAR_SAMPLES
    assert scan.angle_increment == pytest.approx(2 * LIDAR_HALF_ANGLE / (LIDAR_SAMPLES - 1))
    assert abs(scan.ranges[LIDAR_SAMPLES // 2] - WALL_X) <= LIDAR_RESOLUTION
    assert math.isinf(scan.ranges[0]) and scan.ranges[0] > 0
    assert math.isinf(scan.ranges[-1]) and scan.ranges[-1] > 0
    assert scan.scan_time == pytest.approx(1 / 20)


def test_imu_reads_gravity_at_rest_every_sample_at_its_200_hz(rig):
    got = listen(rig, 'imu')
    rig.run_for(0.3)
    messages = got['imu']
    assert {m.header.frame_id for m in messages} == {FRAMES['imu']}
    stamps = [stamp_s(m) for m in messages]
    gaps = numpy.diff(stamps)
    assert len(messages) > 30
    # Above the /clock rate (100 Hz): sim_node stops between /clock messages for it.
    assert gaps == pytest.approx(1 / IMU_RATE, abs=SAME_TIME)
    last = messages[-1].linear_acceleration
    assert (last.x, last.y, last.z) == pytest.approx((0.0, 0.0, STANDARD_GRAVITY), abs=1e-6)


def test_imu_on_the_turning_joint_reads_its_rate(rig):
    got = listen(rig, 'imu')
    rig.command('spin_controller', Float64(data=2.0))
    rig.run_for(2.0)
    last = got['imu'][-1]
    assert last.angular_velocity.z == pytest.approx(2.0, rel=ONE_PERCENT)
    rate = last.angular_velocity.z
    assert last.linear_acceleration.x == pytest.approx(-rate * rate * 0.5, rel=ONE_PERCENT)


def test_force_torque_reads_the_hanging_weight(rig):
    got = listen(rig, 'wrench')
    rig.run_for(0.2)
    wrench = got['wrench'][-1]
    assert wrench.header.frame_id == FRAMES['wrench']
    assert wrench.wrench.force.z == pytest.approx(HANG_MASS * STANDARD_GRAVITY,
                                                  rel=ONE_PERCENT)
    stamps = [stamp_s(m) for m in got['wrench']]
    assert numpy.diff(stamps) == pytest.approx(1 / 50, abs=SAME_TIME)


def test_nothing_is_measured_while_nobody_listens(rig):
    rig.run_for(0.5)
    publishers = rig.node.features.sensors.publishers
    assert [publisher.messages for publisher in publishers] == [0, 0, 0, 0]
    force_torque = next(p for p in publishers if p.sensor.name == 'ft').force_torque
    assert not force_torque.enabled  # PyBullet's joint feedback costs every step
    listen(rig, 'wrench')
    rig.run_for(0.2)
    assert force_torque.enabled
    counts = {p.sensor.name: p.messages for p in publishers}
    assert counts['ft'] > 0
    assert counts['depth_camera'] == counts['laser'] == counts['imu'] == 0
    assert [p.cost_per_message > 0 for p in publishers] == [False, False, False, True]


def test_a_frame_the_urdf_lacks_gets_a_static_transform_from_the_sensor_link(rig):
    frames = {child: (parent, pose)
              for parent, child, pose in rig.node.features.robot_state.static_frames}
    parent, pose = frames['front_optical']
    assert parent == 'camera_link'
    assert pose.rotation == pytest.approx(OPTICAL_ROTATION)
    assert 'lidar_link' not in frames or frames['lidar_link'][0] == 'base_link'  # a URDF link


def test_reset_starts_every_sensor_schedule_again(rig):
    got = listen(rig, 'wrench')
    rig.run_for(0.3)
    rig.node.reset()
    rig.run_for(0.05)
    stamps = [stamp_s(m) for m in got['wrench']]
    restart = next(index for index in range(1, len(stamps)) if stamps[index] < stamps[index - 1])
    assert stamps[restart] == pytest.approx(0.0, abs=SAME_TIME)
    assert stamps[restart + 1] == pytest.approx(0.02, abs=SAME_TIME)


def test_force_torque_feedback_is_switched_off_when_the_last_listener_leaves(rig):
    force_torque = next(p for p in rig.node.features.sensors.publishers
                        if p.sensor.name == 'ft').force_torque
    received = []
    subscription = rig.probe.create_subscription(WrenchStamped, TOPICS['wrench'],
                                                 received.append, PROBE_QUEUE)
    assert rig.spin_until(lambda: len(received) > 2), 'no wrench arrived'
    assert force_torque.enabled
    rig.probe.destroy_subscription(subscription)
    assert rig.spin_until(lambda: not force_torque.enabled), 'feedback stayed on'
