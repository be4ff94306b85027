"""hardware_interfaces: the sensor and gpio interfaces controllers and the simulation share."""

import math

from controller_fixtures import FakeSource, sensor

from pan_tilt_sim.controllers.framework.hardware_interfaces import (
    CommandInterface,
    GpioHandle,
    HardwareInterfaces,
    StateInterface,
    example_hardware,
)


def test_an_interface_starts_at_its_initial_value_else_nan_and_resets_to_it():
    given, none = StateInterface('io/in', 2.5), StateInterface('io/out')
    assert given.value == 2.5 and math.isnan(none.value)
    given.value = 7.0
    given.reset()
    assert given.value == 2.5


def test_a_finite_command_is_echoed_into_its_state_and_nan_leaves_the_state_alone():
    state = StateInterface('io/vacuum', 1.0)
    command = CommandInterface('io/vacuum', echo=state)
    assert math.isnan(command.value)
    command.write(0.0)
    assert (command.value, state.value) == (0.0, 0.0)
    command.write(math.nan)
    assert state.value == 0.0
    lone = CommandInterface('io/lamp')
    lone.write(1.0)
    assert lone.value == 1.0


def test_interfaces_are_found_by_full_name_and_sensor_interfaces_lead_to_their_sensor():
    fts = sensor('fts', ['force.x', 'torque.z'])
    state = StateInterface('io/out', 0.0)
    io = GpioHandle('io', [CommandInterface('io/out', state)], [state, StateInterface('io/in')])
    found = HardwareInterfaces([fts], [io])
    assert list(found.state_interfaces) == ['fts/force.x', 'fts/torque.z', 'io/out', 'io/in']
    assert list(found.command_interfaces) == ['io/out']
    assert found.sensor_of('fts/torque.z') is fts
    assert found.sensor_of('io/in') is None


def test_the_source_hears_only_when_the_first_reader_comes_and_the_last_one_goes():
    source = FakeSource()
    handle = sensor('fts', ['force.x'], source)
    first, second = object(), object()
    handle.watch(first, True)
    assert source.watched
    handle.watch(second, True)
    handle.watch(first, False)
    assert source.watched
    handle.watch(second, False)
    assert not source.watched


def test_without_a_source_a_sensor_keeps_its_values_and_counts_as_fresh():
    handle = sensor('thermo', ['temperature'])
    assert handle.refresh(0.5)
    assert math.isnan(handle.interfaces['temperature'].value)
    assert handle.use_frame('anything') is None


def test_a_reset_puts_every_value_back_and_tells_the_sources():
    source = FakeSource({'force.x': 3.0})
    fts = sensor('fts', ['force.x'], source)
    state = StateInterface('io/out', 1.0)
    command = CommandInterface('io/out', state)
    found = HardwareInterfaces([fts], [GpioHandle('io', [command], [state])])
    fts.refresh(0.0)
    command.write(0.0)
    found.reset()
    assert math.isnan(fts.interfaces['force.x'].value)
    assert (math.isnan(command.value), state.value) == (True, 1.0)
    assert source.resets == 1


def test_the_example_hardware_has_every_interface_the_broadcasters_read():
    example = example_hardware()
    assert {'sensor1/force.x', 'sensor1/orientation.w', 'sensor1/linear_acceleration.z',
            'sensor1/position.z', 'sensor1/range'} <= set(example.state_interfaces)
    assert list(example.command_interfaces) == ['gpio1/output1']
