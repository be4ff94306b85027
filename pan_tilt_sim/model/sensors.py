"""Sensors declared the Gazebo way, and the ROS names their plugins would give them. No ROS.

A URDF declares a sensor in ``<gazebo reference="LINK"><sensor type="..." name="...">``
(a force-torque sensor references a JOINT), optionally with a gazebo_ros plugin
inside that decides the ROS topics and the frame.  The parser
(:mod:`pan_tilt_sim.model.urdf`) reads them into :class:`SensorSpec`; this
module also resolves, per plugin convention, the topic names and the frame id
a Gazebo user would see (:func:`sensor_interface`):

* **ROS 1** gazebo_plugins (noetic): a ``ros::NodeHandle`` in
  ``robotNamespace`` (plus ``/cameraName`` for cameras), topics from
  ``imageTopicName``, ``topicName``... relative to it (absolute ones stay);
* **ROS 2** gazebo_ros (``<ros><namespace>``, ``<remapping>``): a node named
  after the plugin, topics ``<camera_name>/image_raw``, ``~/out`` and
  ``wrench``, remapped as rcl remaps them;
* **gz-sim** (no plugin): the sensor's ``<topic>`` as ros_gz_bridge would
  carry it under the same name, else gz's default topic.

Plain values; the simulation and the ROS layer read these, never the XML.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Mapping

from pan_tilt_sim.model.transforms import Transform

ROS1 = 'ros1'
ROS2 = 'ros2'
GZ = 'gz'
GZ_WORLD = 'default'  # the world name in gz's default sensor topics
ROS1_NODE = '/gazebo'  # ROS 1: '~' names resolve under Gazebo's node
OPTICAL_ROTATION = (-0.5, 0.5, -0.5, 0.5)  # rpy(-pi/2, 0, -pi/2): x fwd, z up -> REP-103 optical
DEFAULT_ROS2_MIN_DEPTH = 0.4  # m: gazebo_ros_camera's min_depth
ROS1_POINT_CLOUD_CUTOFF = 0.4  # m: openni_kinect / depth_camera pointCloudCutoff
ROS1_KINECT_CUTOFF_MAX = 5.0  # m: openni_kinect pointCloudCutoffMax
ROS1_IMU_RATE = 1.0  # Hz: gazebo_ros_imu_sensor's updateRateHZ default


class SensorKind(enum.Enum):
    """What a sensor measures (several SDF types map to one kind)."""

    CAMERA = 'camera'
    DEPTH = 'depth'
    LIDAR = 'lidar'
    IMU = 'imu'
    FORCE_TORQUE = 'force_torque'


# SDF <sensor type> -> (kind, has colour).  Gazebo classic's 'depth' sensor also
# renders colour (its plugins publish an image and an rgb point cloud); gz-sim's
# 'depth_camera' does not, its 'rgbd_camera' does.
SENSOR_TYPES: dict[str, tuple[SensorKind, bool]] = {
    'camera': (SensorKind.CAMERA, True),
    'depth': (SensorKind.DEPTH, True),
    'rgbd_camera': (SensorKind.DEPTH, True),
    'rgbd': (SensorKind.DEPTH, True),
    'depth_camera': (SensorKind.DEPTH, False),
    'ray': (SensorKind.LIDAR, False),
    'gpu_ray': (SensorKind.LIDAR, False),
    'gpu_lidar': (SensorKind.LIDAR, False),
    'lidar': (SensorKind.LIDAR, False),
    'imu': (SensorKind.IMU, False),
    'force_torque': (SensorKind.FORCE_TORQUE, False),
}

# Plugins by their file name without 'lib' and '.so': which kind each serves.
ROS1_ONLY_PLUGINS = {
    'gazebo_ros_openni_kinect': SensorKind.DEPTH,
    'gazebo_ros_depth_camera': SensorKind.DEPTH,
    'gazebo_ros_laser': SensorKind.LIDAR,
    'gazebo_ros_gpu_laser': SensorKind.LIDAR,
    'gazebo_ros_block_laser': SensorKind.LIDAR,
}
SHARED_PLUGINS = {  # the same file name in ROS 1 and ROS 2 gazebo_plugins
    'gazebo_ros_camera': (SensorKind.CAMERA, SensorKind.DEPTH),
    'gazebo_ros_imu_sensor': (SensorKind.IMU,),
    'gazebo_ros_ft_sensor': (SensorKind.FORCE_TORQUE,),
}
ROS2_ONLY_PLUGINS = {
    'gazebo_ros_ray_sensor': SensorKind.LIDAR,
}
# Elements only one generation's plugins read: they tell which one a shared file name is.
ROS1_KEYS = {'robotNamespace', 'cameraName', 'imageTopicName', 'cameraInfoTopicName',
             'frameName', 'topicName', 'updateRate', 'updateRateHZ', 'gaussianNoise',
             'jointName', 'initialOrientationAsReference', 'hackBaseline'}
ROS2_KEYS = {'ros', 'camera_name', 'frame_name', 'output_type', 'min_depth', 'max_depth',
             'joint_name', 'update_rate', 'gaussian_noise', 'initial_orientation_as_reference',
             'hack_baseline'}
LASER_SCAN = 'sensor_msgs/LaserScan'
POINT_CLOUD2 = 'sensor_msgs/PointCloud2'

# ForceTorque frames and measure directions (SDF <force_torque>).
CHILD = 'child'
PARENT = 'parent'
SENSOR = 'sensor'
CHILD_TO_PARENT = 'child_to_parent'
PARENT_TO_CHILD = 'parent_to_child'


def plugin_stem(filename: str) -> str:
    """Return a plugin file name without its ``lib`` prefix and ``.so`` suffix."""
    stem = filename.strip()
    stem = stem.rsplit('/', 1)[-1]
    stem = stem.removesuffix('.so')
    return stem.removeprefix('lib')


@dataclasses.dataclass(frozen=True)
class Noise:
    """An SDF ``<noise>``: Gaussian with a mean and a standard deviation, plus a bias.

    The bias is drawn once per run from N(bias_mean, bias_stddev) with a random
    sign, as Gazebo does.  ``stddev`` 0 and ``mean`` 0 and no bias: no noise.
    """

    mean: float = 0.0
    stddev: float = 0.0
    bias_mean: float = 0.0
    bias_stddev: float = 0.0

    @property
    def is_zero(self) -> bool:
        """Whether this noise changes nothing."""
        return not (self.mean or self.stddev or self.bias_mean or self.bias_stddev)


NO_NOISE = Noise()
NO_NOISE_3 = (NO_NOISE, NO_NOISE, NO_NOISE)


@dataclasses.dataclass(frozen=True)
class CameraSpec:
    """A ``<camera>``: image size, horizontal field of view (rad), clip planes (m)."""

    width: int = 320
    height: int = 240
    horizontal_fov: float = 1.047
    near: float = 0.1
    far: float = 100.0
    format: str = 'R8G8B8'
    noise: Noise = NO_NOISE
    depth_near: float | None = None  # gz's <depth_camera><clip>, when given
    depth_far: float | None = None

    @property
    def focal_length(self) -> float:
        """Return fx = fy in pixels (square pixels): (width / 2) / tan(hfov / 2)."""
        return (self.width / 2.0) / math.tan(self.horizontal_fov / 2.0)

    @property
    def vertical_fov(self) -> float:
        """The vertical field of view (rad) for square pixels."""
        return 2.0 * math.atan(math.tan(self.horizontal_fov / 2.0) * self.height / self.width)


@dataclasses.dataclass(frozen=True)
class ScanAxis:
    """One axis of a ``<scan>``: ``samples`` rays from ``min_angle`` to ``max_angle`` (rad)."""

    samples: int = 1
    resolution: float = 1.0
    min_angle: float = 0.0
    max_angle: float = 0.0

    @property
    def count(self) -> int:
        """Rays cast along this axis: samples x resolution, as Gazebo returns them."""
        return max(1, round(self.samples * self.resolution))

    def angles(self) -> tuple[float, ...]:
        """Return the rays' angles, first to last, evenly spaced."""
        count = self.count
        if count == 1:
            return (self.min_angle,)
        step = (self.max_angle - self.min_angle) / (count - 1)
        return tuple(self.min_angle + index * step for index in range(count))

    @property
    def increment(self) -> float:
        """Angle between neighbouring rays (0 for a single ray)."""
        count = self.count
        return 0.0 if count == 1 else (self.max_angle - self.min_angle) / (count - 1)


