"""What the browser view reads from sim_node and sends back to it, without the web server.

The view (:mod:`pan_tilt_sim.ros.viewer`) runs in threads of its own; the
simulation may be read and changed only between two batches of physics
steps.  :class:`SimulationAccess` runs a function there: in the sim_node
program in a turn of :class:`~pan_tilt_sim.ros.physics_thread.Turns` (as an
executor callback would), otherwise as a guard-condition callback on the
node's executor.  Through it the view takes a :class:`Snapshot` (sim time,
joint positions, where every entity is, the sliders' commands) a few dozen
times a second while a browser is connected, and nothing while none is.

The joint sliders command a joint the way a user would: they publish on the
command topic of the active controller that drives the joint's position
(``std_msgs/Float64`` on ``~/command``, ``Float64MultiArray`` on
``~/commands`` with every joint of the group, a one-point
``JointTrajectory`` on ``~/joint_trajectory``), and the node's own
subscriptions store it as any other command.

Design notes: docs/design/ros.md#view_feedpy.
"""

from __future__ import annotations

import dataclasses
import errno
import importlib.util
import math
import queue
import socket
import threading
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

import numpy as np
from builtin_interfaces.msg import Duration
from rclpy.node import Node
from sensor_msgs.msg import Image, LaserScan, PointCloud2
from std_msgs.msg import Float64, Float64MultiArray
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from pan_tilt_sim.controllers.commands.forward_command_controller import ForwardCommandController
from pan_tilt_sim.controllers.commands.joint_position_controller import JointPositionController
from pan_tilt_sim.controllers.framework.base import Controller
from pan_tilt_sim.controllers.trajectory.joint_trajectory_controller import (
    JointTrajectoryController,
)
from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.model.robot import JointKind, JointSpec, RobotModel
from pan_tilt_sim.model.sensors import SensorKind
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.ros import parameters as params
from pan_tilt_sim.ros.physics_thread import Turns

VISER_HINT = 'viewer:=true needs viser: pip install viser (or scripts/run_sim.sh --viewer)'
DEFAULT_PORT = 8080
LOOPBACK = '127.0.0.1'
MAX_PORT = 65535
ACCESS_TIMEOUT_S = 2.0  # a call waits at most this long for its turn, then gives up
CONTINUOUS_RANGE = math.pi  # rad either side of 0 on a slider of a joint without limits
PRISMATIC_RANGE = 1.0  # m either side of 0 on a slider of a prismatic joint without limits
# A slider's trajectory point is reached no sooner than this (s), nor faster than the
# joints' velocity limits allow.
TRAJECTORY_MIN_S = 0.5
QUEUE_DEPTH = 1  # the view wants the newest sample only
POSITION = 'position'
WILDCARD_HOSTS = ('0.0.0.0', '::', '')  # bound to every address of the machine

# A TF edge: parent frame, child frame, child pose in the parent frame.
Frame = tuple[str, str, Transform]


@dataclasses.dataclass(frozen=True)
class ViewerSettings:
    """The ``viewer.*`` parameters, checked."""

    enabled: bool
    host: str = LOOPBACK
    port: int = DEFAULT_PORT

    @property
    def url(self) -> str:
        """The address a browser opens (the machine's name when bound to every address)."""
        host = socket.gethostname() if self.host in WILDCARD_HOSTS else self.host
        return f"http://{f'[{host}]' if ':' in host else host}:{self.port}/"


def declare_viewer(node: Node) -> ViewerSettings:
    """Declare ``viewer``, ``viewer.host`` and ``viewer.port``; return them, checked."""
    enabled = params.declare(
        node, 'viewer', params.BOOL, False,
        'Serve a live 3D view of the simulation to a browser (needs viser: '
        'pip install viser).')
    host = params.declare(
        node, 'viewer.host', params.STRING, LOOPBACK,
        'Address the view is served on: 127.0.0.1 (this machine only), 0.0.0.0 (every '
        'network the machine is on), or one address of the machine.')
    port = params.declare(node, 'viewer.port', params.INTEGER, DEFAULT_PORT,
                          'TCP port of the view (0: any free port; the log says which).')
    if not 0 <= port <= MAX_PORT:
        raise ParameterError(f"parameter 'viewer.port' must be 0..{MAX_PORT}, got {port}")
    if enabled and not host.strip():
        raise ParameterError("parameter 'viewer.host' is empty: give an address to serve the "
                             f'view on ({LOOPBACK}: this machine only)')
    return ViewerSettings(enabled, host.strip(), port)


