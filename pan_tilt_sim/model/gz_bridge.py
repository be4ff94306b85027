"""ros_gz_bridge's entries: its argument syntax, its config_file YAML and its type pairs.

An entry says which gz topic appears under which ROS name and type, in which
direction.  :func:`parse_argument` reads ``/clock@rosgraph_msgs/msg/Clock[gz.msgs.Clock``
(``@`` both ways, ``[`` gz to ROS, ``]`` ROS to gz); :func:`read_config` the YAML
list (``topic_name`` or ``ros_topic_name``/``gz_topic_name``, ``ros_type_name``,
``gz_type_name``, ``direction``, ``lazy``, queue sizes).  A pair ros_gz_bridge has no
conversion for, or a malformed entry, is a :class:`BridgeError` naming the entry.
:func:`encode` and :func:`decode` carry entries in sim_node's ``gz_bridge`` parameter.
"""

from __future__ import annotations

import dataclasses
import pathlib

import yaml

from pan_tilt_sim.errors import ConfigurationError

BIDIRECTIONAL, GZ_TO_ROS, ROS_TO_GZ = 'BIDIRECTIONAL', 'GZ_TO_ROS', 'ROS_TO_GZ'
DIRECTIONS = (BIDIRECTIONAL, GZ_TO_ROS, ROS_TO_GZ)
ARGUMENT_DIRECTIONS = {'@': BIDIRECTIONAL, '[': GZ_TO_ROS, ']': ROS_TO_GZ}
GZ_PREFIXES = ('gz.msgs.', 'ignition.msgs.')
# The pairs ros_gz_bridge (jazzy) converts: ROS type -> the gz.msgs types it pairs with.
PAIRS = {
    'builtin_interfaces/msg/Time': ('Time',),
    'actuator_msgs/msg/Actuators': ('Actuators',),
    'geometry_msgs/msg/Point': ('Vector3d',),
    'geometry_msgs/msg/Pose': ('Pose',),
    'geometry_msgs/msg/PoseArray': ('Pose_V',),
    'geometry_msgs/msg/PoseStamped': ('Pose',),
    'geometry_msgs/msg/PoseWithCovariance': ('PoseWithCovariance',),
    'geometry_msgs/msg/PoseWithCovarianceStamped': ('PoseWithCovariance',),
    'geometry_msgs/msg/Quaternion': ('Quaternion',),
    'geometry_msgs/msg/Transform': ('Pose',),
    'geometry_msgs/msg/TransformStamped': ('Pose',),
    'geometry_msgs/msg/Twist': ('Twist',),
    'geometry_msgs/msg/TwistStamped': ('Twist',),
    'geometry_msgs/msg/TwistWithCovariance': ('TwistWithCovariance',),
    'geometry_msgs/msg/TwistWithCovarianceStamped': ('TwistWithCovariance',),
    'geometry_msgs/msg/Wrench': ('Wrench',),
    'geometry_msgs/msg/WrenchStamped': ('Wrench',),
    'geometry_msgs/msg/Vector3': ('Vector3d',),
    'gps_msgs/msg/GPSFix': ('NavSat',),
    'nav_msgs/msg/Odometry': ('Odometry', 'OdometryWithCovariance'),
    'rcl_interfaces/msg/ParameterValue': ('Any',),
    'ros_gz_interfaces/msg/Altimeter': ('Altimeter',),
    'ros_gz_interfaces/msg/Contact': ('Contact',),
    'ros_gz_interfaces/msg/Contacts': ('Contacts',),
    'ros_gz_interfaces/msg/Dataframe': ('Dataframe',),
    'ros_gz_interfaces/msg/Entity': ('Entity',),
    'ros_gz_interfaces/msg/EntityWrench': ('EntityWrench',),
    'ros_gz_interfaces/msg/Float32Array': ('Float_V',),
    'ros_gz_interfaces/msg/GuiCamera': ('GUICamera',),
    'ros_gz_interfaces/msg/JointWrench': ('JointWrench',),
    'ros_gz_interfaces/msg/Light': ('Light',),
    'ros_gz_interfaces/msg/MaterialColor': ('MaterialColor',),
    'ros_gz_interfaces/msg/ParamVec': ('Param', 'Param_V'),
    'ros_gz_interfaces/msg/SensorNoise': ('SensorNoise',),
    'ros_gz_interfaces/msg/StringVec': ('StringMsg_V',),
    'ros_gz_interfaces/msg/TrackVisual': ('TrackVisual',),
    'ros_gz_interfaces/msg/VideoRecord': ('VideoRecord',),
    'rosgraph_msgs/msg/Clock': ('Clock',),
    'sensor_msgs/msg/BatteryState': ('BatteryState',),
    'sensor_msgs/msg/CameraInfo': ('CameraInfo',),
    'sensor_msgs/msg/FluidPressure': ('FluidPressure',),
    'sensor_msgs/msg/Image': ('Image',),
    'sensor_msgs/msg/Imu': ('IMU',),
    'sensor_msgs/msg/JointState': ('Model',),
    'sensor_msgs/msg/Joy': ('Joy',),
    'sensor_msgs/msg/LaserScan': ('LaserScan',),
    'sensor_msgs/msg/MagneticField': ('Magnetometer',),
    'sensor_msgs/msg/NavSatFix': ('NavSat',),
    'sensor_msgs/msg/PointCloud2': ('PointCloudPacked',),
    'std_msgs/msg/Bool': ('Boolean',),
    'std_msgs/msg/ColorRGBA': ('Color',),
    'std_msgs/msg/Empty': ('Empty',),
    'std_msgs/msg/Float32': ('Float',),
    'std_msgs/msg/Float64': ('Double',),
    'std_msgs/msg/Header': ('Header',),
    'std_msgs/msg/Int32': ('Int32',),
    'std_msgs/msg/UInt32': ('UInt32',),
    'std_msgs/msg/String': ('StringMsg',),
    'tf2_msgs/msg/TFMessage': ('Pose_V',),
    'trajectory_msgs/msg/JointTrajectory': ('JointTrajectory',),
    'vision_msgs/msg/Detection2DArray': ('AnnotatedAxisAligned2DBox_V',),
    'vision_msgs/msg/Detection2D': ('AnnotatedAxisAligned2DBox',),
    'vision_msgs/msg/Detection3DArray': ('AnnotatedOriented3DBox_V',),
    'vision_msgs/msg/Detection3D': ('AnnotatedOriented3DBox',),
}
CONFIG_KEYS = ('topic_name', 'ros_topic_name', 'gz_topic_name', 'ros_type_name',
               'gz_type_name', 'direction', 'lazy', 'publisher_queue', 'subscriber_queue')