@dataclasses.dataclass(frozen=True)
class RaySpec:
    """A ``<ray>`` / ``<lidar>``: the scan, the range limits (m) and the range noise."""

    horizontal: ScanAxis = ScanAxis()
    vertical: ScanAxis = ScanAxis()
    range_min: float = 0.0
    range_max: float = 0.0
    range_resolution: float = 0.0
    noise: Noise = NO_NOISE

    @property
    def rows(self) -> int:
        """Rows of the scan (1 for a planar lidar)."""
        return self.vertical.count


# Bounds of a sensor's sizes, each with the reason the error gives (see sensor_size_problem).
# A scan: as many beams as the densest real lidars return per scan (128 channels x 2048
# columns); each beam is one PyBullet ray cast every scan.
MAX_SCAN_BEAMS = 128 * 2048
SCAN_BEAMS_REASON = 'the densest real lidars: 128 channels x 2048 columns'
# An image: 4K UHD.  PyBullet renders on the CPU; a larger image costs seconds and
# hundreds of MB per frame (rgb, depth, and a depth camera's point cloud).
MAX_IMAGE_PIXELS = 3840 * 2160
IMAGE_PIXELS_REASON = "4K UHD (3840 x 2160): what PyBullet's CPU renderer draws in " \
    'reasonable time and memory'