def check_viewer(settings: ViewerSettings) -> None:
    """Raise :class:`ParameterError` in one line if the view cannot be served.

    viser is not installed; a port another program listens on, an address
    that is not this machine's, a name that does not resolve: checked by
    binding a socket as the server will (port 0 always succeeds).
    """
    if importlib.util.find_spec('viser') is None:
        raise ParameterError(VISER_HINT)
    host, port = settings.host, settings.port
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM,
                                   flags=socket.AI_PASSIVE)
    except socket.gaierror as err:
        raise ParameterError(f"parameter 'viewer.host': cannot serve the view on '{host}': "
                             f'{err.strerror}') from None
    family, kind, protocol, _name, address = infos[0]
    with socket.socket(family, kind, protocol) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as the server does
        try:
            probe.bind(address)
        except OSError as err:
            raise address_error(settings, err) from None


def address_error(settings: ViewerSettings, err: OSError) -> ParameterError:
    """Return the one-line error for a failed bind of the view's address."""
    if isinstance(err, PermissionError):
        return ParameterError(
            f"parameter 'viewer.port': port {settings.port} needs privileges (ports below "
            '1024 are reserved); choose another, e.g. -p viewer.port:=8081')
    if err.errno == errno.EADDRINUSE:
        return ParameterError(
            f"parameter 'viewer.port': port {settings.port} on {settings.host} is in use by "
            'another program; choose another, e.g. -p viewer.port:=8081 (0: any free port)')
    return ParameterError(f"parameter 'viewer.host': cannot serve the view on "
                          f'{settings.host}:{settings.port}: {err.strerror}')


class SimulationAccess:
    """Runs functions between two batches of physics steps, from any thread.

    With ``turns`` (the sim_node program's physics thread) a call takes a
    turn as an executor callback does; without, it is queued for a guard
    condition's callback on the node's executor, which the physics timer
    shares.  A call that does not get its turn within ``timeout`` seconds
    (the executor has stopped) returns None.
    """

    def __init__(self, node: Node, turns: Turns | None) -> None:
        self._turns = turns
        self._pending: queue.SimpleQueue = queue.SimpleQueue()
        self._guard = None if turns is not None else node.create_guard_condition(self._serve)
        self._node = node
        self.calls = 0  # functions run (or asked to run) so far

    def call(self, function: Callable[[], Any], timeout: float = ACCESS_TIMEOUT_S) -> Any:
        """Return ``function()`` run in the simulation's turn (None if it got none in time)."""
        self.calls += 1
        if self._turns is not None:
            with self._turns.callback():
                return function()
        done = threading.Event()
        result: list[Any] = []
        self._pending.put((function, result, done))
        self._guard.trigger()
        if not done.wait(timeout):
            return None
        if isinstance(result[0], BaseException):
            raise result[0]
        return result[0]

    def _serve(self) -> None:
        while True:
            try:
                function, result, done = self._pending.get_nowait()
            except queue.Empty:
                return
            try:
                result.append(function())
            except Exception as err:  # handed to the caller, which raises it
                result.append(err)
            done.set()

    def close(self) -> None:
        """Release the guard condition."""
        if self._guard is not None:
            self._node.destroy_guard_condition(self._guard)
            self._guard = None


# --- the joint sliders --------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class CommandChannel:
    """A command topic that takes joint positions: what a slider publishes on."""

    controller: str
    topic: str
    message: str  # 'float64', 'float64_array' or 'joint_trajectory'
    joints: tuple[str, ...]


