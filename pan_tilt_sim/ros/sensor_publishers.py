"""The URDF's sensors on ROS: a publisher set per sensor, on its schedule of sim time.

Each sensor measures every ``1 / rate`` seconds of sim time (its
``<update_rate>``, limited by its plugin's; 0 = every physics step) on a
:class:`~pan_tilt_sim.schedule.PeriodicSchedule` that a reset of the
simulation starts again.  As Gazebo's plugins do, nothing is measured while
nobody subscribes to any of the sensor's topics, so an unwatched sensor
costs one due-check per /clock period.  While one is watched, sim_node stops
its batch of physics steps exactly at the sensor's due steps (and, for an
IMU, one step before, to difference the velocity), so a 1 kHz IMU gets
every step's sample.

Topic names and frames follow the plugin conventions of
:mod:`pan_tilt_sim.model.sensors`; a frame that is no link of the robot
(a ``frame_name`` of an optical frame the URDF does not declare, gz's
default frame, the sensor's name) gets a ``/tf_static`` from the sensor's
link, so every message's frame is in the TF tree.

Design notes: docs/design/ros.md#sensor_publisherspy.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy
from geometry_msgs.msg import WrenchStamped
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image, Imu, LaserScan, PointCloud2

from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.sensors import (
    CHILD,
    PARENT,
    SensorInterface,
    SensorKind,
    data_frame,
    sensor_interface,
)
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.ros import parameters as params
from pan_tilt_sim.ros import sensor_messages as messages
from pan_tilt_sim.ros.ros_interfaces import stamp
from pan_tilt_sim.schedule import PeriodicSchedule
from pan_tilt_sim.sim.engine import Simulation
from pan_tilt_sim.sim.sensors.force_torque import ForceTorque
from pan_tilt_sim.sim.sensors.imu import Imu as ImuSensor
from pan_tilt_sim.sim.sensors.lidar import Lidar
from pan_tilt_sim.sim.sensors.noise import NoiseModel, generator
from pan_tilt_sim.sim.sensors.vision import VisionSensor

QUEUE_DEPTH = 5  # gazebo_ros: SensorDataQoS depth, made reliable
NO_SEED = -1
# A TF edge: parent frame, child frame, child pose in the parent frame.
Frame = tuple[str, str, Transform]


def declare_noise_seed(node: Node) -> int | None:
    """Declare ``sensors.noise_seed``; return it, or None for a seed from the OS."""
    seed = params.declare(
        node, 'sensors.noise_seed', params.INTEGER, NO_SEED,
        "Seed of the sensors' Gaussian noise (reproducible runs); -1: a new seed each run.")
    return None if seed < 0 else seed


class SensorPublisher:
    """One sensor's topics and schedule; subclasses measure and build the messages."""

    def __init__(self, node: Node, interface: SensorInterface, simulation: Simulation) -> None:
        self.interface = interface
        self.sensor = interface.sensor
        self._simulation = simulation
        self._time_step = simulation.time_step
        self.period = 1.0 / interface.rate if interface.rate > 0.0 else simulation.time_step
        self._schedule = PeriodicSchedule(self.period)
        self._publishers = []
        self._topic_types: list[tuple[str, type]] = []
        self.messages = 0  # measurements published
        self.cost_s = 0.0  # wall time spent measuring, building and publishing them
        self._node = node
        # Whether anyone listened at the last due time: each question is a call
        # into DDS, so it is asked once per due time, not at every batch of steps.
        self._watched = False

    def publisher(self, message_type: type, role: str):
        """Create the publisher of topic ``role`` if the sensor has that topic, else None."""
        topic = self.interface.topics.get(role)
        if topic is None:
            return None
        created = self._node.create_publisher(message_type, topic, QUEUE_DEPTH)
        self._publishers.append(created)
        self._topic_types.append((topic, message_type))
        return created

    def topic_types(self) -> list[tuple[str, type]]:
        """Return (topic, message type) of every topic the sensor publishes."""
        return list(self._topic_types)

    @staticmethod
    def watched(publisher) -> bool:
        """Whether ``publisher`` exists and someone subscribes to it."""
        return publisher is not None and publisher.get_subscription_count() > 0

    @property
    def active(self) -> bool:
        """Whether anyone subscribes to any of the sensor's topics."""
        return any(publisher.get_subscription_count() > 0 for publisher in self._publishers)

    @property
    def cost_per_message(self) -> float:
        """Mean wall seconds per measurement published (0 before the first)."""
        return self.cost_s / self.messages if self.messages else 0.0

    def due_step(self) -> int:
        """Return the physics step at or after the next due time."""
        return self._schedule.due_step(self._time_step)

    def next_step(self, step: int) -> int | None:
        """Return the next step after ``step`` this sensor must see (None: unwatched)."""
        if not self._watched:
            return None
        return self._schedule.next_step(step, self._time_step)

    def update(self) -> None:
        """Measure and publish if due at the present sim time and watched."""
        now = self._simulation.time
        if not self._schedule.take(now):
            return
        self._watched = self.active
        if not self._watched:
            return
        started = time.perf_counter()
        if self.measure_and_publish(now):
            self.cost_s += time.perf_counter() - started
            self.messages += 1

    def measure_and_publish(self, now: float) -> bool:
        """Measure the world as it is now and publish; False if there was nothing to send."""
        raise NotImplementedError

    def reset(self) -> None:
        """Start the schedule again (sim time was reset, or the world put back)."""
        self._schedule.reset()


