"""Gazebo's drive plugins, read from ``<gazebo><plugin>``, as the plugin would read them. No ROS.

``libgazebo_ros_diff_drive.so`` drives a differential base from a
``geometry_msgs/Twist`` and publishes its odometry and the odom -> base
transform.  Both gazebo_plugins generations are read, each with its own
element names and defaults (from the plugins' sources) (see the design notes).

Design notes: docs/design/plugins.md#drive_pluginspy.
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
from collections.abc import Collection, Mapping
from xml.etree import ElementTree

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.frame_ids import frame_id_problem
from pan_tilt_sim.model.rates import rate_problem
from pan_tilt_sim.model.sensors import (
    GZ_WORLD,
    ROS1,
    ROS2,
    Ros2Names,
    plugin_stem,
    ros1_resolve,
)

DIFF_DRIVE = 'gazebo_ros_diff_drive'
P3D = 'gazebo_ros_p3d'
JOINT_STATE_PUBLISHER = 'gazebo_ros_joint_state_publisher'
WORLD_FRAMES = ('world', '/world', 'map', '/map')  # p3d: poses in the world
ROS1_P3D_KEYS = {'bodyName', 'frameName', 'topicName', 'xyzOffsets', 'rpyOffsets',
                 'gaussianNoise', 'updateRate', 'robotNamespace'}
ENCODER, WORLD = 'encoder', 'world'
GZ = 'gz'  # gz-sim's systems: SDF element names, gz-transport topics
ROS2_SOURCES = {0: ENCODER, 1: WORLD}  # gazebo_ros's odometry_source numbers
# Elements only one generation's diff drive reads: they tell which one a plugin is.
ROS1_DIFF_DRIVE_KEYS = {'leftJoint', 'rightJoint', 'wheelSeparation', 'wheelDiameter',
                        'commandTopic', 'odometryTopic', 'odometryFrame', 'robotBaseFrame',
                        'publishOdomTF', 'publishTf', 'updateRate', 'wheelTorque',
                        'wheelAcceleration', 'odometrySource', 'robotNamespace'}
UNPLANAR_COVARIANCE = 1e12  # z, roll, pitch: what the plugins put there
RATE_KEYS = ('rate', 'frequency')  # elements (lower case) whose value is a rate in Hz


@dataclasses.dataclass(frozen=True)
class DiffDrivePlugin:
    """One ``gazebo_ros_diff_drive`` plugin: wheels, geometry, limits, topics and frames.

    ``left_joints[i]`` and ``right_joints[i]`` are wheel pair i, with
    ``wheel_separation[i]`` (m) and ``wheel_diameter[i]`` (m).  Topics are
    as the plugin resolves them, before sim_node's namespace override
    (:meth:`topics`).  ``update_rate`` 0: every physics step.
    """

    name: str
    convention: str
    left_joints: tuple[str, ...]
    right_joints: tuple[str, ...]
    wheel_separation: tuple[float, ...]
    wheel_diameter: tuple[float, ...]
    max_wheel_torque: float = 5.0
    max_wheel_acceleration: float = 0.0
    update_rate: float = 100.0
    odometry_frame: str = 'odom'
    robot_base_frame: str = 'base_footprint'
    odometry_source: str = WORLD
    publish_odom: bool = False
    publish_odom_tf: bool = False
    covariance: tuple[float, float, float] = (1e-5, 1e-5, 1e-3)  # x, y, yaw
    command_topic: str = 'cmd_vel'
    odometry_topic: str = 'odom'
    namespace: str = ''
    remappings: tuple[tuple[str, str], ...] = ()

    filename = 'libgazebo_ros_diff_drive.so'

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Every wheel, left ones first."""
        return self.left_joints + self.right_joints

    def topics(self, override: str = '') -> tuple[str, str]:
        """Return the command and odometry topics (absolute), ``override`` as the namespace.

        ``override`` (sim_node's namespace or ``robot_namespace``) replaces the
        plugin's, as spawn's ``-robot_namespace`` does in Gazebo.
        """
        namespace = override or self.namespace
        if self.convention == ROS1:
            return (ros1_resolve(namespace, self.command_topic),
                    ros1_resolve(namespace, self.odometry_topic))
        names = Ros2Names(self.name, namespace, self.remappings)
        return names.topic(self.command_topic), names.topic(self.odometry_topic)

    @property
    def pose_covariance(self) -> tuple[float, ...]:
        """The odometry pose covariance's diagonal (x, y, z, roll, pitch, yaw)."""
        x, y, yaw = self.covariance
        return (x, y, UNPLANAR_COVARIANCE, UNPLANAR_COVARIANCE, UNPLANAR_COVARIANCE, yaw)

    @property
    def twist_covariance(self) -> tuple[float, ...]:
        """The odometry twist covariance's diagonal: ROS 2 repeats the pose's, ROS 1 has none."""
        return self.pose_covariance if self.convention == ROS2 else (0.0,) * 6


