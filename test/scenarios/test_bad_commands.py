"""Bad commands at run time: rejected or clamped with a throttled warning; the sim goes on.

NaN, +-Inf and huge finite values (1e308) are ignored (the setpoint does not
move); a merely out-of-range value is clamped to the limit; an array command
of the wrong length or with a bad element is rejected whole.  The node runs
in-process at real_time_factor 0.
"""

from __future__ import annotations

import math
import time

import pytest
from node_harness import PROBE_QUEUE, sim_node
from rcl_interfaces.msg import Log
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray

PAN = 'joint1_position_controller'
PAN_LIMIT = 3.14
PAN_SPEED = 0.1  # rad/s, the URDF velocity limit
TILT_START = -1.570796
GROUP = 'group'
GROUP_YAML = f'''ex_urdf_pan_tilt:
  joint_state_controller: {{type: joint_state_controller/JointStateController, publish_rate: 50}}
  {GROUP}:
    type: position_controllers/JointGroupPositionController
    joints: [pan_joint, tilt_joint]
'''
WARNING_THROTTLE_S = 1.0
FLOOD_COUNT = 100


@pytest.fixture
def seed_sim():
    with sim_node() as sim:
        yield sim


@pytest.fixture
def group_sim(tmp_path):
    config = tmp_path / 'group.yaml'
    config.write_text(GROUP_YAML)
    with sim_node(controllers_file=str(config)) as sim:
        yield sim


@pytest.fixture
def log(seed_sim) -> list[Log]:
    """What the probe hears on /rosout."""
    return seed_sim.collect(Log, '/rosout', PROBE_QUEUE)


def _all_finite(states: list[JointState]) -> bool:
    return all(math.isfinite(value) for message in states
               for value in (*message.position, *message.velocity, *message.effort))


@pytest.mark.parametrize('bad', [math.nan, math.inf, -math.inf, 1e308, -1e308,
                                 1.7976931348623157e308])
def test_a_non_finite_or_huge_command_leaves_the_setpoint_and_the_joint_alone(seed_sim, log, bad):
    start = seed_sim.send_paused(PAN, Float64(data=0.2))
    seed_sim.run_for(0.5)
    seed_sim.node.set_paused(True)
    setpoint = seed_sim.setpoints(PAN)
    seed_sim.command(PAN, Float64(data=bad))
    assert seed_sim.setpoints(PAN) == setpoint
    seed_sim.node.set_paused(False)
    seed_sim.run_for(1.0)
    # Still ramping toward 0.2 at the velocity limit, not toward the bad value.
    ramp_s = seed_sim.node.simulation.time - start
    assert seed_sim.setpoints(PAN)[0] == pytest.approx(min(0.2, PAN_SPEED * ramp_s), abs=1e-6)
    assert _all_finite(seed_sim.states)
    assert 'ignored' in _warnings(log)[0].msg


def test_an_out_of_range_command_is_clamped_to_the_limit(seed_sim, log):
    start = seed_sim.send_paused(PAN, Float64(data=10.0))
    seed_sim.run_for(2.0)
    setpoint, = seed_sim.setpoints(PAN)
    # Heading for the upper limit, at the velocity limit.
    assert setpoint == pytest.approx(PAN_SPEED * (seed_sim.node.simulation.time - start),
                                     abs=1e-6)
    assert seed_sim.states and _all_finite(seed_sim.states)
    assert 'clamped' in _warnings(log)[0].msg


@pytest.mark.parametrize('bad', [
    pytest.param([], id='empty'),
    pytest.param([0.5], id='too short'),
    pytest.param([0.5, -2.0, 1.0], id='too long'),
    pytest.param([math.nan, -2.0], id='NaN element'),
    pytest.param([0.5, -math.inf], id='infinite element'),
    pytest.param([1e308, -2.0], id='huge element'),
])
def test_a_bad_array_command_is_rejected_whole(group_sim, bad):
    before = group_sim.setpoints(GROUP)
    group_sim.command(GROUP, Float64MultiArray(data=bad))
    group_sim.run_for(0.5)
    assert group_sim.setpoints(GROUP) == pytest.approx(before)
    assert before == pytest.approx([0.0, TILT_START])
    # A good command afterwards is taken.
    group_sim.command(GROUP, Float64MultiArray(data=[0.5, -2.0]))
    group_sim.run_for(0.5)
    pan, tilt = group_sim.setpoints(GROUP)
    assert pan > 0.0 and tilt < TILT_START
    assert _all_finite(group_sim.states)


def _warnings(log: list[Log]) -> list[Log]:
    return [entry for entry in log
            if entry.name == 'sim_node' and entry.level == Log.WARN and PAN in entry.msg]


def test_a_stream_of_bad_commands_warns_at_most_once_per_second(seed_sim, log):
    start = time.monotonic()
    for _ in range(FLOOD_COUNT):
        seed_sim.command(PAN, Float64(data=math.nan))
    elapsed = time.monotonic() - start
    seed_sim.drain()
    warnings = _warnings(log)
    assert warnings, 'no warning at all'
    assert 'ignored command nan' in warnings[0].msg
    assert len(warnings) <= 1 + int(elapsed / WARNING_THROTTLE_S)
    assert seed_sim.node.commands_received[PAN] == FLOOD_COUNT