class CameraPublisher(SensorPublisher):
    """A camera or depth camera: image, camera_info, depth image, depth info, points."""

    def __init__(self, node: Node, interface: SensorInterface, simulation: Simulation,
                 renderer: VisionSensor) -> None:
        super().__init__(node, interface, simulation)
        self.renderer = renderer
        camera = renderer.camera
        frame = interface.frame_id
        self._format = camera.format
        self._image = self.publisher(Image, 'image')
        self._info = self.publisher(CameraInfo, 'camera_info')
        self._depth = self.publisher(Image, 'depth')
        self._depth_info = self.publisher(CameraInfo, 'depth_info')
        self._points = self.publisher(PointCloud2, 'points')
        intrinsics = renderer.intrinsics
        self._info_message = messages.camera_info_message(
            intrinsics.k, intrinsics.p, camera.width, camera.height, frame)
        lower, upper = interface.depth_range
        self._range = (max(lower, renderer.near), min(upper, renderer.far))
        self._colour = self.sensor.kind is SensorKind.CAMERA or self.sensor.colour

    def measure_and_publish(self, now: float) -> bool:
        """Render once, then publish what is watched."""
        frame_id = self.interface.frame_id
        view = self.renderer.render()
        stamp_info = None
        for publisher in (self._info, self._depth_info):
            if self.watched(publisher):
                if stamp_info is None:
                    stamp(now, self._info_message.header.stamp)
                    stamp_info = True
                publisher.publish(self._info_message)
        if self.watched(self._image):
            self._image.publish(messages.colour_image(view.rgb, self._format, frame_id, now))
        if not (self.watched(self._depth) or self.watched(self._points)):
            return True
        depth = messages.depth_in_range(view.depth, *self._range)
        if self.watched(self._depth):
            self._depth.publish(messages.depth_image(depth, frame_id, now))
        if self.watched(self._points):
            xyz = messages.depth_points(depth, self.renderer.ray_x, self.renderer.ray_y)
            extra = ('rgb', messages.pack_rgb(view.rgb)) if self._colour else None
            self._points.publish(messages.point_cloud(xyz, frame_id, now, extra))
        return True


class LidarPublisher(SensorPublisher):
    """A lidar: LaserScan (the row nearest the horizon) and/or an organized PointCloud2."""

    def __init__(self, node: Node, interface: SensorInterface, simulation: Simulation,
                 lidar: Lidar) -> None:
        super().__init__(node, interface, simulation)
        self.lidar = lidar
        self._scan = self.publisher(LaserScan, 'scan')
        self._points = self.publisher(PointCloud2, 'points')
        vertical = numpy.array(lidar.ray.vertical.angles())
        self._row = int(numpy.argmin(numpy.abs(vertical)))

    def measure_and_publish(self, now: float) -> bool:
        """Cast the beams once, then publish what is watched."""
        ray = self.lidar.ray
        ranges = self.lidar.scan()
        frame_id = self.interface.frame_id
        if self.watched(self._scan):
            horizontal = ray.horizontal
            scan_time = self.period if self.interface.rate > 0.0 else self._time_step
            self._scan.publish(messages.laser_scan(
                ranges[self._row], horizontal.min_angle, horizontal.max_angle,
                horizontal.increment, ray.range_min, ray.range_max, scan_time, frame_id, now))
        if self.watched(self._points):
            finite = numpy.where(numpy.isfinite(ranges), ranges, numpy.nan)
            xyz = self.lidar.directions * finite[..., numpy.newaxis]
            intensity = numpy.zeros(ranges.shape, numpy.float32)
            self._points.publish(messages.point_cloud(xyz, frame_id, now,
                                                      ('intensity', intensity)))
        return True


