"""URDF sensors in the simulation, against the rig's truth (test/support/sensor_fixtures.py)."""

import math
import pathlib
import textwrap

import numpy
import pytest
from sensor_fixtures import (
    CAMERA_Z,
    HANG_DROP,
    HANG_MASS,
    IMU_RADIUS,
    LIDAR_RESOLUTION,
    LIDAR_Z,
    WALL_HALF,
    WALL_X,
    write_sensor_rig,
)

from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.sensors import (
    CHILD,
    CHILD_TO_PARENT,
    PARENT,
    PARENT_TO_CHILD,
    SENSOR,
    Noise,
    SensorSpec,
)
from pan_tilt_sim.model.transforms import rotation_matrix
from pan_tilt_sim.sim.engine import Simulation, make_simulation
from pan_tilt_sim.sim.physics import STANDARD_GRAVITY
from pan_tilt_sim.sim.sensors.force_torque import ForceTorque
from pan_tilt_sim.sim.sensors.imu import Imu
from pan_tilt_sim.sim.sensors.lidar import MAX_BATCH, Lidar
from pan_tilt_sim.sim.sensors.noise import NoiseModel, generator
from pan_tilt_sim.sim.sensors.vision import VisionSensor, linear_depth

TIME_STEP = 0.001
ONE_PERCENT = 0.01
SPIN_RATE = 2.0  # rad/s


@pytest.fixture(scope='module')
def rig(tmp_path_factory):
    """Return the rig's simulation (world 'empty': only the rig itself)."""
    urdf, controllers = write_sensor_rig(tmp_path_factory.mktemp('rig'))
    simulation = make_simulation(str(urdf), str(controllers), TIME_STEP)
    yield simulation
    simulation.close()


def sensor(simulation: Simulation, name: str) -> SensorSpec:
    return next(s for s in simulation.description.model.sensors if s.name == name)


def model(simulation: Simulation) -> RobotModel:
    return simulation.description.model


# --- depth camera -------------------------------------------------------------------------------

def test_depth_camera_facing_a_wall_measures_its_distance_within_one_percent(rig):
    camera = VisionSensor(rig.physics, sensor(rig, 'depth_camera'), 'empty')
    view = camera.render()
    assert view.depth.shape == (48, 64)
    # Planar depth: the same for every pixel on a wall facing the camera.
    assert numpy.abs(view.depth - WALL_X).max() <= ONE_PERCENT * WALL_X
    assert view.rgb.shape == (48, 64, 3)


@pytest.mark.parametrize(('yaw', 'pitch'), [(0.5, 0.0), (0.0, 0.4), (-0.4, -0.3)])
def test_each_pixel_sees_along_the_ray_its_published_intrinsics_give(rig, yaw, pitch):
    # Turned to the wall, the depth changes across the image: a pixel that looked half a
    # pixel off its CameraInfo ray (TinyRenderer's own principal point is w/2, h/2) reads
    # a depth 2 % off at this size.
    from dataclasses import replace

    from pan_tilt_sim.model.transforms import Transform, quaternion_from_rpy

    spec = sensor(rig, 'depth_camera')
    turned = replace(spec, pose=Transform(rotation=quaternion_from_rpy(0.0, pitch, yaw)))
    camera = VisionSensor(rig.physics, turned, 'empty')
    optical = numpy.array(rotation_matrix(camera.optical_pose().rotation))
    intrinsics = camera.intrinsics
    u, v = numpy.meshgrid((numpy.arange(64) - intrinsics.cx) / intrinsics.fx,
                          (numpy.arange(48) - intrinsics.cy) / intrinsics.fy)
    rays = numpy.stack([u, v, numpy.ones_like(u)], axis=-1) @ optical.T  # world, z_optical = 1
    # The wall's face is the plane x = WALL_X; the camera is at the origin's x.
    expected = WALL_X / rays[..., 0]
    view = camera.render()
    seen = numpy.isfinite(view.depth)
    assert seen.sum() > 1000
    assert numpy.abs(view.depth[seen] - expected[seen]).max() <= 1e-3 * WALL_X


