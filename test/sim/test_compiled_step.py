"""The compiled step: PyBullet's per-step calls from C, the same commands, the same results.

That both ways give the same JointStates to the last bit is
test_engine_bit_identity's business (it runs every scenario both ways);
here: the test install has it, the switch turns it off, it was built with
step_law's row layout and one built with another is refused, each
simulation's steps go to its own client, and a step after the simulation is
gone is an error, not a crash.
"""

import gc
import importlib
from types import SimpleNamespace

import pytest

from pan_tilt_sim.controllers.toolbox import step_law
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.sim import _compiled_step, compiled_step
from pan_tilt_sim.sim.physics import Physics, pybullet

EFFORTS = ([40.0, -10.0], [-25.0, 30.0])


@pytest.fixture
def description(repo_root):
    return load_description(repo_root / 'urdf' / 'pan_tilt.xacro')


# What a malformed number may do to the C reader; PyBullet's own module (the fallback) crashes.
needs_the_compiled_step = pytest.mark.skipif(
    compiled_step.unavailable_reason() != '',
    reason='the compiled step is not in use, and PyBullet itself does not survive such numbers')


def effort_stepper(physics: Physics):
    return physics.effort_stepper([physics.joint_index(joint.name) for joint in physics.joints])


def test_the_test_install_steps_from_c(description, monkeypatch):
    # .ci/run installs with a compiler: a silent fallback would hide a broken build.
    monkeypatch.delenv(compiled_step.ENVIRONMENT_SWITCH, raising=False)
    assert compiled_step.unavailable_reason() == ''
    assert pybullet.getAPIVersion() == compiled_step.API_VERSION
    with Physics(description, 0.001) as physics:
        assert physics.compiled_step


def test_the_environment_switch_makes_the_physics_step_through_python(description, monkeypatch):
    monkeypatch.setenv(compiled_step.ENVIRONMENT_SWITCH, '0')
    assert compiled_step.unavailable_reason() == 'PAN_TILT_SIM_COMPILED_STEP=0'
    with Physics(description, 0.001) as physics:
        assert not physics.compiled_step
        assert callable(effort_stepper(physics))  # Python's three calls serve


def step_law_layout() -> dict:
    """Return step_law's layout as the compiled step exports it."""
    return {'LAW_FIELDS': {name: getattr(step_law, name) for name in step_law.FIELDS},
            'LAW_ROW_SIZE': step_law.ROW_SIZE, 'LAW_KINDS': dict(step_law.KINDS)}


def test_the_compiled_step_exports_step_laws_row_layout_and_law_kinds():
    assert {name: getattr(_compiled_step, name) for name in step_law_layout()} == \
        step_law_layout()
    assert compiled_step.layout_mismatch(_compiled_step) == ''


def swapped(fields: dict, first: str, second: str) -> dict:
    return {**fields, first: fields[second], second: fields[first]}


def without(mapping: dict, name: str) -> dict:
    return {key: value for key, value in mapping.items() if key != name}


@pytest.mark.parametrize(('change', 'named'), [
    (lambda layout: {'LAW_FIELDS': swapped(layout['LAW_FIELDS'], 'P_GAIN', 'I_GAIN')},
     ['field P_GAIN at index 1 in step_law, index 2 in C',
      'field I_GAIN at index 2 in step_law, index 1 in C']),
    (lambda layout: {'LAW_FIELDS': {**layout['LAW_FIELDS'], 'JERK_LIMIT': 17},
                     'LAW_ROW_SIZE': 18},
     ['field JERK_LIMIT at no index in step_law, index 17 in C',
      'ROW_SIZE 17 in step_law, 18 in C']),
    (lambda layout: {'LAW_FIELDS': without(layout['LAW_FIELDS'], 'PERIOD'),
                     'LAW_ROW_SIZE': 16},
     ['field PERIOD at index 16 in step_law, no index in C',
      'ROW_SIZE 17 in step_law, 16 in C']),
    (lambda layout: {'LAW_KINDS': {**layout['LAW_KINDS'], 'EFFORT': 3}},
     ['law kind EFFORT is 2 in step_law, is 3 in C']),
    (lambda layout: {'LAW_KINDS': without(layout['LAW_KINDS'], 'VELOCITY_PID')},
     ['law kind VELOCITY_PID is 1 in step_law, missing in C']),
], ids=['swapped fields', 'a field only in C', 'a field only in step_law', 'a kind code',
        'a kind only in step_law'])
def test_a_law_layout_other_than_step_laws_is_found_and_every_difference_named(change, named):
    layout = step_law_layout()
    mismatch = compiled_step.layout_mismatch(SimpleNamespace(**{**layout, **change(layout)}))
    assert mismatch.split('; ') == named


def test_a_build_without_a_law_layout_is_a_mismatch():
    assert 'exports no law layout' in compiled_step.layout_mismatch(SimpleNamespace())


def test_a_compiled_step_built_with_another_law_layout_is_refused_at_import(description,
                                                                             monkeypatch):
    monkeypatch.delenv(compiled_step.ENVIRONMENT_SWITCH, raising=False)
    fields = swapped(_compiled_step.LAW_FIELDS, 'SETPOINT', 'COMMAND')
    try:
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(_compiled_step, 'LAW_FIELDS', fields)
            with pytest.warns(RuntimeWarning, match='another law row layout') as warned:
                importlib.reload(compiled_step)
            assert 'field SETPOINT at index 9 in step_law, index 10 in C' in \
                str(warned[0].message)
            assert 'field COMMAND' in compiled_step.unavailable_reason()
            with Physics(description, 0.001) as physics:
                assert not physics.compiled_step
                assert physics.law_runner() is None  # the engine's Python loop serves
    finally:
        importlib.reload(compiled_step)  # the installed extension's layout again
    assert compiled_step.unavailable_reason() == ''


