"""gazebo_ros's spawn_entity.py stand-in as a program: -wait, -b (bond) and -gazebo_namespace.

The simulation runs in-process (a world-only SimNode on a harness, spun while the
program runs); spawn_entity.py runs as ``python -m pan_tilt_sim.tools.stand_ins
spawn_entity.py``.
"""

from __future__ import annotations

import importlib.util
import signal
import subprocess
import threading

import pytest
from entity_fixtures import write_box
from mobile_fixtures import plugin_rover_urdf
from node_harness import NodeHarness
from stand_in_fixtures import EXIT_BUDGET_S, finish, spawn, start, world_only

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('simulation_interfaces') is None,
    reason='simulation_interfaces is not installed')

GET_ENTITIES = '/sim_node/get_entities'
BUDGET_S = 30.0
QUIET_S = 2.0  # how long a spawn that must not happen is watched for (4 of -wait's polls)


def run(*arguments: str) -> subprocess.Popen:
    """Start spawn_entity.py with ``arguments``."""
    return start('spawn_entity.py', *arguments)


def entities(harness: NodeHarness, service: str = GET_ENTITIES) -> list[str]:
    """The simulation's entity names (GetEntities)."""
    from simulation_interfaces.srv import GetEntities

    return list(harness.call(GetEntities, service).entities)


def write_rover(folder) -> str:
    """Write a rover URDF (a first robot: it has joints); return its path."""
    path = folder / 'rover.urdf'
    path.write_text(plugin_rover_urdf())
    return str(path)


def asks_for_entities(harness: NodeHarness) -> bool:
    """Whether spawn_entity.py's node has a GetEntities client."""
    if ('spawn_entity', '/') not in harness.probe.get_node_names_and_namespaces():
        return False
    return GET_ENTITIES in dict(
        harness.probe.get_client_names_and_types_by_node('spawn_entity', '/'))


class Output:
    """The program's output lines, read as they come."""

    def __init__(self, process: subprocess.Popen) -> None:
        self.lines: list[str] = []
        self._reader = threading.Thread(target=self._read, args=(process,), daemon=True)
        self._reader.start()

    def _read(self, process: subprocess.Popen) -> None:
        for line in process.stdout:
            self.lines.append(line)

    def has(self, text: str) -> bool:
        return any(text in line for line in self.lines)

    def text(self) -> str:
        self._reader.join(EXIT_BUDGET_S)
        return ''.join(self.lines)


def test_wait_spawns_only_once_the_named_entity_is_in(tmp_path):
    box = write_box(tmp_path)
    with world_only() as (harness, node):
        process = run('-entity', 'box', '-file', str(box), '-wait', 'rover')
        try:
            # It asks the simulation for its entities; nothing comes while rover is missing
            # (the world is empty until a first robot is spawned).
            assert harness.spin_until(lambda: asks_for_entities(harness), BUDGET_S), (
                'spawn_entity.py never asked for the entities')
            harness.spin_for(QUIET_S)
            assert node.simulation is None and process.poll() is None
            assert spawn(harness, name='rover',
                         resource_string=plugin_rover_urdf()).result.result == 1
        except BaseException:
            process.kill()
            raise
        finally:
            code, output = finish(harness, process)
        assert code == 0, output
        assert 'Waiting for entity rover before proceeding.' in output
        assert {'rover', 'box'} <= set(entities(harness))


@pytest.mark.parametrize('stop', [signal.SIGINT, signal.SIGTERM], ids=['SIGINT', 'SIGTERM'])
def test_with_b_it_stays_until_stopped_then_deletes_what_it_spawned(tmp_path, stop):
    rover = write_rover(tmp_path)
    with world_only() as (harness, node):
        process = run('-entity', 'rover', '-file', str(rover), '-b')
        output = Output(process)
        try:
            assert harness.spin_until(
                lambda: output.has('Waiting for shutdown to delete entity [rover]')
                or process.poll() is not None, BUDGET_S), 'spawn_entity.py never got there'
            assert process.poll() is None, output.text()  # bonded: it stays
            assert 'rover' in entities(harness)
        finally:
            process.send_signal(stop)
            assert harness.spin_until(lambda: process.poll() is not None, EXIT_BUDGET_S)
        text = output.text()
        assert process.returncode == 0, text
        assert 'Deleting entity [rover]' in text
        assert not node.simulation.has_robot and 'rover' not in entities(harness), text


def test_gazebo_namespace_names_the_simulation_in_that_namespace(tmp_path):
    rover = write_rover(tmp_path)
    with world_only(namespace='/world1') as (harness, node):
        code, output = finish(harness, run('-entity', 'rover', '-file', rover,
                                           '-gazebo_namespace', '/elsewhere', '-timeout', '2'))
        assert code == 1, output
        assert 'Service /elsewhere/spawn_entity unavailable' in output
        assert node.simulation is None  # nothing spawned
        code, output = finish(harness, run('-entity', 'rover', '-file', rover,
                                           '-gazebo_namespace', '/world1'))
        assert code == 0, output
        assert 'not honoured' not in output
        assert 'rover' in entities(harness, '/world1' + GET_ENTITIES)