@dataclasses.dataclass(frozen=True)
class P3dPlugin:
    """One ``gazebo_ros_p3d`` plugin: which link, in which frame, offsets, noise, rate, topic.

    ``frame_name`` a link of the robot: the pose and twist relative to that
    link; ``world``/``map``: in the world.  Offsets: m and rad (roll, pitch,
    yaw); ``gaussian_noise``: the standard deviation added to each twist
    component.  ``update_rate`` 0: every physics step.
    """

    name: str
    convention: str
    body_name: str
    frame_name: str = 'world'
    xyz_offsets: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_offsets: tuple[float, float, float] = (0.0, 0.0, 0.0)
    gaussian_noise: float = 0.0
    update_rate: float = 0.0
    topic: str = 'odom'
    namespace: str = ''
    remappings: tuple[tuple[str, str], ...] = ()

    @property
    def in_world(self) -> bool:
        """Whether poses are in the world (not relative to a link)."""
        return self.frame_name in WORLD_FRAMES

    def topics(self, override: str = '') -> str:
        """Return the odometry topic (absolute), ``override`` as the namespace."""
        namespace = override or self.namespace
        if self.convention == ROS1:
            return ros1_resolve(namespace, self.topic)
        return Ros2Names(self.name, namespace, self.remappings).topic(self.topic)


@dataclasses.dataclass(frozen=True)
class JointStatePlugin:
    """One ``gazebo_ros_joint_state_publisher``: which joints, how often (Hz; 0: every step)."""

    name: str
    convention: str
    joints: tuple[str, ...]
    update_rate: float = 100.0
    namespace: str = ''
    remappings: tuple[tuple[str, str], ...] = ()
    topic: str = ''  # gz-sim's: the topic as the bridge carries it (no namespace applies)

    def topics(self, override: str = '') -> str:
        """Return the joint states topic (absolute), ``override`` as the namespace."""
        if self.convention == GZ:
            return self.topic
        namespace = override or self.namespace
        if self.convention == ROS1:
            return ros1_resolve(namespace, 'joint_states')
        return Ros2Names(self.name, namespace, self.remappings).topic('joint_states')


def read_joint_state_plugins(root: ElementTree.Element, source: pathlib.Path | str,
                             joints: Collection[str]) -> tuple[JointStatePlugin, ...]:
    """Return the robot's ``gazebo_ros_joint_state_publisher`` plugins (see the module).

    ``joints`` are the robot's movable joints: a name outside them, or none, ends start-up.
    """
    plugins = []
    for gazebo in root.findall('gazebo'):
        if gazebo.get('reference') is not None:
            continue
        for element in gazebo.findall('plugin'):
            if plugin_stem(element.get('filename', '')) != JOINT_STATE_PUBLISHER:
                continue
            reader = _PluginReader(element, source, root.get('name', ''))
            ros1 = 'jointName' in reader.texts or 'updateRate' in reader.texts or \
                'robotNamespace' in reader.texts
            key = 'jointName' if ros1 else 'joint_name'
            names = [name.strip() for text in reader.all(key) for name in (
                text.split(',') if ros1 else [text]) if name.strip()]
            if not names:
                raise reader.error(key, 'is missing: name the joints to publish')
            for name in names:
                if name not in joints:
                    raise reader.error(key, f"'{name}' is not a movable joint of this robot")
            namespace, remappings = ('', ()) if ros1 else reader.ros()
            plugins.append(JointStatePlugin(
                name=reader.name, convention=ROS1 if ros1 else ROS2, joints=tuple(names),
                update_rate=reader.number('updateRate' if ros1 else 'update_rate', 100.0,
                                          non_negative=True),
                namespace=reader.ros1_namespace() if ros1 else namespace,
                remappings=remappings))
    return tuple(plugins)


