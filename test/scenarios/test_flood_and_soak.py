"""Flood and soak: sim_node keeps its pace, its memory and its numbers under long abuse.

Minutes long, so off by default; run them with

    PAN_TILT_SIM_SLOW=1 scripts/run_tests.sh -m soak -s test/scenarios/test_flood_and_soak.py

(``-s`` shows the figures each test prints).  sim_node runs in its own
process, so its RSS is its own; the test process is the probe.

* Flood: 20,000 Float64 commands per second for 10 s from a third process
  (``flood_publisher.py``) at real_time_factor 1: sim time stays within 1 %
  of wall time, JointState keeps its 50 Hz (within 1 %), RSS grows by less
  than 2 MB.
* Soak: 3,600 s of sim time at real_time_factor 0, pan and tilt commands
  changing every sim second (some out of range, some NaN or 1e308): no
  non-finite value in any JointState, RSS grows by less than 1 MB after the
  first minute, and JointState comes at 50 Hz of sim time in the last five
  minutes as in the five after the first.
"""

from __future__ import annotations

import math
import os
import pathlib
import subprocess
import sys
import time

import pytest
import sim_process
from node_harness import PROBE_QUEUE, NodeHarness
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

psutil = pytest.importorskip('psutil')

SLOW_ENV = 'PAN_TILT_SIM_SLOW'
pytestmark = [
    pytest.mark.soak,
    pytest.mark.slow,
    pytest.mark.skipif(os.environ.get(SLOW_ENV) != '1',
                       reason=f'flood/soak tests take minutes: set {SLOW_ENV}=1'),
]

NS = '/ex_urdf_pan_tilt'
PAN_COMMAND = f'{NS}/joint1_position_controller/command'
TILT_COMMAND = f'{NS}/joint2_position_controller/command'
FLOOD_SCRIPT = pathlib.Path(__file__).resolve().parent / 'flood_publisher.py'
MEGABYTE = 1024 * 1024
STARTUP_BUDGET_S = 30.0
STOP_BUDGET_S = 2.0
PUBLISH_RATE_HZ = 50.0

FLOOD_RATE_HZ = 20_000
FLOOD_S = 10.0
FLOOD_WARM_UP_S = 2.0
FLOOD_MIN_ACHIEVED = 0.9  # of FLOOD_RATE_HZ, or the test did not test a flood
FLOOD_PACE_TOLERANCE = 0.01
FLOOD_RSS_GROWTH_MB = 2.0

SOAK_S = 3600
SOAK_BASELINE_S = 60  # RSS is measured from here: allocators and DDS settle first
SOAK_WINDOW_S = 300
SOAK_BUDGET_S = 3600.0  # wall seconds; ~2 min at the usual 30x
SOAK_RSS_GROWTH_MB = 1.0
SOAK_RATE_TOLERANCE = 0.01


