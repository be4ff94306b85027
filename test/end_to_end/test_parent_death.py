"""sim_node started by a launch file never outlives it (no orphan with parent PID 1).

The launch file sets ``PAN_TILT_SIM_PARENT_PID`` to its own pid; sim_node
then stops -- cleanly, as on SIGTERM -- when that process dies, however it
dies, and at once if it died before sim_node got going.  Without the
variable sim_node outlives its parent, as ``nohup sim_node &`` should.  The
parent here is a small Python process standing in for ``ros2 launch``.
"""

from __future__ import annotations

import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import pytest
import sim_process
from waiting import wait_for

from pan_tilt_sim.ros.runner import PARENT_PID_VARIABLE

BUDGET_S = 30.0
GONE_BUDGET_S = 5.0
STARTED_LINE = b'simulating'

# argv: log file, whether to set the variable, then sim_node's command line.
PARENT = textwrap.dedent('''
    import os, subprocess, sys
    env = dict(os.environ)
    if sys.argv[2] != 'plain':
        env[sys.argv[3]] = str(os.getpid())
    command = sys.argv[4:]
    if sys.argv[2] == 'prefixed':  # a launch prefix: a shell between us and sim_node
        command = ['sh', '-c', '"$@"; exit $?', 'sh', *command]
    with open(sys.argv[1], 'wb') as log:
        child = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=log)
    print(child.pid, flush=True)
    if sys.argv[2] == 'exit-at-once':
        os._exit(0)
    sys.stdin.read()  # until the test kills us
''')


def is_running(pid: int) -> bool:
    """Whether ``pid`` is alive (a zombie awaiting its reaper counts as gone)."""
    try:
        stat = pathlib.Path(f'/proc/{pid}/stat').read_text()
    except FileNotFoundError:
        return False
    return stat.rpartition(')')[2].split()[0] != 'Z'


def start_under_parent(tmp_path: pathlib.Path,
                       mode: str) -> tuple[subprocess.Popen, int, pathlib.Path]:
    """Start sim_node under a stand-in parent; return the parent, sim_node's pid, its log."""
    log = tmp_path / 'sim_node.log'
    parent = subprocess.Popen(
        [sys.executable, '-c', PARENT, str(log), mode, PARENT_PID_VARIABLE,
         *sim_process.command('-p', 'real_time_factor:=1.0')],
        env=sim_process.environment(), stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    child = int(parent.stdout.readline())
    return parent, child, log


@pytest.fixture
def cleanup():
    """Stop what a test leaves running: SIGTERM (a clean DDS exit), SIGKILL if that fails.

    A SIGKILLed DDS participant leaves its shared-memory ports behind in
    /dev/shm, where the next tests in this domain would meet them.
    """
    pids: list[int] = []
    yield pids
    running = [pid for pid in pids if is_running(pid)]
    for pid in running:
        os.kill(pid, signal.SIGTERM)
    for pid in running:
        if not wait_for(lambda pid=pid: not is_running(pid), GONE_BUDGET_S):
            os.kill(pid, signal.SIGKILL)


@pytest.mark.skipif(not sys.platform.startswith('linux'), reason='reads /proc')
def test_sim_node_stops_when_its_launch_parent_is_killed(tmp_path, cleanup):
    parent, child, log = start_under_parent(tmp_path, 'watch')
    cleanup.append(child)
    assert wait_for(lambda: STARTED_LINE in log.read_bytes(), BUDGET_S), log.read_text()
    parent.kill()  # SIGKILL: the launch process cannot clean up after itself
    parent.wait()
    assert wait_for(lambda: not is_running(child), GONE_BUDGET_S), 'sim_node was orphaned'
    assert 'Traceback' not in log.read_text()


@pytest.mark.skipif(not sys.platform.startswith('linux'), reason='reads /proc')
def test_sim_node_stops_when_its_parent_died_before_it_got_going(tmp_path, cleanup):
    parent, child, log = start_under_parent(tmp_path, 'exit-at-once')
    cleanup.append(child)
    parent.wait()
    assert wait_for(lambda: not is_running(child), BUDGET_S), 'sim_node was orphaned'
    assert STARTED_LINE not in log.read_bytes()


@pytest.mark.skipif(not sys.platform.startswith('linux'), reason='reads /proc')
def test_sim_node_under_a_launch_prefix_stops_when_the_launch_process_dies(tmp_path, cleanup):
    parent, shell, log = start_under_parent(tmp_path, 'prefixed')
    cleanup.append(shell)
    assert wait_for(lambda: STARTED_LINE in log.read_bytes(), BUDGET_S), log.read_text()
    (child,) = map(int, pathlib.Path(f'/proc/{shell}/task/{shell}/children').read_text().split())
    cleanup.append(child)
    parent.kill()
    parent.wait()
    assert wait_for(lambda: not is_running(child), GONE_BUDGET_S), 'sim_node was orphaned'


@pytest.mark.skipif(not sys.platform.startswith('linux'), reason='reads /proc')
def test_without_the_variable_sim_node_outlives_its_parent(tmp_path, cleanup):
    parent, child, log = start_under_parent(tmp_path, 'plain')
    cleanup.append(child)
    assert wait_for(lambda: STARTED_LINE in log.read_bytes(), BUDGET_S), log.read_text()
    parent.kill()
    parent.wait()
    time.sleep(1.0)  # long enough for a parent-death signal to have arrived
    assert is_running(child)
