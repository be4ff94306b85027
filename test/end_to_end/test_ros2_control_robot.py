"""A ros2_control robot run as a program: what sim_node says about it, once, on its logger.

xacro's own warnings, the vendor controllers skipped, the controllers loaded
but inactive, a missing joint_state_broadcaster and a command to an inactive
controller each get one log line through the node's logger -- nothing
reaches stderr around it -- and a start-up error is still the one line.
"""

from __future__ import annotations

import os
import selectors
import signal
import subprocess
import time

import pytest
import sim_process
from node_harness import NodeHarness
from ros2_control_fixtures import HEAD_YAML, write, write_arm
from std_msgs.msg import Float64MultiArray

BUDGET_S = 30.0
STARTED_LINE = 'simulating'
LOG_LINE_START = '['  # rcl's console format: [LEVEL] [time] [node]: text
UR_STYLE_ARGS = ('-p', "xacro_args:=['prefix:=left_']", '-p', "controllers_args:=['prefix:=left_']",
                 '-p', 'active_controllers:=[joint_state_broadcaster, '
                 'joint_trajectory_controller]', '-p', 'real_time_factor:=1.0')


def read_until(process: subprocess.Popen, seen: list[bytes], text: str) -> str:
    """Read stderr into ``seen`` until it holds ``text`` (bounded); return all of it."""
    deadline = time.monotonic() + BUDGET_S
    with selectors.DefaultSelector() as selector:
        selector.register(process.stderr, selectors.EVENT_READ)
        while text.encode() not in b''.join(seen):
            remaining = deadline - time.monotonic()
            if remaining <= 0 or process.poll() is not None:
                pytest.fail(f'sim_node never said {text!r}; stderr:\n{b"".join(seen).decode()}')
            if selector.select(remaining):
                seen.append(os.read(process.stderr.fileno(), 65536))
    return b''.join(seen).decode()


def stop(process: subprocess.Popen, seen: list[bytes]) -> str:
    """SIGINT, wait for the exit (code 0); return everything it wrote on stderr."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
    _stdout, rest = process.communicate(timeout=BUDGET_S)
    assert process.returncode == 0, rest
    return b''.join(seen).decode() + rest


def test_the_robot_s_warnings_and_choices_are_logged_once(tmp_path):
    xacro = write_arm(tmp_path)
    process = sim_process.start('-p', f'robot_description_file:={xacro}', *UR_STYLE_ARGS)
    harness = NodeHarness()
    seen: list[bytes] = []
    try:
        read_until(process, seen, STARTED_LINE)
        publisher = harness.probe.create_publisher(
            Float64MultiArray, '/forward_position_controller/commands', 10)
        assert harness.spin_until(lambda: publisher.get_subscription_count() > 0)
        publisher.publish(Float64MultiArray(data=[1.0, 1.0]))
        read_until(process, seen, 'ignored a command')
    finally:
        harness.close()
        stderr = stop(process, seen)
    lines = stderr.splitlines()
    assert all(line.startswith(LOG_LINE_START) for line in lines), stderr
    assert [line for line in lines if 'redefining global symbol: pi' in line] == [
        line for line in lines if line.startswith('[WARN]') and 'xacro' in line]
    assert len([line for line in lines if 'redefining global symbol: pi' in line]) == 1
    for name, kind in (('io_and_status_controller', 'GPIOController'),
                       ('speed_scaling_state_broadcaster', 'SpeedScalingStateBroadcaster'),
                       ('scaled_joint_trajectory_controller', 'ScaledJointTrajectoryController')):
        (line,) = [line for line in lines if f"'{name}'" in line]
        assert line.startswith('[INFO]') and f"'acme_controllers/{kind}'" in line
        assert 'skipped' in line
    (inactive,) = [line for line in lines if 'loaded but inactive' in line]
    assert inactive.endswith(': forward_velocity_controller, forward_position_controller')
    (ignored,) = [line for line in lines if 'ignored a command' in line]
    assert ignored.startswith('[WARN]') and 'forward_position_controller' in ignored
    assert 'inactive' in ignored


def test_a_file_without_a_broadcaster_is_warned_about(tmp_path):
    xacro = write_arm(tmp_path)
    head = write(tmp_path, 'head.yaml', HEAD_YAML)
    process = sim_process.start('-p', f'robot_description_file:={xacro}',
                                '-p', f'controllers_file:={head}')
    seen: list[bytes] = []
    try:
        read_until(process, seen, STARTED_LINE)
    finally:
        stderr = stop(process, seen)
    (line,) = [line for line in stderr.splitlines() if 'joint_state_broadcaster' in line]
    assert line.startswith('[WARN]')
    assert line.endswith(f'no joint_state_broadcaster in {head}: nothing will be published on '
                         '/joint_states')


def test_a_start_up_error_is_one_line_even_when_xacro_warned(tmp_path):
    xacro = write_arm(tmp_path)  # xacro warns about pi; the controllers lack $(var prefix)
    completed = sim_process.run('-p', f'robot_description_file:={xacro}')
    assert completed.returncode == 2
    assert completed.stderr.count('\n') == 1, completed.stderr
    assert completed.stderr.startswith('sim_node: error: ')
    assert '$(var prefix) is not set' in completed.stderr