def python_reference(description, efforts, steps: int) -> list:
    """Return the states after each step, stepping through PyBullet's Python module."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv(compiled_step.ENVIRONMENT_SWITCH, '0')
        with Physics(description, 0.001) as physics:
            step = effort_stepper(physics)
            return [step(efforts) for _ in range(steps)]


def test_two_simulations_stepped_in_turn_each_step_their_own_robot(description):
    expected = [python_reference(description, efforts, 50) for efforts in EFFORTS]
    with Physics(description, 0.001) as first, Physics(description, 0.001) as second:
        assert first.compiled_step and second.compiled_step
        steps = [effort_stepper(first), effort_stepper(second)]
        seen = [[], []]
        for _ in range(50):
            for which in (0, 1):
                seen[which].append(steps[which](EFFORTS[which]))
    assert seen == expected


def test_the_states_have_get_joint_states_shape(description):
    with Physics(description, 0.001) as physics:
        states = effort_stepper(physics)(EFFORTS[0])
        assert states == pybullet.getJointStates(
            physics.body_id, [physics.joint_index(joint.name) for joint in physics.joints],
            physicsClientId=physics.client_id)
        assert [len(state) for state in states] == [4, 4]
        assert [len(state[2]) for state in states] == [6, 6]  # the reaction wrench


def test_a_step_after_close_is_an_error_not_a_crash(description):
    physics = Physics(description, 0.001)
    step = effort_stepper(physics)
    step(EFFORTS[0])
    physics.close()
    with pytest.raises(RuntimeError, match='closed'):
        step(EFFORTS[0])


def test_a_step_after_the_physics_was_collected_is_an_error_not_a_crash(description):
    physics = Physics(description, 0.001)
    step = effort_stepper(physics)
    del physics
    gc.collect()  # its finalizer disconnects PyBullet, and closes the connection first
    with pytest.raises(RuntimeError, match='closed'):
        step(EFFORTS[0])


@pytest.mark.parametrize(('efforts', 'error'), [
    ([1.0], ValueError), ([1.0, 'x'], TypeError), (3.0, TypeError)])
def test_efforts_it_cannot_apply_are_refused_before_anything_is_sent(description, efforts,
                                                                    error):
    with Physics(description, 0.001) as physics:
        step = effort_stepper(physics)
        before = physics.read_states()
        with pytest.raises(error):
            step(efforts)
        assert physics.read_states() == before  # no step was taken


@needs_the_compiled_step
def test_a_number_that_empties_the_efforts_it_is_read_from_is_no_crash(description):
    class Emptying:
        def __float__(self):
            efforts.clear()
            return 5.0
    efforts = [Emptying(), 1.0]
    with Physics(description, 0.001) as physics:
        states = effort_stepper(physics)(efforts)  # the C side reads a snapshot
    assert efforts == [] and len(states) == 2


@needs_the_compiled_step
def test_a_number_that_closes_the_simulation_is_an_error_not_a_crash(description):
    physics = Physics(description, 0.001)
    step = effort_stepper(physics)

    class Closing:
        def __float__(self):
            physics.close()
            return 1.0
    with pytest.raises(RuntimeError, match='closed'):
        step([Closing(), 1.0])  # the client is looked up after the efforts are read


def drive_reference(description, targets: list[float], steps: int) -> list:
    """Velocity motors on both joints then a step, through PyBullet's Python module."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv(compiled_step.ENVIRONMENT_SWITCH, '0')
        with Physics(description, 0.001) as physics:
            indices = [physics.joint_index(joint.name) for joint in physics.joints]
            step = physics.effort_stepper([])
            count = len(indices)
            states = []
            for _ in range(steps):
                pybullet.setJointMotorControlArray(
                    physics.body_id, indices, pybullet.VELOCITY_CONTROL, [0.0] * count,
                    targets, [5.0] * count, [0.0] * count, [0.7] * count, physics.client_id)
                states.append(step([]))
            return states


@needs_the_compiled_step
def test_velocity_motors_driven_from_c_move_the_joints_as_pybullet_s_own_call(description):
    targets = [1.5, -0.5]
    expected = drive_reference(description, targets, 50)
    with Physics(description, 0.001) as physics:
        indices = [physics.joint_index(joint.name) for joint in physics.joints]
        drive = physics.effort_stepper([], indices).drive
        seen = [drive([], targets, [5.0, 5.0], [0.7, 0.7]) for _ in range(50)]
    assert seen == expected  # to the last bit
    assert expected[-1][0][1] != 0.0  # the motors moved the joints


@needs_the_compiled_step
@pytest.mark.parametrize(('targets', 'forces', 'error'), [
    ([1.0], [5.0, 5.0], ValueError), ([1.0, 2.0], [5.0, 'x'], TypeError)])
def test_motor_values_it_cannot_apply_are_refused_before_anything_is_sent(description, targets,
                                                                         forces, error):
    with Physics(description, 0.001) as physics:
        indices = [physics.joint_index(joint.name) for joint in physics.joints]
        drive = physics.effort_stepper([], indices).drive
        before = physics.read_states()
        with pytest.raises(error):
            drive([], targets, forces, [1.0, 1.0])
        assert physics.read_states() == before  # no step was taken