class _PluginReader:
    """Reads one ``<plugin>`` element's children; bad values name the plugin and the element."""

    def __init__(self, element: ElementTree.Element, source: pathlib.Path | str,
                 robot_name: str) -> None:
        self.element = element
        self.name = element.get('name', '') or plugin_stem(element.get('filename', ''))
        self.filename = element.get('filename', '')
        self.source = source
        self.robot_name = robot_name
        self.texts: dict[str, list[str]] = {}
        for child in element:
            self.texts.setdefault(child.tag, []).append((child.text or '').strip())

    def error(self, key: str, problem: str) -> DescriptionError:
        return DescriptionError(
            f"{self.source}: plugin '{self.name}' ({self.filename}): <{key}> {problem}")

    def text(self, key: str, default: str) -> str:
        values = self.texts.get(key)
        return values[0] if values and values[0] else default

    def all(self, key: str) -> list[str]:
        return [value for value in self.texts.get(key, []) if value]

    def number(self, key: str, default: float, *, positive: bool = False,
               non_negative: bool = False) -> float:
        value = self.check(key, self.text(key, ''), default, positive, non_negative)
        if key.lower().endswith(RATE_KEYS):  # a rate: its period must be finite too
            problem = rate_problem(value, zero_allowed=not positive)
            if problem:
                raise self.error(key, problem)
        return value

    def check(self, key: str, text: str, default: float, positive: bool = False,
              non_negative: bool = False) -> float:
        if not text:
            return default
        try:
            value = float(text)
        except ValueError:
            raise self.error(key, f"'{text}' is not a number") from None
        if not math.isfinite(value):
            raise self.error(key, f"'{text}' is not a finite number")
        if positive and value <= 0.0:
            raise self.error(key, f'must be > 0, got {value:g}')
        if non_negative and value < 0.0:
            raise self.error(key, f'must be >= 0, got {value:g}')
        return value

    def vector(self, key: str) -> tuple[float, float, float]:
        text = self.text(key, '')
        if not text:
            return (0.0, 0.0, 0.0)
        words = text.split()
        if len(words) != 3:
            raise self.error(key, f"'{text}' is not three numbers")
        x, y, z = (self.check(key, word, 0.0) for word in words)
        return (x, y, z)

    def flag(self, key: str, default: bool) -> bool:
        text = self.text(key, '').lower()
        if not text:
            return default
        if text in ('true', '1'):
            return True
        if text in ('false', '0'):
            return False
        raise self.error(key, f"'{text}' is not a boolean (true/false)")

    def ros1_namespace(self) -> str:
        values = self.texts.get('robotNamespace')
        if values is None:
            return ''
        return values[0] or self.robot_name

    def ros(self) -> tuple[str, tuple[tuple[str, str], ...]]:
        ros = self.element.find('ros')
        if ros is None:
            return '', ()
        rules = []
        for child in ros.findall('remapping'):
            source, separator, target = (child.text or '').strip().partition(':=')
            if not separator or not source.strip() or not target.strip():
                raise self.error('ros/remapping', f"'{(child.text or '').strip()}' is not "
                                 "'from:=to'")
            rules.append((source.strip(), target.strip()))
        return (ros.findtext('namespace') or '').strip(), tuple(rules)


def read_p3d_plugins(root: ElementTree.Element, source: pathlib.Path | str,
                     links: Collection[str]) -> tuple[P3dPlugin, ...]:
    """Return the ``gazebo_ros_p3d`` plugins of the robot's ``<gazebo>`` tags (see the module).

    ``links`` are the robot's links: a ``body_name`` outside them ends start-up.
    """
    plugins = []
    for gazebo in root.findall('gazebo'):
        if gazebo.get('reference') is not None:
            continue
        for element in gazebo.findall('plugin'):
            if plugin_stem(element.get('filename', '')) != P3D:
                continue
            reader = _PluginReader(element, source, root.get('name', ''))
            ros1 = bool(set(reader.texts) & ROS1_P3D_KEYS) and 'ros' not in reader.texts
            names = ('bodyName', 'frameName', 'xyzOffsets', 'rpyOffsets', 'gaussianNoise',
                     'updateRate') if ros1 else ('body_name', 'frame_name', 'xyz_offsets',
                                                 'rpy_offsets', 'gaussian_noise', 'update_rate')
            body, frame, xyz, rpy, noise, rate = names
            link = reader.text(body, '')
            if link not in links:
                raise reader.error(body, f"'{link}' is not a link of this robot" if link
                                   else 'is missing (the plugin needs the link to track)')
            frame_name = reader.text(frame, 'world')
            if frame_name not in WORLD_FRAMES and frame_name not in links:
                raise reader.error(frame, f"'{frame_name}' is neither world, map nor a link of "
                                   'this robot')
            namespace, remappings = ('', ()) if ros1 else reader.ros()
            plugins.append(P3dPlugin(
                name=reader.name, convention=ROS1 if ros1 else ROS2, body_name=link,
                frame_name=frame_name, xyz_offsets=reader.vector(xyz),
                rpy_offsets=reader.vector(rpy),
                gaussian_noise=reader.number(noise, 0.0, non_negative=True),
                update_rate=reader.number(rate, 0.0, non_negative=True),
                topic=reader.text('topicName', 'odom') if ros1 else 'odom',
                namespace=reader.ros1_namespace() if ros1 else namespace,
                remappings=remappings))
    return tuple(plugins)


