"""IMUSensorBroadcaster (imu_sensor_broadcaster/), without a simulator."""

import pytest
from controller_fixtures import DT, FakeSource, hardware, loaded, raises_naming, sample_sink, sensor

from pan_tilt_sim.controllers import create_controller

TYPE = 'imu_sensor_broadcaster/IMUSensorBroadcaster'
IMU = ('orientation.x', 'orientation.y', 'orientation.z', 'orientation.w',
       'angular_velocity.x', 'angular_velocity.y', 'angular_velocity.z',
       'linear_acceleration.x', 'linear_acceleration.y', 'linear_acceleration.z')
AT_REST = dict(zip(IMU, (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.5, 0.0, 0.0, 9.81), strict=True))


def test_publishes_orientation_angular_velocity_and_acceleration_with_the_covariances():
    covariance = [0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01]
    tilt = [0.05, 0, 0, 0, 0.05, 0, 0, 0, 0.1]
    manager = loaded('imu', TYPE, {'sensor_name': 'imu_sensor', 'frame_id': 'imu_link',
                                   'static_covariance_orientation': tilt,
                                   'static_covariance_angular_velocity': covariance}, {},
                     hardware(sensor('imu_sensor', IMU, FakeSource(AT_REST))))
    manager.configure('imu')
    controller = manager.controller('imu')
    (topic,) = controller.ros_surface()
    assert (topic.name, topic.message) == ('~/imu', 'sensor_msgs/msg/Imu')
    assert topic.fields['frame_id'] == 'imu_link'
    assert topic.fields['covariances'] == (tuple(tilt), tuple(covariance), (0.0,) * 9)
    samples = []
    topic.connect(sample_sink(samples))
    controller.update(0.0, DT)
    assert samples == [(0.0, [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.5], [0.0, 0.0, 9.81])]
    assert controller.state_interfaces() == {'imu_sensor': IMU}


def test_a_sensor_lacking_one_of_the_ten_interfaces_fails_at_configure():
    manager = loaded('imu', TYPE, {'sensor_name': 'imu_sensor', 'frame_id': 'imu_link'}, {},
                     hardware(sensor('imu_sensor', IMU[:7])))
    with raises_naming('imu.sensor_name'):
        manager.configure('imu')


@pytest.mark.parametrize(('params', 'field'), [
    ({'frame_id': 'imu_link'}, 'imu.sensor_name'),
    ({'sensor_name': 'imu_sensor'}, 'imu.frame_id'),
    ({'sensor_name': 'imu_sensor', 'frame_id': 'imu_link',
      'static_covariance_orientation': [0.0] * 3}, 'imu.static_covariance_orientation'),
])
def test_missing_names_and_a_covariance_of_the_wrong_size_are_refused(params, field):
    with raises_naming(field):
        create_controller('imu', TYPE, params)
