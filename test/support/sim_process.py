"""sim_node as a program in its own process, started from the package the tests import.

``python -m pan_tilt_sim`` with this package first on PYTHONPATH:
the source tree under test, installed or not.  The child inherits the test
process's ROS_DOMAIN_ID and ROS_AUTOMATIC_DISCOVERY_RANGE (see conftest.py).
"""

from __future__ import annotations

import os
import pathlib
import signal
import subprocess
import sys

import pan_tilt_sim

PACKAGE_ROOT = pathlib.Path(pan_tilt_sim.__file__).resolve().parents[1]
# The program's one entry (the console script calls the same main()).
MODULE_ENTRY = ('-m', 'pan_tilt_sim')
EXIT_CONFIGURATION_ERROR = 2  # malformed input: sim_node's exit code
ERROR_PREFIX = 'sim_node: error: '
DUMP_BUDGET_S = 5.0  # for a process that did not stop to print its threads' stacks


def environment() -> dict[str, str]:
    """Return this process's environment with the package under test first on PYTHONPATH."""
    env = dict(os.environ)
    paths = [str(PACKAGE_ROOT), *filter(None, env.get('PYTHONPATH', '').split(os.pathsep))]
    env['PYTHONPATH'] = os.pathsep.join(paths)
    # A child that hangs can be made to print every thread's Python stack (see stop()).
    env['PYTHONFAULTHANDLER'] = '1'
    return env


def command(*ros_args: str, entry: tuple[str, ...] = MODULE_ENTRY) -> list[str]:
    """Return the command line of sim_node with ``--ros-args`` and ``ros_args`` (if any)."""
    args = ['--ros-args', *ros_args] if ros_args else []
    return [sys.executable, *entry, *args]


def run(*ros_args: str, timeout: float = 30.0) -> subprocess.CompletedProcess:
    """Run sim_node to its end (a start-up error) and return what it did."""
    return subprocess.run(command(*ros_args), env=environment(), capture_output=True,
                          text=True, timeout=timeout, check=False)


def error_line(result: subprocess.CompletedProcess) -> str:
    """Return the one line a start-up error printed, checking it exited 2 and said nothing else."""
    assert result.returncode == EXIT_CONFIGURATION_ERROR, result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(ERROR_PREFIX), result.stderr
    return lines[0]


def start(*ros_args: str, entry: tuple[str, ...] = MODULE_ENTRY,
          **popen_kwargs) -> subprocess.Popen:
    """Start sim_node in the background (stdout/stderr piped, text)."""
    return subprocess.Popen(command(*ros_args, entry=entry), env=environment(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            **popen_kwargs)


def stop(process: subprocess.Popen, budget_s: float, *,
         interrupt: bool = True) -> tuple[bool, str]:
    """SIGINT ``process`` (unless already sent); return (ended within ``budget_s``, stderr).

    One that does not is sent SIGABRT, on which Python's faulthandler (see
    environment()) prints every thread's stack to stderr before it dies, so
    the failure says where it hung; then it is killed if it still lives.
    """
    if interrupt:
        process.send_signal(signal.SIGINT)
    try:
        return True, process.communicate(timeout=budget_s)[1]
    except subprocess.TimeoutExpired:
        process.send_signal(signal.SIGABRT)
    try:
        return False, process.communicate(timeout=DUMP_BUDGET_S)[1]
    except subprocess.TimeoutExpired:
        process.kill()
        return False, process.communicate()[1]
