"""Controller laws stepped in C: the Python loop's results, to the last bit, many steps per call.

When every controller updated each step is a position or velocity PID or an
effort controller (the pan/tilt example's case) and a step sends PyBullet nothing but
the torques, the simulation runs the steps between two broadcaster samples
in C (``run_laws``); the sampled step runs in Python.  The pan/tilt example's and the
other scenarios' digests are test_engine_bit_identity's; here: each C law is
its controller's Python update for any input, a robot with every law, group
members, clamps, a passive joint holding an effort and an uneven
broadcaster rate gives the same samples both ways, and what cannot be run
that way, or would not gain from it, is not.
"""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from robot_fixtures import JointDef, write_star_robot, write_text

from pan_tilt_sim.controllers.commands.joint_effort_controller import JointEffortController
from pan_tilt_sim.controllers.commands.joint_position_controller import JointPositionController
from pan_tilt_sim.controllers.commands.joint_velocity_controller import JointVelocityController
from pan_tilt_sim.controllers.framework.base import JointHandle
from pan_tilt_sim.controllers.toolbox import step_law
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.sim import compiled_step
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.sim.physics import Physics

TIME_STEP = 0.001
CONTROLLERS = """
jsb:
  type: joint_state_broadcaster/JointStateBroadcaster
  publish_rate: 150
single:
  type: effort_controllers/JointPositionController
  joint: a
  pid: {p: 400.0, i: 30.0, d: 4.0, i_clamp: 0.5, antiwindup: true}
group:
  type: position_controllers/JointGroupPositionController
  joints: [b, c]
  gains:
    b: {p: 60.0, i: 5.0, d: 2.0, i_clamp_min: -0.2, i_clamp_max: 1.0}
    c: {p: 900.0, i: 0.0, d: 0.5}
roller:
  type: effort_controllers/JointVelocityController
  joint: v
  pid: {p: 3.0, i: 40.0, d: 0.01, i_clamp: 0.4}
push:
  type: effort_controllers/JointEffortController
  joint: e
"""
JOINTS = [
    JointDef('a', damping=0.0, friction=0.1, effort=8.0, velocity=3.0),
    JointDef('b', 'prismatic', -0.3, 0.3, damping=0.0, velocity=0.4),
    JointDef('c', damping=0.0, friction=0.05, effort=2.0),
    JointDef('passive', damping=0.0),
    JointDef('v', 'continuous', None, None, damping=0.0, friction=0.02, effort=1.5),
    JointDef('e', 'prismatic', -0.2, 0.2, damping=0.0),
]
BATCHES = (1, 2, 3, 17, 250, 729)  # cut across the 150 Hz samples (every 6 or 7 steps)


def run_script(folder, switch: str) -> tuple[list, dict, int]:
    """Drive the robot through the batches; return the samples, the final PID states, C steps."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv(compiled_step.ENVIRONMENT_SWITCH, switch)
        urdf = write_star_robot(folder, JOINTS)
        controllers = write_text(folder, 'controllers.yaml', CONTROLLERS)
        with make_simulation(str(urdf), str(controllers), TIME_STEP) as simulation:
            samples = []
            simulation.controller('jsb').set_sink(
                lambda time, names, *values: samples.append(
                    (time, *(tuple(value) for value in values))))
            single, group = simulation.controller('single'), simulation.controller('group')
            roller, push = simulation.controller('roller'), simulation.controller('push')
            simulation.handles['passive'].effort = 0.3  # the last effort applied, kept
            for round_number in range(2):
                for batch in BATCHES:
                    sign = 1.0 if (round_number + batch) % 2 else -1.0
                    single.set_command(1.2 * sign)
                    group.set_command([0.25 * sign, -1.0 * sign])
                    roller.set_command(4.0 * sign)
                    push.set_command(-3.0 * sign)
                    simulation.advance(batch)
            pids = {**single.pids(), **group.pids(), **roller.pids()}
            states = {name: [value.hex() for value in pid.law_values()]
                      for name, pid in pids.items()}
            states['setpoints'] = {**single.setpoints(), **group.setpoints()}
            states['handles'] = [(handle.position, handle.velocity, handle.effort)
                                 for handle in simulation.handles.values()]
            return samples, states, simulation.compiled_steps


def test_every_law_group_members_and_a_passive_joint_give_the_python_samples(tmp_path):
    compiled = run_script(tmp_path, '1')
    python = run_script(tmp_path, '0')
    assert python[2] == 0
    total = 2 * sum(BATCHES)
    # All but the ~300 sampled steps and the stretches too short to hand over ran in C.
    assert total * 0.6 < compiled[2] < total
    assert len(compiled[0]) == len(python[0]) > 250
    assert compiled[0] == python[0]  # every sample, float for float
    # The PIDs' states (integral, last output, last measurement), setpoints, the joint handles.
    assert compiled[1] == python[1]


def test_the_pan_tilt_example_steps_its_position_pids_in_c(monkeypatch):
    share = package_share()
    monkeypatch.delenv(compiled_step.ENVIRONMENT_SWITCH, raising=False)
    with make_simulation(str(share / DEFAULT_DESCRIPTION), str(share / DEFAULT_CONTROLLERS),
                         TIME_STEP) as simulation:
        simulation.advance(1000)
        # 50 Hz broadcaster: 50 of the 1000 steps sample in Python.
        assert simulation.compiled_steps == 950


def steps_in_c(folder, joints, controllers: str, check=None, steps: int = 300) -> int:
    """Run a star robot with ``controllers`` (``check(simulation)`` first); return C's steps."""
    urdf = write_star_robot(folder, joints)
    path = write_text(folder, 'controllers.yaml', controllers)
    with make_simulation(str(urdf), str(path), TIME_STEP) as simulation:
        if check is not None:
            check(simulation)
        simulation.advance(steps)
        return simulation.compiled_steps


