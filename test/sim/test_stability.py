"""Instability is never silent: refused or named at start-up, reported at run time.

A description PyBullet cannot integrate ends start-up; PID gains too high for
their joint are named at start-up; a runaway joint is reported while running.
"""

import math

import pytest
from robot_fixtures import (
    LINK_LENGTH,
    LINK_MASS,
    LINK_WIDTH,
    JointDef,
    Log,
    write_star_robot,
    write_text,
)

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.sim import compiled_step
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.sim.stability import check_startup_stability, largest_stable_time_step

DT = 0.001
# A star link about its joint's z axis: box about its centre plus m (L / 2)^2.
STAR_INERTIA = LINK_MASS * (LINK_LENGTH ** 2 + LINK_WIDTH ** 2) / 12 + LINK_MASS * (
    LINK_LENGTH / 2) ** 2


def star(tmp_path, gains, log, damping=0.0):
    # A huge effort limit: a clamped effort would turn divergence into bounded chatter.
    robot = write_star_robot(tmp_path, [JointDef('hinge', damping=damping, effort=1e6)])
    controllers = write_text(tmp_path, 'controllers.yaml', f"""
        pos:
          type: effort_controllers/JointPositionController
          joint: hinge
          pid: {gains}
        """)
    return make_simulation(str(robot), str(controllers), DT, logger=log)


def critical_d(p=0.0):
    """The d at which d dt / 2 + p dt^2 / 4 equals the star link's inertia."""
    return (4 * STAR_INERTIA - p * DT * DT) / (2 * DT)


def test_gains_within_the_rule_give_no_warning_and_stay_bounded(tmp_path):
    log = Log()
    d = 0.9 * critical_d(p=1000.0)
    with star(tmp_path, f'{{p: 1000.0, d: {d}}}', log) as sim:
        sim.controller('pos').set_command(0.5)
        sim.advance(2000)
        assert sim.joint_positions()['hinge'] == pytest.approx(0.5, abs=0.01)
    assert log.warnings == []


def test_gains_beyond_the_rule_are_named_with_the_largest_stable_value(tmp_path):
    log = Log()
    d = 1.1 * critical_d(p=100.0)
    with star(tmp_path, f'{{p: 100.0, d: {d}}}', log) as sim:
        sim.controller('pos').set_command(0.5)
        sim.advance(500)
        # ... and they are unstable indeed: the joint runs away to PyBullet's cap.
        assert abs(sim.joint_velocities()['hinge']) > 50.0
    startup = [line for line in log.warnings if 'is unstable at time_step' in line]
    assert startup == [
        f"joint 'hinge' (pos): PID p 100 d {d:g} is unstable at time_step 0.001 s for its "
        f'effective inertia {STAR_INERTIA:.3g} kg*m^2 (needs d * time_step / 2 + '
        f'p * time_step^2 / 4 = {d * DT / 2 + 100 * DT * DT / 4:.3g} < inertia): use '
        f'd < {critical_d(100.0):.3g}, a time_step below '
        f'{largest_stable_time_step(100.0, d, STAR_INERTIA):.3g} s, or no gains '
        '(the ideal actuator)']


@pytest.mark.parametrize(('interface', 'checked'), [('effort', True), ('velocity', False)])
def test_only_a_pid_whose_output_is_the_effort_is_checked(tmp_path, interface, checked):
    log = Log()
    robot = write_star_robot(tmp_path, [JointDef('hinge', effort=1e6)])
    # p far beyond the rule: an effort loop this stiff would run away; as the ideal
    # actuator's velocity target it is a different loop, which the rule says nothing about.
    controllers = write_text(tmp_path, 'controllers.yaml', f"""
        controller_manager:
          ros__parameters:
            pid: {{type: pid_controller/PidController}}
        pid:
          ros__parameters:
            dof_names: [hinge]
            command_interface: {interface}
            reference_and_state_interfaces: [position]
            gains: {{hinge: {{p: 1000000.0}}}}
        """)
    with make_simulation(str(robot), str(controllers), DT, logger=log):
        pass
    # At the controller_manager's 100 Hz: checked at the controller's own period.
    unstable = [line for line in log.warnings if 'is unstable at its update period 0.01 s' in line]
    assert bool(unstable) is checked


def test_urdf_damping_does_not_count_it_is_applied_implicitly(tmp_path):
    log = Log()
    with star(tmp_path, '{p: 100.0, d: 10.0}', log, damping=1000.0) as sim:
        sim.advance(500)
        assert abs(sim.joint_velocities()['hinge']) < 1e-3
    assert log.warnings == []