@pytest.mark.parametrize(('near', 'far'), [(0.01, 100.0), (0.5, 3.0), (1.9, 2.2)])
def test_depth_is_linearised_from_the_depth_buffer_whatever_the_clip_planes(rig, near, far):
    spec = sensor(rig, 'depth_camera')
    from dataclasses import replace

    clipped = replace(spec, camera=replace(spec.camera, near=near, far=far))
    view = VisionSensor(rig.physics, clipped, 'empty').render()
    assert numpy.abs(view.depth - WALL_X).max() <= ONE_PERCENT * WALL_X


def test_depth_buffer_linearisation_inverts_the_opengl_projection():
    near, far = 0.1, 10.0
    for z in (0.1, 0.5, 2.0, 9.9):
        # OpenGL: z_ndc = (far + near) / (far - near) - 2 far near / ((far - near) z)
        ndc = (far + near) / (far - near) - 2 * far * near / ((far - near) * z)
        assert linear_depth(numpy.array((ndc + 1) / 2), near, far) == pytest.approx(z)


def test_nothing_in_view_is_infinitely_far(rig):
    from dataclasses import replace

    spec = sensor(rig, 'depth_camera')
    backwards = replace(spec, pose=replace(spec.pose, rotation=(0.0, 0.0, 1.0, 0.0)))
    view = VisionSensor(rig.physics, backwards, 'empty').render()
    assert numpy.isinf(view.depth).all()


def test_a_ground_in_the_world_has_its_depth(rig):
    from dataclasses import replace

    spec = sensor(rig, 'depth_camera')
    # Look straight down from CAMERA_Z: pitch +90 degrees turns +x to -z.
    down = replace(spec, pose=replace(spec.pose, rotation=(0.0, math.sqrt(0.5), 0.0,
                                                           math.sqrt(0.5))))
    view = VisionSensor(rig.physics, down, 'targets').render()
    # The base link has no visual; the ground is at z = 0, CAMERA_Z below.
    centre = view.depth[22:26, 30:34]
    assert numpy.abs(centre - CAMERA_Z).max() <= ONE_PERCENT * CAMERA_Z


# The clip ranges and sizes users declare: Gazebo's defaults (320x240, 0.1-100 m), and
# 160x120 to 1280x720 with near 0.02-0.1 m and far 10-100 m.  TinyRenderer's "nothing
# drawn" depth is 1.0 give or take a float32 step or two, depending on near and far.
GROUND_CLIPS = [(0.1, 100.0), (0.02, 10.0), (0.05, 10.0), (0.1, 10.0), (0.02, 100.0),
                (0.05, 30.0)]
GROUND_PITCHES = [0.3, 0.8, math.pi / 2]  # rad below horizontal; pi/2: straight down
GROUND_HEIGHT = 1.2  # m: the camera above the ground


def _ground_view(rig, width, height, near, far, pitch):
    """Render a depth camera GROUND_HEIGHT above the ground, facing away from the wall."""
    from dataclasses import replace

    from pan_tilt_sim.model.transforms import Transform, quaternion_from_rpy

    spec = sensor(rig, 'depth_camera')
    # Declared the gazebo_ros way: on the link, +x forward, pitched down by `pitch`,
    # turned to look along -x (the wall is at +x).
    pose = Transform((0.0, 0.0, GROUND_HEIGHT - CAMERA_Z), quaternion_from_rpy(0.0, pitch, math.pi))
    declared = replace(spec, pose=pose, camera=replace(spec.camera, width=width, height=height,
                                                       near=near, far=far))
    return VisionSensor(rig.physics, declared, 'ground')


def _expected_ground_depth(camera: VisionSensor, pitch: float) -> numpy.ndarray:
    """Planar depth of the plane z = 0 for each pixel (inf where the ray misses it)."""
    # Optical ray (x, y, 1) with y down: its world z is -sin(pitch) - y cos(pitch).
    intrinsics = camera.intrinsics
    rows = (numpy.arange(camera.camera.height) - intrinsics.cy) / intrinsics.fy
    falling = math.sin(pitch) + rows * math.cos(pitch)
    with numpy.errstate(divide='ignore'):
        column = numpy.where(falling > 0.0, GROUND_HEIGHT / falling, math.inf)
    return numpy.repeat(column[:, numpy.newaxis], camera.camera.width, axis=1)


