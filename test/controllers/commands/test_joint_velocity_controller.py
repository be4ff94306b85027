"""JointVelocityController (velocity_ and effort_controllers/), without a simulator.

Parameters, the lifecycle through the controller manager, the velocity
target of the ideal actuator or the PID's effort, and every limit it
enforces:

* velocity commands are clamped to +-velocity limit (whatever drives the
  joint); NaN, Inf and magnitudes beyond MAX_COMMAND_MAGNITUDE are rejected;
* with a PID: the effort is clamped to +-effort limit, and the integral term
  is bounded by the effort limit unless the YAML gives a clamp.
"""

import math

import pytest
from controller_fixtures import DT, loaded, raises_naming, step

from pan_tilt_sim.controllers import CommandKind, CommandResult, JointHandle, create_controller
from pan_tilt_sim.controllers.commands.joint_velocity_controller import DEFAULT_VELOCITY_GAINS
from pan_tilt_sim.controllers.framework.base import MAX_COMMAND_MAGNITUDE, ActuatorKind
from pan_tilt_sim.controllers.framework.manager import ACTIVE, INACTIVE, UNCONFIGURED
from pan_tilt_sim.model.robot import JointKind, JointSpec

VELOCITY_TYPE = 'velocity_controllers/JointVelocityController'
EFFORT_TYPE = 'effort_controllers/JointVelocityController'
ROLLER = JointSpec('roller', JointKind.CONTINUOUS, effort_limit=30.0, velocity_limit=0.5)
WHEEL = JointSpec('wheel', JointKind.CONTINUOUS)  # no limits at all


def _controller(type_name=VELOCITY_TYPE, spec=ROLLER, **params):
    handle = JointHandle(spec)
    controller = create_controller('roll', type_name, {'joint': spec.name, **params})
    controller.configure({spec.name: handle})
    return controller, handle


def _run(controller, steps, start=0):
    """Update ``steps`` times, DT apart (joint state frozen)."""
    for step_number in range(start, start + steps):
        controller.update(step_number * DT, DT)


# --- parameters ----------------------------------------------------------------------------

def test_a_missing_joint_field_is_a_configuration_error():
    with raises_naming('roll.joint'):
        create_controller('roll', VELOCITY_TYPE, {'pid': {'p': 1.0}})


@pytest.mark.parametrize('pid', [{'p': -1.0}, {'d': math.nan}, 'fast'])
def test_invalid_pid_gains_are_a_configuration_error(pid):
    with raises_naming('roll.pid'):
        create_controller('roll', VELOCITY_TYPE, {'joint': 'roller', 'pid': pid})


def test_a_joint_the_robot_lacks_fails_at_configure_naming_the_joint_field():
    controller = create_controller('roll', VELOCITY_TYPE, {'joint': 'elbow'})
    with raises_naming('roll.joint'):
        controller.configure({'roller': JointHandle(ROLLER)})


# --- interfaces and lifecycle --------------------------------------------------------------

@pytest.mark.parametrize(('type_name', 'interface'), [(VELOCITY_TYPE, 'velocity'),
                                                      (EFFORT_TYPE, 'effort')])
def test_takes_float64_on_command_and_claims_its_packages_interface(type_name, interface):
    controller = create_controller('roll', type_name, {'joint': 'roller'})
    assert controller.command_topic == 'command'
    assert controller.command_kind is CommandKind.FLOAT64
    assert controller.command_interfaces() == {'roller': (interface,)}


def test_the_manager_configures_activates_and_cleans_it_up():
    handles = {'roller': JointHandle(ROLLER)}
    manager = loaded('roll', VELOCITY_TYPE, {'joint': 'roller'}, handles)
    assert manager.state('roll') == UNCONFIGURED
    controller = manager.configure('roll')
    assert manager.state('roll') == INACTIVE
    controller.set_command(0.4)
    manager.switch(activate=['roll'])  # activation starts it afresh: at rest
    assert manager.state('roll') == ACTIVE
    step(manager, 1)
    assert handles['roller'].velocity_target == 0.0
    controller.set_command(0.3)
    step(manager, 1, start=1)
    assert controller.setpoints() == {'roller': 0.3}
    assert handles['roller'].velocity_target == 0.3
    manager.switch(deactivate=['roll'])
    controller.set_command(-0.3)
    step(manager, 5, start=2)
    assert handles['roller'].velocity_target == 0.3  # the last command stays applied
    manager.cleanup('roll')
    assert manager.state('roll') == UNCONFIGURED


