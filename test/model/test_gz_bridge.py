"""ros_gz_bridge's entries, read as parameter_bridge reads its arguments and config_file."""

import pathlib

import pytest

from pan_tilt_sim.model.gz_bridge import (
    BIDIRECTIONAL,
    GZ_TO_ROS,
    ROS_TO_GZ,
    BridgeEntry,
    BridgeError,
    decode,
    encode,
    parse_argument,
    read_config,
)


@pytest.mark.parametrize(('argument', 'direction'), [
    ('/clock@rosgraph_msgs/msg/Clock[gz.msgs.Clock', GZ_TO_ROS),
    ('/clock@rosgraph_msgs/msg/Clock]gz.msgs.Clock', ROS_TO_GZ),
    ('/clock@rosgraph_msgs/msg/Clock@gz.msgs.Clock', BIDIRECTIONAL),
])
def test_an_argument_gives_topic_types_and_direction(argument, direction):
    assert parse_argument(argument) == BridgeEntry(
        '/clock', '/clock', 'rosgraph_msgs/msg/Clock', 'gz.msgs.Clock', direction)


def test_short_ros_types_and_ignition_names_are_taken_as_ros_gz_bridge_takes_them():
    entry = parse_argument('/cmd_vel@geometry_msgs/Twist]ignition.msgs.Twist')
    assert entry.ros_type == 'geometry_msgs/msg/Twist' and entry.direction == ROS_TO_GZ


def test_a_service_argument_is_told_apart():
    assert parse_argument('/world/default/control@ros_gz_interfaces/srv/ControlWorld') == (
        '/world/default/control')


@pytest.mark.parametrize(('argument', 'message'), [
    ('/scan@sensor_msgs/msg/LaserScan[gz.msgs.Image',
     "'sensor_msgs/msg/LaserScan' pairs with gz.msgs.LaserScan, not 'gz.msgs.Image'"),
    ('/x@my_msgs/msg/Thing[gz.msgs.Thing', "ROS type 'my_msgs/msg/Thing' has no gz"),
    ('/clock', 'expected topic@ROS_type'),
    ('/clock@rosgraph_msgs/msg/Clock', 'expected topic@ROS_type'),
    # The first '@' splits, as parameter_bridge reads it: the ROS type is then nonsense.
    ('/clock@rosgraph_msgs/msg/Clock[gz.msgs.Clock@x', 'has no gz counterpart'),
])
def test_an_argument_that_makes_no_sense_is_one_line_naming_it(argument, message):
    with pytest.raises(BridgeError) as raised:
        parse_argument(argument)
    line = str(raised.value)
    assert line.startswith(f"argument '{argument}'") and message in line and '\n' not in line


def write(tmp_path: pathlib.Path, text: str) -> pathlib.Path:
    path = tmp_path / 'bridge.yaml'
    path.write_text(text)
    return path


def test_a_config_file_gives_names_as_ros_gz_bridge_does(tmp_path):
    path = write(tmp_path, '''
- topic_name: "/clock"
  ros_type_name: "rosgraph_msgs/msg/Clock"
  gz_type_name: "gz.msgs.Clock"
  direction: GZ_TO_ROS
- ros_topic_name: "odom"
  gz_topic_name: "/model/rover/odometry"
  ros_type_name: "nav_msgs/msg/Odometry"
  gz_type_name: "gz.msgs.Odometry"
  lazy: true
- gz_topic_name: "scan"
  ros_type_name: "sensor_msgs/msg/LaserScan"
  gz_type_name: "gz.msgs.LaserScan"
''')
    clock, odom, scan = read_config(path)
    assert (clock.ros_topic, clock.gz_topic, clock.direction) == ('/clock', '/clock', GZ_TO_ROS)
    assert (odom.ros_topic, odom.gz_topic, odom.direction, odom.lazy) == (
        'odom', '/model/rover/odometry', BIDIRECTIONAL, True)
    assert (scan.ros_topic, scan.gz_topic) == ('scan', 'scan')


@pytest.mark.parametrize(('text', 'message'), [
    ('- topic_name: a\n  ros_type_name: std_msgs/msg/Bool\n  gz_type_name: gz.msgs.Double\n',
     "entry 0 ('a'): 'std_msgs/msg/Bool' pairs with gz.msgs.Boolean, not 'gz.msgs.Double'"),
    ('- topic_name: a\n  ros_type_name: std_msgs/msg/Bool\n  gz_type_name: gz.msgs.Boolean\n'
     '  direction: UP\n', "entry 0: invalid direction 'UP'"),
    ('- topic_name: a\n  ros_topic_name: b\n  ros_type_name: std_msgs/msg/Bool\n'
     '  gz_type_name: gz.msgs.Boolean\n', 'topic_name and ros_topic_name are mutually'),
    ('- topic_name: a\n  ros_type_name: std_msgs/msg/Bool\n',
     'both ros_type_name and gz_type_name must be set'),
    ('topic_name: a\n', 'the top level must be a YAML list'),
    ('- [a]\n', 'entry 0: must be a YAML map'),
    ('- topic_name: a\n  ros_type: std_msgs/msg/Bool\n', "unknown key 'ros_type'"),
])
def test_a_config_entry_that_makes_no_sense_names_the_file_and_the_entry(
        tmp_path, text, message):
    path = write(tmp_path, text)
    with pytest.raises(BridgeError) as raised:
        read_config(path)
    assert str(raised.value).startswith(str(path)) and message in str(raised.value)


def test_entries_travel_in_the_parameter_with_their_bridges_name():
    entry = BridgeEntry('/odom', '/model/rover/odometry', 'nav_msgs/msg/Odometry',
                        'gz.msgs.Odometry', GZ_TO_ROS)
    assert decode(encode('/ros_gz_bridge', [entry])) == ('/ros_gz_bridge', [entry])
    assert decode(encode('/ros_gz_bridge', [])) == ('/ros_gz_bridge', [])
    with pytest.raises(BridgeError, match='expected gz_topic'):
        decode(['/b', 'a|b|c'])
