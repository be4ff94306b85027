"""Every sensor on every base agrees with the world: the simulation loop, no ROS.

Each case builds one robot of the matrix (:mod:`consistency_fixtures`: a
drive, a root link, sensors on the base or on a pan/tilt mast) in the world
of walls, a pillar and a ball, drives it along the scripted path (straight,
stop, turn, arc, [sideways,] reverse, stop) and, in the middle and at the end
of every leg, checks each sensor against what it must read, computed in
:mod:`world_truth` from the world's shapes and the robot's true pose (the
root link's pose, as GetEntityState reports it, carried out to the sensor by
the URDF's joints in the test's own kinematics):

* lidar ranges within 1 cm of the analytic ray--box / --cylinder / --sphere /
  --ground distance (beams that graze an edge -- that would hit another
  shape, or none, in a world 5 mm bigger or smaller -- are left out, never
  more than a tenth of them);
* depth within 1 cm + 1 % of the planar depth to the walls and the ground
  (planes; the renderer draws round shapes as facets); pixels that must
  show the red ball are red, and no other pixel is;
* IMU: angular velocity and specific force within 1 % of the true pose's
  (the rotation over the last step; ``R^T (a - g)`` with ``a`` the second
  difference of the sensor point's true position); at rest (at the start and
  at the end of the path, where the base must be at rest) ``+g`` up;
* force-torque at rest: what holds the payload up, ``m (a - g)`` in its
  frame with ``a`` its true acceleration -- its weight, ``m g`` up --, 1 %;
* the link poses the simulation reports (p3d's and the sensors' source,
  and the entity frames) within 1 mm and 0.1 degree of the truth;
* the drive's odometry and its odom -> base transform agree exactly, and
  the odometry stays within :data:`ODOMETRY_DRIFT` of the distance driven;
* the base drives level: the simulation never warns that it leant, tipped
  over or fell.

A sample of the matrix runs by default (:data:`CI_SAMPLE`, one case per drive,
under a minute); the whole matrix is opt-in:

    PAN_TILT_SIM_MATRIX=1 scripts/run_tests.sh -m matrix test/consistency
"""

from __future__ import annotations

import dataclasses
import itertools
import logging
import math
import os

import numpy
import pytest
from consistency_fixtures import (
    BALL_RGB,
    BASE_MOUNTS,
    CAMERA_HFOV,
    CAMERA_SIZE,
    DRIVES,
    LIDAR_MAX_ANGLE,
    LIDAR_MIN_ANGLE,
    LIDAR_RANGE,
    LIDAR_SAMPLES,
    MAST_CONTROLLER,
    MAST_JOINTS,
    MAST_MOUNTS,
    MAST_PAN_ORIGIN,
    MAST_TILT_ORIGIN,
    PAYLOAD_DROP,
    PAYLOAD_MASS,
    SENSOR_LINKS,
    SHAPES,
    Box,
    Leg,
    Sphere,
    mast_pose,
    path,
    write_robot,
)
from world_truth import (
    about_y,
    about_z,
    angle_between,
    first_hits,
    pose,
    quaternion_matrix,
)

from pan_tilt_sim.controllers.framework.surface import StampedTwist
from pan_tilt_sim.model.world_file import read_world_file
from pan_tilt_sim.sim.engine import Simulation, make_simulation
from pan_tilt_sim.sim.entities import Entities, spawn_world_objects
from pan_tilt_sim.sim.sensors.force_torque import ForceTorque
from pan_tilt_sim.sim.sensors.imu import Imu
from pan_tilt_sim.sim.sensors.lidar import Lidar
from pan_tilt_sim.sim.sensors.mount import LinkReader
from pan_tilt_sim.sim.sensors.vision import VisionSensor