def test_without_gains_the_ideal_actuator_turns_the_joint_at_the_command():
    controller, handle = _controller()
    assert controller.actuators()['roller'].kind is ActuatorKind.IDEAL_VELOCITY
    assert controller.pids() == {}
    _run(controller, 1)
    assert handle.velocity_target == 0.0  # before the first command: at rest
    assert controller.set_command(-0.25) is CommandResult.ACCEPTED
    _run(controller, 1, start=1)
    assert (handle.velocity_target, handle.effort) == (-0.25, 0.0)


def test_the_effort_type_keeps_a_pid_with_default_gains():
    controller, _handle = _controller(EFFORT_TYPE)
    assert controller.actuators()['roller'].kind is ActuatorKind.VELOCITY_PID
    assert controller.pid.gains == DEFAULT_VELOCITY_GAINS.with_default_clamp(30.0)


def test_with_gains_the_effort_is_pid_on_the_velocity_error():
    controller, handle = _controller(pid={'p': 10.0, 'i': 2.0})
    handle.velocity = 0.1
    controller.set_command(0.4)
    _run(controller, 1)
    assert handle.effort == pytest.approx(10.0 * 0.3 + 2.0 * 0.3 * DT)


def test_the_derivative_acts_on_the_measured_velocity_so_a_command_step_gives_no_kick():
    controller, handle = _controller(pid={'d': 0.1})
    _run(controller, 1)
    controller.set_command(0.5)
    _run(controller, 1, start=1)
    assert handle.effort == 0.0
    handle.velocity = 0.2  # 0.2 rad/s faster within one step
    _run(controller, 1, start=2)
    assert handle.effort == pytest.approx(-0.1 * 0.2 / DT)


def test_reset_forgets_the_command():
    controller, handle = _controller()
    controller.set_command(0.4)
    controller.reset()
    _run(controller, 1)
    assert handle.velocity_target == 0.0


# --- limits --------------------------------------------------------------------------------

@pytest.mark.parametrize(('command', 'limited'), [(2.0, 0.5), (-3.0, -0.5)])
def test_without_gains_a_command_beyond_the_velocity_limit_is_clamped_to_it(command, limited):
    controller, handle = _controller()
    assert controller.set_command(command) is CommandResult.CLAMPED
    _run(controller, 1)
    assert handle.velocity_target == limited


@pytest.mark.parametrize(('command', 'limited'), [(2.0, 0.5), (-3.0, -0.5)])
def test_with_gains_the_pid_chases_the_clamped_command(command, limited):
    controller, handle = _controller(pid={'p': 10.0})
    assert controller.set_command(command) is CommandResult.CLAMPED
    _run(controller, 1)
    assert handle.effort == pytest.approx(10.0 * limited)


@pytest.mark.parametrize('command', [0.5, -0.5])
def test_the_pid_effort_is_clamped_to_the_effort_limit(command):
    controller, handle = _controller(pid={'p': 1000.0})
    controller.set_command(command)
    _run(controller, 10)
    assert handle.effort == math.copysign(30.0, command)


def _windup_then_overshoot(controller, handle):
    """Hold the joint 0.2 rad/s short of a zero command for a second, then 5 rad/s past it."""
    handle.velocity = -0.2
    _run(controller, 1000)
    handle.velocity = 5.0
    _run(controller, 1, start=1000)
    return handle.effort


def test_the_integral_term_is_bounded_by_the_effort_limit_unless_the_yaml_clamps_it():
    # i 1e4 integrates 2 N*m per step: without a bound the term would reach 2000 N*m,
    # and still outweigh the proportional -20 N*m once the joint overshoots.
    controller, handle = _controller(pid={'p': 4.0, 'i': 1e4})
    assert _windup_then_overshoot(controller, handle) == pytest.approx(-20.0 + 30.0)
    assert controller.pid.integral_term == 30.0
    controller, handle = _controller(pid={'p': 4.0, 'i': 1e4, 'i_clamp': 5.0})
    assert _windup_then_overshoot(controller, handle) == pytest.approx(-20.0 + 5.0)


@pytest.mark.parametrize('value', [math.nan, math.inf, -math.inf, -10 * MAX_COMMAND_MAGNITUDE])
def test_non_finite_or_absurd_commands_are_rejected_and_change_nothing(value):
    controller, handle = _controller(spec=WHEEL)
    assert controller.set_command(MAX_COMMAND_MAGNITUDE) is CommandResult.ACCEPTED
    assert controller.set_command(0.3) is CommandResult.ACCEPTED
    assert controller.set_command(value) is CommandResult.REJECTED
    _run(controller, 1)
    assert handle.velocity_target == 0.3
