"""Rigid transforms and unit quaternions, as URDF and geometry_msgs use them. No ROS.

Rotations are unit quaternions ``(x, y, z, w)``, as in ``geometry_msgs``;
URDF's ``rpy`` is fixed-axis roll, pitch, yaw.  Plain Python floats
throughout: robots have tens of joints and this runs at tens of Hz, not in
the physics loop (PyBullet is not importable here: this is the model layer).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable

Vector = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]  # x, y, z, w

IDENTITY_ROTATION: Quaternion = (0.0, 0.0, 0.0, 1.0)
ZERO_VECTOR: Vector = (0.0, 0.0, 0.0)


@dataclasses.dataclass(frozen=True)
class Transform:
    """A rigid transform: rotate by ``rotation``, then translate by ``translation``."""

    translation: Vector = ZERO_VECTOR
    rotation: Quaternion = IDENTITY_ROTATION

    def apply(self, point: Iterable[float]) -> Vector:
        """Return ``point`` mapped by this transform."""
        x, y, z = rotate(self.rotation, point)
        tx, ty, tz = self.translation
        return (x + tx, y + ty, z + tz)

    def then(self, child: Transform) -> Transform:
        """Return ``self * child``: ``child``'s frame expressed in ``self``'s parent frame."""
        return Transform(self.apply(child.translation),
                         quaternion_multiply(self.rotation, child.rotation))


def quaternion_from_rpy(roll: float, pitch: float, yaw: float) -> Quaternion:
    """Return URDF's fixed-axis roll/pitch/yaw (Rz(yaw) Ry(pitch) Rx(roll)) as a quaternion."""
    cr, sr = math.cos(roll / 2.0), math.sin(roll / 2.0)
    cp, sp = math.cos(pitch / 2.0), math.sin(pitch / 2.0)
    cy, sy = math.cos(yaw / 2.0), math.sin(yaw / 2.0)
    return (sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


def quaternion_from_axis_angle(axis: Iterable[float], angle: float) -> Quaternion:
    """Return the rotation by ``angle`` (rad) about ``axis`` (any non-zero length)."""
    ax, ay, az = axis
    norm = math.sqrt(ax * ax + ay * ay + az * az)
    if norm == 0.0:
        return IDENTITY_ROTATION
    scale = math.sin(angle / 2.0) / norm
    return (ax * scale, ay * scale, az * scale, math.cos(angle / 2.0))


def quaternion_multiply(a: Quaternion, b: Quaternion) -> Quaternion:
    """Return the rotation ``a`` after ``b`` (Hamilton product ``a * b``)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def rotation_matrix(q: Quaternion) -> tuple[Vector, Vector, Vector]:
    """Return the 3x3 rotation matrix of ``q`` as rows."""
    x, y, z, w = q
    return ((1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
            (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
            (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)))


def rotate(q: Quaternion, vector: Iterable[float]) -> Vector:
    """Return ``vector`` rotated by ``q``."""
    vx, vy, vz = vector
    rows = rotation_matrix(q)
    return tuple(r[0] * vx + r[1] * vy + r[2] * vz for r in rows)  # type: ignore[return-value]


def quaternion_from_matrix(columns: tuple[Vector, Vector, Vector]) -> Quaternion:
    """Return the quaternion of the rotation whose matrix has these three columns."""
    (m00, m10, m20), (m01, m11, m21), (m02, m12, m22) = columns
    trace = m00 + m11 + m22
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        return ((m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s)
    if m00 >= m11 and m00 >= m22:
        s = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        return (0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s)
    if m11 >= m22:
        s = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        return ((m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s)
    s = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
    return ((m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s)