def read_drive_plugins(root: ElementTree.Element, source: pathlib.Path | str,
                       joints: Mapping[str, object]) -> tuple[DiffDrivePlugin, ...]:
    """Return the diff drive plugins of the robot's ``<gazebo><plugin>`` tags (see the module).

    ``joints`` are the robot's joints by name: a wheel outside them ends start-up.
    """
    plugins = []
    for gazebo in root.findall('gazebo'):
        if gazebo.get('reference') is not None:
            continue
        for element in gazebo.findall('plugin'):
            if plugin_stem(element.get('filename', '')) == DIFF_DRIVE:
                reader = _PluginReader(element, source, root.get('name', ''))
                ros1 = bool(set(reader.texts) & ROS1_DIFF_DRIVE_KEYS) and 'ros' not in \
                    reader.texts
                plugin = _ros1_diff_drive(reader) if ros1 else _ros2_diff_drive(reader)
                keys = ('leftJoint', 'rightJoint') if ros1 else ('left_joint', 'right_joint')
                _check_wheels(reader, ((keys[0], plugin.left_joints),
                                       (keys[1], plugin.right_joints)), joints)
                frames = ('odometryFrame', 'robotBaseFrame') if ros1 else (
                    'odometry_frame', 'robot_base_frame')
                _check_frames(reader, ((frames[0], plugin.odometry_frame),
                                       (frames[1], plugin.robot_base_frame)))
                plugins.append(plugin)
    return tuple(plugins)


def _check_wheels(reader: _PluginReader, keyed: tuple[tuple[str, tuple[str, ...]], ...],
                  joints: Mapping[str, object]) -> None:
    """Refuse a wheel that is no joint, no movable one, a mimic, or named twice.

    The checks a driving controller makes of its wheels (distinct, movable,
    commandable), the error naming the file, the plugin and the element.
    """
    seen: dict[str, str] = {}
    for key, wheels in keyed:
        for wheel in wheels:
            joint = joints.get(wheel)
            if joint is None:
                raise reader.error(key, f"'{wheel}' is not a joint of this robot")
            kind = getattr(joint, 'kind', None)
            if kind is not None and not kind.is_actuated:
                raise reader.error(key, f"'{wheel}' is a {kind.value} joint: a wheel must be a "
                                   'movable (revolute or continuous) joint')
            mimic = getattr(joint, 'mimic', None)
            if mimic is not None:
                raise reader.error(key, f"'{wheel}' mimics '{mimic.joint}': it follows that "
                                   'joint and cannot be driven')
            if wheel in seen:
                raise reader.error(key, f"'{wheel}' is already a wheel (<{seen[wheel]}>): each "
                                   'wheel needs its own joint')
            seen[wheel] = key


def _check_frames(reader: _PluginReader, keyed: tuple[tuple[str, str], ...]) -> None:
    """Refuse a frame that is no valid frame id, and an odometry frame equal to the base's."""
    for key, frame in keyed:
        problem = frame_id_problem(frame)
        if problem:
            raise reader.error(key, problem)
    (parent_key, parent), (child_key, child) = keyed
    if parent.removeprefix('/') == child.removeprefix('/'):
        raise reader.error(child_key, f"'{child}' is <{parent_key}> too: the odometry's "
                           'transform needs two different frames')