@dataclasses.dataclass(frozen=True)
class Slider:
    """One position-controlled joint's slider: its range (rad or m) and its channel."""

    joint: str
    lower: float
    upper: float
    channel: CommandChannel

    def clamp(self, value: float) -> float:
        """Return ``value`` within the slider's range."""
        return min(max(value, self.lower), self.upper)


FLOAT64 = 'float64'
FLOAT64_ARRAY = 'float64_array'
JOINT_TRAJECTORY = 'joint_trajectory'


def position_channel(controller: Controller, topic: Callable[..., str]) -> CommandChannel | None:
    """Return the topic on which ``controller`` takes joint positions, or None if it takes none.

    ``topic(controller, name)`` resolves the controller's own topic name.
    Position controllers (``position_controllers/`` and ``effort_controllers/``
    JointPositionController), forward command controllers on the position
    interface (JointGroupPositionController) and joint trajectory controllers.
    """
    joints = tuple(controller.joint_names)
    if isinstance(controller, JointPositionController):
        return CommandChannel(controller.name, topic(controller.name, 'command'), FLOAT64,
                              joints)
    if isinstance(controller, ForwardCommandController) and \
            controller.interface_name == POSITION:
        return CommandChannel(controller.name, topic(controller.name, 'commands'),
                              FLOAT64_ARRAY, joints)
    if isinstance(controller, JointTrajectoryController):
        return CommandChannel(controller.name, topic(controller.name, 'joint_trajectory'),
                              JOINT_TRAJECTORY, joints)
    return None


def slider_range(joint: JointSpec) -> tuple[float, float]:
    """Return a slider's range for ``joint``: its limits, else a turn or a metre either way."""
    if joint.has_position_limits and math.isfinite(joint.lower) and math.isfinite(joint.upper):
        return joint.lower, joint.upper
    span = PRISMATIC_RANGE if joint.kind is JointKind.PRISMATIC else CONTINUOUS_RANGE
    lower = joint.lower if math.isfinite(joint.lower) and joint.has_position_limits else -span
    upper = joint.upper if math.isfinite(joint.upper) and joint.has_position_limits else span
    return lower, max(upper, lower)


def position_sliders(active: Iterable[Controller], model: RobotModel,
                     topic: Callable[..., str]) -> tuple[Slider, ...]:
    """Return a slider per joint whose position an active controller takes, in model order."""
    found: dict[str, Slider] = {}
    for controller in active:
        channel = position_channel(controller, topic)
        if channel is None:
            continue
        for joint in channel.joints:
            if joint in model.joint_names:
                found.setdefault(joint, Slider(joint, *slider_range(model.joint(joint)), channel))
    return tuple(found[name] for name in model.joint_names if name in found)


def command_message(channel: CommandChannel, targets: Mapping[str, float],
                    positions: Mapping[str, float], model: RobotModel) -> Any:
    """Return the message that sends ``channel``'s joints to ``targets``.

    A joint without a target keeps its present position (``positions``).  A
    trajectory reaches its one point in :data:`TRAJECTORY_MIN_S`, or in the
    time the slowest joint needs at its velocity limit.
    """
    values = [float(targets.get(joint, positions.get(joint, 0.0))) for joint in channel.joints]
    if channel.message == FLOAT64:
        return Float64(data=values[0])
    if channel.message == FLOAT64_ARRAY:
        return Float64MultiArray(data=values)
    duration = TRAJECTORY_MIN_S
    for joint, value in zip(channel.joints, values, strict=True):
        limit = model.joint(joint).velocity_limit
        if math.isfinite(limit) and limit > 0.0:
            duration = max(duration, abs(value - positions.get(joint, value)) / limit)
    seconds = math.floor(duration)
    point = JointTrajectoryPoint(
        positions=values,
        time_from_start=Duration(sec=seconds, nanosec=round((duration - seconds) * 1e9)))
    return JointTrajectory(joint_names=list(channel.joints), points=[point])


MESSAGE_TYPES = {FLOAT64: Float64, FLOAT64_ARRAY: Float64MultiArray,
                 JOINT_TRAJECTORY: JointTrajectory}


