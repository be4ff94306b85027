"""``range_sensor_broadcaster/RangeSensorBroadcaster``: a range sensor's reading on ``~/range``.

It reads ``<sensor_name>/range`` and publishes ``sensor_msgs/msg/Range``
stamped ``frame_id``, with the radiation type, field of view, range limits
and variance given (upstream copies them into every message and checks
nothing against them).  The simulation casts one ray along the sensor
frame's +x (see :mod:`pan_tilt_sim.sim.hardware`); nothing hit reads +inf.
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
    DOUBLE,
    INT,
    REQUIRED,
    STRING,
    Param,
    ParameterSpec,
    frame_id,
    not_empty,
)
from pan_tilt_sim.controllers.framework.shared_parameters import UPDATE_RATE
from pan_tilt_sim.controllers.framework.surface import Endpoint, StateTopic

RANGE_TOPIC = '~/range'
RANGE_MESSAGE = 'sensor_msgs/msg/Range'
MESSAGE_FIELDS = ('radiation_type', 'field_of_view', 'min_range', 'max_range', 'variance')


class RangeSensorBroadcaster(SensorBroadcaster):
    """Publishes a range sensor's distance with the limits and field of view given."""

    type_names = ('range_sensor_broadcaster/RangeSensorBroadcaster',)
    parameters = ParameterSpec([
        UPDATE_RATE,
        Param(SENSOR_NAME, STRING, REQUIRED, 'The sensor whose <sensor_name>/range is read.',
              (not_empty(),), read_only=True, example='sensor1'),
        Param(FRAME_ID, STRING, REQUIRED, 'The frame the reading is published in.',
              (frame_id(),), read_only=True, example='range_link'),
        Param('radiation_type', INT, 0, 'The radiation the sensor uses: 0 ultrasound, '
              '1 infrared.', read_only=True),
        Param('field_of_view', DOUBLE, 0.52, 'The arc the distance reading is valid for '
              '(rad).', read_only=True),
        Param('min_range', DOUBLE, 0.52, 'Minimum range value (m).', read_only=True),
        Param('max_range', DOUBLE, 4.0, 'Maximum range value (m).', read_only=True),
        Param('variance', DOUBLE, 0.0, 'Variance of the range value (m^2).', read_only=True),
    ])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._sensor = self.params[SENSOR_NAME]

    def interface_names(self) -> list[tuple[str, str]]:
        """Return ``<sensor_name>/range``."""
        return [(f'{self._sensor}/range', SENSOR_NAME)]

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the ``sensor_msgs/msg/Range`` publisher on ``~/range``."""
        fields = {FRAME_ID: self.frame_id}
        fields.update({field: self.params[field] for field in MESSAGE_FIELDS})
        return (StateTopic(RANGE_TOPIC, RANGE_MESSAGE, self.connect(RANGE_TOPIC), fields),)

    def take_sample(self, time: float, values: Sequence[float]) -> None:
        """Hand ``sink(time, range)`` the distance (m)."""
        sink = self.sink(RANGE_TOPIC)
        if sink is not None:
            sink(time, values[0])