def test_a_runaway_joint_is_reported_at_run_time_once_a_second(tmp_path):
    log = Log()
    with star(tmp_path, f'{{p: 100.0, d: {3 * critical_d(100.0)}}}', log) as sim:
        log.warnings.clear()
        sim.controller('pos').set_command(0.5)
        for _ in range(100):
            sim.advance(10)
    runtime = [line for line in log.warnings if "PyBullet's speed cap" in line]
    assert len(runtime) == 1  # throttled: the loop took less than a second
    assert runtime[0].startswith('at sim time ')
    assert "joint 'hinge' moves at " in runtime[0] and 'unstable' in runtime[0]


def test_a_non_finite_state_is_reported(tmp_path, monkeypatch):
    log = Log()
    # The states are poisoned where the Python loop takes them.
    monkeypatch.setenv(compiled_step.ENVIRONMENT_SWITCH, '0')
    with star(tmp_path, '{p: 1.0}', log) as sim:
        step = sim._physics_step

        def poisoned(efforts, targets, forces=None):
            states = step(efforts, targets, forces)
            return [(math.nan, math.nan, *state[2:]) for state in states]
        sim._physics_step = poisoned
        sim.advance(1)
    assert any("joint 'hinge' has a non-finite state (position nan" in line
               for line in log.warnings)


# --- a description PyBullet cannot integrate: refused at start-up -----------------------------

def far_out(tmp_path, distance):
    """A two-link arm whose elbow sits ``distance`` metres out along the upper arm."""
    inertial = ('<inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.01" ixy="0" '
                'ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>')
    joint = ('<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
             '<origin xyz="{x} 0 0"/><axis xyz="0 1 0"/>'
             '<limit lower="-3" upper="3" effort="10" velocity="2"/></joint>')
    robot = write_text(tmp_path, 'far.urdf', f"""
        <robot name="far">
          <link name="base"/>
          <link name="upper">{inertial}</link><link name="lower">{inertial}</link>
          {joint.format(name='shoulder', parent='base', child='upper', x=0)}
          {joint.format(name='elbow', parent='upper', child='lower', x=distance)}
        </robot>
        """)
    controllers = write_text(tmp_path, 'controllers.yaml', """
        eff:
          type: effort_controllers/JointGroupEffortController
          joints: [shoulder, elbow]
        """)
    return robot, controllers


def test_a_description_whose_states_go_non_finite_at_once_is_refused_naming_joint_and_cause(
        tmp_path):
    # 1e155 m squared overflows: PyBullet's first step makes every state NaN.
    robot, controllers = far_out(tmp_path, '1e155')
    with pytest.raises(DescriptionError) as refused:
        make_simulation(str(robot), str(controllers), DT)
    message = str(refused.value)
    assert '\n' not in message
    assert message.startswith(f'{robot}: ')
    assert "joint 'elbow'" in message
    assert 'non-finite' in message
    assert "likely cause: joint 'elbow' <origin xyz> 1e+155" in message


def test_a_description_far_out_but_finite_starts(tmp_path):
    robot, controllers = far_out(tmp_path, '1e6')
    with make_simulation(str(robot), str(controllers), DT) as sim:
        sim.advance(300)
        assert all(math.isfinite(v) for v in sim.joint_positions().values())


def test_the_start_up_trial_leaves_no_trace(tmp_path):
    # An arm that swings under gravity: a trial not undone would leave it elsewhere.
    robot, controllers = far_out(tmp_path, '0.2')

    def run(trials):
        with make_simulation(str(robot), str(controllers), DT) as sim:
            for _ in range(trials):  # more than the one at start-up
                check_startup_stability(sim.physics, sim.description)
            sim.controller('eff').set_command([0.5, -0.2])
            sim.advance(700)
            return sim.joint_positions(), sim.joint_velocities()
    moved = run(0)
    assert moved[0]['shoulder'] != 0.0
    assert run(3) == moved  # to the last bit


def test_largest_stable_time_step_solves_the_rule():
    p, d, inertia = 100.0, 10.0, 0.003
    dt = largest_stable_time_step(p, d, inertia)
    assert d * dt / 2 + p * dt * dt / 4 == pytest.approx(inertia)
    assert largest_stable_time_step(0.0, 4.0, 0.002) == pytest.approx(0.001)


@pytest.mark.parametrize('factor', [0.9, 1.1])
def test_a_stiff_p_alone_is_held_to_p_dt_squared_over_4_below_the_inertia(tmp_path, factor):
    log = Log()
    p = factor * 4 * STAR_INERTIA / DT ** 2  # ~1e5: the p term of the rule decides alone
    with star(tmp_path, f'{{p: {p}}}', log) as sim:
        sim.controller('pos').set_command(0.01)
        sim.advance(1000)
        speed = abs(sim.joint_velocities()['hinge'])
    startup = [line for line in log.warnings if 'is unstable at time_step' in line]
    if factor < 1:
        assert speed < 5.0 and startup == []
    else:
        assert speed > 50.0
        assert len(startup) == 1 and f'use p < {4 * STAR_INERTIA / DT ** 2:.3g} and a ' \
                                      'smaller d' in startup[0]