def _ros2_diff_drive(reader: _PluginReader) -> DiffDrivePlugin:
    pairs = reader.number('num_wheel_pairs', 1.0)
    if pairs < 1 or pairs != int(pairs):
        raise reader.error('num_wheel_pairs', f'must be a whole number >= 1, got {pairs:g}')
    count = int(pairs)
    left, right = reader.all('left_joint'), reader.all('right_joint')
    if len(left) != count or len(right) != count:
        raise reader.error('left_joint', f'{len(left)} left and {len(right)} right wheels for '
                           f'num_wheel_pairs {count}: each pair needs one of each')
    separations = [reader.check('wheel_separation', text, 0.34, positive=True)
                   for text in reader.all('wheel_separation')[:count]]
    diameters = [reader.check('wheel_diameter', text, 0.15, positive=True)
                 for text in reader.all('wheel_diameter')[:count]]
    source = reader.number('odometry_source', 1.0)
    if source not in ROS2_SOURCES:
        raise reader.error('odometry_source', f'must be 0 (encoder) or 1 (world), got {source:g}')
    namespace, remappings = reader.ros()
    return DiffDrivePlugin(
        name=reader.name, convention=ROS2, left_joints=tuple(left), right_joints=tuple(right),
        wheel_separation=tuple(separations + [0.34] * (count - len(separations))),
        wheel_diameter=tuple(diameters + [0.15] * (count - len(diameters))),
        max_wheel_torque=reader.number('max_wheel_torque', 5.0, positive=True),
        max_wheel_acceleration=reader.number('max_wheel_acceleration', 0.0, non_negative=True),
        update_rate=reader.number('update_rate', 100.0, non_negative=True),
        odometry_frame=reader.text('odometry_frame', 'odom'),
        robot_base_frame=reader.text('robot_base_frame', 'base_footprint'),
        odometry_source=ROS2_SOURCES[int(source)],
        publish_odom=reader.flag('publish_odom', False),
        publish_odom_tf=reader.flag('publish_odom_tf', False),
        covariance=(reader.number('covariance_x', 1e-5), reader.number('covariance_y', 1e-5),
                    reader.number('covariance_yaw', 1e-3)),
        namespace=namespace, remappings=remappings)


def _ros1_diff_drive(reader: _PluginReader) -> DiffDrivePlugin:
    source = reader.text('odometrySource', WORLD).lower()
    if source not in (ENCODER, WORLD):
        raise reader.error('odometrySource', f"must be '{ENCODER}' or '{WORLD}', got '{source}'")
    left, right = reader.text('leftJoint', 'left_joint'), reader.text('rightJoint', 'right_joint')
    return DiffDrivePlugin(
        name=reader.name, convention=ROS1, left_joints=(left,), right_joints=(right,),
        wheel_separation=(reader.number('wheelSeparation', 0.34, positive=True),),
        wheel_diameter=(reader.number('wheelDiameter', 0.15, positive=True),),
        max_wheel_torque=reader.number('wheelTorque', 5.0, positive=True),
        max_wheel_acceleration=reader.number('wheelAcceleration', 0.0, non_negative=True),
        update_rate=reader.number('updateRate', 100.0, non_negative=True),
        odometry_frame=reader.text('odometryFrame', 'odom'),
        robot_base_frame=reader.text('robotBaseFrame', 'base_footprint'),
        odometry_source=source,
        publish_odom=reader.flag('publishTf', True),
        publish_odom_tf=reader.flag('publishOdomTF', True),
        covariance=(1e-5, 1e-5, 1e-3),
        command_topic=reader.text('commandTopic', 'cmd_vel'),
        odometry_topic=reader.text('odometryTopic', 'odom'),
        namespace=reader.ros1_namespace())


# --- libgazebo_ros_planar_move.so ------------------------------------------------------------

PLANAR_MOVE = 'gazebo_ros_planar_move'
ROS1_PLANAR_MOVE_KEYS = {'commandTopic', 'odometryTopic', 'odometryFrame', 'odometryRate',
                         'robotBaseFrame', 'publishOdometryTf', 'cmdTimeout', 'robotNamespace'}