MATRIX_ENV = 'PAN_TILT_SIM_MATRIX'
DT = 0.001  # s
GRAVITY = 9.80665  # m/s^2, standard gravity
RANGE_TOLERANCE = 0.01  # m
EDGE = 0.005  # m: a beam whose truth changes more than RANGE_TOLERANCE within this grazes
MAX_GRAZING = 0.1  # of the beams
DEPTH_TOLERANCE = (0.01, 0.01)  # m + fraction of the depth
PIXEL_EDGE = 0.08  # m: pixels this close to an outline are not judged
POSE_TOLERANCE = (0.001, math.radians(0.1))  # m, rad
IMU_TOLERANCE = 0.01  # of the true value
ANGULAR_FLOOR = 1e-3  # rad/s: below it a body's rate is contact jitter, not turning
FT_TOLERANCE = 0.01
AT_REST = 0.01 * GRAVITY  # m/s^2: a base accelerating less is at rest, to the IMU's 1 %
ODOMETRY_DRIFT = 0.05  # of the distance driven, and at least 1 cm
COMMAND_PERIOD = 0.01  # s between two commands, as a 100 Hz teleop sends them
# The most a command changes from one to the next: 1 m/s^2 and 3 rad/s^2, as the
# Gazebo plugin's max_wheel_acceleration -- a step would spin the wheels.
RAMP = (1.0 * COMMAND_PERIOD, 1.0 * COMMAND_PERIOD, 3.0 * COMMAND_PERIOD)
ROOTS = ('base_link', 'base_footprint')
MOUNTS = ('base', 'mast')
CASES = list(itertools.product(DRIVES, ROOTS, MOUNTS))
# One case per drive; every root with every mount twice.
CI_SAMPLE = [
    ('gazebo_ros_diff_drive', 'base_footprint', 'base'),  # the TurtleBot3-style rover
    ('diff_drive_controller', 'base_link', 'mast'),
    ('planar_move', 'base_footprint', 'mast'),
    ('gz_diff_drive', 'base_link', 'base'),
    ('mecanum', 'base_footprint', 'base'),
    ('omni', 'base_link', 'mast'),
    ('ackermann', 'base_footprint', 'mast'),
    ('tricycle', 'base_link', 'base'),
]


def _case_id(case: tuple[str, str, str]) -> str:
    return '-'.join(case)


def _matrix_params():
    opt_in = pytest.mark.skipif(os.environ.get(MATRIX_ENV) != '1',
                                reason=f'the whole matrix takes minutes: set {MATRIX_ENV}=1')
    return [pytest.param(*case, id=_case_id(case),
                         marks=[pytest.mark.matrix, pytest.mark.slow, opt_in])
            for case in CASES]


def _matrix(transform) -> numpy.ndarray:
    """A package Transform as a 4 x 4 matrix (the numbers only)."""
    return pose(transform.translation, quaternion_matrix(transform.rotation))


