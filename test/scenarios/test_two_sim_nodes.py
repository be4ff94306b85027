"""Two sim_node processes with different namespaces on one domain do not cross-talk.

Each runs the pan/tilt example under its own node namespace (``-r __ns:=/left``,
``/right``), so its topics and services are under that namespace.  /clock is
absolute by ROS convention, as with two Gazebos: each process remaps it
(``-r /clock:=/left/clock``), which the test does and checks.
"""

from __future__ import annotations

import signal

import pytest
import sim_process
from node_harness import PROBE_QUEUE, NodeHarness, stamp_s
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64
from std_srvs.srv import Empty

SIDES = ('left', 'right')
STARTUP_BUDGET_S = 30.0
MOVE_BUDGET_S = 10.0
STOP_BUDGET_S = 2.0
MOVED_RAD = 0.01
HELD_WALL_S = 0.5


@pytest.fixture
def two_sims():
    processes = {side: sim_process.start('-r', f'__ns:=/{side}',
                                         '-r', f'/clock:=/{side}/clock',
                                         '-p', 'real_time_factor:=1.0')
                 for side in SIDES}
    harness = NodeHarness()
    try:
        yield harness
    finally:
        harness.close()
        for process in processes.values():
            process.send_signal(signal.SIGINT)  # both at once
        for side, process in processes.items():
            stopped, err = sim_process.stop(process, STOP_BUDGET_S, interrupt=False)
            assert stopped, f'{side} did not stop within {STOP_BUDGET_S} s of SIGINT: {err}'
            assert process.returncode == 0, f'{side}: {err}'


def test_two_namespaced_sims_keep_to_their_own_topics_services_and_clocks(two_sims):
    harness, probe = two_sims, two_sims.probe
    states = {side: [] for side in SIDES}
    clocks = {side: [] for side in SIDES}
    global_clock = []
    for side in SIDES:
        probe.create_subscription(JointState, f'/{side}/joint_states', states[side].append,
                                  PROBE_QUEUE)
        probe.create_subscription(Clock, f'/{side}/clock', clocks[side].append, PROBE_QUEUE)
    probe.create_subscription(Clock, '/clock', global_clock.append, PROBE_QUEUE)
    left_pan = probe.create_publisher(Float64, '/left/joint1_position_controller/command', 10)
    assert harness.spin_until(
        lambda: all(states.values()) and all(clocks.values())
        and left_pan.get_subscription_count() == 1, STARTUP_BUDGET_S), 'sims did not come up'

    left_pan.publish(Float64(data=1.0))
    assert harness.spin_until(lambda: states['left'][-1].position[0] > MOVED_RAD, MOVE_BUDGET_S)
    assert all(message.position[0] == pytest.approx(0.0, abs=1e-6)
               for message in states['right'])

    # Pausing the left sim stops its clock only.
    harness.call(Empty, '/left/pause_physics', budget_s=STARTUP_BUDGET_S)
    harness.spin_for(HELD_WALL_S)
    left_held, right_before = stamp_s(clocks['left'][-1]), stamp_s(clocks['right'][-1])
    harness.spin_for(HELD_WALL_S)
    assert stamp_s(clocks['left'][-1]) == left_held
    assert stamp_s(clocks['right'][-1]) > right_before

    # Resetting the left sim sends its clock back to 0, not the right one.
    right_count = len(clocks['right'])
    harness.call(Empty, '/left/reset_simulation', budget_s=STARTUP_BUDGET_S)
    assert harness.spin_until(lambda: stamp_s(clocks['left'][-1]) == 0.0)
    assert harness.spin_until(lambda: len(clocks['right']) > right_count + 10, STARTUP_BUDGET_S)
    right_times = [stamp_s(message) for message in clocks['right']]
    assert right_times == sorted(right_times)
    assert global_clock == []
