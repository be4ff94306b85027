"""GpioCommandController (gpio_controllers/), without a simulator.

Which interfaces it claims and publishes, commands checked whole, written at
its update rate after the states are published, and forgotten when it stops.
"""

import math

import pytest
from controller_fixtures import DT, hardware, loaded, raises_naming, sample_sink

from pan_tilt_sim.controllers import CommandResult, create_controller
from pan_tilt_sim.controllers.framework.hardware_interfaces import (
    CommandInterface,
    GpioHandle,
    StateInterface,
)
from pan_tilt_sim.controllers.framework.manager import ACTIVE

TYPE = 'gpio_controllers/GpioCommandController'
# ros2_control_demos' example 10: two gpios, an analog output echoed, two inputs, a vacuum.
EXAMPLE = {'gpios': ['flange_analog_IOs', 'flange_vacuum'],
           'command_interfaces': {'flange_analog_IOs': {'interfaces': ['analog_output1']},
                                  'flange_vacuum': {'interfaces': ['vacuum']}}}


def example_10_gpios():
    output = StateInterface('flange_analog_IOs/analog_output1')
    analog = GpioHandle('flange_analog_IOs',
                        [CommandInterface('flange_analog_IOs/analog_output1', output)],
                        [output, StateInterface('flange_analog_IOs/analog_input1'),
                         StateInterface('flange_analog_IOs/analog_input2')])
    vacuum_state = StateInterface('flange_vacuum/vacuum', 1.0)
    vacuum = GpioHandle('flange_vacuum',
                        [CommandInterface('flange_vacuum/vacuum', vacuum_state)], [vacuum_state])
    return hardware(gpios=[analog, vacuum])


def active(params=EXAMPLE, gpios=None):
    manager = loaded('gpio', TYPE, params, {}, gpios or example_10_gpios())
    manager.configure('gpio')
    manager.switch(['gpio'])
    controller = manager.controller('gpio')
    samples = []
    controller.set_sink(sample_sink(samples))
    return manager, controller, samples


def update(controller, time):
    controller.update(time, DT)


def command(*groups):
    """A DynamicInterfaceGroupValues as the adapter hands it over."""
    return ([group for group, _names, _values in groups],
            [(names, values) for _group, names, values in groups])


def test_it_claims_its_command_interfaces_and_publishes_every_state_of_its_gpios():
    manager, controller, _samples = active()
    assert manager.state('gpio') == ACTIVE
    assert controller.command_interfaces() == {'flange_analog_IOs': ('analog_output1',),
                                               'flange_vacuum': ('vacuum',)}
    assert controller.state_names == (('analog_output1', 'analog_input1', 'analog_input2'),
                                      ('vacuum',))
    topics = {topic.name: topic for topic in controller.ros_surface()}
    assert {name: topic.message for name, topic in topics.items()} == {
        '~/commands': 'control_msgs/msg/DynamicInterfaceGroupValues',
        '~/gpio_states': 'control_msgs/msg/DynamicInterfaceGroupValues'}
    assert topics['~/gpio_states'].fields == {
        'groups': ('flange_analog_IOs', 'flange_vacuum'),
        'interface_names': controller.state_names}


def test_states_start_at_their_initial_values_and_a_command_shows_at_the_next_update():
    _manager, controller, samples = active()
    update(controller, 0.0)
    (time, (analog, vacuum)), = samples
    assert all(math.isnan(value) for value in analog) and vacuum == [1.0]
    result = controller.set_command(command(('flange_vacuum', ['vacuum'], [0.0]),
                                            ('flange_analog_IOs', ['analog_output1'], [3.3])))
    assert result is CommandResult.ACCEPTED
    update(controller, 0.01)  # publishes, then writes
    update(controller, 0.02)
    assert samples[1][1][1] == [1.0]
    assert samples[2][1][0][0] == 3.3 and samples[2][1][1] == [0.0]


def test_only_the_states_listed_are_published_when_some_are():
    params = {**EXAMPLE, 'state_interfaces': {'flange_analog_IOs': {'interfaces':
                                                                    ['analog_input2']}}}
    _manager, controller, _samples = active(params)
    assert controller.state_names == (('analog_input2',), ())


def test_without_command_interfaces_it_only_publishes():
    _manager, controller, _samples = active({'gpios': ['flange_vacuum']})
    assert [topic.name for topic in controller.ros_surface()] == ['~/gpio_states']
    assert controller.command_interfaces() == {}


@pytest.mark.parametrize(('value', 'problem'), [
    (command(('flange_vacuum', ['vacuum', 'vacuum2'], [0.0])),
     'for gpio flange_vacuum interface_names do not match values'),
    (command(('flange_vacuum', ['pump'], [0.0])),
     "'flange_vacuum/pump' is not a command interface of this controller"),
    (command(('flange_analog_IOs', ['analog_input1'], [1.0])),
     "'flange_analog_IOs/analog_input1' is not a command interface"),
    (command(('flange_vacuum', ['vacuum'], [math.inf])), 'is not a finite number'),
    ((['flange_vacuum'], []), '1 interface_groups but 0 interface_values'),
])
def test_a_bad_command_is_rejected_whole_and_nothing_changes(value, problem):
    _manager, controller, samples = active()
    assert controller.set_command(command(('flange_vacuum', ['vacuum'], [0.5]))) is \
        CommandResult.ACCEPTED
    assert controller.set_command(value) is CommandResult.REJECTED
    assert problem in controller.command_problem(value, CommandResult.REJECTED)
    update(controller, 0.0)
    update(controller, 0.01)
    assert samples[-1][1][1] == [0.5]
    assert math.isnan(samples[-1][1][0][0])


def test_activated_again_it_starts_without_a_command():
    manager, controller, samples = active()
    controller.set_command(command(('flange_vacuum', ['vacuum'], [0.0])))
    manager.switch([], ['gpio'])
    manager.switch(['gpio'])
    update(controller, 0.0)
    update(controller, 0.01)
    assert samples[-1][1][1] == [1.0]


def test_a_gpio_or_interface_the_robot_lacks_fails_at_configure_naming_the_field():
    manager = loaded('gpio', TYPE, {'gpios': ['flange_vacuum', 'tool_io']}, {},
                     example_10_gpios())
    with raises_naming('gpio.gpios'):
        manager.configure('gpio')
    manager = loaded('gpio', TYPE, {'gpios': ['flange_vacuum'], 'command_interfaces': {
        'flange_vacuum': {'interfaces': ['blow']}}}, {}, example_10_gpios())
    with raises_naming('gpio.command_interfaces.flange_vacuum.interfaces'):
        manager.configure('gpio')


def test_no_command_and_no_state_interface_at_all_is_refused():
    empty = hardware(gpios=[GpioHandle('dummy', [], [])])
    manager = loaded('gpio', TYPE, {'gpios': ['dummy']}, {}, empty)
    with raises_naming('gpio.gpios'):
        manager.configure('gpio')


def test_gpios_must_be_named_once_each():
    with raises_naming('gpio.gpios'):
        create_controller('gpio', TYPE, {'gpios': ['a', 'a']})
    with raises_naming('gpio.gpios'):
        create_controller('gpio', TYPE, {'gpios': []})
