"""Lidars declared in the URDF (ray, gpu_ray, gpu_lidar, lidar): batched ray casts. No ROS.

Each beam is cast with PyBullet's ``rayTestBatch`` from ``range_min`` to
``range_max`` along its direction, against every collision shape in the
simulation's client: the robot's own links and the scenery's targets
(:mod:`pan_tilt_sim.sim.world`).  A beam that hits nothing and points down,
in a world with a ground, meets the ground plane z = 0 (the ground is no
body, see the world module); else it has no return: ``+inf`` (REP 117).

Directions in the sensor frame (Gazebo's): horizontal angle ``h`` about +z
from +x, vertical angle ``v`` up from the xy plane:
``(cos v cos h, cos v sin h, sin v)``.
"""

from __future__ import annotations

import math

import numpy

from pan_tilt_sim.model.sensors import RaySpec, SensorSpec
from pan_tilt_sim.model.transforms import rotation_matrix
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.physics import Physics
from pan_tilt_sim.sim.sensors.mount import LinkReader
from pan_tilt_sim.sim.sensors.noise import NoiseModel
from pan_tilt_sim.sim.world import has_ground

HIT_FRACTION = 2  # index of the hit fraction in one rayTestBatch result
NO_HIT = -1  # object id of a ray that hit nothing
# Rays one rayTestBatch call casts and answers.  PyBullet takes up to its
# MAX_RAY_INTERSECTION_BATCH_SIZE (16,384) rays a call but answers at most 16,383 of them
# (test/dependencies/test_pybullet_limits.py); a scan of more is cast in batches of this size.
MAX_BATCH = 16383


def beam_directions(ray: RaySpec) -> numpy.ndarray:
    """Return unit beam directions in the sensor frame: rows x columns x 3."""
    horizontal = numpy.array(ray.horizontal.angles())
    vertical = numpy.array(ray.vertical.angles())
    cos_v = numpy.cos(vertical)[:, numpy.newaxis]
    return numpy.stack([cos_v * numpy.cos(horizontal), cos_v * numpy.sin(horizontal),
                        numpy.sin(vertical)[:, numpy.newaxis] * numpy.ones_like(horizontal)],
                       axis=-1)


class Lidar:
    """Casts a URDF lidar's beams in the simulation's client, as the physics has it now."""

    def __init__(self, physics: Physics, sensor: SensorSpec, world: str,
                 noise: NoiseModel | None = None) -> None:
        self.sensor = sensor
        self.ray = sensor.ray or RaySpec(range_max=1.0)
        self._client = physics.client_id
        self._link = LinkReader(physics, sensor.link)
        self._ground = has_ground(world)
        self._noise = noise
        self.directions = beam_directions(self.ray)  # rows x columns x 3, sensor frame
        self._flat = self.directions.reshape(-1, 3)

    def scan(self) -> numpy.ndarray:
        """Return the ranges (m) of every beam, rows x columns; ``inf`` where nothing is hit."""
        ray = self.ray
        pose = self._link.frame().then(self.sensor.pose)
        rows = numpy.array(rotation_matrix(pose.rotation))
        origin = numpy.array(pose.translation)
        world = self._flat @ rows.T  # beam directions in the world
        starts = origin + world * ray.range_min
        ends = origin + world * ray.range_max
        fractions = numpy.empty(len(world))
        hit = numpy.empty(len(world), dtype=bool)
        for first in range(0, len(world), MAX_BATCH):
            last = first + MAX_BATCH
            results = pybullet.rayTestBatch(starts[first:last].tolist(),
                                            ends[first:last].tolist(),
                                            physicsClientId=self._client)
            fractions[first:last] = [result[HIT_FRACTION] for result in results]
            hit[first:last] = [result[0] != NO_HIT for result in results]
        ranges = numpy.where(hit, ray.range_min + fractions * (ray.range_max - ray.range_min),
                             math.inf)
        if self._ground and origin[2] > 0.0:
            with numpy.errstate(divide='ignore', invalid='ignore'):
                ground = -origin[2] / world[:, 2]
            meets = ~hit & (ground >= ray.range_min) & (ground <= ray.range_max)
            ranges[meets] = ground[meets]
        if self._noise is not None and self._noise.active:
            finite = numpy.isfinite(ranges)
            ranges[finite] = numpy.clip(self._noise.apply(ranges[finite]), ray.range_min,
                                        ray.range_max)
        return ranges.reshape(self.directions.shape[:2])