MAX_SCAN_ANGLE = 2.0 * math.pi  # rad: a scan angle beyond a full turn either way means nothing
# A camera's clip range: far / near at most this.  PyBullet renders with a float32 depth
# buffer; from a ratio of 1e8 on its every depth is NaN (test/sim/test_sensors.py).
MAX_CLIP_RATIO = 1e6


def scan_axis_problem(axis: ScanAxis, tag: str) -> str | None:
    """Say what is wrong with one axis of a scan (``tag``: horizontal, vertical), or None."""
    for name in ('min_angle', 'max_angle'):
        value = getattr(axis, name)
        if not -MAX_SCAN_ANGLE <= value <= MAX_SCAN_ANGLE:
            return (f'<{tag}><{name}> {value:g} rad is beyond +-2 pi: a scan angle must lie '
                    'within one turn either way')
    if axis.count > 1 and not axis.min_angle < axis.max_angle:
        return (f'<{tag}> needs min_angle < max_angle for {axis.count} beams, got min_angle '
                f'{axis.min_angle:g}, max_angle {axis.max_angle:g}')
    if axis.max_angle < axis.min_angle:
        return (f'<{tag}> max_angle {axis.max_angle:g} is below min_angle '
                f'{axis.min_angle:g}')
    return None


def scan_size_problem(ray: RaySpec) -> str | None:
    """Say what is wrong with a scan's angles or beam count (at most MAX_SCAN_BEAMS), or None."""
    for tag in ('horizontal', 'vertical'):
        axis = getattr(ray, tag)
        if axis.samples * axis.resolution > MAX_SCAN_BEAMS:  # before counting: may overflow
            return (f'<{tag}> {axis.samples} samples x resolution {axis.resolution:g} is more '
                    f'than the limit of {MAX_SCAN_BEAMS} beams per scan ({SCAN_BEAMS_REASON})')
        problem = scan_axis_problem(axis, tag)
        if problem:
            return problem
    beams = ray.horizontal.count * ray.vertical.count
    if beams > MAX_SCAN_BEAMS:
        return (f'{ray.horizontal.count} x {ray.vertical.count} = {beams} beams per scan is '
                f'more than the limit of {MAX_SCAN_BEAMS} ({SCAN_BEAMS_REASON})')
    return None


def clip_problem(camera: CameraSpec) -> str | None:
    """Say why a camera's clip planes (and a depth camera's own) cannot render, or None."""
    planes = [('<clip>', camera.near, camera.far)]
    if camera.depth_near is not None or camera.depth_far is not None:
        planes.append(('<depth_camera><clip>', camera.depth_near or camera.near,
                       camera.depth_far or camera.far))
    for tag, near, far in planes:
        if not 0.0 < near < far:
            return f'{tag} needs 0 < near < far, got near {near:g}, far {far:g}'
        if far / near > MAX_CLIP_RATIO:
            return (f'{tag} far / near = {far / near:g} is more than the limit of '
                    f'{MAX_CLIP_RATIO:g} (PyBullet renders every depth as NaN from 1e8 on)')
    return None


