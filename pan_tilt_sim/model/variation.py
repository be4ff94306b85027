"""Physical variations of a robot: heavier links, stiffer joints, a payload -- for robustness runs.

:func:`vary_description` returns a copy of a :class:`RobotDescription` in
which the robot model *and* PyBullet's copy of the URDF (``physics_urdf``)
say the same changed thing, so whatever the simulation reads -- the model's
joint friction, PyBullet's URDF damping, the links' inertials -- it sees
the variation:

* ``mass_scale`` multiplies every link's mass and its inertia tensor (the
  same shape, denser);
* ``inertia_scale`` multiplies every inertia tensor alone;
* ``friction_scale`` and ``damping_scale`` multiply every joint's URDF
  ``<dynamics friction=... damping=...>``;
* ``payload`` adds a point mass (a 1 cm solid sphere, so the tensor is never
  singular) at a point of a link: the link's inertial becomes the combined
  body (mass added, centre of mass moved, inertia by the parallel-axis
  theorem), expressed in the link frame.

Design notes: docs/design/model.md#variationpy.
"""

from __future__ import annotations

import dataclasses
import math
import xml.etree.ElementTree as ElementTree

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.model.robot import Inertial, JointSpec, Link
from pan_tilt_sim.model.transforms import ZERO_VECTOR, Transform, Vector, rotation_matrix
from pan_tilt_sim.model.urdf import inertial_beyond_bounds

INERTIA_FIELDS = ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz')
PAYLOAD_RADIUS_M = 0.01  # the payload is a solid sphere this big
SOLID_SPHERE_FACTOR = 0.4  # I = 2/5 m r^2
Matrix = tuple[Vector, Vector, Vector]


@dataclasses.dataclass(frozen=True)
class Payload:
    """A mass (kg) fixed to ``link`` at ``offset`` (m, in the link frame)."""

    link: str
    mass: float
    offset: Vector = ZERO_VECTOR


@dataclasses.dataclass(frozen=True)
class PhysicalVariation:
    """Factors on the robot's physical parameters (1 = as written) and an optional payload."""

    mass_scale: float = 1.0
    inertia_scale: float = 1.0
    friction_scale: float = 1.0
    damping_scale: float = 1.0
    payload: Payload | None = None

    def __post_init__(self) -> None:
        for field in ('mass_scale', 'inertia_scale', 'friction_scale', 'damping_scale'):
            value = getattr(self, field)
            if not (math.isfinite(value) and value >= 0.0):
                raise DescriptionError(f'{field}: {value!r} must be a finite number >= 0')
        for field in ('mass_scale', 'inertia_scale'):
            if getattr(self, field) == 0.0:
                raise DescriptionError(f'{field}: 0 would leave links without mass or inertia')
        if self.payload is not None and not (
                math.isfinite(self.payload.mass) and self.payload.mass >= 0.0
                and all(math.isfinite(v) for v in self.payload.offset)):
            raise DescriptionError(
                f'payload: mass {self.payload.mass!r} kg at {self.payload.offset!r} must be '
                'finite and >= 0')

    @property
    def is_nominal(self) -> bool:
        """Whether this variation changes nothing."""
        scales = (self.mass_scale, self.inertia_scale, self.friction_scale, self.damping_scale)
        return all(scale == 1.0 for scale in scales) and (
            self.payload is None or self.payload.mass == 0.0)


def vary_description(description: RobotDescription,
                     variation: PhysicalVariation) -> RobotDescription:
    """Return ``description`` with ``variation`` applied to its model and PyBullet's URDF."""
    if variation.is_nominal:
        return description
    model = description.model
    payload = variation.payload
    if payload is not None and payload.link not in model.link_names:
        raise DescriptionError(
            f"{description.source}: payload link '{payload.link}' is not a link of the robot "
            f"(links: {', '.join(model.link_names)})")
    links = tuple(_vary_link(link, variation) for link in model.links)
    for link in links:
        problem = '' if link.inertial is None else inertial_beyond_bounds(link.inertial)
        if problem:
            raise DescriptionError(f"{description.source}: the variation makes link "
                                   f"'{link.name}': {problem}")
    joints = tuple(_vary_joint(joint, variation) for joint in model.joints)
    root = ElementTree.fromstring(description.physics_urdf)
    for link, element in zip(links, _children(root, 'link', model.link_names), strict=True):
        _write_inertial(element, link.inertial, rewrite=payload is not None
                        and link.name == payload.link)
    for joint, element in zip(joints, _children(root, 'joint', model.joint_names), strict=True):
        _write_dynamics(element, joint)
    return dataclasses.replace(
        description, model=dataclasses.replace(model, links=links, joints=joints),
        physics_urdf=ElementTree.tostring(root, encoding='unicode'))