def _assert_the_ground_has_its_depth_and_colour(view, expected, far):
    from pan_tilt_sim.sim.world import GROUND_RGB

    seen = expected < 0.99 * far  # clear of the far plane's own margin
    assert seen.any()
    error = numpy.abs(view.depth[seen] - expected[seen]) / expected[seen]
    assert error.max() <= ONE_PERCENT, (
        f'{(error > ONE_PERCENT).sum()} of {seen.sum()} ground pixels off; '
        f'worst reads {view.depth[seen][error.argmax()]:.3f} m for '
        f'{expected[seen][error.argmax()]:.3f} m')
    assert (view.rgb[seen] == GROUND_RGB).all()


@pytest.mark.parametrize(('near', 'far'), GROUND_CLIPS)
def test_the_ground_has_its_depth_whatever_the_clip_range_and_pitch(rig, near, far):
    for pitch in GROUND_PITCHES:
        camera = _ground_view(rig, 160, 120, near, far, pitch)
        _assert_the_ground_has_its_depth_and_colour(
            camera.render(), _expected_ground_depth(camera, pitch), far)


@pytest.mark.parametrize(('width', 'height'), [(160, 120), (320, 240), (640, 480), (1280, 720)])
def test_the_ground_has_its_depth_at_every_image_size(rig, width, height):
    near, far = 0.05, 10.0
    for pitch in (0.5, math.pi / 2):
        camera = _ground_view(rig, width, height, near, far, pitch)
        _assert_the_ground_has_its_depth_and_colour(
            camera.render(), _expected_ground_depth(camera, pitch), far)


def test_pybullet_renders_a_clip_ratio_at_the_models_limit_and_nothing_but_nan_at_1e8(rig):
    from pan_tilt_sim.model.sensors import MAX_CLIP_RATIO

    near = 0.01
    at_limit = _ground_view(rig, 32, 24, near, near * MAX_CLIP_RATIO, math.pi / 2).render()
    assert not numpy.isnan(at_limit.depth).any()
    assert numpy.isfinite(at_limit.depth).any()  # the ground is seen
    beyond = _ground_view(rig, 32, 24, near, near * 1e8, math.pi / 2).render()
    assert numpy.isnan(beyond.depth).all()


# --- lidar --------------------------------------------------------------------------------------

def test_lidar_centre_beam_meets_the_wall_within_the_declared_resolution(rig):
    lidar = Lidar(rig.physics, sensor(rig, 'laser'), 'empty')
    ranges = lidar.scan()
    assert ranges.shape == (1, 121)
    assert abs(ranges[0, 60] - WALL_X) <= LIDAR_RESOLUTION


def test_lidar_beams_meet_the_wall_at_their_slant_and_see_nothing_past_its_edges(rig):
    lidar = Lidar(rig.physics, sensor(rig, 'laser'), 'empty')
    ranges = lidar.scan()[0]
    angles = numpy.array(lidar.ray.horizontal.angles())
    on_wall = numpy.abs(numpy.tan(angles)) * WALL_X < WALL_HALF - 0.05
    past_edge = numpy.abs(numpy.tan(angles)) * WALL_X > WALL_HALF + 0.05
    assert on_wall.sum() > 50 and past_edge.sum() > 20
    expected = WALL_X / numpy.cos(angles[on_wall])
    assert numpy.abs(ranges[on_wall] - expected).max() <= LIDAR_RESOLUTION
    assert numpy.isposinf(ranges[past_edge]).all()  # REP 117: no return within range