def image_size_problem(camera: CameraSpec) -> str | None:
    """Say why a camera's image is too large (more than MAX_IMAGE_PIXELS), or None."""
    pixels = camera.width * camera.height
    if pixels > MAX_IMAGE_PIXELS:
        return (f'{camera.width} x {camera.height} = {pixels} pixels per image is more than '
                f'the limit of {MAX_IMAGE_PIXELS} ({IMAGE_PIXELS_REASON})')
    return None


@dataclasses.dataclass(frozen=True)
class ImuSpec:
    """An ``<imu>``: noise per axis of angular velocity (rad/s) and linear acceleration."""

    angular_velocity_noise: tuple[Noise, Noise, Noise] = NO_NOISE_3
    linear_acceleration_noise: tuple[Noise, Noise, Noise] = NO_NOISE_3


@dataclasses.dataclass(frozen=True)
class ForceTorqueSpec:
    """A ``<force_torque>``: the frame the wrench is given in, its direction, its noise."""

    frame: str = CHILD
    measure_direction: str = CHILD_TO_PARENT
    force_noise: tuple[Noise, Noise, Noise] = NO_NOISE_3
    torque_noise: tuple[Noise, Noise, Noise] = NO_NOISE_3


@dataclasses.dataclass(frozen=True)
class PluginSpec:
    """A gazebo_ros plugin as written: its file, name, elements, namespace and remappings."""

    filename: str
    name: str = ''
    params: Mapping[str, str] = dataclasses.field(default_factory=dict)  # child text by tag
    ros_namespace: str | None = None  # ROS 2 <ros><namespace>
    remappings: tuple[tuple[str, str], ...] = ()  # ROS 2 <ros><remapping>from:=to

    @property
    def stem(self) -> str:
        """The file name without ``lib`` and ``.so``."""
        return plugin_stem(self.filename)

    @property
    def generation(self) -> str:
        """ROS1 or ROS2: which gazebo_plugins this plugin (and its element names) belongs to."""
        stem = self.stem
        if stem in ROS1_ONLY_PLUGINS:
            return ROS1
        if stem in ROS2_ONLY_PLUGINS:
            return ROS2
        keys = set(self.params)
        if self.ros_namespace is not None or self.remappings or keys & ROS2_KEYS:
            return ROS2
        if keys & ROS1_KEYS:
            return ROS1
        return ROS2  # a bare plugin: this is a ROS 2 package

    def get(self, key: str, default: str | None = None) -> str | None:
        """Return the text of element ``key`` (stripped), or ``default`` if absent."""
        value = self.params.get(key)
        return default if value is None else value

    def number(self, key: str, default: float) -> float:
        """Return element ``key`` as a float (already checked by the parser)."""
        value = self.params.get(key)
        return default if value is None or value == '' else float(value)

    def flag(self, key: str, default: bool) -> bool:
        """Return element ``key`` as a boolean (``true``/``1``)."""
        value = self.params.get(key)
        if value is None:
            return default
        return value.strip().lower() in ('true', '1')


@dataclasses.dataclass(frozen=True)
class SensorSpec:
    """One sensor: where it is, how often it measures, what it measures and its plugin.

    ``link`` carries the sensor (for a force-torque sensor, the joint's child
    link); ``pose`` places the sensor frame in the link frame (Gazebo's
    ``<pose>``; cameras and lidars look along its +x, +z up).  ``update_rate``
    0 means every physics step, as "as fast as possible" does in Gazebo.
    """

    name: str
    type: str
    kind: SensorKind
    link: str
    pose: Transform = Transform()
    update_rate: float = 0.0
    joint: str = ''  # force-torque sensors: the joint measured ...
    parent_link: str = ''  # ... and its parent link
    colour: bool = False  # depth sensors: whether they also see colour
    topic: str = ''  # gz <topic>
    frame_id: str = ''  # gz <frame_id> / <gz_frame_id> / <ignition_frame_id>
    camera: CameraSpec | None = None
    ray: RaySpec | None = None
    imu: ImuSpec | None = None
    force_torque: ForceTorqueSpec | None = None
    plugin: PluginSpec | None = None
    model_plugin: bool = False  # declared as a <gazebo><plugin> (ft_sensor), not a <sensor>


