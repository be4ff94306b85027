"""``imu_sensor_broadcaster/IMUSensorBroadcaster``: an IMU's readings on ``~/imu``.

It reads the ten state interfaces of ``sensor_name`` -- ``orientation.x`` ...
``orientation.w``, ``angular_velocity.x`` ... ``z``, ``linear_acceleration.x``
... ``z``, as upstream's IMUSensor semantic component claims them -- and
publishes ``sensor_msgs/msg/Imu`` stamped ``frame_id``, with the static
covariances given.  The simulation measures the IMU where the URDF places it
(or at ``frame_id``, when nothing in the URDF does; see
:mod:`pan_tilt_sim.sim.hardware`): orientation in the world, angular
velocity and specific force in the sensor frame (a resting IMU reads +9.81
m/s^2 up).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.broadcasters.sensor_broadcaster import (
    FRAME_ID,
    SENSOR_NAME,
    SensorBroadcaster,
)
from pan_tilt_sim.controllers.framework.parameter_spec import (
    DOUBLE_ARRAY,
    REQUIRED,
    STRING,
    Param,
    ParameterSpec,
    fixed_size,
    frame_id,
    not_empty,
)
from pan_tilt_sim.controllers.framework.shared_parameters import UPDATE_RATE
from pan_tilt_sim.controllers.framework.surface import Endpoint, StateTopic

INTERFACES = ('orientation.x', 'orientation.y', 'orientation.z', 'orientation.w',
              'angular_velocity.x', 'angular_velocity.y', 'angular_velocity.z',
              'linear_acceleration.x', 'linear_acceleration.y', 'linear_acceleration.z')
COVARIANCES = ('static_covariance_orientation', 'static_covariance_angular_velocity',
               'static_covariance_linear_acceleration')
IMU_TOPIC = '~/imu'
IMU_MESSAGE = 'sensor_msgs/msg/Imu'
ZERO_COVARIANCE = [0.0] * 9


class IMUSensorBroadcaster(SensorBroadcaster):
    """Publishes an IMU's orientation, angular velocity and linear acceleration."""

    type_names = ('imu_sensor_broadcaster/IMUSensorBroadcaster',)
    parameters = ParameterSpec([
        UPDATE_RATE,
        Param(SENSOR_NAME, STRING, REQUIRED, 'The sensor whose interfaces '
              '(<sensor_name>/orientation.x ... linear_acceleration.z) are read.',
              (not_empty(),), read_only=True, example='sensor1'),
        Param(FRAME_ID, STRING, REQUIRED, 'The frame the readings are published in.',
              (frame_id(),), read_only=True, example='imu_link'),
        *(Param(name, DOUBLE_ARRAY, ZERO_COVARIANCE,
                f'Static {name.removeprefix("static_covariance_").replace("_", " ")} '
                'covariance, row major about x, y, z.', (fixed_size(9),))
          for name in COVARIANCES),
    ])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._sensor = self.params[SENSOR_NAME]

    def interface_names(self) -> list[tuple[str, str]]:
        """Return the ten interfaces, orientation first."""
        return [(f'{self._sensor}/{interface}', SENSOR_NAME) for interface in INTERFACES]

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the ``sensor_msgs/msg/Imu`` publisher on ``~/imu``."""
        return (StateTopic(IMU_TOPIC, IMU_MESSAGE, self.connect(IMU_TOPIC),
                           {FRAME_ID: self.frame_id,
                            'covariances': tuple(tuple(self.params[name])
                                                 for name in COVARIANCES)}),)

    def take_sample(self, time: float, values: Sequence[float]) -> None:
        """Hand ``sink(time, orientation, angular_velocity, linear_acceleration)`` the readings."""
        sink = self.sink(IMU_TOPIC)
        if sink is not None:
            sink(time, values[:4], values[4:7], values[7:])
