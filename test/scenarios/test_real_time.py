"""sim_node keeps pace with wall time: at real_time_factor 1, and when the factor changes live.

These run in-process like the other node tests, but at factor > 0, so they
measure sim time against wall time (within +-20 %, over more than a second).
"""

import time

import pytest
from node_harness import PROBE_QUEUE, sim_node, stamp_s
from rosgraph_msgs.msg import Clock

PACE_TOLERANCE = 0.2
MEASURE_WALL_S = 1.5
FAST_AT_LEAST = 3.0  # at factor 0 the pan/tilt runs ~100x real time; 3x is surely not paced


def measured_factor(harness, wall_s: float = MEASURE_WALL_S) -> float:
    """Return sim seconds per wall second over ``wall_s`` of wall time, the executor spinning."""
    sim_start, wall_start = harness.simulation.time, time.monotonic()
    harness.spin_for(wall_s)
    return (harness.simulation.time - sim_start) / (time.monotonic() - wall_start)


def test_at_real_time_factor_1_sim_time_follows_wall_time():
    with sim_node(real_time_factor=1.0) as harness:
        assert harness.spin_until(lambda: harness.simulation.time > 0.05), 'sim did not start'
        factor = measured_factor(harness)
    assert factor == pytest.approx(1.0, rel=PACE_TOLERANCE)


def test_at_real_time_factor_1_every_10_ms_stamp_reaches_a_clock_subscriber():
    with sim_node(real_time_factor=1.0) as harness:
        clock = harness.collect(Clock, '/clock', PROBE_QUEUE)
        harness.wait_for_subscribers('/clock')
        first = len(clock)
        assert harness.spin_until(lambda: len(clock) >= first + 100, 5.0)
        times = [stamp_s(m) for m in clock[first:]]
    assert all(b - a == pytest.approx(0.01, abs=1e-9)
               for a, b in zip(times, times[1:], strict=False)), times


def test_a_live_change_of_real_time_factor_sets_the_pace_0_then_1_then_half():
    with sim_node(real_time_factor=0.0) as harness:
        assert harness.spin_until(lambda: harness.simulation.time > 0.05), 'sim did not start'
        fast = measured_factor(harness, 0.5)
        paced = []
        for factor in (1.0, 0.5):
            result, = harness.set_parameters(real_time_factor=factor)
            assert result.successful, result.reason
            paced.append(measured_factor(harness))
    assert fast > FAST_AT_LEAST
    assert paced[0] == pytest.approx(1.0, rel=PACE_TOLERANCE)
    assert paced[1] == pytest.approx(0.5, rel=PACE_TOLERANCE)