class ImuPublisher(SensorPublisher):
    """An IMU: sensor_msgs/Imu, its acceleration differenced over the last physics step."""

    def __init__(self, node: Node, interface: SensorInterface, simulation: Simulation,
                 imu: ImuSensor, covariances: Sequence[Sequence[float]]) -> None:
        super().__init__(node, interface, simulation)
        self.imu = imu
        self._covariances = covariances
        self._publisher = self.publisher(Imu, 'imu')
        self._message = Imu()

    def next_step(self, step: int) -> int | None:
        """Return the step before the due step (to remember the velocity), then the due one."""
        if not self._watched:
            return None
        due = self.due_step()
        return max(due - 1, step + 1) if step < due - 1 else max(due, step + 1)

    def update(self) -> None:
        """Remember the velocity one step before a due sample; measure when due."""
        step = self._simulation.steps
        if self._watched and step == self.due_step() - 1:
            self.imu.remember(step)
        super().update()

    def measure_and_publish(self, now: float) -> bool:
        """Read the IMU and publish; skip a sample whose previous step was not seen.

        That happens once when someone starts listening (sim_node then starts
        stopping one step before each sample) and at sim time 0.
        """
        step = self._simulation.steps
        if not self.imu.has_previous(step):
            self.imu.remember(step)
            return False
        reading = self.imu.read(step)
        self._publisher.publish(messages.imu_message(
            reading.orientation, reading.angular_velocity, reading.linear_acceleration,
            self._covariances, self.interface.frame_id, now, self._message))
        return True

    def reset(self) -> None:
        """Start again; the stored velocity belongs to the old run."""
        super().reset()
        self.imu.forget()


class WrenchPublisher(SensorPublisher):
    """A force-torque sensor: geometry_msgs/WrenchStamped."""

    def __init__(self, node: Node, interface: SensorInterface, simulation: Simulation,
                 sensor: ForceTorque) -> None:
        super().__init__(node, interface, simulation)
        self.force_torque = sensor
        self._publisher = self.publisher(WrenchStamped, 'wrench')
        self._message = WrenchStamped()

    def update(self) -> None:
        """Measure when due and watched; switch PyBullet's joint feedback off when unwatched."""
        super().update()
        if not self._watched and self.force_torque.enabled:
            self.force_torque.enable(False)

    def measure_and_publish(self, now: float) -> bool:
        """Read the joint's wrench (of the step just taken) and publish.

        The joint feedback is switched on at the first due time someone listens;
        that step's wrench was not computed, so the first sample is skipped.
        """
        if not self.force_torque.enabled:
            self.force_torque.enable(True)
            return False
        wrench = self.force_torque.read()
        self._publisher.publish(messages.wrench_message(
            wrench.force, wrench.torque, self.interface.frame_id, now, self._message))
        return True


def _variance(stddev: float, extra: float) -> float:
    return stddev * stddev + extra * extra


