"""The robot's kinematic tree from its URDF: joint origins, axes, link transforms.

What robot_state_publisher computes, without ROS: each joint's transform
from its parent link to its child link is the joint's ``<origin>`` followed
by the joint's motion (a rotation about ``<axis>`` for revolute and
continuous joints, a translation along it for prismatic ones).  Rotations
are unit quaternions ``(x, y, z, w)``, as in ``geometry_msgs``.  Plain
Python floats throughout: the tree is small and this runs at tens of Hz,
not in the physics loop.

It also measures how far a link's visual geometry reaches along the link's
+z axis, which is where the camera sits (see :mod:`pan_tilt_sim.camera`).
"""

from __future__ import annotations

import dataclasses
import math
import xml.etree.ElementTree as ElementTree
from collections.abc import Iterable, Mapping

Vector = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]  # x, y, z, w

IDENTITY_ROTATION: Quaternion = (0.0, 0.0, 0.0, 1.0)
ZERO_VECTOR: Vector = (0.0, 0.0, 0.0)
DEFAULT_AXIS: Vector = (1.0, 0.0, 0.0)  # URDF's default joint axis
ROTATING_KINDS = ('revolute', 'continuous')
SLIDING_KINDS = ('prismatic',)
FIXED_KIND = 'fixed'


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


@dataclasses.dataclass(frozen=True)
class KinematicJoint:
    """One URDF joint as the kinematic tree needs it."""

    name: str
    kind: str
    parent: str
    child: str
    origin: Transform
    axis: Vector = DEFAULT_AXIS

    @property
    def is_fixed(self) -> bool:
        """Whether the joint never moves (its transform is constant)."""
        return self.kind not in ROTATING_KINDS + SLIDING_KINDS

    def transform(self, position: float = 0.0) -> Transform:
        """Return the parent-to-child transform at joint ``position`` (rad or m)."""
        if self.kind in ROTATING_KINDS:
            return self.origin.then(
                Transform(rotation=quaternion_from_axis_angle(self.axis, position)))
        if self.kind in SLIDING_KINDS:
            ax, ay, az = self.axis
            return self.origin.then(Transform(translation=(ax * position, ay * position,
                                                           az * position)))
        return self.origin


@dataclasses.dataclass(frozen=True)
class KinematicTree:
    """The joints of a URDF, parents before children, and its root link."""

    root: str
    joints: tuple[KinematicJoint, ...]

    @property
    def fixed_joints(self) -> tuple[KinematicJoint, ...]:
        """Joints whose transform is constant (for /tf_static)."""
        return tuple(joint for joint in self.joints if joint.is_fixed)

    @property
    def moving_joints(self) -> tuple[KinematicJoint, ...]:
        """Joints whose transform follows the joint position (for /tf)."""
        return tuple(joint for joint in self.joints if not joint.is_fixed)

    def link_poses(self, positions: Mapping[str, float]) -> dict[str, Transform]:
        """Return every link's pose in the root link's frame; missing positions count as 0."""
        poses = {self.root: Transform()}
        for joint in self.joints:  # parents come first
            poses[joint.child] = poses[joint.parent].then(
                joint.transform(positions.get(joint.name, 0.0)))
        return poses


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


def parse_kinematics(urdf_xml: str) -> KinematicTree:
    """Read the joints of a URDF (already checked by the description layer) into a tree."""
    root_element = ElementTree.fromstring(urdf_xml)
    joints = {}
    for element in root_element.findall('joint'):
        parent = element.find('parent')
        child = element.find('child')
        if parent is None or child is None:
            continue
        joints[child.get('link', '')] = KinematicJoint(
            name=element.get('name', ''),
            kind=element.get('type', FIXED_KIND),
            parent=parent.get('link', ''),
            child=child.get('link', ''),
            origin=_origin(element.find('origin')),
            axis=_vector(element.find('axis'), 'xyz', DEFAULT_AXIS))
    links = [link.get('name', '') for link in root_element.findall('link')]
    roots = [link for link in links if link not in joints] or links[:1]
    root = roots[0] if roots else ''
    return KinematicTree(root=root, joints=tuple(_parents_first(root, joints)))


def link_reach(urdf_xml: str, link: str) -> float:
    """Return how far the link's visual geometry reaches along the link's +z (0 if none).

    Boxes, cylinders and spheres count (a cylinder as its bounding box);
    meshes, whose size is unknown here, are ignored.
    """
    root_element = ElementTree.fromstring(urdf_xml)
    reach = 0.0
    for element in root_element.findall('link'):
        if element.get('name') != link:
            continue
        for visual in element.findall('visual'):
            half = _half_extents(visual.find('geometry'))
            if half is None:
                continue
            origin = _origin(visual.find('origin'))
            # Half-extent of the rotated box along the link's z: |R[2,:]| . half.
            row = rotation_matrix(origin.rotation)[2]
            extent = sum(abs(r) * h for r, h in zip(row, half, strict=True))
            reach = max(reach, origin.translation[2] + extent)
    return reach


def link_names(urdf_xml: str) -> tuple[str, ...]:
    """Return the names of the URDF's links, in file order."""
    return tuple(link.get('name', '') for link in ElementTree.fromstring(urdf_xml).findall('link'))


def _parents_first(root: str, by_child: dict[str, KinematicJoint]) -> list[KinematicJoint]:
    children: dict[str, list[KinematicJoint]] = {}
    for joint in by_child.values():
        children.setdefault(joint.parent, []).append(joint)
    ordered = []
    pending = [root]
    while pending:
        link = pending.pop(0)
        for joint in children.get(link, ()):
            ordered.append(joint)
            pending.append(joint.child)
    return ordered


def _origin(element: ElementTree.Element | None) -> Transform:
    if element is None:
        return Transform()
    return Transform(_vector(element, 'xyz', ZERO_VECTOR),
                     quaternion_from_rpy(*_vector(element, 'rpy', ZERO_VECTOR)))


def _vector(element: ElementTree.Element | None, attribute: str, default: Vector) -> Vector:
    if element is None or element.get(attribute) is None:
        return default
    try:
        x, y, z = (float(value) for value in element.get(attribute, '').split())
    except ValueError:
        return default
    return (x, y, z)


def _half_extents(geometry: ElementTree.Element | None) -> Vector | None:
    if geometry is None:
        return None
    box = geometry.find('box')
    if box is not None:
        sx, sy, sz = _vector(box, 'size', ZERO_VECTOR)
        return (sx / 2.0, sy / 2.0, sz / 2.0)
    cylinder = geometry.find('cylinder')
    if cylinder is not None:
        radius = float(cylinder.get('radius', 0.0))
        return (radius, radius, float(cylinder.get('length', 0.0)) / 2.0)
    sphere = geometry.find('sphere')
    if sphere is not None:
        radius = float(sphere.get('radius', 0.0))
        return (radius, radius, radius)
    return None