@dataclasses.dataclass(frozen=True)
class PlanarMovePlugin:
    """One ``gazebo_ros_planar_move`` plugin: the base's planar velocity set from a Twist.

    ``update_rate`` (Hz, 0: every step): how often the base's velocity is
    set; ``publish_rate`` (Hz, 0: every step): odometry and TF.
    ``command_timeout`` (s, negative: none; ROS 1's ``cmdTimeout``).
    """

    name: str
    convention: str
    update_rate: float = 20.0
    publish_rate: float = 20.0
    odometry_frame: str = 'odom'
    robot_base_frame: str = 'base_footprint'
    publish_odom: bool = True
    publish_odom_tf: bool = True
    covariance: tuple[float, float, float] = (1e-5, 1e-5, 1e-3)  # x, y, yaw
    command_timeout: float = -1.0
    command_topic: str = 'cmd_vel'
    odometry_topic: str = 'odom'
    namespace: str = ''
    remappings: tuple[tuple[str, str], ...] = ()

    filename = 'libgazebo_ros_planar_move.so'

    def topics(self, override: str = '') -> tuple[str, str]:
        """Return the command and odometry topics (absolute), ``override`` as the namespace."""
        namespace = override or self.namespace
        if self.convention == ROS1:
            return (ros1_resolve(namespace, self.command_topic),
                    ros1_resolve(namespace, self.odometry_topic))
        names = Ros2Names(self.name, namespace, self.remappings)
        return names.topic(self.command_topic), names.topic(self.odometry_topic)

    @property
    def pose_covariance(self) -> tuple[float, ...]:
        """The odometry pose (and twist) covariance's diagonal (x, y, z, roll, pitch, yaw)."""
        x, y, yaw = self.covariance
        return (x, y, UNPLANAR_COVARIANCE, UNPLANAR_COVARIANCE, UNPLANAR_COVARIANCE, yaw)


def read_planar_move_plugins(root: ElementTree.Element,
                             source: pathlib.Path | str) -> tuple[PlanarMovePlugin, ...]:
    """Return the robot's ``gazebo_ros_planar_move`` plugins (see the module)."""
    plugins = []
    for element in _model_plugins(root, {PLANAR_MOVE}):
        reader = _PluginReader(element, source, root.get('name', ''))
        ros1 = bool(set(reader.texts) & ROS1_PLANAR_MOVE_KEYS) and 'ros' not in reader.texts
        if ros1:
            rate = reader.number('odometryRate', 20.0, non_negative=True)
            plugins.append(PlanarMovePlugin(
                name=reader.name, convention=ROS1, update_rate=0.0, publish_rate=rate,
                odometry_frame=reader.text('odometryFrame', 'odom'),
                robot_base_frame=reader.text('robotBaseFrame', 'base_footprint'),
                publish_odom=True, publish_odom_tf=reader.flag('publishOdometryTf', True),
                command_timeout=reader.number('cmdTimeout', -1.0),
                command_topic=reader.text('commandTopic', 'cmd_vel'),
                odometry_topic=reader.text('odometryTopic', 'odom'),
                namespace=reader.ros1_namespace()))
            _check_frames(reader, (('odometryFrame', plugins[-1].odometry_frame),
                                   ('robotBaseFrame', plugins[-1].robot_base_frame)))
            continue
        namespace, remappings = reader.ros()
        plugins.append(PlanarMovePlugin(
            name=reader.name, convention=ROS2,
            update_rate=reader.number('update_rate', 20.0, non_negative=True),
            publish_rate=reader.number('publish_rate', 20.0, non_negative=True),
            odometry_frame=reader.text('odometry_frame', 'odom'),
            robot_base_frame=reader.text('robot_base_frame', 'base_footprint'),
            publish_odom=reader.flag('publish_odom', True),
            publish_odom_tf=reader.flag('publish_odom_tf', True),
            covariance=(reader.number('covariance_x', 1e-5), reader.number('covariance_y', 1e-5),
                        reader.number('covariance_yaw', 1e-3)),
            namespace=namespace, remappings=remappings))
        _check_frames(reader, (('odometry_frame', plugins[-1].odometry_frame),
                               ('robot_base_frame', plugins[-1].robot_base_frame)))
    return tuple(plugins)


def _model_plugins(root: ElementTree.Element, stems: Collection[str],
                   names: Collection[str] = ()) -> list[ElementTree.Element]:
    """Return the ``<gazebo><plugin>`` elements (no ``reference``) of these files or names."""
    return [element for gazebo in root.findall('gazebo') if gazebo.get('reference') is None
            for element in gazebo.findall('plugin')
            if plugin_stem(element.get('filename', '')) in stems
            or element.get('name', '').strip() in names]