class SensorSet:
    """Every sensor of the robot on ``node``: created once, told after each batch of steps."""

    def __init__(self, node: Node, simulation: Simulation, world: str, *,
                 namespace_override: str = '', seed: int | None = None) -> None:
        model = simulation.description.model
        logger = node.get_logger()
        for warning in model.sensor_warnings:
            logger.warning(warning)
        self.publishers: list[SensorPublisher] = []
        self.static_frames: list[Frame] = []
        links = set(model.link_names)
        framed = set()
        for index, sensor in enumerate(model.sensors):
            interface = sensor_interface(sensor, model.name, namespace_override)
            rng = generator(seed, index)
            publisher = self._create(node, simulation, model, interface, world, rng)
            if sensor.kind in (SensorKind.CAMERA, SensorKind.DEPTH) and \
                    sensor.camera is not None and \
                    messages.image_encoding(sensor.camera.format) == 'rgb8' and \
                    sensor.camera.format not in messages.FORMATS:
                logger.warning(f"sensor '{sensor.name}': image format "
                               f"'{sensor.camera.format}' is not simulated; publishing rgb8")
            self.publishers.append(publisher)
            frame = interface.frame_id
            if frame not in links and frame not in framed:
                framed.add(frame)
                self.static_frames.append(_frame_edge(interface, model))
            logger.info(f"sensor '{sensor.name}' ({sensor.type}, {interface.convention}) on "
                        f"'{sensor.link}' at {interface.rate:g} Hz, frame '{frame}': "
                        f"{', '.join(interface.topics.values())}")

    @staticmethod
    def _create(node: Node, simulation: Simulation, model: RobotModel,
                interface: SensorInterface, world: str, rng) -> SensorPublisher:
        sensor = interface.sensor
        physics = simulation.physics
        extra = interface.noise_stddev
        if sensor.kind in (SensorKind.CAMERA, SensorKind.DEPTH):
            camera = sensor.camera
            noise = NoiseModel([camera.noise], rng) if camera is not None else None
            depth_noise = noise if sensor.kind is SensorKind.DEPTH else None
            colour_noise = noise if sensor.kind is SensorKind.CAMERA or sensor.colour else None
            renderer = VisionSensor(physics, sensor, world, colour_noise, depth_noise)
            return CameraPublisher(node, interface, simulation, renderer)
        if sensor.kind is SensorKind.LIDAR:
            noise = NoiseModel([sensor.ray.noise], rng, extra)
            return LidarPublisher(node, interface, simulation,
                                  Lidar(physics, sensor, world, noise))
        if sensor.kind is SensorKind.IMU:
            imu = sensor.imu
            angular = NoiseModel(imu.angular_velocity_noise, rng, extra)
            linear = NoiseModel(imu.linear_acceleration_noise, rng, extra)
            covariances = (
                [_variance(0.0, extra) if row == column else 0.0
                 for row in range(3) for column in range(3)],
                [_variance(imu.angular_velocity_noise[row].stddev, extra) if row == column
                 else 0.0 for row in range(3) for column in range(3)],
                [_variance(imu.linear_acceleration_noise[row].stddev, extra) if row == column
                 else 0.0 for row in range(3) for column in range(3)])
            reader = ImuSensor(physics, sensor,
                               orientation_from_start=interface.orientation_from_start,
                               angular_noise=angular, linear_noise=linear,
                               orientation_stddev=extra, rng=rng)
            return ImuPublisher(node, interface, simulation, reader, covariances)
        spec = sensor.force_torque
        noises = (*spec.force_noise, *spec.torque_noise)
        reader = ForceTorque(physics, sensor, model.joint(sensor.joint),
                             frame=interface.wrench_frame,
                             measure_direction=interface.measure_direction,
                             noise=NoiseModel(noises, rng, extra), enabled=False)
        return WrenchPublisher(node, interface, simulation, reader)

    def update(self) -> None:
        """Measure and publish whatever is due and watched."""
        for publisher in self.publishers:
            publisher.update()

    def next_step(self, step: int) -> int | None:
        """Return the next step after ``step`` a watched sensor must see (None: none is)."""
        steps = [found for publisher in self.publishers
                 if (found := publisher.next_step(step)) is not None]
        return min(steps) if steps else None

    def reset(self) -> None:
        """Start every sensor's schedule again."""
        for publisher in self.publishers:
            publisher.reset()

    def destroy(self, node: Node) -> None:
        """Destroy every sensor's publishers on ``node`` (its robot left the world)."""
        for publisher in self.publishers:
            while publisher._publishers:
                node.destroy_publisher(publisher._publishers.pop())
        self.publishers = []


def _frame_edge(interface: SensorInterface, model: RobotModel) -> Frame:
    """Return the TF edge placing a sensor's data frame on the link that carries it.

    A force-torque sensor gives its wrench at the joint, in the child link's,
    the parent link's or the sensor's axes: the child link's origin, or the
    joint's origin on the parent link (exact but for a prismatic joint's travel).
    """
    sensor = interface.sensor
    frame = interface.frame_id
    if sensor.kind is SensorKind.FORCE_TORQUE:
        joint = model.joint(sensor.joint)
        if interface.wrench_frame == CHILD:
            return (joint.child, frame, Transform())
        if interface.wrench_frame == PARENT:
            return (joint.parent, frame, Transform(joint.origin.translation))
    return (sensor.link, frame, data_frame(sensor))