@dataclasses.dataclass
class Run:
    """One robot of the matrix in the world, its sensors, and its truths."""

    simulation: Simulation
    entities: Entities
    drive: str
    root: str
    mount: str

    def __post_init__(self) -> None:
        model = self.simulation.description.model
        physics = self.simulation.physics
        specs = {sensor.name: sensor for sensor in model.sensors}
        self.lidar = Lidar(physics, specs['lidar'], 'ground')
        self.camera = VisionSensor(physics, specs['depth'], 'ground')
        self.imu = Imu(physics, specs['imu'])
        self.ft = ForceTorque(physics, specs['ft'], model.joint(specs['ft'].joint))
        self.odometry: list[tuple] = []
        self.transforms: list[tuple] = []
        driver = self.driver
        if hasattr(driver, 'set_odometry_sink'):
            driver.set_odometry_sink(lambda *sample: self.odometry.append(sample))
            driver.set_tf_sink(lambda time, edges: self.transforms.append((time, edges)))
        self.driven = 0.0  # m, along the path
        self.start = self.base_link_pose()  # where the odometry starts
        self.twist = (0.0, 0.0, 0.0)  # the last command
        self.failures: list[str] = []

    @property
    def driver(self):
        """The controller or plugin that drives the base."""
        name = DRIVES[self.drive].controller
        return self.simulation.plugins[0] if name is None else self.simulation.controller(name)

    # --- truth ---------------------------------------------------------------------------------

    def root_pose(self) -> numpy.ndarray:
        """The root link's pose, as GetEntityState reports the robot entity."""
        return _matrix(self.entities.state(self.entities.robot_name).pose)

    def base_link_pose(self) -> numpy.ndarray:
        root = self.root_pose()
        if self.root == 'base_footprint':
            return root @ pose((0.0, 0.0, DRIVES[self.drive].rest_height))
        return root

    def true_link(self, link: str) -> numpy.ndarray:
        """``link``'s pose from the root's and the URDF's joints (the test's own kinematics)."""
        base = self.base_link_pose()
        if self.mount == 'base':
            return base @ pose(BASE_MOUNTS[link])
        positions = self.simulation.joint_positions()
        pan, tilt = (positions[joint] for joint in MAST_JOINTS)
        return (base @ pose(MAST_PAN_ORIGIN, about_z(pan)) @ pose(MAST_TILT_ORIGIN, about_y(tilt))
                @ pose(MAST_MOUNTS[link]))

    # --- driving ---------------------------------------------------------------------------------

    def command(self, twist: tuple[float, float, float]) -> None:
        forward, left, turn = twist
        self.driver.set_command(StampedTwist(self.simulation.time, (forward, left, 0.0),
                                             (0.0, 0.0, turn)))

    def follow(self, leg: Leg, index: int, seconds: float) -> None:
        """Drive ``seconds`` of ``leg``: the twist ramped as a user's teleop would, resent."""
        if self.mount == 'mast':
            self.simulation.controller(MAST_CONTROLLER).set_command(list(mast_pose(index)))
        for _ in range(round(seconds / COMMAND_PERIOD)):
            self.twist = tuple(now + max(-limit, min(limit, wanted - now))
                               for now, wanted, limit in zip(self.twist, leg.twist, RAMP,
                                                             strict=True))
            self.command(self.twist)
            self.advance(round(COMMAND_PERIOD / DT))

    def advance(self, steps: int) -> None:
        before = self.base_link_pose()[:3, 3]
        self.simulation.advance(steps)
        self.driven += float(numpy.linalg.norm(self.base_link_pose()[:3, 3] - before))

    def fail(self, where: str, text: str) -> None:
        self.failures.append(f'{where}: {text}')

    # --- the checks ------------------------------------------------------------------------------

    def check_poses(self, where: str) -> None:
        physics = self.simulation.physics
        for link in SENSOR_LINKS:
            truth = self.true_link(link)
            reported = {
                'link_state (p3d)': _matrix(self.simulation.link_state(link)[0]),
                'LinkReader (sensors)': _matrix(LinkReader(physics, link).frame()),
                'entity frame_pose': _matrix(self.entities.frame_pose(link)),
            }
            for source, found in reported.items():
                offset = float(numpy.linalg.norm(found[:3, 3] - truth[:3, 3]))
                turned = angle_between(found, truth)
                if offset > POSE_TOLERANCE[0] or turned > POSE_TOLERANCE[1]:
                    self.fail(where, f'{link} by {source} is {offset * 1000:.1f} mm and '
                                     f'{math.degrees(turned):.2f} deg off')

    def check_lidar(self, where: str) -> None:
        sensor = self.true_link('lidar_link')
        angles = numpy.linspace(LIDAR_MIN_ANGLE, LIDAR_MAX_ANGLE, LIDAR_SAMPLES)
        local = numpy.stack([numpy.cos(angles), numpy.sin(angles), numpy.zeros_like(angles)],
                            axis=-1)
        directions = local @ sensor[:3, :3].T
        origin = sensor[:3, 3]
        low, high = LIDAR_RANGE

        def truth(grow: float) -> tuple[numpy.ndarray, numpy.ndarray]:
            hits, which = first_hits(origin, directions, SHAPES, grow)
            seen = (hits >= low) & (hits <= high)
            return numpy.where(seen, hits, numpy.inf), numpy.where(seen, which, -2)

        (exact, _), (_, bigger), (_, smaller) = truth(0.0), truth(EDGE), truth(-EDGE)
        grazing = bigger != smaller
        if grazing.mean() > MAX_GRAZING:
            self.fail(where, f'{grazing.sum()} lidar beams graze an edge: the world is wrong')
        measured = self.lidar.scan()[0]
        with numpy.errstate(invalid='ignore'):
            right = (measured == exact) | (numpy.abs(measured - exact) <= RANGE_TOLERANCE)
        wrong = numpy.flatnonzero(~right & ~grazing)
        if wrong.size:
            beam = wrong[0]
            self.fail(where, f'{wrong.size} lidar beams wrong, e.g. beam {beam} '
                             f'({math.degrees(angles[beam]):.0f} deg) reads {measured[beam]:.3f} m '
                             f'where {exact[beam]:.3f} m is right (lidar at '
                             f'{numpy.round(origin, 3).tolist()})')

    def check_camera(self, where: str) -> None:
        width, height = CAMERA_SIZE
        focal = (width / 2) / math.tan(CAMERA_HFOV / 2)
        u, v = numpy.meshgrid((numpy.arange(width) - (width - 1) / 2) / focal,
                              (numpy.arange(height) - (height - 1) / 2) / focal)
        # REP 103 optical axes in the camera link: z forward (link x), x right (-y), y down (-z).
        optical = numpy.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
        camera = self.true_link('camera_link')
        rotation = camera[:3, :3] @ optical
        rays = numpy.stack([u, v, numpy.ones_like(u)], axis=-1) @ rotation.T
        origin = camera[:3, 3]
        depth, which = first_hits(origin, rays, SHAPES)
        bigger, which_bigger = first_hits(origin, rays, SHAPES, PIXEL_EDGE)
        smaller, which_smaller = first_hits(origin, rays, SHAPES, -PIXEL_EDGE)
        inside = (which_bigger == which) & (which_smaller == which)
        view = self.camera.render()
        planes = [index for index, shape in enumerate(SHAPES) if isinstance(shape, Box)]
        judged = inside & numpy.isfinite(depth) & (numpy.isin(which, planes) | (which == -1))
        with numpy.errstate(invalid='ignore'):
            error = numpy.where(view.depth == depth, 0.0, numpy.abs(view.depth - depth))
        allowed = DEPTH_TOLERANCE[0] + DEPTH_TOLERANCE[1] * depth
        bad = judged & ~(error <= allowed)
        if bad.any():
            row, column = numpy.argwhere(bad)[0]
            self.fail(where, f'{bad.sum()} depth pixels wrong, e.g. ({column}, {row}) reads '
                             f'{view.depth[row, column]:.3f} m where {depth[row, column]:.3f} m '
                             'is right')
        ball = next(index for index, shape in enumerate(SHAPES) if isinstance(shape, Sphere))
        rgb = view.rgb.astype(int)
        red = (rgb[..., 0] > 2 * rgb[..., 1] + 20) & (rgb[..., 0] > 2 * rgb[..., 2] + 20)
        must = inside & (which == ball)
        must_not = inside & (which != ball)
        if (must & ~red).any() or (must_not & red).any():
            self.fail(where, f'the red ball: {(must & ~red).sum()} of {must.sum()} pixels that '
                             f'must show it do not, {(must_not & red).sum()} that must not do '
                             f'(ball colour {BALL_RGB})')

    def check_imu(self, where: str, at_rest: bool) -> None:
        """Step twice more; compare the IMU with the true pose's motion over those steps."""
        points, rotations = [], []
        for step in range(3):
            if step:
                self.advance(1)
            truth = self.true_link('imu_link')
            points.append(truth[:3, 3])
            rotations.append(truth[:3, :3])
            if step == 1:
                self.imu.remember(self.simulation.steps)
        reading = self.imu.read(self.simulation.steps)
        rotation = rotations[2]
        acceleration = (points[2] - 2 * points[1] + points[0]) / (DT * DT)
        force = rotation.T @ (acceleration - numpy.array((0.0, 0.0, -GRAVITY)))
        turn = rotations[2] @ rotations[1].T  # the last step's rotation, world axes
        spin = numpy.array((turn[2, 1] - turn[1, 2], turn[0, 2] - turn[2, 0],
                            turn[1, 0] - turn[0, 1])) / (2.0 * DT)
        angular = rotation.T @ spin
        if at_rest:
            if numpy.linalg.norm(acceleration) > AT_REST:
                self.fail(where, f'the base is not at rest: it accelerates at '
                                 f'{numpy.round(acceleration, 3)} m/s^2')
            up = rotation.T @ numpy.array((0.0, 0.0, GRAVITY))
            if numpy.linalg.norm(reading.linear_acceleration - up) > IMU_TOLERANCE * GRAVITY:
                self.fail(where, f'IMU at rest reads {numpy.round(reading.linear_acceleration, 3)}'
                                 f' where gravity is {numpy.round(up, 3)}')
        error = numpy.linalg.norm(reading.linear_acceleration - force)
        if error > IMU_TOLERANCE * numpy.linalg.norm(force):
            self.fail(where, f'IMU specific force {numpy.round(reading.linear_acceleration, 3)} '
                             f'where the true pose gives {numpy.round(force, 3)}')
        error = numpy.linalg.norm(reading.angular_velocity - angular)
        if error > IMU_TOLERANCE * numpy.linalg.norm(angular) + ANGULAR_FLOOR:
            self.fail(where, f'IMU angular velocity {numpy.round(reading.angular_velocity, 4)} '
                             f'where the true pose turns at {numpy.round(angular, 4)}')

    def check_force_torque(self, where: str) -> None:
        """Step twice more; the payload's weight plus what accelerates it (its true pose's)."""
        centres = []
        for step in range(3):
            if step:
                self.advance(1)
            payload = self.true_link('payload_link') @ pose((0.0, 0.0, -PAYLOAD_DROP))
            centres.append(payload[:3, 3])
        acceleration = (centres[2] - 2 * centres[1] + centres[0]) / (DT * DT)
        # What the parent applies on the payload: m (a - g), in the payload's axes.
        truth = payload[:3, :3].T @ (PAYLOAD_MASS * (acceleration - numpy.array(
            (0.0, 0.0, -GRAVITY))))
        force = self.ft.read().force
        if numpy.linalg.norm(force - truth) > FT_TOLERANCE * numpy.linalg.norm(truth):
            self.fail(where, f'force-torque reads {numpy.round(force, 3)} N where the payload '
                             f'needs {numpy.round(truth, 3)} N')

    def check_odometry(self, where: str) -> None:
        if not self.odometry:
            return
        sample = self.odometry[-1]
        if len(sample) == 6:  # planar: time, x, y, heading, linear, angular
            _, x, y, heading, *_ = sample
            odometry = pose((x, y, 0.0), about_z(heading))
        else:  # spatial: time, pose, linear, angular
            odometry = _matrix(sample[1])
        if self.transforms:
            time, edges = self.transforms[-1]
            transform = _matrix(edges[0][2])
            offset = numpy.linalg.norm(transform[:3, 3] - odometry[:3, 3])
            if offset > POSE_TOLERANCE[0] or angle_between(transform, odometry) > \
                    POSE_TOLERANCE[1]:
                self.fail(where, f'odom -> base transform is {offset * 1000:.1f} mm from the '
                                 'odometry')
        point = pose((DRIVES[self.drive].odometry_point, 0.0, 0.0))
        truth = numpy.linalg.inv(self.start @ point) @ self.base_link_pose() @ point
        drift = numpy.linalg.norm(truth[:2, 3] - odometry[:2, 3])
        if drift > max(0.01, ODOMETRY_DRIFT * self.driven):
            self.fail(where, f'odometry {numpy.round(odometry[:2, 3], 3)} is {drift:.3f} m '
                             f'from the true pose {numpy.round(truth[:2, 3], 3)} after '
                             f'{self.driven:.2f} m')


