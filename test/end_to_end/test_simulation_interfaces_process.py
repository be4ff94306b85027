"""End to end: the sim_node program controlled through simulation_interfaces, to QUITTING.

The program steps its physics from a thread of its own and runs callbacks in
turns with it (ros/physics_thread.py); the stepping requests, the action and
QUITTING must work there as in-process.
"""

from __future__ import annotations

import contextlib
import subprocess
import sys
from collections.abc import Iterator

import pytest
import sim_process
from entity_fixtures import UNSPAWNABLE, box_urdf
from node_harness import PROBE_QUEUE, NodeHarness, stamp_s
from rosgraph_msgs.msg import Clock
from sim_interfaces_client import OK, SimInterfaces, State, action, pose, position, srv

STARTUP_BUDGET_S = 20.0
EXIT_BUDGET_S = 5.0
Spawn = srv.SpawnEntity.Response


@contextlib.contextmanager
def paused_program() -> Iterator[tuple[subprocess.Popen, NodeHarness]]:
    """Start sim_node paused on the ground; yield it and a probe; kill it if it still runs."""
    process = sim_process.start('-p', 'paused:=true', '-p', 'world:=ground')
    harness = NodeHarness()
    try:
        yield process, harness
    finally:
        harness.close()
        if process.poll() is None:
            process.kill()
            process.communicate()


def quits(client: SimInterfaces, process: subprocess.Popen) -> str:
    """Ask for QUITTING; check the program ends with code 0 and no traceback; return stderr."""
    assert client.set_state(State.STATE_QUITTING).result == OK
    try:
        _stdout, stderr = process.communicate(timeout=EXIT_BUDGET_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f'sim_node did not quit within {EXIT_BUDGET_S} s of QUITTING')
    assert process.returncode == 0, stderr
    assert 'Traceback' not in stderr
    return stderr


def test_a_paused_program_steps_spawns_and_quits_with_exit_code_0():
    with paused_program() as (process, harness):
        clock = []
        harness.probe.create_subscription(Clock, '/clock', clock.append, PROBE_QUEUE)
        client = SimInterfaces(harness)
        assert client.state() == State.STATE_STOPPED
        assert client.spawn('box', resource_string=box_urdf(),
                            at=pose(1.0, 0.0, 0.3)).result.result == OK
        assert client.step(500).result == OK
        assert harness.spin_until(lambda: clock and stamp_s(clock[-1]) >= 0.5)
        assert stamp_s(clock[-1]) == pytest.approx(0.5)
        assert position(client.entity_state('box'))[2] == pytest.approx(0.1, abs=2e-3)

        goal = client.action_client().send_goal_async(action.SimulateSteps.Goal(steps=2000))
        assert harness.spin_until(goal.done)
        result = goal.result().get_result_async()
        assert harness.spin_until(result.done)
        assert result.result().result.result.result == OK
        assert harness.spin_until(lambda: stamp_s(clock[-1]) >= 2.5)
        assert client.state() == State.STATE_PAUSED

        assert 'QUITTING' in quits(client, process)


def test_the_program_refuses_objects_pybullet_would_crash_on_and_goes_on():
    with paused_program() as (process, harness):
        client = SimInterfaces(harness)
        assert client.state() == State.STATE_STOPPED
        for case, (urdf, expected) in UNSPAWNABLE.items():
            refused = client.spawn('thing', resource_string=urdf, at=pose(1.0, 0.0, 0.3))
            assert refused.result.result == Spawn.RESOURCE_PARSE_ERROR, case
            assert expected in refused.result.error_message, case
            assert process.poll() is None, case
        assert client.spawn('box', resource_string=box_urdf(),
                            at=pose(1.0, 0.0, 0.3)).result.result == OK
        assert client.step(100).result == OK
        quits(client, process)


def test_a_bad_world_file_ends_the_program_with_one_line_and_exit_code_2(tmp_path):
    world = tmp_path / 'world.yaml'
    world.write_text('entities:\n  - name: box\n    pose: {position: [0, 0]}\n')
    result = sim_process.run('-p', f'world:={world}')
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert lines[-1] == (f'sim_node: error: {world}: entities[0]: give a uri, a '
                         'resource_string or a shape')
    assert 'Traceback' not in result.stderr


def test_the_spawn_example_drops_the_shipped_box_onto_the_ground(repo_root):
    process = sim_process.start('-p', 'paused:=true', start_new_session=True)
    try:
        result = subprocess.run(
            [sys.executable, str(repo_root / 'examples' / 'spawn_and_step.py'), '--z', '0.3',
             '--steps', '1000', '--timeout', str(STARTUP_BUDGET_S)],
            capture_output=True, text=True, env=sim_process.environment(),
            timeout=STARTUP_BUDGET_S * 4, check=False)
    finally:
        sim_process.stop(process, EXIT_BUDGET_S)
    assert result.returncode == 0, result.stdout + result.stderr
    assert 'simulation STOPPED' in result.stdout
    # The shipped box is a 10 cm cube: it rests with its centre 5 cm up.
    line = result.stdout.splitlines()[-1]
    assert line.startswith("after 1000 steps (sim time 1.000 s): 'box' at ("), line
    x, y, z = (float(value) for value in line.rpartition('(')[2].rstrip(')').split(','))
    assert (x, y, z) == pytest.approx((-1.2, 0.0, 0.05), abs=3e-3)
