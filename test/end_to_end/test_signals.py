"""SIGINT and SIGTERM: sim_node stops within 2 s, disconnects PyBullet, exits 0, no traceback.

Also when it was started with SIGINT ignored (a shell's background job), when
Ctrl-C reaches it through its process group under a parent that does not
forward signals (as `ros2 run` does not), and when the signal comes while it
is still importing rclpy and PyBullet.  Each case runs sim_node in its own
process with ``--log-level sim_node:=debug``, whose last word is the debug
line saying PyBullet was disconnected.
"""

from __future__ import annotations

import os
import pathlib
import selectors
import signal
import subprocess
import time

import pytest
import rclpy
import sim_process
from rclpy.context import Context
from rclpy.parameter import Parameter

from pan_tilt_sim.ros.sim_node import SimNode
from pan_tilt_sim.sim.physics import pybullet

STARTUP_BUDGET_S = 30.0
STOP_BUDGET_S = 2.0
RUNNING_LINE = 'spinning until SIGINT or SIGTERM'
STARTED_LINE = 'simulating'
DISCONNECTED_LINE = 'PyBullet disconnected'
DEBUG_ARGS = ('-p', 'real_time_factor:=1.0', '--log-level', 'sim_node:=debug')
SIGTERM_BIT = 1 << (signal.SIGTERM - 1)
POLL_S = 0.001


def _read_until(process: subprocess.Popen, text: str, budget_s: float) -> str:
    """Return stderr read so far once it contains ``text`` (raw reads, bounded wait)."""
    seen = b''
    deadline = time.monotonic() + budget_s
    with selectors.DefaultSelector() as selector:
        selector.register(process.stderr, selectors.EVENT_READ)
        while text.encode() not in seen:
            remaining = deadline - time.monotonic()
            if remaining <= 0 or process.poll() is not None:
                pytest.fail(f'sim_node never said {text!r}; stderr so far:\n{seen.decode()}')
            if selector.select(remaining):
                seen += os.read(process.stderr.fileno(), 65536)
    return seen.decode()


def _stop(process: subprocess.Popen, signum: int, *, group: bool = False) -> tuple[float, str]:
    """Send ``signum``; return the seconds until the process ended and the rest of stderr."""
    start = time.monotonic()
    if group:
        os.killpg(process.pid, signum)
    else:
        process.send_signal(signum)
    stopped, stderr = sim_process.stop(process, STOP_BUDGET_S, interrupt=False)
    if not stopped:
        pytest.fail(f'still running {STOP_BUDGET_S} s after {signal.Signals(signum).name}: '
                    f'{stderr}')
    return time.monotonic() - start, stderr


def _assert_clean_stop(process: subprocess.Popen, stderr: str) -> None:
    assert process.returncode == 0, stderr
    assert 'Traceback' not in stderr, stderr
    assert DISCONNECTED_LINE in stderr, stderr


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@pytest.mark.parametrize(('signum', 'start_options'), [
    pytest.param(signal.SIGINT, {}, id='SIGINT'),
    pytest.param(signal.SIGTERM, {}, id='SIGTERM'),
    # A shell starts background jobs with SIGINT ignored; the child inherits that.
    pytest.param(signal.SIGINT, {'preexec_fn': _ignore_sigint}, id='SIGINT, started ignored'),
    pytest.param(signal.SIGTERM, {'preexec_fn': _ignore_sigint},
                 id='SIGTERM, SIGINT started ignored'),
])
def test_a_running_node_stops_cleanly(signum, start_options):
    process = sim_process.start(*DEBUG_ARGS, **start_options)
    _read_until(process, RUNNING_LINE, STARTUP_BUDGET_S)
    elapsed, stderr = _stop(process, signum)
    _assert_clean_stop(process, stderr)
    assert elapsed < STOP_BUDGET_S


def test_ctrl_c_to_the_process_group_under_a_non_forwarding_parent():
    # `ros2 run` waits for its child without forwarding signals; the terminal
    # sends SIGINT to the whole foreground process group.  A shell that waits
    # (no exec) plays ros2 run; the group gets the signal.
    command = ' '.join(f"'{part}'" for part in sim_process.command(*DEBUG_ARGS))
    process = subprocess.Popen(['sh', '-c', f'{command}; echo "parent saw $?"'],
                               env=sim_process.environment(), stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, start_new_session=True)
    _read_until(process, RUNNING_LINE, STARTUP_BUDGET_S)
    elapsed, stderr = _stop(process, signal.SIGINT, group=True)
    assert 'Traceback' not in stderr, stderr
    assert DISCONNECTED_LINE in stderr, stderr
    assert elapsed < STOP_BUDGET_S


def _catches_sigterm(pid: int) -> bool:
    status = pathlib.Path(f'/proc/{pid}/status').read_text()
    caught = next(line for line in status.splitlines() if line.startswith('SigCgt:'))
    return bool(int(caught.split()[1], 16) & SIGTERM_BIT)


@pytest.mark.skipif(not pathlib.Path('/proc/self/status').exists(), reason='needs Linux /proc')
@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM], ids=['SIGINT', 'SIGTERM'])
def test_a_signal_during_start_up_stops_it_cleanly(signum):
    # The runner entry point installs its handlers before importing rclpy and
    # PyBullet (~0.5 s): signal as soon as the handler is there, mid-import.
    process = sim_process.start(*DEBUG_ARGS)
    deadline = time.monotonic() + STARTUP_BUDGET_S
    while not _catches_sigterm(process.pid):
        assert time.monotonic() < deadline and process.poll() is None
        time.sleep(POLL_S)
    elapsed, stderr = _stop(process, signum)
    assert process.returncode == 0, stderr
    assert 'Traceback' not in stderr, stderr
    assert STARTED_LINE not in stderr  # it really was stopped during start-up
    assert elapsed < STOP_BUDGET_S


def test_destroying_the_node_disconnects_pybullet():
    context = Context()
    rclpy.init(context=context)
    try:
        node = SimNode(context=context,
                       parameter_overrides=[Parameter('real_time_factor', value=0.0)])
        client = node.simulation.physics.client_id
        assert pybullet.getConnectionInfo(physicsClientId=client)['isConnected'] == 1
        node.destroy_node()
        assert pybullet.getConnectionInfo(physicsClientId=client)['isConnected'] == 0
    finally:
        rclpy.try_shutdown(context=context)
