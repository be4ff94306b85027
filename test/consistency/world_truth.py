"""What a sensor must read, computed from the world's shapes and the robot's true pose.

Plain numpy, written for the consistency suite and sharing nothing with the
simulation's sensor code: rigid poses as 4 x 4 matrices, analytic ray
intersections with boxes (slabs), vertical cylinders (the quadratic in x y,
plus the caps), spheres (the quadratic) and the ground plane z = 0.

A ray is ``origin + t * direction``; every function returns the smallest
``t >= 0`` at which the ray enters the shape, ``inf`` where it never does.
With a unit direction ``t`` is the distance; with an optical-frame direction
``(x, y, 1)`` rotated into the world it is the planar depth.  ``grow``
enlarges every shape by that much (negative: shrinks it), so that a sensor
whose beam grazes an edge can be held between the two truths.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy
from consistency_fixtures import Box, Cylinder, Sphere

INF = math.inf


def quaternion_matrix(q: Sequence[float]) -> numpy.ndarray:
    """Return the rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = (float(v) for v in q)
    return numpy.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def pose(translation: Sequence[float] = (0.0, 0.0, 0.0),
         rotation: numpy.ndarray | None = None) -> numpy.ndarray:
    """Return the 4 x 4 rigid transform of a translation and a rotation matrix."""
    matrix = numpy.eye(4)
    if rotation is not None:
        matrix[:3, :3] = rotation
    matrix[:3, 3] = translation
    return matrix


def about_z(angle: float) -> numpy.ndarray:
    """Return the rotation by ``angle`` (rad) about z."""
    c, s = math.cos(angle), math.sin(angle)
    return numpy.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def about_y(angle: float) -> numpy.ndarray:
    """Return the rotation by ``angle`` (rad) about y."""
    c, s = math.cos(angle), math.sin(angle)
    return numpy.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def yaw_of(matrix: numpy.ndarray) -> float:
    """Return the heading (rad) of a pose's x axis in the world's xy plane."""
    return math.atan2(matrix[1, 0], matrix[0, 0])


def angle_between(a: numpy.ndarray, b: numpy.ndarray) -> float:
    """Return the angle (rad) of the rotation between two poses' orientations."""
    relative = a[:3, :3].T @ b[:3, :3]
    return math.acos(max(-1.0, min(1.0, (numpy.trace(relative) - 1.0) / 2.0)))


# --- ray intersections ------------------------------------------------------------------------

def _entry(near: numpy.ndarray, far: numpy.ndarray) -> numpy.ndarray:
    """The entry distance of intervals [near, far], inf where empty or behind the ray."""
    hit = (far >= near) & (far >= 0.0)
    return numpy.where(hit, numpy.maximum(near, 0.0), INF)


def ray_box(origin: numpy.ndarray, directions: numpy.ndarray, box: Box,
            grow: float = 0.0) -> numpy.ndarray:
    """Slab test: where each ray enters an axis-aligned box."""
    low = numpy.array(box.low) - grow
    high = numpy.array(box.high) + grow
    with numpy.errstate(divide='ignore', invalid='ignore'):
        t1 = (low - origin) / directions
        t2 = (high - origin) / directions
    # A direction parallel to a slab: inside it for all t, or never.
    parallel = directions == 0.0
    inside = (origin >= low) & (origin <= high)
    t_low = numpy.where(parallel, numpy.where(inside, -INF, INF), numpy.minimum(t1, t2))
    t_high = numpy.where(parallel, numpy.where(inside, INF, -INF), numpy.maximum(t1, t2))
    return _entry(t_low.max(axis=-1), t_high.min(axis=-1))


def ray_cylinder(origin: numpy.ndarray, directions: numpy.ndarray, cylinder: Cylinder,
                 grow: float = 0.0) -> numpy.ndarray:
    """Where each ray enters a vertical cylinder (side, top and bottom caps)."""
    radius = cylinder.radius + grow
    bottom, top = cylinder.bottom - grow, cylinder.top + grow
    ox, oy = origin[0] - cylinder.centre[0], origin[1] - cylinder.centre[1]
    dx, dy, dz = directions[..., 0], directions[..., 1], directions[..., 2]
    a = dx * dx + dy * dy
    b = 2.0 * (ox * dx + oy * dy)
    c = ox * ox + oy * oy - radius * radius
    with numpy.errstate(divide='ignore', invalid='ignore'):
        root = numpy.sqrt(b * b - 4.0 * a * c)
        side_near = numpy.where(a > 0.0, (-b - root) / (2.0 * a), numpy.where(c <= 0, -INF, INF))
        side_far = numpy.where(a > 0.0, (-b + root) / (2.0 * a), numpy.where(c <= 0, INF, -INF))
        side_near = numpy.where(numpy.isnan(side_near), INF, side_near)
        side_far = numpy.where(numpy.isnan(side_far), -INF, side_far)
        t1 = (bottom - origin[2]) / dz
        t2 = (top - origin[2]) / dz
    flat = dz == 0.0
    between = (origin[2] >= bottom) & (origin[2] <= top)
    cap_near = numpy.where(flat, -INF if between else INF, numpy.minimum(t1, t2))
    cap_far = numpy.where(flat, INF if between else -INF, numpy.maximum(t1, t2))
    return _entry(numpy.maximum(side_near, cap_near), numpy.minimum(side_far, cap_far))


def ray_sphere(origin: numpy.ndarray, directions: numpy.ndarray, sphere: Sphere,
               grow: float = 0.0) -> numpy.ndarray:
    """Where each ray enters a sphere."""
    offset = origin - numpy.array(sphere.centre)
    a = (directions * directions).sum(axis=-1)
    b = 2.0 * (directions @ offset)
    c = offset @ offset - (sphere.radius + grow) ** 2
    discriminant = b * b - 4.0 * a * c
    with numpy.errstate(invalid='ignore'):
        root = numpy.sqrt(discriminant)
    near = numpy.where(discriminant >= 0.0, (-b - root) / (2.0 * a), INF)
    far = numpy.where(discriminant >= 0.0, (-b + root) / (2.0 * a), -INF)
    return _entry(near, far)


def ray_ground(origin: numpy.ndarray, directions: numpy.ndarray) -> numpy.ndarray:
    """Where each ray meets the ground plane z = 0 from above."""
    dz = directions[..., 2]
    with numpy.errstate(divide='ignore', invalid='ignore'):
        t = -origin[2] / dz
    return numpy.where((dz < 0.0) & (origin[2] > 0.0), t, INF)


def first_hits(origin: numpy.ndarray, directions: numpy.ndarray,
               shapes: Sequence[Box | Cylinder | Sphere], grow: float = 0.0,
               ground: bool = True) -> tuple[numpy.ndarray, numpy.ndarray]:
    """Return each ray's nearest hit and what it hits (index in ``shapes``; -1 the ground).

    ``inf`` and -2 where it hits nothing.
    """
    found = []
    for shape in shapes:
        if isinstance(shape, Box):
            found.append(ray_box(origin, directions, shape, grow))
        elif isinstance(shape, Cylinder):
            found.append(ray_cylinder(origin, directions, shape, grow))
        else:
            found.append(ray_sphere(origin, directions, shape, grow))
    found.append(ray_ground(origin, directions) if ground
                 else numpy.full(directions.shape[:-1], INF))
    stacked = numpy.stack(found)
    nearest = stacked.min(axis=0)
    which = numpy.argmin(stacked, axis=0)
    which = numpy.where(which == len(shapes), -1, which)
    return nearest, numpy.where(numpy.isfinite(nearest), which, -2)
