"""JointEffortController (effort_controllers/), without a simulator.

Parameters, the lifecycle through the controller manager, the effort it
applies, and the limits it enforces: effort commands are clamped to +-effort
limit; NaN, Inf and magnitudes beyond MAX_COMMAND_MAGNITUDE are rejected.
"""

import math

import pytest
from controller_fixtures import DT, loaded, raises_naming, step

from pan_tilt_sim.controllers import CommandKind, CommandResult, JointHandle, create_controller
from pan_tilt_sim.controllers.framework.base import MAX_COMMAND_MAGNITUDE, ActuatorKind, Drive
from pan_tilt_sim.controllers.framework.manager import ACTIVE, INACTIVE, UNCONFIGURED
from pan_tilt_sim.model.robot import JointKind, JointSpec

TYPE = 'effort_controllers/JointEffortController'
SLIDE = JointSpec('slide', JointKind.PRISMATIC, lower=0.0, upper=0.4, effort_limit=30.0,
                  velocity_limit=0.2)
WHEEL = JointSpec('wheel', JointKind.CONTINUOUS)  # no limits at all


def _controller(spec=SLIDE):
    handle = JointHandle(spec)
    controller = create_controller('push', TYPE, {'joint': spec.name})
    controller.configure({spec.name: handle})
    return controller, handle


# --- parameters ----------------------------------------------------------------------------

@pytest.mark.parametrize('params', [{}, {'joint': ''}, {'joint': ['slide']}])
def test_a_missing_or_invalid_joint_field_is_a_configuration_error(params):
    with raises_naming('push.joint'):
        create_controller('push', TYPE, params)


def test_a_joint_the_robot_lacks_fails_at_configure_naming_the_joint_field():
    controller = create_controller('push', TYPE, {'joint': 'elbow'})
    with raises_naming('push.joint'):
        controller.configure({'slide': JointHandle(SLIDE)})


# --- interfaces and lifecycle --------------------------------------------------------------

def test_takes_float64_on_command_and_claims_the_effort_interface():
    controller, _handle = _controller()
    assert controller.command_topic == 'command'
    assert controller.command_kind is CommandKind.FLOAT64
    assert controller.command_interfaces() == {'slide': ('effort',)}
    actuator = controller.actuators()['slide']
    assert actuator.kind is ActuatorKind.EFFORT and actuator.drive is Drive.EFFORT
    assert controller.pids() == {}


def test_the_manager_configures_activates_and_cleans_it_up():
    handles = {'slide': JointHandle(SLIDE)}
    manager = loaded('push', TYPE, {'joint': 'slide'}, handles)
    assert manager.state('push') == UNCONFIGURED
    controller = manager.configure('push')
    assert manager.state('push') == INACTIVE
    controller.set_command(5.0)
    manager.switch(activate=['push'])  # activation starts it afresh: no effort
    assert manager.state('push') == ACTIVE
    step(manager, 1)
    assert handles['slide'].effort == 0.0
    controller.set_command(-7.5)
    step(manager, 1, start=1)
    assert controller.setpoints() == {'slide': -7.5}
    assert handles['slide'].effort == -7.5
    manager.switch(deactivate=['push'])
    controller.set_command(2.0)
    step(manager, 5, start=2)
    assert handles['slide'].effort == -7.5  # the last effort stays applied
    manager.cleanup('push')
    assert manager.state('push') == UNCONFIGURED


def test_the_command_is_the_effort_until_the_next_one():
    controller, handle = _controller()
    assert controller.set_command(12.0) is CommandResult.ACCEPTED
    for step_number in range(5):
        controller.update(step_number * DT, DT)
        assert handle.effort == 12.0


def test_reset_applies_no_effort_until_commanded_again():
    controller, handle = _controller()
    controller.set_command(12.0)
    controller.reset()
    controller.update(0.0, DT)
    assert handle.effort == 0.0


# --- limits --------------------------------------------------------------------------------

@pytest.mark.parametrize(('command', 'limited'), [(100.0, 30.0), (-31.0, -30.0)])
def test_an_effort_beyond_the_effort_limit_is_clamped_to_it(command, limited):
    controller, handle = _controller()
    assert controller.set_command(command) is CommandResult.CLAMPED
    controller.update(0.0, DT)
    assert handle.effort == limited


@pytest.mark.parametrize('value', [math.nan, math.inf, -math.inf, 10 * MAX_COMMAND_MAGNITUDE])
def test_non_finite_or_absurd_commands_are_rejected_and_change_nothing(value):
    controller, handle = _controller(WHEEL)
    assert controller.set_command(-MAX_COMMAND_MAGNITUDE) is CommandResult.ACCEPTED
    assert controller.set_command(4.0) is CommandResult.ACCEPTED
    assert controller.set_command(value) is CommandResult.REJECTED
    controller.update(0.0, DT)
    assert handle.effort == 4.0