def _stamp(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def _rss_mb(process: subprocess.Popen) -> float:
    return psutil.Process(process.pid).memory_info().rss / MEGABYTE


def _finite(message: JointState) -> bool:
    return all(map(math.isfinite, (*message.position, *message.velocity, *message.effort)))


class SimUnderTest:
    """sim_node in its own process, watched by the harness's probe.

    The probe takes every JointState (checked for non-finite values, then
    handed to ``on_state``) and, if ``watch_clock``, every /clock.  At
    real_time_factor 0 that is thousands of messages per wall second: keep
    the callbacks lean, or the probe, not the node, drops messages.
    """

    def __init__(self, *ros_args: str, on_state=None, watch_clock: bool = True) -> None:
        self.process = sim_process.start(*ros_args)
        self.harness = NodeHarness()
        self.clock: list[tuple[float, float]] = []  # (wall receive time, sim time)
        self.state_times: list[float] = []          # wall receive time of each JointState
        self.non_finite = 0
        self._on_state_extra = on_state
        probe = self.harness.probe
        if watch_clock:
            probe.create_subscription(Clock, '/clock', self._on_clock, PROBE_QUEUE)
        probe.create_subscription(JointState, f'{NS}/joint_states', self._on_state, PROBE_QUEUE)
        assert self.harness.spin_until(lambda: self.state_times, STARTUP_BUDGET_S), (
            'sim_node did not come up')

    def _on_clock(self, message: Clock) -> None:
        self.clock.append((time.monotonic(), _stamp(message.clock)))

    def _on_state(self, message: JointState) -> None:
        self.state_times.append(time.monotonic())
        self.non_finite += not _finite(message)
        if self._on_state_extra is not None:
            self._on_state_extra(message)

    def close(self) -> None:
        self.harness.close()
        self.process.terminate()
        stopped, stderr = sim_process.stop(self.process, STOP_BUDGET_S, interrupt=False)
        assert stopped and self.process.returncode == 0, stderr


def _flood_window(output: str) -> tuple[int, float, float]:
    """Parse flood_publisher.py's last line: (messages, start, end) in monotonic time."""
    words = output.split()
    return int(words[1]), float(words[3]), float(words[5])


def test_a_command_flood_leaves_sim_time_paced_and_memory_flat():
    sim = SimUnderTest('-p', 'real_time_factor:=1.0')
    try:
        sim.harness.spin_until(lambda: False, FLOOD_WARM_UP_S)
        rss_before = _rss_mb(sim.process)
        flood = subprocess.Popen(
            [sys.executable, str(FLOOD_SCRIPT), PAN_COMMAND, str(FLOOD_RATE_HZ),
             str(FLOOD_S)], env=sim_process.environment(), stdout=subprocess.PIPE, text=True)
        rss_peak = rss_before
        deadline = time.monotonic() + FLOOD_S + STARTUP_BUDGET_S
        while flood.poll() is None and time.monotonic() < deadline:
            sim.harness.spin_until(lambda: False, 0.5)
            rss_peak = max(rss_peak, _rss_mb(sim.process))
        output, _ = flood.communicate(timeout=STOP_BUDGET_S)
        rss_after = _rss_mb(sim.process)
    finally:
        sim.close()
    sent, start, end = _flood_window(output.splitlines()[-1])
    inside = [(wall, sim_s) for wall, sim_s in sim.clock if start <= wall <= end]
    (wall0, sim0), (wall1, sim1) = inside[0], inside[-1]
    pace = (sim1 - sim0) / (wall1 - wall0)
    states_hz = sum(start <= wall <= end for wall in sim.state_times) / (end - start)
    achieved_hz = sent / (end - start)
    print(f'\nflood: {sent} messages in {end - start:.2f} s ({achieved_hz:.0f}/s); '
          f'sim/wall {pace:.4f}; JointState {states_hz:.1f} Hz; RSS {rss_before:.1f} -> '
          f'{rss_after:.1f} MB (peak {rss_peak:.1f}), growth {rss_after - rss_before:+.2f} MB')
    assert achieved_hz >= FLOOD_MIN_ACHIEVED * FLOOD_RATE_HZ, 'the flood was not a flood'
    assert abs(pace - 1.0) < FLOOD_PACE_TOLERANCE
    assert abs(states_hz - PUBLISH_RATE_HZ) < FLOOD_PACE_TOLERANCE * PUBLISH_RATE_HZ
    assert rss_after - rss_before < FLOOD_RSS_GROWTH_MB
    assert sim.non_finite == 0


def _soak_command(second: int) -> tuple[float, float]:
    """Pan and tilt commands for one sim second: mostly in range, some not, some garbage."""
    if second % 13 == 0:
        return math.nan, math.nan
    if second % 17 == 0:
        return 1e308, -1e308
    return 3.5 * math.sin(0.7 * second), -3.14 + 2.5 * math.sin(1.3 * second)


def test_an_hour_of_sim_time_with_commands_every_second_stays_finite_flat_and_regular():
    per_second = [0] * (SOAK_S + 2)
    commanded = [-1]
    publishers = []

    def on_state(message: JointState) -> None:
        index = round(_stamp(message.header.stamp) * PUBLISH_RATE_HZ)
        second = index // int(PUBLISH_RATE_HZ)
        if second < len(per_second):
            per_second[second] += 1
        if second > commanded[0] and publishers:
            commanded[0] = second
            for publisher, value in zip(publishers, _soak_command(second), strict=True):
                publisher.publish(Float64(data=value))

    # JointState only: at ~40x real time, /clock as well would swamp a Python probe.
    sim = SimUnderTest('-p', 'real_time_factor:=0', on_state=on_state, watch_clock=False)
    probe, harness = sim.harness.probe, sim.harness
    publishers.extend(probe.create_publisher(Float64, topic, 10)
                      for topic in (PAN_COMMAND, TILT_COMMAND))
    try:
        assert harness.spin_until(lambda: all(p.get_subscription_count() for p in publishers),
                                  STARTUP_BUDGET_S)
        assert harness.spin_until(lambda: commanded[0] >= SOAK_BASELINE_S, SOAK_BUDGET_S)
        rss_baseline, wall_baseline = _rss_mb(sim.process), time.monotonic()
        assert harness.spin_until(lambda: commanded[0] >= SOAK_BASELINE_S + SOAK_WINDOW_S,
                                  SOAK_BUDGET_S)
        early_speed = SOAK_WINDOW_S / (time.monotonic() - wall_baseline)
        assert harness.spin_until(lambda: commanded[0] >= SOAK_S - SOAK_WINDOW_S,
                                  SOAK_BUDGET_S)
        wall_late = time.monotonic()
        assert harness.spin_until(lambda: commanded[0] >= SOAK_S + 1, SOAK_BUDGET_S)
        late_speed = SOAK_WINDOW_S / (time.monotonic() - wall_late)
        rss_end = _rss_mb(sim.process)
    finally:
        sim.close()
    # From the baseline on: the probe may join a few sim seconds after the start.
    early = per_second[SOAK_BASELINE_S:SOAK_BASELINE_S + SOAK_WINDOW_S]
    late = per_second[SOAK_S - SOAK_WINDOW_S:SOAK_S]
    early_hz, late_hz = sum(early) / len(early), sum(late) / len(late)
    print(f'\nsoak: {SOAK_S} s of sim time; JointState {early_hz:.3f} Hz (sim '
          f'{SOAK_BASELINE_S}-{SOAK_BASELINE_S + SOAK_WINDOW_S} s) vs {late_hz:.3f} Hz (last '
          f'{SOAK_WINDOW_S} s); sim speed '
          f'{early_speed:.1f}x -> {late_speed:.1f}x wall; RSS {rss_baseline:.1f} MB at '
          f'{SOAK_BASELINE_S} s -> {rss_end:.1f} MB, growth {rss_end - rss_baseline:+.2f} MB; '
          f'non-finite JointStates {sim.non_finite}')
    assert sim.non_finite == 0
    assert rss_end - rss_baseline < SOAK_RSS_GROWTH_MB
    assert early_hz == pytest.approx(PUBLISH_RATE_HZ, rel=SOAK_RATE_TOLERANCE)
    assert late_hz == pytest.approx(early_hz, rel=SOAK_RATE_TOLERANCE)
