"""The URDF's Gazebo plugins in the simulation loop: they free the base and run every step."""

from __future__ import annotations

import pytest
from mobile_fixtures import WHEEL_RADIUS, plugin_rover_urdf

from pan_tilt_sim.controllers.surface import StampedTwist
from pan_tilt_sim.sim.engine import make_simulation

DT = 0.001


@pytest.fixture
def rover_file(tmp_path):
    path = tmp_path / 'rover.urdf'
    path.write_text(plugin_rover_urdf(), encoding='utf-8')
    return str(path)


def test_a_drive_plugin_frees_the_base_with_fixed_base_auto_and_no_controllers_file(rover_file):
    with make_simulation(rover_file, None, DT, fixed_base=None) as simulation:
        assert not simulation.physics.fixed_base
        assert [unit.name for unit in simulation.plugins] == [
            'diff_drive', 'joint_states', 'ground_truth']
        assert simulation.controllers == []
    with make_simulation(rover_file, None, DT, fixed_base=True) as simulation:
        assert simulation.physics.fixed_base


def test_the_drive_moves_the_base_and_keeps_driving_after_time_is_reset(rover_file):
    with make_simulation(rover_file, None, DT, fixed_base=None) as simulation:
        drive = simulation.plugins[0]
        drive.set_command(StampedTwist(0.0, (0.2, 0.0, 0.0), (0.0, 0.0, 0.0)))
        simulation.advance(1000)
        (x, _, _), (forward, _, _) = simulation.base_state()
        assert x == pytest.approx(0.2 - 0.02, abs=0.02)  # 1 s at 0.2 m/s, less the ramp
        assert forward == pytest.approx(0.2, abs=0.01)
        simulation.reset_time()
        drive.set_command(StampedTwist(0.0, (0.1, 0.0, 0.0), (0.0, 0.0, 0.0)))
        simulation.advance(500)
        target = simulation.handles['left_wheel_joint'].velocity_target
        assert target * WHEEL_RADIUS == pytest.approx(0.1, abs=1e-6)
