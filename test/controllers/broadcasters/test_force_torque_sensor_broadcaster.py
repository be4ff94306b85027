"""ForceTorqueSensorBroadcaster (force_torque_sensor_broadcaster/), without a simulator.

Which interfaces it reads (sensor_name or interface_names, one of them), the
wrench it hands on (offset, then multiplied; NaN for an axis it does not
read), and what it does not simulate.
"""

import math

import pytest
from controller_fixtures import DT, FakeSource, hardware, loaded, raises_naming, sample_sink, sensor

from pan_tilt_sim.controllers import create_controller

TYPE = 'force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster'
WRENCH = ('force.x', 'force.y', 'force.z', 'torque.x', 'torque.y', 'torque.z')
READINGS = dict(zip(WRENCH, (1.0, 2.0, -19.62, 0.1, 0.2, 0.3), strict=True))


def sample(params, interfaces=WRENCH, readings=READINGS):
    source = FakeSource({name: readings[name] for name in interfaces})
    manager = loaded('fts', TYPE, params, {}, hardware(sensor('tcp_fts_sensor', interfaces,
                                                              source)))
    manager.configure('fts')
    controller = manager.controller('fts')
    samples = []
    (topic,) = controller.ros_surface()
    topic.connect(sample_sink(samples))
    controller.update(0.0, DT)
    return controller, topic, samples


def test_sensor_name_reads_its_six_standard_interfaces_into_force_and_torque():
    controller, topic, samples = sample({'sensor_name': 'tcp_fts_sensor', 'frame_id': 'tool0'})
    assert (topic.name, topic.message, topic.fields) == (
        '~/wrench', 'geometry_msgs/msg/WrenchStamped', {'frame_id': 'tool0'})
    assert samples == [(0.0, [1.0, 2.0, -19.62], [0.1, 0.2, 0.3])]
    assert controller.state_interfaces() == {'tcp_fts_sensor': WRENCH}


def test_interface_names_read_the_axes_named_and_the_others_are_nan():
    # ros2_control_demos' example 4: a 2D sensor, force.x and torque.z.
    _controller, _topic, samples = sample(
        {'interface_names': {'force': {'x': 'tcp_fts_sensor/force.x'},
                             'torque': {'z': 'tcp_fts_sensor/torque.z'}},
         'frame_id': 'tool_link'}, interfaces=('force.x', 'torque.z'))
    ((_, force, torque),) = samples
    assert force[0] == 1.0 and torque[2] == 0.3
    assert all(math.isnan(value) for value in (force[1], force[2], torque[0], torque[1]))


def test_each_value_is_offset_then_multiplied():
    _controller, _topic, samples = sample({
        'sensor_name': 'tcp_fts_sensor', 'frame_id': 'tool0',
        'offset': {'force': {'z': 19.62}, 'torque': {'x': 1.0}},
        'multiplier': {'force': {'x': -2.0}, 'torque': {'x': 10.0}}})
    ((_, force, torque),) = samples
    assert force == pytest.approx([-2.0, 2.0, 0.0])
    assert torque == pytest.approx([11.0, 0.2, 0.3])


@pytest.mark.parametrize(('params', 'field'), [
    ({'frame_id': 'tool0'}, 'fts.sensor_name'),
    ({'frame_id': 'tool0', 'sensor_name': 's',
      'interface_names': {'force': {'x': 's/force.x'}}}, 'fts.sensor_name'),
    ({'sensor_name': 's'}, 'fts.frame_id'),
    ({'sensor_name': 's', 'frame_id': ''}, 'fts.frame_id'),
])
def test_sensor_name_xor_interface_names_and_a_frame_id_must_be_given(params, field):
    with raises_naming(field):
        create_controller('fts', TYPE, params)


def test_an_interface_the_robot_lacks_fails_at_configure_naming_its_field():
    manager = loaded('fts', TYPE, {'interface_names': {'torque': {'y': 'tcp_fts_sensor/tq.y'}},
                                   'frame_id': 'tool0'}, {},
                     hardware(sensor('tcp_fts_sensor', WRENCH)))
    with raises_naming('fts.interface_names.torque.y'):
        manager.configure('fts')


def test_a_filter_chain_is_one_warning_that_it_is_not_simulated():
    controller = create_controller('fts', TYPE, {
        'sensor_name': 's', 'frame_id': 'tool0',
        'sensor_filter_chain': {'filter1': {'type': 'control_filters/LowPassFilterWrench',
                                            'name': 'low_pass', 'params': {'a': 1.0}}}},
        'f.yaml')
    assert controller.config_warnings == [
        'f.yaml: fts.sensor_filter_chain: filter chains are not simulated: '
        '~/wrench_filtered is not published']