def _vary_link(link: Link, variation: PhysicalVariation) -> Link:
    inertial = link.inertial
    if inertial is not None:
        tensor = variation.mass_scale * variation.inertia_scale
        inertial = dataclasses.replace(
            inertial, mass=inertial.mass * variation.mass_scale,
            **{field: getattr(inertial, field) * tensor for field in INERTIA_FIELDS})
    payload = variation.payload
    if payload is not None and payload.link == link.name and payload.mass > 0.0:
        inertial = combined_inertial(inertial, payload.mass, payload.offset)
    return dataclasses.replace(link, inertial=inertial)


def _vary_joint(joint: JointSpec, variation: PhysicalVariation) -> JointSpec:
    return dataclasses.replace(joint, friction=joint.friction * variation.friction_scale,
                               damping=joint.damping * variation.damping_scale)


def combined_inertial(inertial: Inertial | None, mass: float, point: Vector) -> Inertial:
    """Return ``inertial`` with a small solid sphere of ``mass`` at ``point`` added (link frame).

    The result's frame is at the combined centre of mass, axes along the link's.
    """
    sphere = SOLID_SPHERE_FACTOR * mass * PAYLOAD_RADIUS_M ** 2
    bodies = [(mass, point, ((sphere, 0.0, 0.0), (0.0, sphere, 0.0), (0.0, 0.0, sphere)))]
    if inertial is not None and inertial.mass > 0.0:
        bodies.append((inertial.mass, inertial.origin.translation, _link_frame_tensor(inertial)))
    total = sum(body[0] for body in bodies)
    centre = tuple(sum(m * c[axis] for m, c, _ in bodies) / total for axis in range(3))
    tensor = [[0.0] * 3 for _ in range(3)]
    for body_mass, body_centre, body_tensor in bodies:
        d = [body_centre[axis] - centre[axis] for axis in range(3)]
        squared = sum(value * value for value in d)
        for row in range(3):
            for column in range(3):
                shift = body_mass * ((squared if row == column else 0.0) - d[row] * d[column])
                tensor[row][column] += body_tensor[row][column] + shift
    return Inertial(mass=total, origin=Transform(translation=centre),  # type: ignore[arg-type]
                    ixx=tensor[0][0], ixy=tensor[0][1], ixz=tensor[0][2],
                    iyy=tensor[1][1], iyz=tensor[1][2], izz=tensor[2][2])


def _link_frame_tensor(inertial: Inertial) -> Matrix:
    """Return the inertia tensor about the centre of mass, in the link's axes: R I R^T."""
    i = inertial
    local = ((i.ixx, i.ixy, i.ixz), (i.ixy, i.iyy, i.iyz), (i.ixz, i.iyz, i.izz))
    r = rotation_matrix(inertial.origin.rotation)
    ri = [[sum(r[row][k] * local[k][column] for k in range(3)) for column in range(3)]
          for row in range(3)]
    return tuple(tuple(sum(ri[row][k] * r[column][k] for k in range(3))  # type: ignore[misc]
                       for column in range(3)) for row in range(3))


def _children(root: ElementTree.Element, tag: str,
              names: tuple[str, ...]) -> list[ElementTree.Element]:
    """Return the ``<tag>`` children of ``root`` in the order of ``names`` (the model's order)."""
    by_name = {element.get('name'): element for element in root.findall(tag)}
    return [by_name[name] for name in names]


def _number(value: float) -> str:
    return repr(float(value))


def _write_inertial(element: ElementTree.Element, inertial: Inertial | None,
                    rewrite: bool) -> None:
    if inertial is None:
        return
    node = element.find('inertial')
    if node is None or rewrite:
        if node is not None:
            element.remove(node)
        node = ElementTree.SubElement(element, 'inertial')
        ElementTree.SubElement(node, 'origin', {
            'xyz': ' '.join(_number(v) for v in inertial.origin.translation),
            'rpy': '0 0 0'})
    mass = node.find('mass')
    if mass is None:
        mass = ElementTree.SubElement(node, 'mass')
    mass.set('value', _number(inertial.mass))
    tensor = node.find('inertia')
    if tensor is None:
        tensor = ElementTree.SubElement(node, 'inertia')
    for field in INERTIA_FIELDS:
        tensor.set(field, _number(getattr(inertial, field)))


def _write_dynamics(element: ElementTree.Element, joint: JointSpec) -> None:
    dynamics = element.find('dynamics')
    if dynamics is None:
        return  # nothing to scale: friction and damping are 0
    dynamics.set('damping', _number(joint.damping))
    dynamics.set('friction', _number(joint.friction))
