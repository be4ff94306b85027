"""``force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster``: a wrench on ``~/wrench``.

It reads six state interfaces -- ``<sensor_name>/force.x`` ... ``torque.z``,
or those ``interface_names.force.x`` ... ``interface_names.torque.z`` name
(an axis left out reads NaN, as upstream's semantic component has it) -- and
publishes ``geometry_msgs/msg/WrenchStamped`` stamped ``frame_id``, each
value ``(reading + offset) * multiplier`` as upstream applies them.  Exactly
one of ``sensor_name`` and ``interface_names`` must be given.

The simulation places a sensor the URDF does not place at ``frame_id``, and
gives the wrench in ``frame_id`` when that names a link (see
:mod:`pan_tilt_sim.sim.hardware`).  Filter chains (``sensor_filter_chain``,
``~/wrench_filtered``) are not simulated; the chainable mode is not either.
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
    REQUIRED,
    STRING,
    Param,
    ParameterSpec,
    frame_id,
)
from pan_tilt_sim.controllers.framework.shared_parameters import UPDATE_RATE
from pan_tilt_sim.controllers.framework.surface import Endpoint, StateTopic

AXES = ('force.x', 'force.y', 'force.z', 'torque.x', 'torque.y', 'torque.z')
INTERFACE_NAMES = 'interface_names'
FILTER_CHAIN = 'sensor_filter_chain'
WRENCH_TOPIC = '~/wrench'
WRENCH_MESSAGE = 'geometry_msgs/msg/WrenchStamped'


def _dotted(values: Mapping[str, Any], name: str) -> Any:
    """Return the checked parameter at dotted ``name`` (every one here has a default)."""
    node: Any = values
    for segment in name.split('.'):
        node = node[segment]
    return node


def _axis_params() -> list[Param]:
    params = []
    for axis in AXES:
        quantity, _, direction = axis.partition('.')
        about = 'around' if quantity == 'torque' else 'on'
        params.append(Param(f'{INTERFACE_NAMES}.{axis}', STRING, '',
                            f"The state interface with the {quantity} {about} '{direction}'.",
                            read_only=True))
    for axis in AXES:
        params.append(Param(f'offset.{axis}', DOUBLE, 0.0, f'Added to {axis}.'))
    for axis in AXES:
        params.append(Param(f'multiplier.{axis}', DOUBLE, 1.0,
                            f'Multiplies {axis} (after the offset).'))
    return params


class ForceTorqueSensorBroadcaster(SensorBroadcaster):
    """Publishes a force-torque sensor's wrench, offset and scaled, in ``frame_id``."""

    type_names = ('force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster',)
    parameters = ParameterSpec([
        UPDATE_RATE,
        Param(FRAME_ID, STRING, REQUIRED, 'The frame the wrench is published in (the '
              'simulation gives it there when it names a link).', (frame_id(),),
              read_only=True, example='tool0'),
        Param(SENSOR_NAME, STRING, '', 'The sensor whose six standard interfaces '
              '(<sensor_name>/force.x ... torque.z) are read; or give interface_names.',
              read_only=True, example='sensor1'),
        *_axis_params(),
    ])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._drop_filter_chain_warnings(source)
        sensor = self.params[SENSOR_NAME]
        named = {axis: _dotted(self.params, f'{INTERFACE_NAMES}.{axis}') for axis in AXES}
        if not sensor and not any(named.values()):
            raise self.error(SENSOR_NAME, "'sensor_name' or at least one "
                             "'interface_names.[force|torque].[x|y|z]' parameter has to be "
                             'specified')
        if sensor and any(named.values()):
            raise self.error(SENSOR_NAME, "both 'sensor_name' and "
                             "'interface_names.[force|torque].[x|y|z]' parameters can not be "
                             'specified together')
        if sensor:
            self._names = [(f'{sensor}/{axis}', SENSOR_NAME) for axis in AXES]
        else:
            self._names = [(named[axis], f'{INTERFACE_NAMES}.{axis}') for axis in AXES]
        self._offsets = [_dotted(self.params, f'offset.{axis}') for axis in AXES]
        self._multipliers = [_dotted(self.params, f'multiplier.{axis}') for axis in AXES]

    def _drop_filter_chain_warnings(self, source: str) -> None:
        """One warning for the whole filter chain, instead of one per unknown key of it."""
        key = f"{f'{source}: ' if source else ''}{self.name}.{FILTER_CHAIN}"
        kept = [line for line in self.config_warnings if not line.startswith(key)]
        if len(kept) != len(self.config_warnings):
            kept.append(f'{key}: filter chains are not simulated: ~/wrench_filtered is not '
                        'published')
        self.config_warnings[:] = kept

    def interface_names(self) -> list[tuple[str, str]]:
        """Return the six interfaces (force x, y, z, torque x, y, z); '' for an axis left out."""
        return list(self._names)

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the ``geometry_msgs/msg/WrenchStamped`` publisher on ``~/wrench``."""
        return (StateTopic(WRENCH_TOPIC, WRENCH_MESSAGE, self.connect(WRENCH_TOPIC),
                           {FRAME_ID: self.frame_id}),)

    def take_sample(self, time: float, values: Sequence[float]) -> None:
        """Hand ``sink(time, force, torque)`` the wrench, offset and scaled."""
        sink = self.sink(WRENCH_TOPIC)
        if sink is None:
            return
        wrench = [(value + offset) * multiplier for value, offset, multiplier
                  in zip(values, self._offsets, self._multipliers, strict=True)]
        sink(time, wrench[:3], wrench[3:])
