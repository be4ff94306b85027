"""ros_gz_sim's create stand-in as a program: its arguments, its exit codes, the robot in.

The simulation runs in-process (a world-only SimNode on a harness, spun while the
program runs); create runs as ``python -m pan_tilt_sim.tools.stand_ins create``.
"""

from __future__ import annotations

import importlib.util
import math

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


def test_help_prints_the_usage_and_exits_1_as_gflags_does():
    code, output = finish(None, run('--help'))
    assert code == 1 and 'Usage: create -world [arg]' in output and '-allow_renaming' in output


def test_it_exits_0_once_the_robot_is_in_and_a_taken_name_fails_unless_renaming(tmp_path):
    urdf = tmp_path / 'rover.urdf'
    urdf.write_text(plugin_rover_urdf())
    with world_only() as (harness, node):
        code, output = finish(harness, run('-file', str(urdf), '-name', 'rover',
                                             '-x', '1.5', '-y', '-2', '-Y', '1.0',
                                             '-world', 'default'))
        assert code == 0, output
        assert node.simulation is not None and node.simulation.description.name == 'rover'
        (x, y, heading), _twist = node.simulation.base_state()
        assert (x, y, heading) == pytest.approx((1.5, -2.0, 1.0), abs=1e-3)
        # One warning for the argument not honoured.
        assert output.count("-world 'default' is not honoured") == 1
        code, output = finish(harness, run('-string', urdf.read_text(), '-name', 'rover'))
        assert code == 1 and 'Entity creation failed' in output and 'rover' in output
        code, output = finish(harness, run('-string', urdf.read_text(), '-name', 'rover',
                                             '-allow_renaming', 'true'))
        assert code == 0, output


def roll_pitch_yaw(q) -> tuple[float, float, float]:
    """(roll, pitch, yaw) of a geometry_msgs Quaternion, fixed axes (rad)."""
    return (math.atan2(2 * (q.w * q.x + q.y * q.z), 1 - 2 * (q.x * q.x + q.y * q.y)),
            math.asin(2 * (q.w * q.y - q.z * q.x)),
            math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z)))


def test_roll_and_pitch_tilt_the_robot_as_gz_poses_it(tmp_path):
    # Welded (fixed_base), the root link frame is exactly at the pose create was given.
    from simulation_interfaces.srv import GetEntityState

    urdf = tmp_path / 'rover.urdf'
    urdf.write_text(plugin_rover_urdf())
    with world_only(fixed_base='true') as (harness, node):
        code, output = finish(harness, run('-file', str(urdf), '-name', 'rover', '-x', '1',
                                             '-z', '0.5', '-R', '0.1', '-P', '0.3', '-Y', '0.2'))
        assert code == 0, output
        assert 'not honoured' not in output
        state = harness.call(GetEntityState, '/sim_node/get_entity_state',
                             GetEntityState.Request(entity='rover')).state
    position = state.pose.position
    assert (position.x, position.y, position.z) == pytest.approx((1.0, 0.0, 0.5), abs=1e-6)
    assert roll_pitch_yaw(state.pose.orientation) == pytest.approx((0.1, 0.3, 0.2), abs=1e-6)