@pytest.mark.parametrize('samples', [MAX_BATCH, MAX_BATCH + 1, 2 * MAX_BATCH + 5, 40000])
def test_lidar_of_more_beams_than_one_pybullet_batch_scans_every_beam(rig, samples):
    from dataclasses import replace

    spec = sensor(rig, 'laser')
    horizontal = replace(spec.ray.horizontal, samples=samples, resolution=1.0)
    wide = replace(spec, ray=replace(spec.ray, horizontal=horizontal))
    ranges = Lidar(rig.physics, wide, 'empty').scan()
    assert ranges.shape == (1, samples)
    centre = ranges[0, samples // 2 - 1:samples // 2 + 1]  # the beams either side of 0 rad
    assert numpy.abs(centre - WALL_X).max() <= LIDAR_RESOLUTION
    assert not numpy.isnan(ranges).any()


def test_lidar_beyond_its_range_sees_nothing(rig):
    from dataclasses import replace

    spec = sensor(rig, 'laser')
    short = replace(spec, ray=replace(spec.ray, range_max=WALL_X - 0.5))
    assert numpy.isposinf(Lidar(rig.physics, short, 'empty').scan()).all()


def test_lidar_hits_the_scenerys_targets(tmp_path):
    # The pan/tilt example's pan link, with a lidar looking along -x at the blue target 2.5 m away.
    urdf = tmp_path / 'lidar.urdf'
    urdf.write_text(textwrap.dedent(f"""\
        <robot name="post">
          <link name="base"><inertial><mass value="1"/>
            <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
          <link name="head"><inertial><mass value="1"/>
            <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
          <joint name="yaw" type="revolute"><parent link="base"/><child link="head"/>
            <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>
            <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
          <gazebo reference="head"><sensor type="gpu_lidar" name="l"><topic>l</topic>
            <lidar><scan><horizontal><samples>1</samples><min_angle>{math.pi}</min_angle>
              <max_angle>{math.pi}</max_angle></horizontal></scan>
              <range><min>0.1</min><max>10</max></range></lidar></sensor></gazebo>
        </robot>"""), encoding='utf-8')
    controllers = tmp_path / 'c.yaml'
    controllers.write_text('js:\n  type: joint_state_controller/JointStateController\n',
                           encoding='utf-8')
    from pan_tilt_sim.sim.world import TARGET_SET, build_world

    with make_simulation(str(urdf), str(controllers), TIME_STEP) as simulation:
        build_world('targets', simulation.physics.client_id)
        blue = next(target for target in TARGET_SET if target.name == 'blue')
        ranges = Lidar(simulation.physics, sensor(simulation, 'l'), 'targets').scan()
        assert ranges[0, 0] == pytest.approx(blue.distance - blue.half_size, abs=1e-3)


# --- IMU ----------------------------------------------------------------------------------------

def read_imu(simulation: Simulation, imu: Imu):
    imu.remember(simulation.steps)
    simulation.advance(1)
    return imu.read(simulation.steps)


def test_an_imu_at_rest_reads_gravity_up_and_no_rotation(rig):
    rig.reset()
    imu = Imu(rig.physics, sensor(rig, 'imu'))
    rig.advance(50)
    reading = read_imu(rig, imu)
    assert reading.linear_acceleration == pytest.approx((0.0, 0.0, STANDARD_GRAVITY), abs=1e-6)
    assert reading.angular_velocity == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)
    assert reading.orientation == pytest.approx((0.0, 0.0, 0.0, 1.0), abs=1e-9)


def test_an_imu_on_a_turning_joint_reads_its_rate_and_the_centripetal_acceleration(rig):
    rig.reset()
    imu = Imu(rig.physics, sensor(rig, 'imu'))
    rig.controller('spin_controller').set_command(SPIN_RATE)
    rig.advance(2000)  # 2 s: the velocity loop has settled
    reading = read_imu(rig, imu)
    rate = rig.joint_velocities()['spin_joint']
    assert rate == pytest.approx(SPIN_RATE, rel=ONE_PERCENT)
    assert reading.angular_velocity[2] == pytest.approx(rate, rel=1e-6)
    # The IMU sits IMU_RADIUS along the spinner's x: the centripetal pull is along -x.
    centripetal = rate * rate * IMU_RADIUS
    assert reading.linear_acceleration[0] == pytest.approx(-centripetal, rel=ONE_PERCENT)
    assert abs(reading.linear_acceleration[1]) < ONE_PERCENT * centripetal
    assert reading.linear_acceleration[2] == pytest.approx(STANDARD_GRAVITY, abs=1e-6)
    # Orientation: the spinner's yaw about z, in the world frame (REP 145).
    x, y, z, w = reading.orientation
    yaw = 2 * math.atan2(z, w)
    angle = rig.joint_positions()['spin_joint']
    assert math.remainder(yaw - angle, 2 * math.pi) == pytest.approx(0.0, abs=1e-6)
    rig.controller('spin_controller').set_command(0.0)