FIELD_SEPARATOR = '|'  # in an encoded entry (no topic or type name has one)


class BridgeError(ConfigurationError):
    """A bridge entry that is malformed or pairs types ros_gz_bridge cannot convert."""


@dataclasses.dataclass(frozen=True)
class BridgeEntry:
    """One bridged topic: its ROS and gz names and types, and its direction."""

    ros_topic: str
    gz_topic: str
    ros_type: str
    gz_type: str
    direction: str = BIDIRECTIONAL
    lazy: bool = False

    @property
    def to_ros(self) -> bool:
        """Whether gz messages appear on ROS."""
        return self.direction in (BIDIRECTIONAL, GZ_TO_ROS)

    @property
    def from_ros(self) -> bool:
        """Whether ROS messages reach gz."""
        return self.direction in (BIDIRECTIONAL, ROS_TO_GZ)


def ros_type_name(name: str) -> str:
    """``geometry_msgs/Twist`` -> ``geometry_msgs/msg/Twist`` (ros_gz_bridge takes both)."""
    parts = name.split('/')
    return f'{parts[0]}/msg/{parts[1]}' if len(parts) == 2 else name


def check_pair(entry: BridgeEntry, where: str) -> BridgeEntry:
    """Return ``entry``, its ROS type spelled in full; BridgeError if the pair makes no sense."""
    ros_type = ros_type_name(entry.ros_type)
    gz_short = next((entry.gz_type[len(prefix):] for prefix in GZ_PREFIXES
                     if entry.gz_type.startswith(prefix)), None)
    partners = PAIRS.get(ros_type)
    if partners is None:
        raise BridgeError(f"{where}: ROS type '{entry.ros_type}' has no gz counterpart in "
                          'ros_gz_bridge')
    if gz_short not in partners:
        raise BridgeError(
            f"{where}: '{entry.ros_type}' pairs with "
            f"{' or '.join('gz.msgs.' + name for name in partners)}, not '{entry.gz_type}'")
    return dataclasses.replace(entry, ros_type=ros_type)


