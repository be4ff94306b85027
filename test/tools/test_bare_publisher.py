"""bare_publisher: the bench's start-up floor publishes JointState and stops on SIGINT."""

import subprocess

import sim_process
from node_harness import NodeHarness
from sensor_msgs.msg import JointState

from pan_tilt_sim.tools.bench import module_command

TOPIC = '/bare_publisher_test/joint_states'
STOP_BUDGET_S = 10.0


def test_publishes_joint_state_on_its_topic_until_interrupted():
    harness = NodeHarness()
    received: list[JointState] = []
    harness.probe.create_subscription(JointState, TOPIC, received.append, 10)
    process = subprocess.Popen(
        module_command('pan_tilt_sim.tools.bare_publisher', TOPIC),  # as the bench starts it
        env=sim_process.environment(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True)
    try:
        assert harness.spin_until(lambda: len(received) >= 3, budget_s=30.0), \
            'no JointStates from bare_publisher'
    finally:
        ended, stderr = sim_process.stop(process, STOP_BUDGET_S)
        harness.close()
    assert ended, stderr
    assert process.returncode == 0, stderr


def test_a_sigint_between_its_check_and_its_publish_stops_it_cleanly():
    from interrupting import interrupted_after_check

    result = interrupted_after_check(
        'from pan_tilt_sim.tools.bare_publisher import publish_until_stopped\n'
        'from sensor_msgs.msg import JointState\n',
        "publish_until_stopped(node, node.create_publisher(JointState, 'bare', 1), JointState())")
    assert (result.returncode, result.stdout) == (0, 'returned\n'), result.stderr