def test_a_controller_without_a_law_keeps_every_step_in_python(tmp_path):
    # Without gains a position controller is the ideal actuator: a velocity motor.
    def check(simulation):
        assert simulation.controller('ideal').step_law() is None
    assert steps_in_c(tmp_path, JOINTS[:1], """
        ideal:
          type: position_controllers/JointPositionController
          joint: a
        """, check) == 0


def test_a_law_beside_a_controller_without_one_keeps_every_step_in_python(tmp_path):
    # An effort-driven trajectory controller: the steps could be compiled, its update not.
    def check(simulation):
        assert simulation.physics.law_runner() is not None
        assert simulation.controller('trajectory').step_law() is None
    assert steps_in_c(tmp_path, JOINTS[:2], """
        pid:
          type: effort_controllers/JointPositionController
          joint: a
        trajectory:
          type: joint_trajectory_controller/JointTrajectoryController
          joints: [b]
          command_interfaces: [effort]
          state_interfaces: [position, velocity]
          gains:
            b: {p: 100.0, d: 5.0}
        """, check) == 0


@pytest.mark.parametrize(('rate', 'in_c'), [(1000, 0), (300, 0), (100, 270)])
def test_a_broadcaster_due_every_few_steps_leaves_them_in_python(tmp_path, rate, in_c):
    # ros2_control's update_rate 1000 samples every step, 300 Hz every 3 or 4 steps: too
    # short a stretch to hand over; 100 Hz leaves 9 of every 10 steps to C.
    assert steps_in_c(tmp_path, JOINTS[:1], f"""
        jsb:
          type: joint_state_broadcaster/JointStateBroadcaster
          publish_rate: {rate}
        pid:
          type: effort_controllers/JointPositionController
          joint: a
        """) == in_c


# --- one law step in C against the controller's update -------------------------------------

finite = st.floats(-50.0, 50.0, allow_nan=False)
measured = st.one_of(finite, st.sampled_from([math.nan, math.inf, -math.inf]))
gain = st.floats(0.0, 500.0)
gains = st.fixed_dictionaries({'p': gain, 'i': gain, 'd': gain, 'i_clamp': st.floats(0.0, 10.0),
                               'antiwindup': st.booleans()})


@pytest.fixture(scope='module')
def one_joint_runner(tmp_path_factory):
    folder = tmp_path_factory.mktemp('one_joint')
    description = load_description(write_star_robot(folder, JOINTS[:1]))
    with Physics(description, TIME_STEP) as physics:
        physics.set_drives([False])
        run = physics.law_runner()
        assert run is not None
        yield physics, run


def bound(controller, physics: Physics, start: float):
    handle = JointHandle(physics.joints[0], start)
    controller.configure({'a': handle})  # a position controller's setpoint starts at ``start``
    return controller


def one_step_both_ways(run, make, position: float, velocity: float) -> tuple:
    """Step a fresh controller once in C and once in Python; return (effort, controller) each."""
    python, in_c = make(), make()
    handle, row = in_c.step_law()
    assert len(row) == step_law.ROW_SIZE
    efforts = [0.0]
    run(1, TIME_STEP, efforts, [(0, 0, row)], [(position, velocity, (0.0,) * 6, 0.0)])
    in_c.absorb_step_law(row)
    python._handle.position, python._handle.velocity = position, velocity
    python.update(0.0, TIME_STEP)
    return (efforts[0], in_c), (python._handle.effort, python)


def pid_state(controller) -> list[str]:
    return [value.hex() for value in controller.pid.law_values()]  # NaN too


@settings(max_examples=300, deadline=None)
@given(start=finite, command=finite, position=measured, velocity=measured, gains=gains,
       integral=st.floats(-20.0, 20.0))
