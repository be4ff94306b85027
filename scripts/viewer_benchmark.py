#!/usr/bin/env python3
"""Measure what the browser view costs: start-up, and sim_node's CPU with the view off and on.

Run from a checkout whose venv has viser (scripts/run_tests.sh installs it)::

    export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST AMENT_PREFIX_PATH=.venv
    .venv/bin/python -P scripts/viewer_benchmark.py

Prints one JSON object.  Each case starts the sim_node program (the pan/tilt
example) in a process of its own:

* ``startup_s``: process start to the end of start-up (the log line with the
  view's URL, or with the view off the "simulating" line);
* ``rtf1_cpu_percent``: the process's CPU share at real_time_factor 1 over
  ``--seconds`` of wall time (user + system over wall, 100 % = one core);
* ``rtf0_steps_per_s``: physics steps per wall second at real_time_factor 0;
* ``cpu_ms_per_frame``: with a browser, the CPU the view adds per scene
  update (at FRAME_RATE_HZ) over the view on with nobody connected.

Cases: the view off, on with nobody connected, on with one headless Chromium
showing it (Chromium's own CPU is not counted) with the pan/tilt's camera off
(the view's own cost) and on (the camera then renders for the view, at its
rate of sim time).  Without Chromium the browser cases are left out.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import QoSProfile
from rosgraph_msgs.msg import Clock

from pan_tilt_sim.ros.viewer import FRAME_RATE_HZ

TIME_STEP = 0.001
URL_LINE = re.compile(r'viewer: open (http://\S+) in a browser')
# The last line of start-up: the view's URL when it is on, else the "simulating" line.
READY_LINE = re.compile(r'viewer: open |simulating \'')
CHROMIUM_FLAGS = ('--headless', '--no-sandbox', '--disable-gpu', '--disable-quic',
                  '--no-first-run', '--disable-background-networking',
                  '--disable-component-update', '--disable-sync', '--enable-unsafe-swiftshader',
                  '--use-angle=swiftshader', '--window-size=800,600')
CONNECT_S = 15.0  # wall seconds for the browser to load the page and the scene
BUDGET_S = 60.0


def cpu_seconds(pid: int) -> float:
    """Return the user + system CPU seconds process ``pid`` has used."""
    with open(f'/proc/{pid}/stat') as stat:
        fields = stat.read().rpartition(')')[2].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


class ClockWatch:
    """The newest /clock stamp, from a node of this process."""

    def __init__(self) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = Node('viewer_benchmark', context=self.context)
        self.latest: float | None = None
        self.node.create_subscription(Clock, '/clock', self._take, QoSProfile(depth=10))
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def _take(self, message: Clock) -> None:
        self.latest = message.clock.sec + message.clock.nanosec * 1e-9

    def spin_until(self, condition, budget_s: float) -> bool:
        """Spin until ``condition()`` holds; False after ``budget_s``."""
        deadline = time.monotonic() + budget_s
        while not condition():
            if time.monotonic() > deadline:
                return False
            self.executor.spin_once(timeout_sec=0.01)
        return True

    def spin_for(self, seconds: float) -> None:
        """Spin for ``seconds`` of wall time."""
        self.spin_until(lambda: False, seconds)

    def close(self) -> None:
        """Destroy the node and its context."""
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


class Case:
    """The sim_node program, with or without the view (and a browser on it)."""

    def __init__(self, *args: str) -> None:
        self.started = time.monotonic()
        self.process = subprocess.Popen(
            [sys.executable, '-m', 'pan_tilt_sim', '--ros-args', *args],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        self.lines: list[str] = []
        self.ready_s: float | None = None  # process start to its last start-up line
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        for line in self.process.stderr:
            self.lines.append(line)
            if READY_LINE.search(line):
                self.ready_s = time.monotonic() - self.started

    def url(self) -> str | None:
        """Return the view's URL once the program logged it."""
        return next((m.group(1) for line in list(self.lines)
                     if (m := URL_LINE.search(line))), None)

    def stop(self) -> None:
        """Stop the program as Ctrl-C does."""
        self.process.send_signal(signal.SIGINT)
        try:
            self.process.wait(10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def measure(clock: ClockWatch, args: tuple[str, ...], seconds: float, chromium: str | None,
            viewer: bool) -> dict[str, float]:
    """Start-up, CPU at factor 1 and steps/s at factor 0 of one case."""
    figures: dict[str, float] = {}
    clock.latest = None
    case = Case(*args)
    browser = None
    profile = tempfile.TemporaryDirectory(prefix='viewer_benchmark_')
    try:
        assert clock.spin_until(lambda: clock.latest is not None, BUDGET_S), 'no /clock'
        if viewer:
            assert clock.spin_until(case.url, BUDGET_S), ''.join(case.lines)
        assert clock.spin_until(lambda: case.ready_s is not None, BUDGET_S)
        figures['startup_s'] = case.ready_s
        if chromium is not None:
            browser = subprocess.Popen(
                [chromium, *CHROMIUM_FLAGS, f'--user-data-dir={profile.name}', case.url()],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            clock.spin_for(CONNECT_S)
        pid = case.process.pid
        cpu, wall = cpu_seconds(pid), time.monotonic()
        clock.spin_for(seconds)
        figures['rtf1_cpu_percent'] = 100.0 * (cpu_seconds(pid) - cpu) / (
            time.monotonic() - wall)
    finally:
        if browser is not None:
            browser.terminate()
            browser.wait()
        case.stop()
        profile.cleanup()
    case = Case(*args, '-p', 'real_time_factor:=0')
    browser = None
    profile = tempfile.TemporaryDirectory(prefix='viewer_benchmark_')
    try:
        assert clock.spin_until(lambda: clock.latest is not None, BUDGET_S), 'no /clock'
        if viewer:
            assert clock.spin_until(case.url, BUDGET_S)
        if chromium is not None:
            browser = subprocess.Popen(
                [chromium, *CHROMIUM_FLAGS, f'--user-data-dir={profile.name}', case.url()],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            clock.spin_for(CONNECT_S)
        start_sim, start_wall = clock.latest, time.monotonic()
        clock.spin_for(seconds / 2)
        figures['rtf0_steps_per_s'] = (clock.latest - start_sim) / TIME_STEP / (
            time.monotonic() - start_wall)
    finally:
        if browser is not None:
            browser.terminate()
            browser.wait()
        case.stop()
        profile.cleanup()
    return figures


def viser_startup_s() -> float:
    """Return the wall seconds of importing viser and starting its server (what the view adds)."""
    code = ('import time, contextlib, io\n'
            't = time.perf_counter()\n'
            'import viser\n'
            'with contextlib.redirect_stdout(io.StringIO()):\n'
            '    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)\n'
            'print(time.perf_counter() - t)\n'
            'with contextlib.redirect_stdout(io.StringIO()):\n'
            '    server.stop()\n')
    result = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                            check=True)
    return float(result.stdout.strip())


def main() -> None:
    """Measure every case and print the figures as JSON."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--seconds', type=float, default=20.0,
                        help='wall seconds each CPU figure is taken over')
    parser.add_argument('--runs', type=int, default=3, help='runs of viser start-up')
    args = parser.parse_args()
    chromium = next((found for name in ('chromium', 'chromium-browser')
                     if (found := shutil.which(name))), None)
    clock = ClockWatch()
    try:
        result = {
            'viser_import_and_start_s': sorted(viser_startup_s() for _ in range(args.runs))[
                args.runs // 2],
            'view_off': measure(clock, ('-p', 'viewer:=false'), args.seconds, None, False),
            'view_on_nobody': measure(clock, ('-p', 'viewer:=true', '-p', 'viewer.port:=0'),
                                      args.seconds, None, True),
        }
        if chromium is not None:
            on = ('-p', 'viewer:=true', '-p', 'viewer.port:=0')
            watched = measure(clock, (*on, '-p', 'camera.enabled:=false'), args.seconds,
                              chromium, True)
            added = watched['rtf1_cpu_percent'] - result['view_on_nobody']['rtf1_cpu_percent']
            watched['cpu_ms_per_frame'] = added / 100.0 * 1000.0 / FRAME_RATE_HZ
            result['view_on_one_browser'] = watched
            result['view_on_one_browser_camera_shown'] = measure(clock, on, args.seconds,
                                                                 chromium, True)
    finally:
        clock.close()
    print(json.dumps(result, indent=2))


if __name__ == '__main__':
    main()
