"""RangeSensorBroadcaster (range_sensor_broadcaster/), without a simulator."""

import math

import pytest
from controller_fixtures import DT, FakeSource, hardware, loaded, raises_naming, sample_sink, sensor

from pan_tilt_sim.controllers import create_controller

TYPE = 'range_sensor_broadcaster/RangeSensorBroadcaster'


@pytest.mark.parametrize('missing', ['sensor_name', 'frame_id'])
def test_sensor_name_and_frame_id_must_be_given(missing):
    params = {'sensor_name': 'sonar', 'frame_id': 'sonar_link'}
    params[missing] = ''
    with raises_naming(f'range.{missing}'):
        create_controller('range', TYPE, params)


def test_a_sensor_without_a_range_interface_fails_at_configure_naming_sensor_name():
    manager = loaded('range', TYPE, {'sensor_name': 'sonar', 'frame_id': 'f'}, {},
                     hardware(sensor('sonar', ['distance'])))
    with raises_naming('range.sensor_name'):
        manager.configure('range')


def test_publishes_the_range_with_the_message_fields_given():
    source = FakeSource({'range': math.inf})
    manager = loaded('range', TYPE, {'sensor_name': 'sonar', 'frame_id': 'sonar_link',
                                     'radiation_type': 1, 'max_range': 2.0},
                     {}, hardware(sensor('sonar', ['range'], source)))
    manager.configure('range')
    controller = manager.controller('range')
    (topic,) = controller.ros_surface()
    assert (topic.name, topic.message) == ('~/range', 'sensor_msgs/msg/Range')
    assert topic.fields == {'frame_id': 'sonar_link', 'radiation_type': 1,
                            'field_of_view': 0.52, 'min_range': 0.52, 'max_range': 2.0,
                            'variance': 0.0}
    samples = []
    topic.connect(sample_sink(samples))
    controller.update(0.0, DT)
    assert samples == [(0.0, math.inf)]
