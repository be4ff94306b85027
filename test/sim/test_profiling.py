"""PyBullet's own cost per step, on the physics a simulation runs (the benchmark's raw figure)."""

import pytest

from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.sim.physics import Physics
from pan_tilt_sim.sim.profiling import WINDOW_STEPS, pybullet_step_cost
from pan_tilt_sim.tools.bench import load_model, recorded_efforts


@pytest.fixture
def recorded():
    """The efforts the pan/tilt's controllers applied over 3 s, and the state they led to."""
    share = package_share()
    model = load_model(share / DEFAULT_DESCRIPTION, share / DEFAULT_CONTROLLERS)
    with make_simulation(model.description_file, model.controllers_file, 0.001) as simulation:
        efforts = recorded_efforts(simulation, model, 3.0)
        yield simulation, efforts, simulation.physics.read_states()


def test_replaying_the_efforts_retraces_the_node_s_motion_exactly(recorded):
    simulation, efforts, final = recorded
    assert len(efforts) == 3000
    assert max(abs(e) for step in efforts for e in step) > 1.0  # the joints were driven
    with Physics(simulation.description, 0.001) as replay:
        step_us, calls_us = pybullet_step_cost(replay, efforts)
        assert replay.read_states() == final  # the same physics, bit for bit
    assert 0.0 < step_us < calls_us


def test_a_recording_shorter_than_a_window_cannot_be_timed(recorded):
    simulation, efforts, _ = recorded
    with Physics(simulation.description, 0.001) as replay, pytest.raises(
            ValueError, match='at least'):
        pybullet_step_cost(replay, efforts[:2 * WINDOW_STEPS - 1])
