"""The rosbag2 bag folder: MCAP storage and metadata.yaml as rosbag2 (jazzy) writes them.

Read back with independent readers: the ``mcap`` package's reader with the
``mcap_ros2`` decoder (its own CDR and .msg parsers), and PyYAML for
``metadata.yaml``, whose fields are checked against rosbag2_storage's
``BagMetadata`` version 9.
"""

from __future__ import annotations

import pathlib
import sys

import pytest
import yaml
from bag_fixtures import FullDisk, read, read_with_rosbags
from rclpy.serialization import serialize_message
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.ros import bag
from pan_tilt_sim.ros.bag import BagWriter, message_definition, qos_profile

DELIMITER = '=' * 80
QOS = [qos_profile(depth=10)]
LATCHED = [qos_profile(depth=1, durability='transient_local')]
RIHS01 = 'RIHS01_'


def joint_state(seconds: int, position: float) -> JointState:
    message = JointState(name=['pan_joint'], position=[position], velocity=[0.0], effort=[0.0])
    message.header.stamp.sec = seconds
    return message


@pytest.fixture
def written(tmp_path) -> pathlib.Path:
    """A bag with two joint states and one Float64 command, closed."""
    folder = tmp_path / 'run'
    writer = BagWriter(folder, field='--record')
    states = writer.add_topic('/ns/joint_states', 'sensor_msgs/msg/JointState', QOS)
    command = writer.add_topic('/ns/c/command', 'std_msgs/msg/Float64', LATCHED)
    writer.write(states, serialize_message(joint_state(1, 0.5)), 1_000_000_000)
    writer.write(command, serialize_message(Float64(data=2.0)), 1_500_000_000)
    writer.write(states, serialize_message(joint_state(2, 0.75)), 2_000_000_000)
    writer.close()
    return folder


def test_the_folder_holds_metadata_yaml_and_one_mcap_file_named_after_it(written):
    assert sorted(path.name for path in written.iterdir()) == ['metadata.yaml', 'run_0.mcap']


def test_every_message_reads_back_intact_at_its_time(written):
    messages = read(written)['messages']
    assert [(topic, time) for topic, time, _ in messages] == [
        ('/ns/joint_states', 1_000_000_000), ('/ns/c/command', 1_500_000_000),
        ('/ns/joint_states', 2_000_000_000)]
    first, command, second = (decoded for _, _, decoded in messages)
    assert list(first.name) == ['pan_joint'] and list(first.position) == [0.5]
    assert first.header.stamp.sec == 1
    assert command.data == 2.0
    assert list(second.position) == [0.75]


def test_the_mcap_file_is_a_ros2_profile_file_with_ros2msg_schemas_and_cdr_channels(written):
    content = read(written)
    assert content['header'].profile == 'ros2'
    schemas = {schema.name: schema for schema in content['schemas'].values()}
    assert set(schemas) == {'sensor_msgs/msg/JointState', 'std_msgs/msg/Float64'}
    assert {schema.encoding for schema in schemas.values()} == {'ros2msg'}
    channels = {channel.topic: channel for channel in content['channels'].values()}
    assert {channel.message_encoding for channel in channels.values()} == {'cdr'}
    states = channels['/ns/joint_states']
    assert content['schemas'][states.schema_id].name == 'sensor_msgs/msg/JointState'
    assert states.metadata['topic_type_hash'].startswith(RIHS01)
    offered = yaml.safe_load(channels['/ns/c/command'].metadata['offered_qos_profiles'])
    assert offered[0]['durability'] == 'transient_local' and offered[0]['depth'] == 1
    assert content['statistics'].message_count == 3


def test_the_rosbag2_metadata_record_holds_the_serialized_bag_metadata(written):
    serialized = yaml.safe_load(read(written)['metadata']['rosbag2']['serialized_metadata'])
    on_disk = yaml.safe_load((written / 'metadata.yaml').read_text())
    assert serialized == on_disk['rosbag2_bagfile_information']


