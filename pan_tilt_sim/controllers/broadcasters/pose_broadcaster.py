"""``pose_broadcaster/PoseBroadcaster``: a pose sensor's reading on ``~/pose`` and ``/tf``.

It reads the seven state interfaces of ``pose_name`` -- ``position.x`` ...
``position.z``, ``orientation.x`` ... ``orientation.w`` -- and publishes
``geometry_msgs/msg/PoseStamped`` stamped ``frame_id``; with ``tf.enable``
also the transform ``frame_id`` -> ``tf.child_frame_id`` (``pose_name`` if
empty) on ``/tf``, but only for a valid pose (finite, a unit quaternion
within 1e-2), as upstream: an invalid one is named in a notice instead.
``tf.publish_rate`` (deprecated upstream, warned about there too) limits
the transforms to that rate.  The simulation gives the sensor link's pose
in ``frame_id`` when that names a link, else in the world (see
:mod:`pan_tilt_sim.sim.hardware`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.broadcasters.sensor_broadcaster import FRAME_ID, SensorBroadcaster
from pan_tilt_sim.controllers.framework.parameter_spec import (
    BOOL,
    DOUBLE,
    REQUIRED,
    STRING,
    Param,
    ParameterSpec,
    frame_id,
    frame_id_or_empty,
    not_empty,
    rate,
)
from pan_tilt_sim.controllers.framework.shared_parameters import UPDATE_RATE
from pan_tilt_sim.controllers.framework.surface import Endpoint, StateTopic
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.schedule import PeriodicSchedule

POSE_NAME = 'pose_name'
INTERFACES = ('position.x', 'position.y', 'position.z',
              'orientation.x', 'orientation.y', 'orientation.z', 'orientation.w')
POSE_TOPIC = '~/pose'
POSE_MESSAGE = 'geometry_msgs/msg/PoseStamped'
TF_TOPIC = '/tf'
TF_MESSAGE = 'tf2_msgs/msg/TFMessage'
UNIT_TOLERANCE = 10e-3  # upstream's |q.q - 1| bound for a valid orientation


def is_valid_pose(values: Sequence[float]) -> bool:
    """Whether position and orientation are finite and the quaternion has unit length."""
    if not all(math.isfinite(value) for value in values):
        return False
    x, y, z, w = values[3:]
    return abs(x * x + y * y + z * z + w * w - 1.0) <= UNIT_TOLERANCE


class PoseBroadcaster(SensorBroadcaster):
    """Publishes a pose sensor's position and orientation, and (valid) as a transform."""

    type_names = ('pose_broadcaster/PoseBroadcaster',)
    parameters = ParameterSpec([
        UPDATE_RATE,
        Param(FRAME_ID, STRING, REQUIRED, 'The frame the pose is given in (and the '
              "transform's parent).", (frame_id(),), read_only=True, example='world'),
        Param(POSE_NAME, STRING, REQUIRED, 'The sensor whose interfaces '
              '(<pose_name>/position.x ... orientation.w) are read.', (not_empty(),),
              read_only=True, example='sensor1'),
        Param('tf.enable', BOOL, True, 'Also publish the pose as a transform on /tf.',
              read_only=True),
        Param('tf.child_frame_id', STRING, '', "The transform's child frame; pose_name "
              'if empty.', (frame_id_or_empty(),), read_only=True),
        Param('tf.publish_rate', DOUBLE, 0.0, 'Limit the transforms to this rate (Hz); 0: '
              'every sample (deprecated upstream).', (rate(zero_allowed=True),),
              read_only=True),
    ])

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._pose_name = self.params[POSE_NAME]
        tf = self.params['tf']
        self._tf = tf['enable']
        self._child = tf['child_frame_id'] or self._pose_name
        rate = tf['publish_rate']
        self._tf_schedule = PeriodicSchedule(1.0 / rate) if rate > 0.0 else None
        if rate > 0.0:
            self.config_warnings.append(
                f"{f'{source}: ' if source else ''}{name}.tf.publish_rate: deprecated, please "
                'set the value to 0.0: the publish rate of TF messages should not be limited')
        self._invalid_told = False

    def interface_names(self) -> list[tuple[str, str]]:
        """Return the seven interfaces, position first."""
        return [(f'{self._pose_name}/{interface}', POSE_NAME) for interface in INTERFACES]

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the ``~/pose`` publisher, and the ``/tf`` one with ``tf.enable``."""
        pose = StateTopic(POSE_TOPIC, POSE_MESSAGE, self.connect(POSE_TOPIC),
                          {FRAME_ID: self.frame_id})
        if not self._tf:
            return (pose,)
        return (pose, StateTopic(TF_TOPIC, TF_MESSAGE, self.connect(TF_TOPIC)))

    def reset(self) -> None:
        """Sample at the next update; transforms from then on too."""
        super().reset()
        if self._tf_schedule is not None:
            self._tf_schedule.reset()

    def take_sample(self, time: float, values: Sequence[float]) -> None:
        """Hand ``sink(time, position, orientation)`` the pose, and the transform if valid."""
        position, orientation = values[:3], values[3:]
        sink = self.sink(POSE_TOPIC)
        if sink is not None:
            sink(time, position, orientation)
        if not is_valid_pose(values):
            if not self._invalid_told:
                self._invalid_told = True
                self.notices.append(f'invalid pose {list(position)}, {list(orientation)}: '
                                    'no transform published')
            return
        self._invalid_told = False
        tf_sink = self.sink(TF_TOPIC)
        if tf_sink is None or (self._tf_schedule is not None
                               and not self._tf_schedule.take(time)):
            return
        # The /tf sink takes frames as (parent, child, transform), as every TF publisher's does.
        tf_sink(time, [(self.frame_id, self._child,
                        Transform(tuple(map(float, position)), tuple(map(float, orientation))))])