# --- gz-sim systems -----------------------------------------------------------------------------

GZ_DIFF_DRIVE_FILES = {'gz-sim-diff-drive-system', 'ignition-gazebo-diff-drive-system'}
GZ_DIFF_DRIVE_NAMES = {'gz::sim::systems::DiffDrive', 'ignition::gazebo::systems::DiffDrive'}
GZ_ODOMETRY_FILES = {'gz-sim-odometry-publisher-system',
                     'ignition-gazebo-odometry-publisher-system'}
GZ_ODOMETRY_NAMES = {'gz::sim::systems::OdometryPublisher',
                     'ignition::gazebo::systems::OdometryPublisher'}
GZ_JOINT_STATE_FILES = {'gz-sim-joint-state-publisher-system',
                        'ignition-gazebo-joint-state-publisher-system'}
GZ_JOINT_STATE_NAMES = {'gz::sim::systems::JointStatePublisher',
                        'ignition::gazebo::systems::JointStatePublisher'}
# DiffDrive's limits: (SDF element, jazzy RateLimits field) per group; min_acceleration
# bounds every change, so it is both the deceleration and the reverse acceleration.
GZ_LIMIT_ELEMENTS = ('min_velocity', 'max_velocity', 'min_acceleration', 'max_acceleration',
                     'min_jerk', 'max_jerk')


def gz_topic(name: str) -> str:
    """Return a gz-transport topic as ROS sees it through the bridge: absolute, one '/' each."""
    parts = [part for part in name.strip().split('/') if part]
    return '/' + '/'.join(parts)


