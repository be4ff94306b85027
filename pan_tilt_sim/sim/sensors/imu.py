"""IMUs declared in the URDF: orientation, angular velocity, specific force. No ROS.

Read from the link states PyBullet computes (:mod:`.mount`) at the sensor's
place (its ``<pose>`` on the link):

* orientation: the sensor frame in the world (REP 145), or relative to its
  initial orientation when the plugin asks for that;
* angular velocity: the link's, in the sensor frame;
* linear acceleration: the specific force an accelerometer measures,
  ``R^T (a - g)`` with ``g = (0, 0, -9.81)``: a resting IMU reads +9.81 on
  its up axis.  ``a`` is the sensor point's acceleration over the last
  physics step, ``(v_k - v_{k-1}) / dt``: PyBullet integrates velocities
  first (semi-implicit Euler), so this difference is exactly the
  acceleration that step applied.  The caller stores ``v_{k-1}`` one step
  before each sample (:meth:`Imu.remember`); :meth:`Imu.read` without it
  takes the point to be at rest, so callers check :meth:`Imu.has_previous`.
  A velocity stored ``n`` steps before gives the mean acceleration over those
  steps, ``(v_k - v_{k-n}) / (n dt)`` (a reader sampling at a lower rate
  than the physics, as a ros2_control IMU read at the controller rate).
"""

from __future__ import annotations

import dataclasses

import numpy

from pan_tilt_sim.model.sensors import SensorSpec
from pan_tilt_sim.model.transforms import (
    Quaternion,
    quaternion_from_axis_angle,
    quaternion_multiply,
    rotation_matrix,
)
from pan_tilt_sim.sim.physics import STANDARD_GRAVITY, Physics
from pan_tilt_sim.sim.sensors.mount import LinkReader
from pan_tilt_sim.sim.sensors.noise import NoiseModel

GRAVITY = numpy.array((0.0, 0.0, -STANDARD_GRAVITY))


@dataclasses.dataclass(frozen=True)
class ImuReading:
    """One IMU sample: orientation (x, y, z, w), angular velocity, linear acceleration."""

    orientation: Quaternion
    angular_velocity: numpy.ndarray  # rad/s, sensor frame
    linear_acceleration: numpy.ndarray  # m/s^2, sensor frame, gravity included


def conjugate(q: Quaternion) -> Quaternion:
    """Return the inverse of a unit quaternion."""
    return (-q[0], -q[1], -q[2], q[3])


class Imu:
    """Samples an IMU on a link of the simulation."""

    def __init__(self, physics: Physics, sensor: SensorSpec, *,
                 orientation_from_start: bool = False,
                 angular_noise: NoiseModel | None = None,
                 linear_noise: NoiseModel | None = None,
                 orientation_stddev: float = 0.0,
                 rng: numpy.random.Generator | None = None) -> None:
        self.sensor = sensor
        self._orientation_stddev = orientation_stddev
        self._rng = rng if rng is not None else numpy.random.default_rng()
        self._link = LinkReader(physics, sensor.link)
        self._time_step = physics.time_step
        self._angular_noise = angular_noise
        self._linear_noise = linear_noise
        self._previous: tuple[int, numpy.ndarray] | None = None
        self._reference = (conjugate(self._pose_now()[0].rotation) if orientation_from_start
                           else None)

    def _pose_now(self):
        state = self._link.state()
        pose = state.frame.then(self.sensor.pose)
        return pose, state

    def _point_velocity(self) -> numpy.ndarray:
        pose, state = self._pose_now()
        return state.point_velocity(numpy.array(pose.translation))

    def remember(self, step: int) -> None:
        """Store the sensor point's velocity at physics step ``step`` (one before a sample)."""
        self._previous = (step, self._point_velocity())

    def has_previous(self, step: int) -> bool:
        """Whether the velocity of the step before ``step`` is stored."""
        return self._previous is not None and self._previous[0] == step - 1

    def has_earlier(self, step: int) -> bool:
        """Whether a velocity of any step before ``step`` is stored."""
        return self._previous is not None and self._previous[0] < step

    def forget(self) -> None:
        """Drop the stored velocity (the simulation was reset)."""
        self._previous = None

    def read(self, step: int) -> ImuReading:
        """Return the reading at physics step ``step``."""
        pose, state = self._pose_now()
        velocity = state.point_velocity(numpy.array(pose.translation))
        previous = self._previous
        if previous is not None and previous[0] < step:
            acceleration = (velocity - previous[1]) / ((step - previous[0]) * self._time_step)
        else:
            acceleration = numpy.zeros(3)
        self._previous = (step, velocity)
        rows = numpy.array(rotation_matrix(pose.rotation))  # sensor -> world
        angular = rows.T @ state.angular_velocity
        linear = rows.T @ (acceleration - GRAVITY)
        if self._angular_noise is not None:
            angular = self._angular_noise.apply(angular)
        if self._linear_noise is not None:
            linear = self._linear_noise.apply(linear)
        orientation = pose.rotation
        if self._reference is not None:
            orientation = quaternion_multiply(self._reference, orientation)
        if self._orientation_stddev > 0.0:
            # A small random rotation (rotation vector ~ N(0, stddev) per axis).
            vector = self._rng.normal(0.0, self._orientation_stddev, 3)
            angle = float(numpy.linalg.norm(vector))
            orientation = quaternion_multiply(
                quaternion_from_axis_angle(vector, angle), orientation)
        return ImuReading(orientation, angular, linear)
