"""Where a driving controller's odometry and its odom -> base transform go.

The ROS adapter gives each controller that declares an odometry or ``/tf``
state topic a sink for it (None: nobody listens, nothing is built).  What a
sink is called with is the controller's own contract: a planar sample
``sink(time, x, y, heading, linear, angular)`` or a spatial one
``sink(time, pose, linear, angular)``; the transform sink always takes
``sink(time, [(parent, child, transform)])``.  Pure Python.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from pan_tilt_sim.model.transforms import Transform

# sink(time, [(parent, child, transform)])
TfSink = Callable[[float, list[tuple[str, str, Transform]]], None]
# The planar sample: sink(time, x, y, heading, linear, angular) in m, rad, m/s, rad/s.
OdometrySink = Callable[[float, float, float, float, float, float], None]
# The command as limited: sink(time, linear, angular) in m/s, rad/s.
TwistSink = Callable[[float, float, float], None]


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
                       angular: float, frames: tuple[str, str]) -> None:
        """Send a planar sample to the odometry sink and ``frames`` (parent, child) to ``/tf``.

        For controllers whose odometry sink takes the planar form; the
        transform is ``(x, y, 0)`` turned by ``heading`` about z.
        """
        if self._odometry_sink is not None:
            self._odometry_sink(time, x, y, heading, linear, angular)
        if self._tf_sink is not None:
            pose = Transform((x, y, 0.0), (0.0, 0.0, math.sin(heading / 2.0),
                                           math.cos(heading / 2.0)))
            self._tf_sink(time, [(frames[0], frames[1], pose)])