def parse_argument(argument: str) -> BridgeEntry | str:
    """Read one ``parameter_bridge`` argument: an entry, or a service's name (a str).

    ``topic@ros_type{@,[,]}gz_type``; ``service@ros_pkg/srv/Type[@gz_req@gz_rep]``.  The
    first ``@`` after the ROS type, else ``[``, else ``]`` splits, as parameter_bridge reads it.
    """
    usage = f"argument '{argument}': expected topic@ROS_type(@|[|])gz_type"
    topic, at, rest = argument.partition('@')
    if not at or not topic:
        raise BridgeError(usage)
    mark, index = None, -1
    for candidate in ARGUMENT_DIRECTIONS:
        index = rest.find(candidate)
        if index > 0:
            mark = candidate
            break
        if index == 0 and candidate == ']':
            raise BridgeError(usage)
    ros_type = rest if mark is None else rest[:index]
    if '/srv/' in ros_type:
        if mark in ('[', ']'):
            raise BridgeError(f"argument '{argument}': a service is bridged with '@' only")
        return topic
    gz_type = '' if mark is None else rest[index + 1:]
    if not gz_type or '@' in gz_type:
        raise BridgeError(usage)
    return check_pair(BridgeEntry(topic, topic, ros_type, gz_type, ARGUMENT_DIRECTIONS[mark]),
                      f"argument '{argument}'")


def read_config(path: pathlib.Path) -> list[BridgeEntry]:
    """Read a ``config_file``: a YAML list of entries; BridgeError names the file and entry."""
    try:
        data = yaml.safe_load(path.read_text())
    except OSError as err:
        raise BridgeError(f'{path}: cannot read: {err.strerror}') from None
    except yaml.YAMLError as err:
        raise BridgeError(f'{path}: not YAML: {str(err).splitlines()[0]}') from None
    if not isinstance(data, list):
        raise BridgeError(f'{path}: the top level must be a YAML list of entries')
    return [_entry(item, f'{path}: entry {index}') for index, item in enumerate(data)]


def _entry(item: object, where: str) -> BridgeEntry:
    if not isinstance(item, dict):
        raise BridgeError(f'{where}: must be a YAML map')
    unknown = sorted(str(key) for key in item if key not in CONFIG_KEYS)
    if unknown:
        raise BridgeError(f"{where}: unknown key '{unknown[0]}' (keys: {', '.join(CONFIG_KEYS)})")
    text = {key: '' if item.get(key) is None else str(item[key]) for key in CONFIG_KEYS}
    for other in ('ros_topic_name', 'gz_topic_name'):
        if text['topic_name'] and text[other]:
            raise BridgeError(f'{where}: topic_name and {other} are mutually exclusive')
    if not text['ros_type_name'] or not text['gz_type_name']:
        raise BridgeError(f'{where}: both ros_type_name and gz_type_name must be set')
    direction = text['direction'] or BIDIRECTIONAL
    if direction not in DIRECTIONS:
        raise BridgeError(f"{where}: invalid direction '{direction}' ({', '.join(DIRECTIONS)})")
    ros_topic = text['topic_name'] or text['ros_topic_name'] or text['gz_topic_name']
    gz_topic = text['topic_name'] or text['gz_topic_name'] or text['ros_topic_name']
    if not ros_topic:
        raise BridgeError(f'{where}: no topic_name, ros_topic_name or gz_topic_name')
    lazy = item.get('lazy', False)
    if not isinstance(lazy, bool):
        raise BridgeError(f"{where}: lazy must be true or false, got '{lazy}'")
    name = f"{where} ('{ros_topic}')"
    return check_pair(BridgeEntry(ros_topic, gz_topic, text['ros_type_name'],
                                  text['gz_type_name'], direction, lazy), name)


def encode(source: str, entries: list[BridgeEntry]) -> list[str]:
    """Return a bridge's entries as sim_node's ``gz_bridge`` parameter: its name, then each."""
    return [source] + [FIELD_SEPARATOR.join((entry.gz_topic, entry.ros_topic, entry.ros_type,
                                             entry.gz_type, entry.direction))
                       for entry in entries]


def decode(texts: list[str]) -> tuple[str, list[BridgeEntry]]:
    """Return the bridge's name and entries :func:`encode` made; BridgeError if they are not."""
    if not texts or FIELD_SEPARATOR in texts[0] or not texts[0]:
        raise BridgeError("gz_bridge: expected the bridge node's name first, then entries")
    entries = []
    for text in texts[1:]:
        fields = text.split(FIELD_SEPARATOR)
        if len(fields) != 5 or fields[4] not in DIRECTIONS or not all(fields[:4]):
            raise BridgeError(f"gz_bridge entry '{text}': expected "
                              'gz_topic|ros_topic|ros_type|gz_type|direction')
        gz_topic, ros_topic, ros_type, gz_type, direction = fields
        entries.append(check_pair(BridgeEntry(ros_topic, gz_topic, ros_type, gz_type,
                                              direction), f"gz_bridge entry '{text}'"))
    return texts[0], entries
