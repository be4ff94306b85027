"""sim_node's ``record:=<folder>``: the run as a rosbag2 MCAP bag, read back independently.

The node runs in-process at a known pace, is paused at a known sim time and
destroyed (which closes the bag); the bag is then read with the ``mcap``
reader and the ``mcap_ros2`` decoder.  What it must hold: ``/clock`` and
``joint_states`` and ``/tf`` at their rates, stamped in sim time; the latched
``/tf_static`` and ``robot_description``; the commands received; controller
states; sensors only on request.  Bad folders end start-up; a full disk
stops only the recording.
"""

from __future__ import annotations

import importlib.util
import math

import pytest
import sim_process
import yaml
from bag_fixtures import (
    NANOSECONDS_PER_SECOND,
    FullDisk,
    read,
    read_with_rosbags,
    topic_messages,
)
from node_harness import sim_node
from rclpy.parameter import Parameter
from ros2_control_fixtures import write

from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.ros import bag
from pan_tilt_sim.ros.sim_node import SimNode

NS = '/ex_urdf_pan_tilt'
RUN_S = 1.0
PACE = 2.0  # real_time_factor: every /clock stamp leaves up to 10x real time
CLOCK_PERIOD_NS = 10_000_000
STATE_PERIOD_NS = 20_000_000  # joint_states (publish_rate 50) and /tf
SMALL_CAMERA = {'camera.width': 32, 'camera.height': 24, 'camera.rate': 10.0}


def run_and_close(tmp_path, seconds: float = RUN_S, **parameters) -> tuple[dict, int]:
    """Run sim_node recording for ``seconds`` of sim time; return the bag and the end in ns.

    The bag is also opened with rosbags' rosbag2 reader (``content['rosbags']``).
    """
    folder = tmp_path / 'bag'
    parameters.setdefault('real_time_factor', PACE)
    parameters = {**SMALL_CAMERA, **parameters}
    with sim_node(record=str(folder), **parameters) as sim:
        sim.run_until_sim_time(seconds)
        sim.node.set_paused(True)
        end_ns = round(sim.simulation.time * NANOSECONDS_PER_SECOND)
    return {**read(folder), 'rosbags': read_with_rosbags(folder)}, end_ns


@pytest.fixture(scope='module')
def recorded(tmp_path_factory):
    """The pan/tilt example recorded for RUN_S of sim time at PACE."""
    return run_and_close(tmp_path_factory.mktemp('recorded'))


def on_grid(times: list[int], period_ns: int, end_ns: int) -> bool:
    """Whether ``times`` are exactly every multiple of ``period_ns`` from 0 up to ``end_ns``."""
    return times == list(range(0, end_ns + 1, period_ns))


def test_clock_holds_every_10_ms_stamp_of_the_run_once(recorded):
    content, end_ns = recorded
    clock = topic_messages(content, '/clock')
    assert on_grid([time for time, _ in clock], CLOCK_PERIOD_NS, end_ns)
    assert all(time == message.clock.sec * NANOSECONDS_PER_SECOND + message.clock.nanosec
               for time, message in clock)


def test_joint_states_and_tf_come_at_50_hz_of_sim_time_logged_at_their_stamps(recorded):
    content, end_ns = recorded
    for topic in (f'{NS}/joint_states', '/tf'):
        messages = topic_messages(content, topic)
        times = [time for time, _ in messages]
        # Every 20 ms stamp from the first to the last, and the last within a period of the
        # end: a sample due at the very step the run paused on is taken by the next step.
        assert times == list(range(times[0], times[-1] + 1, STATE_PERIOD_NS)), topic
        assert times[0] <= STATE_PERIOD_NS, topic
        assert end_ns - STATE_PERIOD_NS <= times[-1] <= end_ns, topic
    for time, message in topic_messages(content, f'{NS}/joint_states'):
        stamp = message.header.stamp
        assert time == stamp.sec * NANOSECONDS_PER_SECOND + stamp.nanosec
        assert list(message.name) == ['pan_joint', 'tilt_joint']


def test_a_second_rosbag2_reader_decodes_every_message_with_the_bags_definitions(recorded):
    content, _ = recorded
    by_rosbags = content['rosbags']
    assert len(by_rosbags['messages']) == len(content['messages'])
    assert sorted((topic, time) for topic, time, _ in by_rosbags['messages']) == sorted(
        (topic, time) for topic, time, _ in content['messages'])
    tf = [message for topic, _, message in by_rosbags['messages'] if topic == '/tf']
    assert tf and {transform.child_frame_id for transform in tf[-1].transforms} >= {
        'pan_link', 'tilt_link'}