@dataclasses.dataclass(frozen=True)
class SensorInterface:
    """What a sensor shows on ROS: topics by role, frame id, rate and plugin options.

    Roles: ``image``, ``camera_info``, ``depth``, ``depth_info``, ``points``,
    ``scan``, ``imu``, ``wrench``.  ``depth_range`` bounds the valid depth of
    depth images and point clouds; ``noise_stddev`` is a plugin's Gaussian
    noise on every value (ROS 1 ``gaussianNoise``, ROS 2 ``gaussian_noise``).
    """

    sensor: SensorSpec
    convention: str
    topics: Mapping[str, str]
    frame_id: str
    rate: float
    depth_range: tuple[float, float] = (0.0, math.inf)
    noise_stddev: float = 0.0
    orientation_from_start: bool = False  # IMU orientation relative to its initial one
    measure_direction: str = CHILD_TO_PARENT  # force-torque: the wrench on whom
    wrench_frame: str = CHILD


def normalize_name(name: str) -> str:
    """Collapse repeated '/' and drop a trailing one; keep a leading one."""
    parts = [part for part in name.split('/') if part]
    return ('/' if name.startswith('/') else '') + '/'.join(parts)


def ros1_resolve(namespace: str, name: str) -> str:
    """Resolve ``name`` as a ROS 1 ``NodeHandle(namespace)`` does (absolute result)."""
    if name.startswith('/'):
        return normalize_name(name)
    if name.startswith('~'):
        return normalize_name(f'{ROS1_NODE}/{name[1:]}')
    return normalize_name(f'/{namespace}/{name}')


class Ros2Names:
    """A ROS 2 node's name expansion and remapping, as rcl does it for topics."""

    def __init__(self, node_name: str, namespace: str,
                 remappings: tuple[tuple[str, str], ...]) -> None:
        self.namespace = normalize_name('/' + namespace.strip('/')) if namespace.strip('/') \
            else '/'
        self.node_name = node_name
        self._rules = [(self.expand(source), target) for source, target in remappings
                       if source and not source.startswith('__')]

    def expand(self, name: str) -> str:
        """Expand ``~`` and relative names to a fully qualified name."""
        base = self.namespace.rstrip('/')
        if name.startswith('/'):
            return normalize_name(name)
        if name.startswith('~'):
            return normalize_name(f'{base}/{self.node_name}/{name[1:]}')
        return normalize_name(f'{base}/{name}')

    def topic(self, name: str) -> str:
        """Return the topic that the node's ``name`` resolves to after remapping."""
        expanded = self.expand(name)
        for source, target in self._rules:
            if source == expanded:
                return self.expand(target)
        return expanded


def _frame(frame: str | None, fallback: str) -> str:
    """Return a tf2 frame id: no leading '/'; an empty one -> ``fallback``."""
    text = (frame or '').strip().lstrip('/')
    return text or fallback


def _min_rate(sensor_rate: float, plugin_rate: float) -> float:
    """Return the rate a plugin throttling a sensor publishes at (0: no limit)."""
    rates = [rate for rate in (sensor_rate, plugin_rate) if rate > 0.0]
    return min(rates) if rates else 0.0


def sensor_interface(sensor: SensorSpec, robot_name: str,
                     namespace_override: str = '') -> SensorInterface:
    """Return the topics, frame and rate ``sensor`` has on ROS.

    ``namespace_override`` (sim_node's own namespace or its ``robot_namespace``
    parameter, as spawn's ``-robot_namespace`` does in Gazebo) replaces the
    plugins' namespaces and prefixes gz topics.
    """
    plugin = sensor.plugin
    if plugin is None:
        return _gz_interface(sensor, robot_name, namespace_override)
    if plugin.generation == ROS1:
        return _ros1_interface(sensor, plugin, robot_name, namespace_override)
    return _ros2_interface(sensor, plugin, namespace_override)