def test_one_step_of_the_position_law_is_the_python_update(one_joint_runner, start, command,
                                                            position, velocity, gains, integral):
    physics, run = one_joint_runner

    def make():
        controller = bound(JointPositionController('c', {'joint': 'a', 'pid': gains}), physics,
                           start)
        controller.set_command(command)
        controller.pid.restore(integral, 1.5, math.nan)
        return controller
    (c_effort, in_c), (effort, python) = one_step_both_ways(run, make, position, velocity)
    assert c_effort.hex() == effort.hex()
    assert in_c.setpoint.hex() == python.setpoint.hex()
    assert pid_state(in_c) == pid_state(python)


@settings(max_examples=300, deadline=None)
@given(command=finite, velocity=measured, last=measured, gains=gains,
       integral=st.floats(-20.0, 20.0))
def test_one_step_of_the_velocity_law_is_the_python_update(one_joint_runner, command, velocity,
                                                            last, gains, integral):
    physics, run = one_joint_runner

    def make():
        controller = bound(JointVelocityController('c', {'joint': 'a', 'pid': gains}), physics,
                           0.0)
        controller.set_command(command)
        controller.pid.restore(integral, 1.5, last)  # last: NaN before the first step
        return controller
    (c_effort, in_c), (effort, python) = one_step_both_ways(run, make, 0.25, velocity)
    assert c_effort.hex() == effort.hex()
    assert pid_state(in_c) == pid_state(python)


@pytest.mark.parametrize('command', [0.0, -0.0, 7.25, -8.0])  # within the limit
def test_one_step_of_the_effort_law_is_the_python_update(one_joint_runner, command):
    physics, run = one_joint_runner

    def make():
        controller = bound(JointEffortController('c', {'joint': 'a'}), physics, 0.0)
        controller.set_command(command)
        return controller
    (c_effort, _), (effort, _) = one_step_both_ways(run, make, 0.1, 0.2)
    assert c_effort.hex() == effort.hex() == command.hex()


def law_row(kind: float, every: float = 1.0, next_update: float = 0.0,
            period: float = 0.0) -> list[float]:
    row = [0.0] * step_law.ROW_SIZE
    row[step_law.KIND] = kind
    row[step_law.UPDATE_STEPS], row[step_law.NEXT_UPDATE] = every, next_update
    row[step_law.PERIOD] = period
    return row


@pytest.mark.parametrize(('laws', 'error'), [
    ([(0, 0, [0.0] * 5)], ValueError),  # a short row
    ([(0, 3, law_row(step_law.POSITION_PID))], ValueError),  # no such joint
    ([(0, 0, law_row(3.0))], ValueError),  # no such law
    ([(0, 0, law_row(0.5))], ValueError),
    ([(0, 0, law_row(math.nan))], ValueError),
    ([(0, 0, [0.0] * (step_law.ROW_SIZE - 1) + ['x'])], TypeError),
    ([[0, 0, law_row(step_law.EFFORT)]], TypeError),  # not a tuple
    ([(0, 0, law_row(step_law.EFFORT, every=0.0))], ValueError),  # no clock
    ([(0, 0, law_row(step_law.EFFORT, every=2.5))], ValueError),
    ([(0, 0, law_row(step_law.EFFORT, next_update=-1.0))], ValueError),
    ([(0, 0, law_row(step_law.EFFORT, next_update=math.inf))], ValueError),
    ([(0, 0, law_row(step_law.EFFORT, period=-0.01))], ValueError),
    ([(0, 0, law_row(step_law.EFFORT, period=math.nan))], ValueError),
])
def test_a_malformed_law_is_refused_before_anything_is_sent(one_joint_runner, laws, error):
    physics, run = one_joint_runner
    before = physics.read_states()
    with pytest.raises(error):
        run(5, TIME_STEP, [30.0], laws, before)
    assert physics.read_states() == before  # no torque, no step


@pytest.mark.parametrize(('empty_the_row', 'error'), [(False, IndexError), (True, ValueError)])
def test_a_number_that_empties_the_lists_it_is_read_from_is_an_error_not_a_crash(
        one_joint_runner, empty_the_row, error):
    physics, run = one_joint_runner
    row = law_row(step_law.EFFORT)
    laws = [(0, 0, row)]

    class Emptying:
        def __float__(self):
            laws.clear()
            efforts.clear()
            if empty_the_row:
                row.clear()
            return 2.0
    efforts = [Emptying()]
    # The C side reads snapshots of the efforts and the laws: an emptied row is refused,
    # and otherwise only the efforts it hands back find no place to go.
    with pytest.raises(error):
        run(3, TIME_STEP, efforts, laws, physics.read_states())


def test_a_number_that_closes_the_simulation_is_an_error_not_a_crash(tmp_path):
    physics = Physics(load_description(write_star_robot(tmp_path, JOINTS[:1])), TIME_STEP)
    physics.set_drives([False])
    run, states = physics.law_runner(), physics.read_states()

    class Closing:
        def __float__(self):
            physics.close()
            return 1.0
    with pytest.raises(RuntimeError, match='closed'):  # the client is looked up last
        run(3, TIME_STEP, [Closing()], [(0, 0, law_row(step_law.EFFORT))], states)