def test_metadata_yaml_has_every_field_of_rosbag2_jazzy_bag_metadata(written):
    info = yaml.safe_load((written / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert list(info) == [
        'version', 'storage_identifier', 'duration', 'starting_time', 'message_count',
        'topics_with_message_count', 'compression_format', 'compression_mode',
        'relative_file_paths', 'files', 'custom_data', 'ros_distro']
    assert info['version'] == 9
    assert info['storage_identifier'] == 'mcap'
    assert info['ros_distro'] == 'jazzy'
    assert info['starting_time'] == {'nanoseconds_since_epoch': 1_000_000_000}
    assert info['duration'] == {'nanoseconds': 1_000_000_000}
    assert info['message_count'] == 3
    assert info['relative_file_paths'] == ['run_0.mcap']
    assert info['files'] == [{'path': 'run_0.mcap',
                              'starting_time': {'nanoseconds_since_epoch': 1_000_000_000},
                              'duration': {'nanoseconds': 1_000_000_000},
                              'message_count': 3}]
    assert (info['compression_format'], info['compression_mode']) == ('', '')
    assert info['custom_data'] == {}
    topics = {entry['topic_metadata']['name']: entry for entry in
              info['topics_with_message_count']}
    assert {name: entry['message_count'] for name, entry in topics.items()} == {
        '/ns/joint_states': 2, '/ns/c/command': 1}
    states = topics['/ns/joint_states']['topic_metadata']
    assert list(states) == ['name', 'type', 'serialization_format', 'offered_qos_profiles',
                            'type_description_hash']
    assert states['type'] == 'sensor_msgs/msg/JointState'
    assert states['serialization_format'] == 'cdr'
    assert states['type_description_hash'].startswith(RIHS01)


def test_rosbags_rosbag2_reader_opens_the_folder_and_decodes_with_the_bags_definitions(written):
    bag_read = read_with_rosbags(written)
    assert bag_read['counts'] == {'/ns/joint_states': 2, '/ns/c/command': 1}
    assert bag_read['start'] == 1_000_000_000
    command = next(message for topic, _, message in bag_read['messages']
                   if topic == '/ns/c/command')
    assert command.data == 2.0


def test_offered_qos_profiles_are_version_9_maps_with_policies_as_words(written):
    info = yaml.safe_load((written / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    (profile,) = info['topics_with_message_count'][0]['topic_metadata']['offered_qos_profiles']
    assert profile == {
        'history': 'keep_last', 'depth': 10, 'reliability': 'reliable',
        'durability': 'volatile', 'deadline': {'sec': 0, 'nsec': 0},
        'lifespan': {'sec': 0, 'nsec': 0}, 'liveliness': 'automatic',
        'liveliness_lease_duration': {'sec': 0, 'nsec': 0},
        'avoid_ros_namespace_conventions': False}


def test_a_definition_is_the_msg_text_then_each_nested_type_once_as_rosbag2_joins_them():
    encoding, text = message_definition('tf2_msgs/msg/TFMessage')
    assert encoding == 'ros2msg'
    sections = text.split(f'\n{DELIMITER}\n')
    assert 'TransformStamped[] transforms' in sections[0]
    names = [section.splitlines()[0] for section in sections[1:]]
    # Depth first, sorted at each level, each type once (Header's Time is not repeated).
    assert names == ['MSG: geometry_msgs/TransformStamped', 'MSG: geometry_msgs/Transform',
                     'MSG: geometry_msgs/Quaternion', 'MSG: geometry_msgs/Vector3',
                     'MSG: std_msgs/Header', 'MSG: builtin_interfaces/Time']
    header = sections[5].split('\n', 1)[1]
    assert header == bag.package_share('std_msgs').joinpath('msg', 'Header.msg').read_text()


def test_a_type_whose_package_is_not_installed_gets_rosbag2s_unknown_definition():
    assert message_definition('no_such_msgs/msg/Nothing') == ('unknown', '')


def test_an_existing_folder_is_refused_naming_the_field_and_folder(tmp_path):
    with pytest.raises(ConfigurationError) as raised:
        BagWriter(tmp_path, field="parameter 'record'")
    message = str(raised.value)
    assert message.startswith("parameter 'record': ") and str(tmp_path) in message
    assert 'already exists' in message and '\n' not in message


def test_a_folder_that_cannot_be_made_is_one_line_naming_it(tmp_path):
    blocker = tmp_path / 'a_file'
    blocker.write_text('')
    with pytest.raises(ConfigurationError) as raised:
        BagWriter(blocker / 'bag', field='--record')
    message = str(raised.value)
    assert message.startswith('--record: cannot write the bag folder') and '\n' not in message
    assert str(blocker / 'bag') in message and 'Not a directory' in message


def test_without_the_mcap_package_the_error_says_what_to_install(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, 'mcap.writer', None)
    with pytest.raises(ConfigurationError, match='pip install mcap'):
        BagWriter(tmp_path / 'bag', field='--record')
    assert not (tmp_path / 'bag').exists()


def test_a_full_disk_stops_the_recording_with_one_warning_and_raises_nothing(
        tmp_path, monkeypatch):
    monkeypatch.setattr(bag, '_open_for_writing', lambda path: FullDisk(path, room=20_000))
    monkeypatch.setattr(bag, 'CHUNK_SIZE', 500)
    warnings = []
    writer = BagWriter(tmp_path / 'bag', field='--record', on_failure=warnings.append)
    states = writer.add_topic('/joint_states', 'sensor_msgs/msg/JointState', QOS)
    for step in range(200):
        writer.write(states, serialize_message(joint_state(step, 0.0)), step)
    assert not writer.recording
    written = writer.message_count
    assert 0 < written < 200
    writer.write(states, serialize_message(joint_state(0, 0.0)), 0)
    writer.close()
    assert writer.message_count == written
    assert len(warnings) == 1 and '\n' not in warnings[0]
    assert warnings[0].startswith(f"--record: stopped recording to '{tmp_path / 'bag'}'")
    assert 'No space left on device' in warnings[0]
    assert not (tmp_path / 'bag' / 'metadata.yaml').exists()


def test_a_file_that_cannot_take_the_header_is_one_line_and_leaves_no_folder(tmp_path,
                                                                           monkeypatch):
    monkeypatch.setattr(bag, '_open_for_writing', lambda path: FullDisk(path, room=0))
    with pytest.raises(ConfigurationError) as raised:
        BagWriter(tmp_path / 'bag', field='--record')
    assert str(raised.value) == (f"--record: cannot write the bag folder '{tmp_path / 'bag'}': "
                                 'No space left on device')
    assert not (tmp_path / 'bag').exists()
