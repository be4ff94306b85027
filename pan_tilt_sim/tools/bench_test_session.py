"""bench's "test session" figure: a pytest session of go-to-goal tests, each on a fresh ``sim``.

Writes a small user package into a temporary folder -- a go-to-goal node
and TESTS tests of it against the rover on the ground, each with its own
simulation -- and runs it with pytest as a user would, once in one
process and once under ``-n 2``.  A conftest of the package notes, after
each test, pytest's own set-up and teardown durations and the worker's
resident memory and open file descriptors.  Keys of :func:`measure`'s dict:

* ``setup_teardown_s_p50`` / ``_max``: set-up + teardown of one test, over
  the one-process run: the fixture's set-up, the ``sim(...)`` call that
  starts the simulation, and the fixture's clean end;
* ``call_s_p50``: the rest of a test, the robot driving to its goal;
* ``rss_growth_mb`` / ``fd_growth``: the process's resident memory and
  open files after its last tests minus after the tests halfway through
  (the mean of GROWTH_WINDOW tests each; the first half warms up imports
  and caches), the one-process run;
* ``wall_s_n1`` / ``wall_s_n2`` and ``speedup_n2``: the two sessions' wall
  time, pytest's start included, and their ratio.
"""

from __future__ import annotations

import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time

TESTS = 100
QUICK_TESTS = 6
GROWTH_WINDOW = 10  # tests averaged at each end for the growth figures
RUN_BUDGET_S = 1800.0

_NODE = '''
    import math

    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from rclpy.node import Node


    class GoToGoal(Node):
        """Drives toward (GOAL_X, GOAL_Y) from odometry; ``arrived`` within 2 cm."""

        def __init__(self, goal):
            super().__init__('go_to_goal')
            self.goal = goal
            self.arrived = False
            self._cmd = self.create_publisher(Twist, 'cmd_vel', 10)
            self.create_subscription(Odometry, 'odom', self._on_odom, 10)

        def _on_odom(self, odom):
            p = odom.pose.pose.position
            q = odom.pose.pose.orientation
            dx, dy = self.goal[0] - p.x, self.goal[1] - p.y
            distance = math.hypot(dx, dy)
            yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
            error = (math.atan2(dy, dx) - yaw + math.pi) % (2 * math.pi) - math.pi
            command = Twist()
            self.arrived = distance < 0.02
            if not self.arrived:
                command.angular.z = max(-1.5, min(1.5, 3.0 * error))
                command.linear.x = min(0.4, distance) * max(0.0, math.cos(error))
            self._cmd.publish(command)
    '''

_TESTS = '''
    import time

    import pytest

    from go_to_goal import GoToGoal

    ROVER = 'package://pan_tilt_sim/urdf/diff_drive_rover.urdf'


    @pytest.mark.parametrize('n', range({tests}))
    def test_go_to_goal(sim, n, record_property):
        started = time.perf_counter()
        s = sim(robot=ROVER, world='ground')
        record_property('start_s', time.perf_counter() - started)
        node = s.add_node(GoToGoal((0.3, 0.1 * (n % 3 - 1))))
        s.run_until(lambda: node.arrived, timeout=10.0)
    '''

_CONFTEST = '''
    import json
    import os
    import resource

    import pytest

    _phases = {}


    def _rss_mb():
        with open('/proc/self/statm') as statm:
            return int(statm.read().split()[1]) * resource.getpagesize() / 1e6


    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_makereport(item, call):
        outcome = yield
        report = outcome.get_result()
        _phases[report.when] = report.duration
        if report.when == 'teardown':
            worker = os.environ.get('PYTEST_XDIST_WORKER', 'main')
            with open(f'notes_{worker}.jsonl', 'a') as notes:
                start = dict(report.user_properties).get('start_s', 0.0)
                notes.write(json.dumps({
                    'setup_s': _phases.get('setup', 0.0) + start,
                    'teardown_s': report.duration, 'start_s': start,
                    'call_s': _phases.get('call', 0.0) - start, 'rss_mb': _rss_mb(),
                    'fds': len(os.listdir('/proc/self/fd'))}) + '\\n')
    '''


def write_session(folder: pathlib.Path, tests: int) -> None:
    """Write the user package: its node, its tests and the conftest that takes notes."""
    (folder / 'pytest.ini').write_text('[pytest]\naddopts = -p no:cacheprovider\n')
    (folder / 'go_to_goal.py').write_text(textwrap.dedent(_NODE))
    (folder / 'test_session.py').write_text(textwrap.dedent(_TESTS).replace(
        '{tests}', str(tests)))
    (folder / 'conftest.py').write_text(textwrap.dedent(_CONFTEST))


def run_session(folder: pathlib.Path, workers: int, domain_base: int) -> float:
    """Run the session (``-n workers`` when more than one); return its wall time."""
    for old in folder.glob('notes_*.jsonl'):
        old.unlink()
    pytest = pathlib.Path(sys.executable).parent / 'pytest'
    command = [str(pytest), '-q', '--rootdir', str(folder), '--ros-domain-base', str(domain_base)]
    if workers > 1:
        command += ['-n', str(workers)]
    else:
        command += ['-p', 'no:xdist']
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
               ROS_DOMAIN_ID=str(domain_base))
    started = time.perf_counter()
    result = subprocess.run(command, cwd=folder, env=env, capture_output=True, text=True,
                            timeout=RUN_BUDGET_S, check=False)
    wall = time.perf_counter() - started
    if result.returncode != 0:
        raise RuntimeError(f'the test session failed:\n{result.stdout[-3000:]}{result.stderr}')
    return wall


def _notes(folder: pathlib.Path, worker: str) -> list[dict]:
    with open(folder / f'notes_{worker}.jsonl') as notes:
        return [json.loads(line) for line in notes]


def measure(quick: bool = False, domain_base: int = 0) -> dict[str, float]:
    """Run both sessions and return the figures (see the module docstring)."""
    tests = QUICK_TESTS if quick else TESTS
    window = min(GROWTH_WINDOW, tests // 4)
    with tempfile.TemporaryDirectory(prefix='pan_tilt_test_session_') as name:
        folder = pathlib.Path(name)
        write_session(folder, tests)
        wall_n1 = run_session(folder, 1, domain_base)
        notes = _notes(folder, 'main')
        wall_n2 = run_session(folder, 2, domain_base)
    overhead = [note['setup_s'] + note['teardown_s'] for note in notes]

    middle = len(notes) // 2

    def growth(key: str) -> float:
        return (statistics.fmean(note[key] for note in notes[-window:])
                - statistics.fmean(note[key] for note in notes[middle - window:middle]))

    return {
        'tests': tests,
        'setup_teardown_s_p50': statistics.median(overhead),
        'setup_teardown_s_max': max(overhead),
        'call_s_p50': statistics.median(note['call_s'] for note in notes),
        'rss_growth_mb': growth('rss_mb'),
        'fd_growth': growth('fds'),
        'wall_s_n1': wall_n1,
        'wall_s_n2': wall_n2,
        'speedup_n2': wall_n1 / wall_n2,
    }