def test_every_log_time_is_sim_time_within_the_run(recorded):
    content, end_ns = recorded
    times = [time for _, time, _ in content['messages']]
    assert min(times) == 0 and max(times) <= end_ns


def test_the_latched_topics_are_there_once(recorded):
    content, _ = recorded
    (static,) = [message for _, message in topic_messages(content, '/tf_static')]
    assert static.transforms, 'no fixed frames in /tf_static'
    (description,) = [message for _, message in
                      topic_messages(content, f'{NS}/robot_description')]
    assert '<robot' in description.data


def test_sensors_are_left_out_unless_asked_for(recorded):
    content, _ = recorded
    topics = {channel.topic for channel in content['channels'].values()}
    assert f'{NS}/joint_states' in topics
    assert not any('camera' in topic for topic in topics), topics


def test_with_record_sensors_the_camera_is_recorded_at_its_rate(tmp_path):
    content, end_ns = run_and_close(tmp_path, 0.5, record_sensors=True)
    images = topic_messages(content, f'{NS}/camera/image_raw')
    assert [time for time, _ in images] == list(range(0, end_ns + 1, 100_000_000))
    assert (images[0][1].width, images[0][1].height) == (32, 24)
    assert len(images[0][1].data) == 32 * 24 * 3
    assert len(topic_messages(content, f'{NS}/camera/camera_info')) == len(images)


def test_the_commands_received_are_recorded_at_the_sim_time_they_arrived(tmp_path):
    folder = tmp_path / 'bag'
    with sim_node(record=str(folder), **SMALL_CAMERA) as sim:
        sim.run_until_sim_time(0.1)
        after_ns = round(sim.command_position('joint1_position_controller', 0.3)
                         * NANOSECONDS_PER_SECOND)
    commands = topic_messages(read(folder), f'{NS}/joint1_position_controller/command')
    assert [message.data for _, message in commands] == [0.3]
    assert 100_000_000 <= commands[0][0] <= after_ns


def test_metadata_yaml_counts_what_the_mcap_file_holds(tmp_path):
    content, _ = run_and_close(tmp_path, 0.2)
    info = yaml.safe_load((tmp_path / 'bag' / 'metadata.yaml').read_text())[
        'rosbag2_bagfile_information']
    counted = {entry['topic_metadata']['name']: entry['message_count']
               for entry in info['topics_with_message_count']}
    held = {}
    for topic, _, _ in content['messages']:
        held[topic] = held.get(topic, 0) + 1
    assert {topic: count for topic, count in counted.items() if count} == held
    assert info['message_count'] == len(content['messages'])
    assert {entry['topic_metadata']['name']: entry['topic_metadata']['offered_qos_profiles'][0][
        'durability'] for entry in info['topics_with_message_count']}['/tf_static'] == (
        'transient_local')


PID_URDF = """\
<?xml version="1.0"?>
<robot name="one_link">
  <link name="world"/>
  <link name="link1">
    <inertial><origin xyz="0.2 0 0"/><mass value="1.0"/>
      <inertia ixx="0.0003" ixy="0" ixz="0" iyy="0.0135" iyz="0" izz="0.0135"/></inertial>
  </link>
  <joint name="joint1" type="revolute">
    <parent link="world"/><child link="link1"/><axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="1.5" effort="20" velocity="2"/>
  </joint>
  <ros2_control name="OneLink" type="system">
    <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>
    <joint name="joint1">
      <command_interface name="effort"/>
      <state_interface name="position"/><state_interface name="velocity"/>
    </joint>
  </ros2_control>
</robot>
"""
PID_CONTROLLERS = """\
controller_manager:
  ros__parameters:
    update_rate: 100
    pid:
      type: pid_controller/PidController
pid:
  ros__parameters:
    dof_names: [joint1]
    command_interface: effort
    reference_and_state_interfaces: [position]
    gains:
      joint1: {p: 20.0, i: 0.0, d: 2.0}
"""


@pytest.mark.skipif(importlib.util.find_spec('control_msgs') is None,
                    reason='control_msgs is not installed')