@dataclasses.dataclass(frozen=True)
class GzDiffDrivePlugin:
    """gz-sim's DiffDrive system: wheels, geometry, limits, topics, frames.

    ``limits`` per group (``linear``, ``angular``): the SDF's
    ``min_/max_velocity``, ``_acceleration``, ``_jerk`` (NaN: not given; a
    group's own element overrides the shared one).  Topics are gz-transport
    names, as ros_gz_bridge carries them under the same name.
    """

    name: str
    left_joints: tuple[str, ...]
    right_joints: tuple[str, ...]
    wheel_separation: float = 1.0
    wheel_radius: float = 0.2
    odom_publish_frequency: float = 50.0
    command_topic: str = ''
    odometry_topic: str = ''
    tf_topic: str = ''
    frame_id: str = ''
    child_frame_id: str = ''
    linear_limits: tuple[float, ...] = (math.nan,) * 6
    angular_limits: tuple[float, ...] = (math.nan,) * 6

    convention = GZ
    filename = 'gz-sim-diff-drive-system'

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Every wheel, left ones first."""
        return self.left_joints + self.right_joints


@dataclasses.dataclass(frozen=True)
class GzOdometryPlugin:
    """gz-sim's OdometryPublisher system: the model's true pose as odometry.

    ``dimensions`` 2: x, y and yaw only (z, roll, pitch 0); 3: the full pose.
    ``xyz_offset`` (m) and ``rpy_offset`` (rad) move the published pose,
    ``gaussian_noise`` is the standard deviation added to pose and twist.
    """

    name: str
    odom_frame: str
    robot_base_frame: str
    odom_publish_frequency: float = 50.0
    odometry_topic: str = ''
    tf_topic: str = ''
    dimensions: int = 2
    xyz_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    gaussian_noise: float = 0.0

    convention = GZ


def read_gz_plugins(root: ElementTree.Element, source: pathlib.Path | str,
                    joints: Mapping[str, object], movable: Collection[str]
                    ) -> tuple[tuple[GzDiffDrivePlugin, ...], tuple[GzOdometryPlugin, ...],
                               tuple[JointStatePlugin, ...]]:
    """Return the robot's gz-sim DiffDrive, OdometryPublisher and JointStatePublisher systems.

    The model's name is the URDF robot's; the world's is ``default`` (sim_node's
    world has no name of its own), as in the gz-sim sensors' topics
    (:mod:`~pan_tilt_sim.model.sensors`).  A wheel or joint the robot does not
    have, a number that is not one, a separation, radius or frequency that is
    not positive, or a limit's min above its max ends start-up.
    """
    model = root.get('name', '')
    drives = []
    for element in _model_plugins(root, GZ_DIFF_DRIVE_FILES, GZ_DIFF_DRIVE_NAMES):
        reader = _PluginReader(element, source, model)
        left, right = tuple(reader.all('left_joint')), tuple(reader.all('right_joint'))
        for key, wheels in (('left_joint', left), ('right_joint', right)):
            if not wheels:
                raise reader.error(key, 'is missing: the system needs at least one on each side')
        _check_wheels(reader, (('left_joint', left), ('right_joint', right)), joints)
        limits = {}
        for group in ('linear', 'angular'):
            values = {}
            for entry in GZ_LIMIT_ELEMENTS:
                kind, what = entry.split('_')
                own = f'{kind}_{group}_{what}'
                values[own] = reader.number(own, reader.number(entry, math.nan))
            for what in ('velocity', 'acceleration', 'jerk'):
                low, high = values[f'min_{group}_{what}'], values[f'max_{group}_{what}']
                if low > high:
                    raise reader.error(f'min_{group}_{what}', f'{low:g} is above max_{group}_'
                                       f'{what} {high:g}')
            limits[group] = tuple(values.values())
        frame = reader.text('frame_id', f'{model}/odom')
        child = reader.text('child_frame_id', f'{model}/{_root_link(root)}')
        _check_frames(reader, (('frame_id', frame), ('child_frame_id', child)))
        drives.append(GzDiffDrivePlugin(
            name=reader.name, left_joints=left, right_joints=right,
            wheel_separation=reader.number('wheel_separation', 1.0, positive=True),
            wheel_radius=reader.number('wheel_radius', 0.2, positive=True),
            odom_publish_frequency=reader.number('odom_publish_frequency', 50.0, positive=True),
            command_topic=gz_topic(reader.text('topic', f'/model/{model}/cmd_vel')),
            odometry_topic=gz_topic(reader.text('odom_topic', f'/model/{model}/odometry')),
            tf_topic=gz_topic(reader.text('tf_topic', f'/model/{model}/tf')),
            frame_id=frame, child_frame_id=child,
            linear_limits=limits['linear'], angular_limits=limits['angular']))
    odometries = []
    for element in _model_plugins(root, GZ_ODOMETRY_FILES, GZ_ODOMETRY_NAMES):
        reader = _PluginReader(element, source, model)
        dimensions = reader.number('dimensions', 2.0)
        if dimensions not in (2.0, 3.0):
            raise reader.error('dimensions', f'must be 2 or 3, got {dimensions:g}')
        odom_frame = reader.text('odom_frame', f'{model}/odom')
        base_frame = reader.text('robot_base_frame', f'{model}/base_footprint')
        _check_frames(reader, (('odom_frame', odom_frame), ('robot_base_frame', base_frame)))
        odometries.append(GzOdometryPlugin(
            name=reader.name, odom_frame=odom_frame, robot_base_frame=base_frame,
            odom_publish_frequency=reader.number('odom_publish_frequency', 50.0, positive=True),
            odometry_topic=gz_topic(reader.text('odom_topic', f'/model/{model}/odometry')),
            tf_topic=gz_topic(reader.text('tf_topic', f'/model/{model}/pose')),
            dimensions=int(dimensions), xyz_offset=reader.vector('xyz_offset'),
            rpy_offset=reader.vector('rpy_offset'),
            gaussian_noise=reader.number('gaussian_noise', 0.0, non_negative=True)))
    states = []
    for element in _model_plugins(root, GZ_JOINT_STATE_FILES, GZ_JOINT_STATE_NAMES):
        reader = _PluginReader(element, source, model)
        names = reader.all('joint_name')
        for name in names:
            if name not in movable:
                raise reader.error('joint_name', f"'{name}' is not a movable joint of this robot")
        states.append(JointStatePlugin(
            name=reader.name, convention=GZ, joints=tuple(names or movable), update_rate=0.0,
            topic=gz_topic(reader.text('topic', f'/world/{GZ_WORLD}/model/{model}/joint_state'))))
    return tuple(drives), tuple(odometries), tuple(states)


def _root_link(root: ElementTree.Element) -> str:
    """Return the URDF's root link (the canonical link gz-sim names frames after)."""
    children = {joint.find('child').get('link', '') for joint in root.findall('joint')
                if joint.find('child') is not None}
    return next((link.get('name', '') for link in root.findall('link')
                 if link.get('name', '') not in children), '')
