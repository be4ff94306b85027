"""Cameras and depth cameras declared in the URDF, rendered with TinyRenderer. No ROS.

A Gazebo camera looks along its sensor frame's +x with +z up; the images are
given in the REP-103 optical frame (z forward, x right, y down) at the same
place (:func:`pan_tilt_sim.model.sensors.data_frame`).  Intrinsics: square
pixels, ``fx = fy = (width / 2) / tan(horizontal_fov / 2)``, principal point
``((width - 1) / 2, (height - 1) / 2)`` (pixel centres at integers), no
distortion -- as the parameter camera (:mod:`pan_tilt_sim.sim.camera`).

Depth comes from the renderer's depth buffer.  PyBullet's projection is
OpenGL's: a buffer value ``d`` in [0, 1] is ``z_ndc = 2 d - 1`` of a
perspective division, so the distance along the optical axis is
``z = far * near / (far - (far - near) * d)`` -- planar depth, what
sensor_msgs/Image depth images and point clouds carry (not the distance
along the pixel's ray).  Where nothing was drawn (``d = 1``, give or take the
renderer's rounding: :func:`~pan_tilt_sim.sim.camera.nothing_drawn`), a world with
a ground gives the depth of the ground plane z = 0 along the pixel's ray,
as the colour image paints it (see :mod:`pan_tilt_sim.sim.world`); else
there is nothing: ``+inf``.
"""

from __future__ import annotations

import dataclasses
import math

import numpy

from pan_tilt_sim.model.sensors import CameraSpec, SensorSpec, data_frame
from pan_tilt_sim.model.transforms import Transform, rotation_matrix
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.camera import (
    Intrinsics,
    centred_intrinsics,
    nothing_drawn,
    projection_matrix,
)
from pan_tilt_sim.sim.physics import Physics
from pan_tilt_sim.sim.sensors.mount import LinkReader
from pan_tilt_sim.sim.sensors.noise import NoiseModel
from pan_tilt_sim.sim.world import GROUND_RGB, has_ground

RGBA_CHANNELS = 4
RGB_CHANNELS = 3
BYTE_MAX = 255.0


def camera_intrinsics(camera: CameraSpec) -> Intrinsics:
    """Return the intrinsics of a Gazebo camera (square pixels, centred)."""
    return centred_intrinsics(camera.width, camera.height, camera.focal_length)


def linear_depth(buffer: numpy.ndarray, near: float, far: float) -> numpy.ndarray:
    """Return planar depth (m) from OpenGL depth-buffer values in [0, 1]."""
    return far * near / (far - (far - near) * buffer)


@dataclasses.dataclass(frozen=True)
class VisionFrame:
    """One rendering: rgb (height x width x 3, uint8) and planar depth (m, inf: nothing)."""

    rgb: numpy.ndarray
    depth: numpy.ndarray


class VisionSensor:
    """Renders a URDF camera's view from the simulation's client, as the physics has it now."""

    def __init__(self, physics: Physics, sensor: SensorSpec, world: str,
                 noise: NoiseModel | None = None, depth_noise: NoiseModel | None = None) -> None:
        camera = sensor.camera or CameraSpec()
        self.sensor = sensor
        self.camera = camera
        self.intrinsics = camera_intrinsics(camera)
        self._client = physics.client_id
        self._link = LinkReader(physics, sensor.link)
        self.mount = data_frame(sensor)  # the optical frame in the link frame
        self._ground = has_ground(world)
        self._noise = noise
        self._depth_noise = depth_noise
        self.near = camera.depth_near or camera.near
        self.far = camera.depth_far or camera.far
        intrinsics = self.intrinsics
        # Each pixel's viewing ray in optical axes: ((u - cx) / fx, (v - cy) / fy, 1).
        ray_x = (numpy.arange(camera.width) - intrinsics.cx) / intrinsics.fx
        ray_y = (numpy.arange(camera.height) - intrinsics.cy) / intrinsics.fy
        self.ray_x, self.ray_y = numpy.meshgrid(ray_x, ray_y)
        self._projection = projection_matrix(math.degrees(camera.vertical_fov), camera.width,
                                             camera.height, self.near, self.far, self._client)

    def optical_pose(self) -> Transform:
        """Return the optical frame's pose in the world, as the scene has it now."""
        return self._link.frame().then(self.mount)

    def render(self) -> VisionFrame:
        """Render colour and planar depth of the world as the physics has it now."""
        pose = self.optical_pose()
        rows = numpy.array(rotation_matrix(pose.rotation))
        eye = numpy.array(pose.translation)
        forward, down = rows[:, 2], rows[:, 1]
        view = pybullet.computeViewMatrix(eye.tolist(), (eye + forward).tolist(),
                                          (-down).tolist(), physicsClientId=self._client)
        camera = self.camera
        _, _, rgba, buffer, _ = pybullet.getCameraImage(
            camera.width, camera.height, view, self._projection,
            renderer=pybullet.ER_TINY_RENDERER, flags=pybullet.ER_NO_SEGMENTATION_MASK,
            physicsClientId=self._client)
        rgb = numpy.array(rgba, dtype=numpy.uint8).reshape(
            camera.height, camera.width, RGBA_CHANNELS)[:, :, :RGB_CHANNELS]
        buffer = numpy.asarray(buffer, dtype=numpy.float32).reshape(camera.height, camera.width)
        depth = linear_depth(buffer.astype(numpy.float64), self.near, self.far)
        empty = nothing_drawn(buffer)
        depth[empty] = math.inf
        if self._ground and empty.any():
            # World z of each pixel's ray (optical (x, y, 1)), and where it meets z = 0:
            # at depth -eye_z / ray_z, for rays pointing towards the plane.
            ray_z = rows[2, 0] * self.ray_x + rows[2, 1] * self.ray_y + rows[2, 2]
            sees_ground = empty & (ray_z * eye[2] < 0.0)
            rgb[sees_ground] = GROUND_RGB
            depth[sees_ground] = -eye[2] / ray_z[sees_ground]
        if self._noise is not None and self._noise.active:
            noisy = self._noise.apply(rgb.astype(numpy.float64) / BYTE_MAX)
            rgb = numpy.clip(numpy.rint(noisy * BYTE_MAX), 0, BYTE_MAX).astype(numpy.uint8)
        if self._depth_noise is not None and self._depth_noise.active:
            finite = numpy.isfinite(depth)
            depth[finite] = self._depth_noise.apply(depth[finite])
        return VisionFrame(rgb, depth)