class CommandSender:
    """Publishes the sliders' commands, one publisher per command topic (made on first use)."""

    def __init__(self, node: Node) -> None:
        self._node = node
        self._publishers: dict[str, Any] = {}
        self._lock = threading.Lock()
        self.sent = 0  # commands published

    def send(self, channel: CommandChannel, message: Any) -> None:
        """Publish ``message`` on ``channel``'s topic (from any thread)."""
        with self._lock:
            publisher = self._publishers.get(channel.topic)
            if publisher is None:
                publisher = self._node.create_publisher(
                    MESSAGE_TYPES[channel.message], channel.topic, 10)
                self._publishers[channel.topic] = publisher
            publisher.publish(message)
            self.sent += 1

    def close(self) -> None:
        """Destroy the publishers."""
        with self._lock:
            for publisher in self._publishers.values():
                self._node.destroy_publisher(publisher)
            self._publishers.clear()


# --- what the view draws, taken between batches of steps ----------------------------------


@dataclasses.dataclass(frozen=True)
class EntityView:
    """An entity other than the first robot: where its root link is, its joints, its description.

    A robot spawned after the first is one too, with its own description and joints.
    """

    pose: Transform
    positions: Mapping[str, float]
    description: RobotDescription | None  # None for the scenery's targets


@dataclasses.dataclass(frozen=True)
class Snapshot:
    """The simulation as the view draws it, at one moment between two batches of steps."""

    time: float
    paused: bool
    real_time_factor: float
    robot_pose: Transform | None  # None: the robot the world began with was deleted
    positions: Mapping[str, float]  # the robot's movable joints
    entities: Mapping[str, EntityView]
    sliders: tuple[Slider, ...]


def take_snapshot(node: Any) -> Snapshot:
    """Return sim_node's simulation as it is now (call it through :class:`SimulationAccess`).

    The first robot (gone once DeleteEntity took it) apart; every other
    entity, later robots with their descriptions and joints, in ``entities``.
    """
    simulation = node.simulation
    entities = node.features.entities
    robot = entities.robot_name if simulation.has_robot else None
    later_robots = node.spawned_robots
    views = {}
    for name in entities.names():
        if name == robot:
            continue
        later = later_robots.get(name)
        if later is not None:
            views[name] = EntityView(entities.state(name).pose,
                                     later.simulation.joint_positions(),
                                     later.simulation.description)
            continue
        views[name] = EntityView(entities.state(name).pose, entities.joint_positions(name),
                                 entities.get(name).description)
    sliders = () if node.topic_hardware is not None else position_sliders(
        simulation.manager.active, simulation.description.model, node.topic)
    return Snapshot(time=simulation.time, paused=node.paused,
                    real_time_factor=node.real_time_factor,
                    robot_pose=None if robot is None else entities.state(robot).pose,
                    positions=simulation.joint_positions(), entities=views, sliders=sliders)


def frame_poses(model: RobotModel, positions: Mapping[str, float], base: Transform,
                extra: Sequence[Frame] = ()) -> dict[str, Transform]:
    """Return the world pose of every link and of every ``extra`` TF frame hung on one.

    ``base`` is the root link's pose in the world; ``extra`` are (parent,
    child, pose) edges (sensor and optical frames) whose parent is a link or
    an earlier extra frame.
    """
    poses = {name: base.then(pose) for name, pose in model.link_poses(positions).items()}
    for parent, child, pose in extra:
        if parent in poses and child not in poses:
            poses[child] = poses[parent].then(pose)
    return poses


# --- the sensors' topics ------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class SensorTopic:
    """A lidar's or camera's topic the view shows: points in ``frame``, or an image."""

    name: str  # the sensor's name (the default camera: 'camera')
    topic: str
    kind: str  # 'scan', 'points' or 'image'


