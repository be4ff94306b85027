"""PyBullet's own cost per step, on the physics a simulation runs (the benchmark's raw figure)."""

import os

import pytest

from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.sim import compiled_step
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.sim.physics import Physics
from pan_tilt_sim.sim.profiling import (
    WINDOW_STEPS,
    CommandRecorder,
    pybullet_step_cost,
    replay_step_cost,
)
from pan_tilt_sim.tools.bench import load_model, recorded_efforts

STEP_SIMULATION = pybullet.stepSimulation
ENVIRONMENT_BEFORE = os.environ.get(compiled_step.ENVIRONMENT_SWITCH)


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


def test_replaying_the_recorded_commands_from_the_saved_state_retraces_the_run():
    share = package_share()
    with CommandRecorder() as recorder, make_simulation(
            str(share / DEFAULT_DESCRIPTION), str(share / DEFAULT_CONTROLLERS),
            0.001) as simulation:
        assert not simulation.physics.compiled_step  # every call through the module
        simulation.controller('joint1_position_controller').set_command(1.0)
        simulation.controller('joint2_position_controller').set_command(-1.0)
        simulation.advance(100)
        client = simulation.physics.client_id
        saved = pybullet.saveState(physicsClientId=client)
        recorder.start()
        simulation.advance(1500)
        recorder.stop()
        final = simulation.physics.read_states()
        assert len(recorder.steps) == 1500
        assert all(recorder.steps), 'every step sent the joints their efforts'
        pybullet.restoreState(stateId=saved, physicsClientId=client)
        step_us = replay_step_cost(client, recorder.steps)
        replayed = simulation.physics.read_states()
    assert step_us > 0.0
    for got, want in zip(replayed, final, strict=True):
        assert got[:2] == pytest.approx(want[:2], abs=1e-9)
    # The recorder leaves PyBullet and the compiled step as they were.
    assert pybullet.stepSimulation is STEP_SIMULATION
    assert os.environ.get(compiled_step.ENVIRONMENT_SWITCH) == ENVIRONMENT_BEFORE


def test_nothing_recorded_cannot_be_replayed():
    with pytest.raises(ValueError, match='no steps'):
        replay_step_cost(0, [])
