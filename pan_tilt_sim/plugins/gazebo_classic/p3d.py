"""``libgazebo_ros_p3d.so`` as a unit of the simulation: a link's true pose and twist. No ROS.

Not a ros2_control controller: the simulation creates one per plugin the
URDF declares (:mod:`pan_tilt_sim.model.drive_plugins`) and updates it every
physics step; it is always active.  As the plugin, every ``1 / update_rate``
s of sim time (0: every step) and only while someone listens, it publishes
``nav_msgs/Odometry``: header frame ``frame_name``, child frame the link;
the link frame's pose and the twist of its origin (m, rad, m/s, rad/s) in
the world -- or, with ``frame_name`` a link, relative to that link (the
twist rotated into its axes) -- then ``xyz_offsets`` added to the position
and ``rpy_offsets`` turning the orientation; Gaussian noise of standard
deviation ``gaussian_noise`` on every twist component, and its variance on
the covariances' diagonals.  Pure Python: the simulation hands in the link
states (:meth:`GazeboP3d.set_link_state`).
"""

from __future__ import annotations

import random
from collections.abc import Callable, Mapping

from pan_tilt_sim.controllers.base import Controller, JointHandle
from pan_tilt_sim.controllers.surface import Endpoint, StateTopic
from pan_tilt_sim.model.drive_plugins import P3dPlugin
from pan_tilt_sim.model.transforms import (
    Transform,
    Vector,
    quaternion_from_rpy,
    quaternion_multiply,
    rotate,
)
from pan_tilt_sim.schedule import DUE_EPSILON

# A link's state: its frame in the world, the world velocity of the frame's origin (m/s)
# and its angular velocity (rad/s), both in world axes.
LinkState = tuple[Transform, Vector, Vector]
# sink(time, pose, linear, angular): a 3-D odometry sample.
SpatialOdometrySink = Callable[[float, Transform, Vector, Vector], None]


def _inverse(transform: Transform) -> Transform:
    x, y, z, w = transform.rotation
    conjugate = (-x, -y, -z, w)
    tx, ty, tz = rotate(conjugate, transform.translation)
    return Transform((-tx, -ty, -tz), conjugate)


class GazeboP3d(Controller):
    """One ``gazebo_ros_p3d`` plugin: ground-truth odometry of one link."""

    def __init__(self, plugin: P3dPlugin, source: str = '', *,
                 rng: random.Random | None = None) -> None:
        super().__init__(plugin.name, {}, source)
        self.plugin = plugin
        self._period = 1.0 / plugin.update_rate if plugin.update_rate > 0.0 else 0.0
        self._offset = quaternion_from_rpy(*plugin.rpy_offsets)
        self._rng = rng or random.Random()
        self._sink: SpatialOdometrySink | None = None
        self._link_state: Callable[[str], LinkState] | None = None
        self.reset()

    def set_link_state(self, source: Callable[[str], LinkState]) -> None:
        """Where the unit reads a link's state (by link name)."""
        self._link_state = source

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the odometry topic, as the plugin names it."""
        plugin = self.plugin
        variance = plugin.gaussian_noise ** 2
        return (StateTopic(plugin.topics(self.node_namespace.strip('/')),
                           'nav_msgs/msg/Odometry', self.set_odometry_sink,
                           {'frame_id': plugin.frame_name, 'child_frame_id': plugin.body_name,
                            'pose_covariance_diagonal': (variance,) * 6,
                            'twist_covariance_diagonal': (variance,) * 6, 'spatial': True}),)

    def set_odometry_sink(self, sink: SpatialOdometrySink | None) -> None:
        """Where samples go (None: nobody listens, none are taken)."""
        self._sink = sink

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Nothing to bind: the plugin reads a link, not joints."""
        self.reset()

    def reset(self) -> None:
        """Start the rate again from sim time 0."""
        self._last = 0.0

    def update(self, time: float, period: float) -> None:
        """Publish the link's state when due and watched."""
        if self._sink is None or self._link_state is None:
            return
        # As the plugin: not before the period is up, and never twice at one time.
        if time <= self._last or time - self._last + DUE_EPSILON < self._period:
            return
        self._last = time
        self._sink(time, *self.measure())

    def measure(self) -> tuple[Transform, Vector, Vector]:
        """Return the pose, linear and angular velocity the plugin would publish now."""
        plugin = self.plugin
        frame, linear, angular = self._link_state(plugin.body_name)
        if not plugin.in_world:
            reference, reference_linear, reference_angular = self._link_state(plugin.frame_name)
            inverse = _inverse(reference)
            frame = inverse.then(frame)
            linear = rotate(inverse.rotation, [a - b for a, b in zip(
                linear, reference_linear, strict=True)])
            angular = rotate(inverse.rotation, [a - b for a, b in zip(
                angular, reference_angular, strict=True)])
        x, y, z = frame.translation
        dx, dy, dz = plugin.xyz_offsets
        pose = Transform((x + dx, y + dy, z + dz),
                         quaternion_multiply(self._offset, frame.rotation))
        noise = plugin.gaussian_noise
        if noise > 0.0:
            gauss = self._rng.gauss
            linear = tuple(value + gauss(0.0, noise) for value in linear)
            angular = tuple(value + gauss(0.0, noise) for value in angular)
        return pose, tuple(linear), tuple(angular)  # type: ignore[return-value]
