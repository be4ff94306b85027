"""ros_gz_sim's create stand-in as a program: its arguments, its exit codes, the robot in.

The simulation runs in-process (a world-only SimNode on a harness, spun while the
program runs); create runs as ``python -m pan_tilt_sim.tools.stand_ins create``.
"""

from __future__ import annotations

import importlib.util

import pytest
from mobile_fixtures import plugin_rover_urdf
from stand_in_fixtures import finish, start, world_only

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('simulation_interfaces') is None,
    reason='simulation_interfaces is not installed')



def run(*arguments: str):
    """Start create with ``arguments``."""
    return start('create', *arguments)


def test_with_no_description_it_says_so_and_exits_255_as_create_does():
    code, output = finish(None, run())
    assert code == 255 and 'Must specify either file, string or topic' in output
    code, output = finish(None, run('-name', 'a'))
    assert code == 255 and 'Must specify either -file, -param, -string or -topic' in output


def test_a_flag_gflags_does_not_know_exits_1_with_its_line():
    code, output = finish(None, run('-colour', 'red'))
    assert (code, output.strip()) == (1, "ERROR: unknown command line flag 'colour'")


def test_it_exits_0_once_the_robot_is_in_and_a_taken_name_fails_unless_renaming(tmp_path):
    urdf = tmp_path / 'rover.urdf'
    urdf.write_text(plugin_rover_urdf())
    with world_only() as (harness, node):
        code, output = finish(harness, run('-file', str(urdf), '-name', 'rover',
                                             '-x', '1.5', '-y', '-2', '-Y', '1.0', '-R', '0.2',
                                             '-world', 'default'))
        assert code == 0, output
        assert node.simulation is not None and node.simulation.description.name == 'rover'
        (x, y, heading), _twist = node.simulation.base_state()
        assert (x, y, heading) == pytest.approx((1.5, -2.0, 1.0), abs=1e-3)
        # One warning for each argument not honoured.
        assert output.count("-world 'default' is not honoured") == 1
        assert output.count('-R 0.2 -P 0.0: roll and pitch are not honoured') == 1
        code, output = finish(harness, run('-string', urdf.read_text(), '-name', 'rover'))
        assert code == 1 and 'Entity creation failed' in output and 'rover' in output
        code, output = finish(harness, run('-string', urdf.read_text(), '-name', 'rover',
                                             '-allow_renaming', 'true'))
        assert code == 0, output
