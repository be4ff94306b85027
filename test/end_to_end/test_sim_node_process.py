"""End to end: the installed sim_node, found the way `ros2 run` finds it, in its own process.

`ros2 run pan_tilt_sim sim_node` looks the package prefix up in the ament
index and runs ``<prefix>/lib/pan_tilt_sim/sim_node``; this test does the
same, then commands the pan joint from the test process over DDS.
"""

import os
import pathlib
import subprocess

import pytest
import sim_process
from node_harness import PROBE_QUEUE, NodeHarness
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

NS = '/ex_urdf_pan_tilt'
STARTUP_BUDGET_S = 20.0
SHUTDOWN_BUDGET_S = 2.0
TARGET = 0.3


@pytest.fixture
def sim_node_executable():
    from ament_index_python.packages import PackageNotFoundError, get_package_prefix

    try:
        prefix = pathlib.Path(get_package_prefix('pan_tilt_sim'))
    except (PackageNotFoundError, OSError) as err:
        reason = (f'pan_tilt_sim is not installed in an ament prefix ({err!r}); '
                  'scripts/run_tests.sh installs it')
        if os.environ.get('CI'):
            pytest.fail(reason)  # CI installs the package: a skip there would hide a break
        pytest.skip(reason)
    executable = prefix / 'lib' / 'pan_tilt_sim' / 'sim_node'
    assert executable.is_file() and os.access(executable, os.X_OK), executable
    return executable


def test_installed_sim_node_moves_the_pan_and_stops_cleanly_on_sigint(sim_node_executable):
    process = subprocess.Popen(
        [str(sim_node_executable), '--ros-args', '-p', 'real_time_factor:=0'],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        env=dict(os.environ, PYTHONFAULTHANDLER='1'))  # a hang prints its stacks (stop())
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
            lambda: abs(states[-1].position[0] - TARGET) < 0.015, STARTUP_BUDGET_S)
    finally:
        harness.close()
        stopped, stderr = sim_process.stop(process, SHUTDOWN_BUDGET_S)
        if not stopped:
            pytest.fail(f'sim_node did not stop within {SHUTDOWN_BUDGET_S} s of SIGINT: {stderr}')
    assert process.returncode == 0, stderr
    assert 'Traceback' not in stderr