class BaseWarnings(logging.Handler):
    """The simulation's warnings that its base leant, tipped over or fell."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        line = record.getMessage()
        if any(word in line for word in ('has leant', 'tipped over', 'fell below')):
            self.lines.append(line)


def _run_path(tmp_path, drive: str, root: str, mount: str) -> list[str]:
    urdf, config, world = write_robot(tmp_path, drive, root, mount)
    warnings = BaseWarnings()
    logger = logging.getLogger(f'consistency.{drive}.{root}.{mount}')
    logger.addHandler(warnings)
    simulation = make_simulation(str(urdf), str(config) if config else None, DT,
                                 fixed_base=None, logger=logger)
    try:
        entities = Entities(simulation.physics, simulation.description.model.name)
        spawn_world_objects(entities, read_world_file(world))
        run = Run(simulation, entities, drive, root, mount)
        run.check_poses('start')
        run.check_lidar('start')
        run.advance(200)
        run.check_imu('start, at rest', at_rest=True)
        run.check_force_torque('start, at rest')
        legs = path(DRIVES[drive])
        for index, leg in enumerate(legs):
            where = f'{leg.name} (leg {index})'
            run.follow(leg, index, leg.seconds / 2)
            run.check_imu(f'{where}, middle', at_rest=False)
            run.check_poses(f'{where}, middle')
            run.check_lidar(f'{where}, middle')
            run.follow(leg, index, leg.seconds / 2)
            last = index == len(legs) - 1
            run.check_imu(f'{where}, end', at_rest=last)
            run.check_poses(f'{where}, end')
            run.check_lidar(f'{where}, end')
            run.check_camera(f'{where}, end')
            run.check_odometry(f'{where}, end')
            if last:
                run.check_force_torque(f'{where}, end')
        # The robots drive level: a base that leans reads the floor, right but not as meant.
        return run.failures + [f'the base: {line}' for line in warnings.lines]
    finally:
        simulation.close()


@pytest.mark.parametrize(('drive', 'root', 'mount'), CI_SAMPLE, ids=map(_case_id, CI_SAMPLE))
def test_every_sensor_agrees_with_the_world_along_the_path(tmp_path, drive, root, mount):
    failures = _run_path(tmp_path, drive, root, mount)
    assert not failures, '\n'.join(failures)


@pytest.mark.parametrize(('drive', 'root', 'mount'), _matrix_params())
def test_the_whole_matrix_agrees_with_the_world(tmp_path, drive, root, mount):
    failures = _run_path(tmp_path, drive, root, mount)
    assert not failures, '\n'.join(failures)
