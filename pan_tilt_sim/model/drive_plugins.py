"""Gazebo's drive plugins, read from ``<gazebo><plugin>``, as the plugin would read them. No ROS.

``libgazebo_ros_diff_drive.so`` drives a differential base from a
``geometry_msgs/Twist`` and publishes its odometry and the odom -> base
transform.  Both gazebo_plugins generations are read, each with its own
element names and defaults (from the plugins' sources):

==========================  ========================  ===============================
what                        ROS 2 (gazebo_ros)        ROS 1 (gazebo_plugins)
==========================  ========================  ===============================
wheels                      ``left_joint`` /          ``leftJoint`` / ``rightJoint``
                            ``right_joint`` (one per  (one pair)
                            pair, ``num_wheel_pairs``
                            pairs, default 1)
separation (m)              ``wheel_separation`` 0.34 ``wheelSeparation`` 0.34
diameter (m)                ``wheel_diameter`` 0.15   ``wheelDiameter`` 0.15
wheel torque (N m)          ``max_wheel_torque`` 5    ``wheelTorque`` 5
wheel acceleration (m/s^2)  ``max_wheel_acceleration``  ``wheelAcceleration`` 0
                            0 (0: none)
update rate (Hz)            ``update_rate`` 100       ``updateRate`` 100
command topic               ``cmd_vel`` (remappable)  ``commandTopic`` cmd_vel
odometry topic              ``odom`` (remappable)     ``odometryTopic`` odom
odometry frame              ``odometry_frame`` odom   ``odometryFrame`` odom
base frame                  ``robot_base_frame``      ``robotBaseFrame``
                            base_footprint            base_footprint
odometry source             ``odometry_source`` 1     ``odometrySource`` world
                            (0 encoder, 1 world)      (encoder / world)
publish odometry            ``publish_odom`` false    ``publishTf`` true
publish odom -> base TF     ``publish_odom_tf`` false ``publishOdomTF`` true
covariance (x, y, yaw)      ``covariance_x``,         fixed: 1e-5, 1e-5, 1e-3
                            ``covariance_y`` 1e-5,
                            ``covariance_yaw`` 1e-3
==========================  ========================  ===============================

``libgazebo_ros_p3d.so`` publishes a link's true pose and twist as
``nav_msgs/Odometry`` (ground truth): ROS 2 ``body_name`` (required),
``frame_name`` (world), ``xyz_offsets``, ``rpy_offsets`` (0 0 0),
``gaussian_noise`` (0), ``update_rate`` (0: every step), topic ``odom`` of
its node; ROS 1 ``bodyName``, ``frameName``, ``xyzOffsets``, ``rpyOffsets``,
``gaussianNoise``, ``updateRate``, ``topicName`` in ``robotNamespace``.

``libgazebo_ros_joint_state_publisher.so`` publishes the named joints'
``sensor_msgs/JointState``: ROS 2 ``joint_name`` (one element per joint,
required), ``update_rate`` (100 Hz), topic ``joint_states`` of its node;
ROS 1 ``jointName`` (comma-separated), ``updateRate`` (100 Hz) in
``robotNamespace``.

Topic names resolve as each generation resolves them: ROS 2 in a node named
after the plugin in ``<ros><namespace>`` with its ``<remapping>``s; ROS 1
in ``robotNamespace`` -- absent: the root (as spawn_model sets it), given
empty: the robot's name, as gazebo_plugins' GazeboRos takes it (see
:mod:`pan_tilt_sim.model.sensors`).  A wheel
the robot does not have, a number that is not one, or a separation,
diameter, torque or rate that is not positive ends start-up
(:class:`~pan_tilt_sim.errors.DescriptionError` naming the plugin and the
element).
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
from collections.abc import Collection, Mapping
from xml.etree import ElementTree

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.sensors import ROS1, ROS2, Ros2Names, plugin_stem, ros1_resolve

DIFF_DRIVE = 'gazebo_ros_diff_drive'
P3D = 'gazebo_ros_p3d'
JOINT_STATE_PUBLISHER = 'gazebo_ros_joint_state_publisher'
WORLD_FRAMES = ('world', '/world', 'map', '/map')  # p3d: poses in the world
ROS1_P3D_KEYS = {'bodyName', 'frameName', 'topicName', 'xyzOffsets', 'rpyOffsets',
                 'gaussianNoise', 'updateRate', 'robotNamespace'}
ENCODER, WORLD = 'encoder', 'world'
ROS2_SOURCES = {0: ENCODER, 1: WORLD}  # gazebo_ros's odometry_source numbers
# Elements only one generation's diff drive reads: they tell which one a plugin is.
ROS1_DIFF_DRIVE_KEYS = {'leftJoint', 'rightJoint', 'wheelSeparation', 'wheelDiameter',
                        'commandTopic', 'odometryTopic', 'odometryFrame', 'robotBaseFrame',
                        'publishOdomTF', 'publishTf', 'updateRate', 'wheelTorque',
                        'wheelAcceleration', 'odometrySource', 'robotNamespace'}
UNPLANAR_COVARIANCE = 1e12  # z, roll, pitch: what the plugins put there


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

    def topics(self, override: str = '') -> str:
        """Return the joint states topic (absolute), ``override`` as the namespace."""
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
        return self.check(key, self.text(key, ''), default, positive, non_negative)

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
                for role, wheels in (('left', plugin.left_joints),
                                     ('right', plugin.right_joints)):
                    key = f'{role}Joint' if ros1 else f'{role}_joint'
                    for wheel in wheels:
                        if wheel not in joints:
                            raise reader.error(key, f"'{wheel}' is not a joint of this robot")
                plugins.append(plugin)
    return tuple(plugins)


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
