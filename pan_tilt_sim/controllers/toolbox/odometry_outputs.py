"""Where a driving controller's odometry and its odom -> base transform go.

The ROS adapter gives each controller that declares an odometry or ``/tf``
state topic a sink for it (None: nobody listens, nothing is built).  What a
sink is called with is the controller's own contract: a planar sample
``sink(time, x, y, heading, linear, angular)`` or a spatial one
``sink(time, pose, linear, angular)``; the transform sink always takes
``sink(time, [(parent, child, transform)])``.  Pure Python.
"""

from __future__ import annotations

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