def test_imu_orientation_from_start_is_relative_to_the_first_pose(rig):
    rig.reset()
    rig.controller('spin_controller').set_command(SPIN_RATE)
    rig.advance(300)
    imu = Imu(rig.physics, sensor(rig, 'imu'), orientation_from_start=True)
    reading = read_imu(rig, imu)
    x, y, z, w = reading.orientation
    assert 2 * math.atan2(z, w) == pytest.approx(SPIN_RATE * TIME_STEP, rel=0.2)
    rig.controller('spin_controller').set_command(0.0)
    rig.reset()


# --- force-torque -------------------------------------------------------------------------------

def test_force_torque_under_a_hanging_mass_reads_its_weight_within_one_percent(rig):
    rig.reset()
    ft = ForceTorque(rig.physics, sensor(rig, 'ft'), model(rig).joint('hang_joint'),
                     frame=CHILD, measure_direction=PARENT_TO_CHILD)
    rig.advance(10)
    wrench = ft.read()
    weight = HANG_MASS * STANDARD_GRAVITY
    assert wrench.force[2] == pytest.approx(weight, rel=ONE_PERCENT)
    assert numpy.abs(wrench.force[:2]).max() < ONE_PERCENT * weight
    assert numpy.abs(wrench.torque).max() < 1e-6  # the weight hangs straight below the joint


def test_child_to_parent_is_the_opposite_wrench(rig):
    ft = ForceTorque(rig.physics, sensor(rig, 'ft'), model(rig).joint('hang_joint'),
                     frame=CHILD, measure_direction=CHILD_TO_PARENT)
    rig.advance(1)
    assert ft.read().force[2] == pytest.approx(-HANG_MASS * STANDARD_GRAVITY, rel=ONE_PERCENT)


OFFSET = 0.3  # m: the offset weight's centre of mass, along the child's x


def offset_weight_urdf(rpy: str) -> str:
    return textwrap.dedent(f"""\
        <robot name="hang">
          <link name="base"><inertial><mass value="1"/>
            <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
          <link name="weight"><inertial><origin xyz="{OFFSET} 0 0" rpy="0.3 0.2 0.1"/>
            <mass value="{HANG_MASS}"/>
            <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
          <link name="arm"><inertial><mass value="1"/>
            <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
          <joint name="hold" type="fixed"><parent link="base"/><child link="weight"/>
            <origin xyz="0 0 1" rpy="{rpy}"/></joint>
          <joint name="free" type="revolute"><parent link="base"/><child link="arm"/>
            <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
          <gazebo reference="hold"><sensor type="force_torque" name="ft"><topic>ft</topic>
            <pose>0 0 0.5 0 0 1.5707963267948966</pose></sensor></gazebo>
        </robot>""")


@pytest.fixture
def offset_weight(tmp_path):
    def build(rpy: str = '0 0 0') -> Simulation:
        urdf = tmp_path / 'hang.urdf'
        urdf.write_text(offset_weight_urdf(rpy), encoding='utf-8')
        controllers = tmp_path / 'c.yaml'
        controllers.write_text('js:\n  type: joint_state_controller/JointStateController\n',
                               encoding='utf-8')
        built.append(make_simulation(str(urdf), str(controllers), TIME_STEP))
        return built[-1]
    built = []
    yield build
    for simulation in built:
        simulation.close()


def test_force_torque_moment_is_taken_about_the_joint(offset_weight):
    simulation = offset_weight()
    ft = ForceTorque(simulation.physics, sensor(simulation, 'ft'),
                     model(simulation).joint('hold'), measure_direction=PARENT_TO_CHILD)
    simulation.advance(10)
    wrench = ft.read()
    weight = HANG_MASS * STANDARD_GRAVITY
    assert wrench.force == pytest.approx((0.0, 0.0, weight), rel=ONE_PERCENT, abs=1e-4)
    # The parent holds the weight's moment about the joint: r x (-m g) + M = 0.
    assert wrench.torque == pytest.approx((0.0, -OFFSET * weight, 0.0), rel=ONE_PERCENT,
                                          abs=1e-6)


