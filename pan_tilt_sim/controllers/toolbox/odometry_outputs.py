"""Where a driving controller's odometry and its odom -> base transform go.

The ROS adapter gives each controller that declares an odometry or ``/tf``
state topic a sink for it (None: nobody listens, nothing is built).  What a
sink is called with is the controller's own contract: a planar sample
``sink(time, x, y, heading, linear, angular)`` or a spatial one
``sink(time, pose, linear, angular)``; the transform sink always takes
``sink(time, [(parent, child, transform)])``.  :meth:`OdometryOutputs.odometry_topic`
declares the odometry topic those sinks feed.  Pure Python.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from pan_tilt_sim.controllers.framework.surface import StateTopic
from pan_tilt_sim.model.transforms import Transform

# sink(time, [(parent, child, transform)])
TfSink = Callable[[float, list[tuple[str, str, Transform]]], None]
# The planar sample: sink(time, x, y, heading, linear, angular) in m, rad, m/s, rad/s.
OdometrySink = Callable[[float, float, float, float, float, float], None]
# The spatial sample: sink(time, pose, linear xyz, angular xyz) in m/s, rad/s.
SpatialOdometrySink = Callable[[float, Transform, Sequence[float], Sequence[float]], None]
# The command as limited: sink(time, linear, angular) in m/s, rad/s.
TwistSink = Callable[[float, float, float], None]


def planar_pose(x: float, y: float, heading: float) -> Transform:
    """Return the planar pose (m, m, rad): ``(x, y, 0)`` turned by ``heading`` about z."""
    return Transform((x, y, 0.0), (0.0, 0.0, math.sin(heading / 2.0), math.cos(heading / 2.0)))


class OdometryOutputs:
    """Mixin of the controllers that publish odometry: the two sinks and their setters."""

    _odometry_sink: Callable[..., None] | None = None
    _tf_sink: TfSink | None = None

    def set_odometry_sink(self, sink: Callable[..., None] | None) -> None:
        """Where odometry samples go, in the controller's own form (module docstring)."""
        self._odometry_sink = sink

    def set_tf_sink(self, sink: TfSink | None) -> None:
        """Where the odom -> base transform goes: ``sink(time, [(parent, child, transform)])``."""
        self._tf_sink = sink

    def publish_planar(self, time: float, x: float, y: float, heading: float, linear: float,
                       angular: float, frames: tuple[str, str], *, twist_only: bool = False,
                       tf: bool = True) -> None:
        """Send a planar sample to the odometry sink and ``frames`` (parent, child) to ``/tf``.

        For controllers whose odometry sink takes the planar form; the
        transform is ``(x, y, 0)`` turned by ``heading`` about z.
        ``twist_only``: the sample's pose is zero (the transform is not);
        ``tf``: False sends no transform.
        """
        if self._odometry_sink is not None:
            if twist_only:
                self._odometry_sink(time, 0.0, 0.0, 0.0, linear, angular)
            else:
                self._odometry_sink(time, x, y, heading, linear, angular)
        if tf and self._tf_sink is not None:
            self._tf_sink(time, [(frames[0], frames[1], planar_pose(x, y, heading))])

    def publish_spatial(self, time: float, x: float, y: float, heading: float,
                        linear: tuple[float, float], angular: float,
                        frames: tuple[str, str]) -> None:
        """Send a planar pose in the spatial form to the odometry sink, and to ``/tf``.

        For controllers whose odometry sink takes ``sink(time, pose, linear
        xyz, angular xyz)``; ``linear`` is the base frame's (x, y) velocity
        (m/s), ``angular`` its yaw rate (rad/s).
        """
        if self._odometry_sink is None and self._tf_sink is None:
            return
        pose = planar_pose(x, y, heading)
        if self._odometry_sink is not None:
            self._odometry_sink(time, pose, (linear[0], linear[1], 0.0), (0.0, 0.0, angular))
        if self._tf_sink is not None:
            self._tf_sink(time, [(frames[0], frames[1], pose)])

    def odometry_topic(self, topic: str, frames: tuple[str, str],
                       pose_covariance: Sequence[float], twist_covariance: Sequence[float],
                       **fields: Any) -> StateTopic:
        """Return the ``nav_msgs/msg/Odometry`` topic the odometry sink feeds.

        ``frames``: (frame_id, child_frame_id); the covariances are the
        diagonals (x, y, z, roll, pitch, yaw); ``fields``: more for the sink
        (``spatial=True`` for the spatial form).
        """
        return StateTopic(topic, 'nav_msgs/msg/Odometry', self.set_odometry_sink, {
            'frame_id': frames[0], 'child_frame_id': frames[1],
            'pose_covariance_diagonal': tuple(pose_covariance),
            'twist_covariance_diagonal': tuple(twist_covariance), **fields})
