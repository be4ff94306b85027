"""End to end: the sim_node program records a run, commands from another process included.

The program has its physics thread and its command reader thread; the
command comes over DDS, SIGINT ends the run, and the bag it leaves is
complete: metadata.yaml, and every message decodes with the mcap_ros2
reader.
"""

import sim_process
import yaml
from bag_fixtures import NANOSECONDS_PER_SECOND, read, topic_messages
from node_harness import PROBE_QUEUE, NodeHarness
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

NS = '/ex_urdf_pan_tilt'
STARTUP_BUDGET_S = 20.0
SHUTDOWN_BUDGET_S = 5.0
TARGET = 0.05


def test_the_program_records_a_commanded_run_and_finishes_the_bag_on_sigint(tmp_path):
    folder = tmp_path / 'run'
    process = sim_process.start('-p', f'record:={folder}', '-p', 'real_time_factor:=5.0')
    harness = NodeHarness()
    try:
        states = []
        harness.probe.create_subscription(JointState, f'{NS}/joint_states', states.append,
                                          PROBE_QUEUE)
        command = harness.probe.create_publisher(
            Float64, f'{NS}/joint1_position_controller/command', 10)
        assert harness.spin_until(lambda: states and command.get_subscription_count() > 0,
                                  STARTUP_BUDGET_S), 'sim_node did not come up'
        command.publish(Float64(data=TARGET))
        assert harness.spin_until(
            lambda: abs(states[-1].position[0] - TARGET) < 0.01, STARTUP_BUDGET_S), (
            'the pan never reached its target')
    finally:
        harness.close()
        stopped, stderr = sim_process.stop(process, SHUTDOWN_BUDGET_S)
    assert stopped and process.returncode == 0, stderr
    assert "recording to '" in stderr
    info = yaml.safe_load((folder / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    content = read(folder)
    assert info['message_count'] == len(content['messages'])
    commands = topic_messages(content, f'{NS}/joint1_position_controller/command')
    assert [message.data for _, message in commands] == [TARGET]
    recorded_states = topic_messages(content, f'{NS}/joint_states')
    assert abs(recorded_states[-1][1].position[0] - TARGET) < 0.01
    assert commands[0][0] < recorded_states[-1][0]
    assert info['duration']['nanoseconds'] < 60 * NANOSECONDS_PER_SECOND  # sim time, not wall