def test_force_torque_in_the_child_parent_or_sensor_frame(offset_weight):
    simulation = offset_weight('1.5707963267948966 0 0')  # the child's y points up
    spec = sensor(simulation, 'ft')
    joint = model(simulation).joint('hold')
    readers = {frame: ForceTorque(simulation.physics, spec, joint, frame=frame,
                                  measure_direction=PARENT_TO_CHILD)
               for frame in (CHILD, PARENT, SENSOR)}
    simulation.advance(10)
    weight = HANG_MASS * STANDARD_GRAVITY
    child = readers[CHILD].read()
    assert child.force == pytest.approx((0.0, weight, 0.0), rel=ONE_PERCENT, abs=1e-4)
    parent = readers[PARENT].read()
    assert parent.force == pytest.approx((0.0, 0.0, weight), rel=ONE_PERCENT, abs=1e-4)
    # The sensor frame is yawed 90 degrees in the child: child +y is the sensor's -x.
    in_sensor = readers[SENSOR].read()
    assert in_sensor.force == pytest.approx((weight, 0.0, 0.0), rel=ONE_PERCENT, abs=1e-4)
    # About the sensor's origin, 0.5 m along the child's z (horizontal here), the moment
    # also balances the lever of the force: |M| grows from OFFSET m g.
    assert numpy.linalg.norm(in_sensor.torque) == pytest.approx(
        math.hypot(OFFSET, 0.5) * weight, rel=ONE_PERCENT)


# --- noise --------------------------------------------------------------------------------------

def test_noise_is_reproducible_with_a_seed_and_has_the_declared_spread():
    noise = [Noise(mean=0.1, stddev=0.05)] * 3
    first = NoiseModel(noise, generator(7, 0)).apply(numpy.zeros((4000, 3)))
    again = NoiseModel(noise, generator(7, 0)).apply(numpy.zeros((4000, 3)))
    other = NoiseModel(noise, generator(7, 1)).apply(numpy.zeros((4000, 3)))
    assert numpy.array_equal(first, again)
    assert not numpy.array_equal(first, other)
    assert first.mean() == pytest.approx(0.1, abs=0.005)
    assert first.std() == pytest.approx(0.05, rel=0.05)


def test_noise_bias_is_drawn_once_per_run():
    model = NoiseModel([Noise(bias_mean=1.0)], generator(3, 0))
    samples = model.apply(numpy.zeros((100, 1)))
    assert numpy.unique(samples).size == 1
    assert abs(samples[0, 0]) == pytest.approx(1.0)


def test_no_noise_changes_nothing():
    model = NoiseModel([Noise()], generator(1, 0))
    values = numpy.arange(5.0)
    assert not model.active
    assert model.apply(values) is values


def test_the_rig_fixture_is_where_the_tests_think(rig):
    # Guards the constants the truths above are computed from.
    assert sensor(rig, 'laser').link == 'lidar_link'
    assert model(rig).joint('lidar_joint').origin.translation[2] == LIDAR_Z
    assert model(rig).link('weight').inertial.origin.translation[2] == -HANG_DROP
    assert pathlib.Path(rig.description.source).name == 'sensor_rig.urdf'


def test_one_reader_switching_off_leaves_the_joint_feedback_on_for_another(rig):
    rig.reset()
    joint = model(rig).joint('hang_joint')
    first = ForceTorque(rig.physics, sensor(rig, 'ft'), joint, enabled=True)
    second = ForceTorque(rig.physics, sensor(rig, 'ft'), joint, enabled=True)
    first.enable(False)
    rig.advance(2)
    weight = HANG_MASS * STANDARD_GRAVITY
    assert numpy.linalg.norm(second.read().force) == pytest.approx(weight, rel=ONE_PERCENT)
    second.enable(False)