def test_controller_states_are_recorded_with_their_control_msgs_definitions(tmp_path):
    urdf = write(tmp_path, 'one_link.urdf', PID_URDF)
    controllers = write(tmp_path, 'controllers.yaml', PID_CONTROLLERS)
    content, end_ns = run_and_close(tmp_path, 0.3, robot_description_file=str(urdf),
                                    controllers_file=str(controllers))
    states = topic_messages(content, '/pid/controller_state')
    assert states, 'no /pid/controller_state in the bag'
    schema = next(content['schemas'][channel.schema_id] for channel
                  in content['channels'].values() if channel.topic == '/pid/controller_state')
    assert schema.name == 'control_msgs/msg/MultiDOFStateStamped'
    assert b'MSG: control_msgs/SingleDOFState' in schema.data
    for time, message in states:
        assert 0 <= time <= end_ns
        assert [state.name for state in message.dof_states] == ['joint1']


@pytest.mark.skipif(importlib.util.find_spec('controller_manager_msgs') is None
                    or importlib.util.find_spec('control_msgs') is None,
                    reason='controller_manager_msgs or control_msgs is not installed')
def test_a_recorded_controllers_topics_go_at_cleanup_and_come_back_recorded(tmp_path):
    from spawner_client import Spawner, srv

    urdf = write(tmp_path, 'one_link.urdf', PID_URDF)
    controllers = write(tmp_path, 'controllers.yaml', PID_CONTROLLERS)
    folder = tmp_path / 'bag'
    with sim_node(record=str(folder), robot_description_file=str(urdf),
                  controllers_file=str(controllers)) as sim:
        spawner = Spawner(sim)
        assert spawner.switch(deactivate=['pid']).ok
        assert spawner.call('cleanup_controller', srv().CleanupController.Request(name='pid')).ok
        assert '/pid/controller_state' not in sim.own_topics()[0]
        assert spawner.configure('pid') and spawner.switch(activate=['pid']).ok
        assert '/pid/controller_state' in sim.own_topics()[0]
        sim.run_until_sim_time(sim.simulation.time + 0.1)
        sim.node.set_paused(True)
        end_ns = round(sim.simulation.time * NANOSECONDS_PER_SECOND)
    times = [time for time, _ in topic_messages(read(folder), '/pid/controller_state')]
    assert times and times[-1] > end_ns - 20_000_000


def test_a_folder_that_exists_ends_start_up_in_one_line(tmp_path, context):
    with pytest.raises(ConfigurationError) as raised:
        SimNode(context=context, parameter_overrides=[Parameter('record', value=str(tmp_path))])
    assert str(raised.value).startswith("parameter 'record': the bag folder")


def test_the_program_exits_2_on_a_folder_it_cannot_write(tmp_path):
    blocker = tmp_path / 'a_file'
    blocker.write_text('')
    result = sim_process.run('-p', f'record:={blocker / "bag"}')
    assert result.returncode == 2, result.stderr
    (line,) = result.stderr.splitlines()
    assert "parameter 'record': cannot write the bag folder" in line
    assert 'Not a directory' in line


def test_a_start_up_error_after_the_bag_was_made_leaves_no_folder(tmp_path, context):
    folder = tmp_path / 'bag'
    with pytest.raises(ConfigurationError, match='camera.link'):
        SimNode(context=context, parameter_overrides=[
            Parameter('record', value=str(folder)),
            Parameter('camera.enabled', value=True),
            Parameter('camera.link', value='no_such_link')])
    assert not folder.exists()


def test_a_full_disk_stops_the_recording_and_the_simulation_goes_on(tmp_path, monkeypatch):
    monkeypatch.setattr(bag, '_open_for_writing', lambda path: FullDisk(path, room=3000))
    monkeypatch.setattr(bag, 'CHUNK_SIZE', 1000)
    with sim_node(record=str(tmp_path / 'bag'), **SMALL_CAMERA) as sim:
        recorder = sim.node.recorder
        assert sim.spin_until(lambda: not recorder.recording), 'the recording never failed'
        assert 'No space left on device' in recorder.bag.failure
        stopped_at = sim.simulation.time
        states_before = len(sim.states)
        sim.run_until_sim_time(stopped_at + 0.5)
        assert sim.spin_until(lambda: len(sim.states) > states_before), (
            'joint_states stopped with the recording')
        assert not math.isnan(sim.simulation.joint_positions()['pan_joint'])