def _ros1_interface(sensor: SensorSpec, plugin: PluginSpec, robot_name: str,
                    override: str) -> SensorInterface:
    kind = sensor.kind
    stem = plugin.stem
    namespace = plugin.get('robotNamespace')
    if namespace is not None and not namespace.strip():
        namespace = robot_name  # GetRobotNamespace: an empty robotNamespace -> the model's name
    if override:
        namespace = override
    frame = _frame(None if plugin.get('frameName') in (None, '/world', 'world')
                   else plugin.get('frameName'), sensor.link)
    rate = sensor.update_rate
    fields: dict = {}
    if kind in (SensorKind.CAMERA, SensorKind.DEPTH):
        base = f"{namespace or ''}/{plugin.get('cameraName', '')}"
        depth_plugin = stem in ('gazebo_ros_openni_kinect', 'gazebo_ros_depth_camera')
        image = plugin.get('imageTopicName', 'ir/image_raw' if depth_plugin else 'image_raw')
        info = plugin.get('cameraInfoTopicName',
                          'ir/camera_info' if depth_plugin else 'camera_info')
        topics = {'image': ros1_resolve(base, image), 'camera_info': ros1_resolve(base, info)}
        if kind is SensorKind.DEPTH:
            topics['depth'] = ros1_resolve(base, plugin.get('depthImageTopicName',
                                                            'depth/image_raw'))
            topics['depth_info'] = ros1_resolve(base, plugin.get(
                'depthImageCameraInfoTopicName', 'depth/camera_info'))
            topics['points'] = ros1_resolve(base, plugin.get('pointCloudTopicName', 'points'))
            cutoff_max = math.inf if stem == 'gazebo_ros_depth_camera' \
                else ROS1_KINECT_CUTOFF_MAX
            fields['depth_range'] = (plugin.number('pointCloudCutoff', ROS1_POINT_CLOUD_CUTOFF),
                                     plugin.number('pointCloudCutoffMax', cutoff_max))
        rate = _min_rate(rate, plugin.number('updateRate', 0.0))
    elif kind is SensorKind.LIDAR:
        if stem == 'gazebo_ros_block_laser':
            namespace = f'{namespace}/' if namespace else ''
        topic = ros1_resolve(namespace or '', plugin.get('topicName', '/world'))
        key = 'points' if stem == 'gazebo_ros_block_laser' else 'scan'
        topics = {key: topic}
        fields['noise_stddev'] = plugin.number('gaussianNoise', 0.0)
        if stem == 'gazebo_ros_block_laser':
            rate = _min_rate(rate, plugin.number('updateRate', 0.0))
    elif kind is SensorKind.IMU:
        if namespace is None:
            namespace = f'/{robot_name}/'  # gazebo_ros_imu_sensor: the model's name
        topics = {'imu': ros1_resolve(namespace, plugin.get('topicName', 'imu_data'))}
        rate = _min_rate(rate, plugin.number('updateRateHZ', ROS1_IMU_RATE))
        fields['noise_stddev'] = plugin.number('gaussianNoise', 0.0)
        fields['orientation_from_start'] = plugin.flag('initialOrientationAsReference', False)
    else:  # force-torque: gazebo_ros_ft_sensor, a model plugin on a joint
        topics = {'wrench': ros1_resolve(namespace or '', plugin.get('topicName', 'ft_sensor'))}
        rate = _min_rate(rate, plugin.number('updateRate', 0.0))
        fields['noise_stddev'] = plugin.number('gaussianNoise', 0.0)
        fields.update(_ft_fields(sensor))
        frame = _ft_frame(sensor, fields['wrench_frame'])
    return SensorInterface(sensor=sensor, convention=ROS1, topics=topics, frame_id=frame,
                           rate=rate, **fields)


