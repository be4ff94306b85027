"""The URDF's Gazebo plugins in the simulation loop: they free the base and run every step.

And a free base that tips over or falls below the ground warns, and keeps simulating.
"""

from __future__ import annotations

import logging

import pytest
from mobile_fixtures import (
    GZ_DIFF_DRIVE,
    PLANAR_MOVE,
    ROS2_DIFF_DRIVE,
    WHEEL_RADIUS,
    plugin_rover_urdf,
)

from pan_tilt_sim.controllers.framework.surface import StampedTwist
from pan_tilt_sim.plugins import registry
from pan_tilt_sim.sim.bullet import pybullet
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


def test_a_plugin_recognised_but_not_simulated_is_one_warning_and_the_rest_runs(
        tmp_path, monkeypatch):
    monkeypatch.setitem(registry.UNSIMULATED, 'gazebo_ros_bumper', 'contacts are not published')
    path = tmp_path / 'rover.urdf'
    path.write_text(plugin_rover_urdf(
        ROS2_DIFF_DRIVE + '<plugin name="bump" filename="libgazebo_ros_bumper.so"/>'),
        encoding='utf-8')
    collector = Collector()
    logger = logging.getLogger('test_unsimulated')
    logger.addHandler(collector)
    with make_simulation(str(path), None, DT, fixed_base=None, logger=logger) as simulation:
        said = [line for line in collector.lines if "'bump'" in line]
        assert len(said) == 1
        assert said[0].endswith("rover.urdf: plugin 'bump' (libgazebo_ros_bumper.so) skipped: "
                                'contacts are not published')
        assert [unit.name for unit in simulation.plugins] == [
            'diff_drive', 'joint_states', 'ground_truth']


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


class Collector(logging.Handler):
    """The warnings a simulation logs."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.lines.append(record.getMessage())


def _urdf(tmp_path, plugin: str) -> str:
    path = tmp_path / 'rover.urdf'
    path.write_text(plugin_rover_urdf(plugin), encoding='utf-8')
    return str(path)


def _place(simulation, position, rotation=(0.0, 0.0, 0.0, 1.0)) -> None:
    physics = simulation.physics
    pybullet.resetBasePositionAndOrientation(physics.body_id, position, rotation,
                                             physicsClientId=physics.client_id)


def test_planar_move_sets_the_base_velocity_in_the_step_and_frees_the_base(tmp_path):
    # Every step (update_rate 0): between updates the wheels' friction would brake the turn.
    every_step = PLANAR_MOVE.replace('<update_rate>100<', '<update_rate>0<')
    with make_simulation(_urdf(tmp_path, every_step), None, DT, fixed_base=None) as simulation:
        assert not simulation.physics.fixed_base
        mover = simulation.plugins[0]
        mover.set_command(StampedTwist(0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.5)))
        simulation.advance(1000)
        (_, _, heading), (_, _, yaw_rate) = simulation.base_state()
        assert heading == pytest.approx(0.5, abs=0.05)  # 1 s at 0.5 rad/s
        assert yaw_rate == pytest.approx(0.5, abs=0.05)  # measured after a step of friction


def test_gz_diff_drive_frees_the_base_and_drives_it(tmp_path):
    with make_simulation(_urdf(tmp_path, GZ_DIFF_DRIVE), None, DT, fixed_base=None) as simulation:
        assert not simulation.physics.fixed_base
        simulation.plugins[0].set_command(StampedTwist(0.0, (0.2, 0.0, 0.0), (0.0, 0.0, 0.0)))
        simulation.advance(1000)
        (x, _, _), (forward, _, _) = simulation.base_state()
        assert x == pytest.approx(0.2 - 0.02, abs=0.02)  # 1 s at 0.2 m/s, less the ramp
        assert forward == pytest.approx(0.2, abs=0.01)


def test_a_tipped_over_base_warns_naming_the_robot_throttled_and_keeps_stepping(tmp_path):
    collector = Collector()
    logger = logging.getLogger('test_tipped')
    logger.addHandler(collector)
    with make_simulation(_urdf(tmp_path, ROS2_DIFF_DRIVE), None, DT, fixed_base=None,
                         logger=logger) as simulation:
        simulation.advance(10)
        assert collector.lines == []
        _place(simulation, (0.0, 0.0, 0.3), (1.0, 0.0, 0.0, 0.0))  # upside down
        for _ in range(100):
            simulation.advance(10)
        assert simulation.steps == 1010
        tipped = [line for line in collector.lines if 'tipped over' in line]
        assert len(tipped) == 1  # once per second of wall time at most
        assert "robot 'rover' has tipped over: its base is tilted 180 deg" in tipped[0]
        assert 'the simulation goes on' in tipped[0]


def test_a_base_below_the_ground_plane_warns_that_it_fell(tmp_path):
    collector = Collector()
    logger = logging.getLogger('test_fell')
    logger.addHandler(collector)
    with make_simulation(_urdf(tmp_path, ROS2_DIFF_DRIVE), None, DT, fixed_base=None,
                         logger=logger) as simulation:
        _place(simulation, (0.0, 0.0, -5.0))
        simulation.advance(10)
        assert any("robot 'rover' fell below the ground plane" in line
                   for line in collector.lines), collector.lines