def sensor_topics(sensor_publishers: Iterable[Any], camera_image_topic: str | None
                  ) -> list[SensorTopic]:
    """Return the topic the view reads for each lidar (points, else scan) and camera (image)."""
    found = []
    for publisher in sensor_publishers:
        interface = publisher.interface
        kind = interface.sensor.kind
        topics = interface.topics
        if kind is SensorKind.LIDAR:
            role = 'points' if 'points' in topics else 'scan' if 'scan' in topics else None
        elif kind in (SensorKind.CAMERA, SensorKind.DEPTH):
            role = 'image' if 'image' in topics else None
        else:
            role = None
        if role is not None:
            found.append(SensorTopic(interface.sensor.name, topics[role],
                                     'image' if role == 'image' else role))
    if camera_image_topic is not None:
        found.append(SensorTopic('camera', camera_image_topic, 'image'))
    return found


_SENSOR_TYPES = {'scan': LaserScan, 'points': PointCloud2, 'image': Image}


class SensorTaps:
    """Subscriptions to the sensors' topics while a browser watches; each keeps its newest message.

    :meth:`watch` must run between batches of steps (through
    :class:`SimulationAccess`): it creates or destroys subscriptions.
    """

    def __init__(self, node: Node, topics: Sequence[SensorTopic]) -> None:
        self._node = node
        self.topics = tuple(topics)
        self._subscriptions: list[Any] = []
        self.latest: dict[str, Any] = {}  # by topic; replaced whole by the callbacks

    @property
    def watching(self) -> bool:
        """Whether the subscriptions exist."""
        return bool(self._subscriptions)

    def watch(self, wanted: bool) -> None:
        """Create the subscriptions (``wanted``) or destroy them."""
        if wanted and not self._subscriptions:
            for entry in self.topics:
                self._subscriptions.append(self._node.create_subscription(
                    _SENSOR_TYPES[entry.kind], entry.topic, self._keeper(entry.topic),
                    QUEUE_DEPTH))
        elif not wanted and self._subscriptions:
            for subscription in self._subscriptions:
                self._node.destroy_subscription(subscription)
            self._subscriptions = []
            self.latest = {}

    def _keeper(self, topic: str) -> Callable[[Any], None]:
        def keep(message: Any) -> None:
            self.latest[topic] = message
        return keep


def scan_points(message: LaserScan) -> np.ndarray:
    """Return a LaserScan's returns as points (N x 3) in its frame (out of range: dropped)."""
    ranges = np.asarray(message.ranges, dtype=float)
    angles = message.angle_min + message.angle_increment * np.arange(len(ranges))
    valid = np.isfinite(ranges) & (ranges >= message.range_min) & (ranges <= message.range_max)
    r, a = ranges[valid], angles[valid]
    return np.column_stack([r * np.cos(a), r * np.sin(a), np.zeros_like(r)]).astype(np.float32)


def cloud_points(message: PointCloud2) -> np.ndarray:
    """Return a PointCloud2's finite x, y, z (FLOAT32 fields) as points (N x 3) in its frame."""
    offsets = {field.name: field.offset for field in message.fields}
    count = message.width * message.height
    if not {'x', 'y', 'z'} <= offsets.keys() or count == 0:
        return np.zeros((0, 3), np.float32)
    order = '>' if message.is_bigendian else '<'
    raw = np.frombuffer(message.data, dtype=np.uint8)[:count * message.point_step]
    rows = raw.reshape(count, message.point_step)
    xyz = np.column_stack([rows[:, offsets[axis]:offsets[axis] + 4].copy().view(f'{order}f4')
                           [:, 0] for axis in 'xyz'])
    return xyz[np.isfinite(xyz).all(axis=1)].astype(np.float32)


def image_pixels(message: Image) -> np.ndarray | None:
    """Return an rgb8, bgr8 or mono8 Image as height x width x 3 uint8 (None: another encoding)."""
    channels = {'rgb8': 3, 'bgr8': 3, 'mono8': 1}.get(message.encoding)
    if channels is None or message.width == 0 or message.height == 0:
        return None
    raw = np.frombuffer(message.data, dtype=np.uint8)[:message.height * message.step]
    pixels = raw.reshape(message.height, message.step)[:, :message.width * channels]
    pixels = pixels.reshape(message.height, message.width, channels)
    if message.encoding == 'bgr8':
        return pixels[..., ::-1]
    if channels == 1:
        return np.repeat(pixels, 3, axis=2)
    return pixels