def _ros2_interface(sensor: SensorSpec, plugin: PluginSpec, override: str) -> SensorInterface:
    kind = sensor.kind
    namespace = override or plugin.ros_namespace or ''
    names = Ros2Names(plugin.name, namespace, plugin.remappings)
    frame = _frame(plugin.get('frame_name'), sensor.link)
    rate = sensor.update_rate
    fields: dict = {}
    if kind in (SensorKind.CAMERA, SensorKind.DEPTH):
        camera = plugin.get('camera_name') or sensor.name
        topics = {'image': names.topic(f'{camera}/image_raw'),
                  'camera_info': names.topic(f'{camera}/camera_info')}
        if kind is SensorKind.DEPTH:
            topics['depth'] = names.topic(f'{camera}/depth/image_raw')
            topics['depth_info'] = names.topic(f'{camera}/depth/camera_info')
            topics['points'] = names.topic(f'{camera}/points')
            fields['depth_range'] = (plugin.number('min_depth', DEFAULT_ROS2_MIN_DEPTH),
                                     plugin.number('max_depth', math.inf))
    elif kind is SensorKind.LIDAR:
        output = plugin.get('output_type', POINT_CLOUD2)
        topics = {'scan' if output == LASER_SCAN else 'points': names.topic('~/out')}
    elif kind is SensorKind.IMU:
        topics = {'imu': names.topic('~/out')}
        fields['orientation_from_start'] = plugin.flag('initial_orientation_as_reference', False)
    else:
        topics = {'wrench': names.topic('wrench')}
        rate = _min_rate(rate, plugin.number('update_rate', 0.0))
        fields['noise_stddev'] = plugin.number('gaussian_noise', 0.0)
        fields.update(_ft_fields(sensor))
        frame = _ft_frame(sensor, fields['wrench_frame'])
    return SensorInterface(sensor=sensor, convention=ROS2, topics=topics, frame_id=frame,
                           rate=rate, **fields)


def _ft_fields(sensor: SensorSpec) -> dict:
    if sensor.model_plugin:
        # Gazebo's JointWrench body2Force / body2Torque: what the parent applies
        # on the child, in the child link frame.
        return {'measure_direction': PARENT_TO_CHILD, 'wrench_frame': CHILD}
    spec = sensor.force_torque or ForceTorqueSpec()
    return {'measure_direction': spec.measure_direction, 'wrench_frame': spec.frame}


def _ft_frame(sensor: SensorSpec, wrench_frame: str) -> str:
    """gazebo_ros_ft_sensor's frame id: the link whose axes the wrench is in."""
    if wrench_frame == PARENT:
        return sensor.parent_link
    if wrench_frame == SENSOR:
        return _frame(sensor.frame_id, sensor.name)
    return sensor.link


GZ_SUFFIX = {SensorKind.CAMERA: 'image', SensorKind.DEPTH: 'depth_image',
             SensorKind.LIDAR: 'scan', SensorKind.IMU: 'imu',
             SensorKind.FORCE_TORQUE: 'forcetorque'}


def _gz_interface(sensor: SensorSpec, robot_name: str, override: str) -> SensorInterface:
    topic = sensor.topic.strip()
    if not topic:
        topic = (f'/world/{GZ_WORLD}/model/{robot_name}/link/{sensor.link}/sensor/'
                 f'{sensor.name}/{GZ_SUFFIX[sensor.kind]}')
    topic = normalize_name(f'/{override}/{topic}')
    parent = topic.rsplit('/', 1)[0]
    frame = _frame(sensor.frame_id, sensor.name)
    kind = sensor.kind
    fields: dict = {}
    if kind is SensorKind.CAMERA:
        topics = {'image': topic, 'camera_info': f'{parent}/camera_info'}
    elif kind is SensorKind.DEPTH and sensor.type == 'depth_camera':
        topics = {'depth': topic, 'depth_info': f'{parent}/camera_info',
                  'points': f'{topic}/points'}
    elif kind is SensorKind.DEPTH:  # rgbd_camera
        topics = {'image': f'{topic}/image', 'depth': f'{topic}/depth_image',
                  'camera_info': f'{topic}/camera_info', 'depth_info': f'{topic}/camera_info',
                  'points': f'{topic}/points'}
    elif kind is SensorKind.LIDAR:
        topics = {'scan': topic, 'points': f'{topic}/points'}
    elif kind is SensorKind.IMU:
        topics = {'imu': topic}
    else:
        topics = {'wrench': topic}
        fields.update(_ft_fields(sensor))
    return SensorInterface(sensor=sensor, convention=GZ, topics=topics, frame_id=frame,
                           rate=sensor.update_rate, **fields)


def data_frame(sensor: SensorSpec) -> Transform:
    """Return the pose, in the sensor's link frame, of the frame its data is given in.

    Cameras: the REP-103 optical frame (z forward, x right, y down) of a
    Gazebo camera looking along the sensor's +x with +z up.  Everything else:
    the sensor frame itself.
    """
    if sensor.kind in (SensorKind.CAMERA, SensorKind.DEPTH):
        return sensor.pose.then(Transform(rotation=OPTICAL_ROTATION))
    return sensor.pose
