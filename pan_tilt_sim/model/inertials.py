"""Links without ``<inertial>`` are massless, as the URDF spec says; PyBullet must be told so.

PyBullet gives every link without ``<inertial>`` 1 kg and 1 kg m^2 -- frames
such as ``tool0``, ``flange`` or ``camera_optical`` then weigh a kilogram each
(a UR5e carries 3 phantom kg at its flange: 84 instead of 60 N m of gravity
on its shoulder).  PyBullet's copy of the URDF therefore gets an explicit
zero inertial for every such link, which PyBullet treats exactly like a
frame merged into its parent (every link name and index is kept, so the
camera, TF and link lookups are unchanged).

One case needs more: a moving joint whose whole child subtree is massless
(a pan joint carrying only a camera frame) would be frozen -- zero inertia
cannot be accelerated.  Its child link gets a negligible mass and inertia
instead, so that an actuator can move it, and a warning says so (Gazebo
classic drops such joints).

Design notes: docs/design/model.md#inertialspy.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree

from pan_tilt_sim.model.robot import Inertial, RobotModel

INERTIA_FIELDS = ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz')
# What a massless link that must still move gets: small enough to change no
# torque measurably, large enough for PyBullet to integrate.
MOVABLE_MASS = 1e-6  # kg
MOVABLE_INERTIA = 1e-9  # kg m^2


def massless_links(model: RobotModel) -> tuple[str, ...]:
    """Return the links that have no ``<inertial>``, in file order."""
    return tuple(link.name for link in model.links if link.inertial is None)


def frozen_joints(model: RobotModel) -> dict[str, tuple[str, ...]]:
    """Return each movable joint whose child subtree has no mass, with that subtree's links.

    One walk over the tree: the links in depth-first order (a subtree is a run of
    them), each subtree's size and mass summed from the leaves up.  (Walking each
    joint's subtree anew was quadratic: minutes for a chain of thousands of links.)
    """
    children: dict[str, list[str]] = {}
    for joint in model.joints:
        children.setdefault(joint.parent, []).append(joint.child)
    order: list[str] = []
    position: dict[str, int] = {}
    roots = [model.root] if model.root in model.link_names else []
    for start in [*roots, *(link.name for link in model.links)]:
        pending = [start]
        while pending:
            name = pending.pop()
            if name in position:  # a malformed URDF with a loop: stop, do not spin
                continue
            position[name] = len(order)
            order.append(name)
            pending.extend(reversed(children.get(name, ())))
    size = dict.fromkeys(order, 1)
    massive = {name: (model.link(name).inertial is not None
                      and model.link(name).inertial.mass > 0.0) for name in order}
    for name in reversed(order):  # children before their parents
        for child in children.get(name, ()):
            if position[child] > position[name]:  # its own subtree, not a loop back
                size[name] += size[child]
                massive[name] = massive[name] or massive[child]
    frozen = {}
    for joint in model.actuated_joints:
        child = joint.child
        if child in position and not massive[child]:
            start = position[child]
            frozen[joint.name] = tuple(order[start:start + size[child]])
    return frozen


def complete_inertials(root: ElementTree.Element, model: RobotModel) -> tuple[str, ...]:
    """Give PyBullet's copy (``root``) explicit inertials; return one warning per frozen joint.

    Links without ``<inertial>`` get mass 0 and inertia 0; the child link of a
    movable joint that moves no mass gets :data:`MOVABLE_MASS` and
    :data:`MOVABLE_INERTIA`.
    """
    elements = {element.get('name'): element for element in root.findall('link')}
    for name in massless_links(model):
        _set_inertial(elements[name], 0.0, 0.0)
    warnings = []
    for joint, links in frozen_joints(model).items():
        child = links[0]
        mass, inertia, why = MOVABLE_MASS, MOVABLE_INERTIA, 'so that the joint can move'
        followers = _follower_inertials(model, joint)
        if followers:
            # A virtual leader (ros2_control_demos' carlikebot) turns real wheels through the
            # mimic gears: a 1e-6 kg leader against them leaves the gear solver unable to.
            mass = max(inertial.mass for inertial in followers)
            inertia = max(max(inertial.ixx, inertial.iyy, inertial.izz) for inertial in followers)
            why = 'as its heaviest <mimic> follower, so that it can turn its followers'
        _set_inertial(elements[child], mass, inertia)
        warnings.append(
            f"joint '{joint}' moves only massless links ({', '.join(links)}): "
            f"'{child}' gets {mass:g} kg and {inertia:g} kg*m^2 {why} (Gazebo would drop "
            'the joint); give the link an <inertial> to silence this')
    return tuple(warnings)


def _follower_inertials(model: RobotModel, leader: str) -> list[Inertial]:
    """Return the inertials of the child links of the joints that mimic ``leader``."""
    inertials = []
    for joint in model.joints:
        if joint.mimic is not None and joint.mimic.joint == leader:
            inertial = model.link(joint.child).inertial
            if inertial is not None and inertial.mass > 0.0:
                inertials.append(inertial)
    return inertials


def _set_inertial(link: ElementTree.Element, mass: float, inertia: float) -> None:
    """Replace ``link``'s inertial by a point mass with a diagonal inertia at the link origin."""
    for old in link.findall('inertial'):
        link.remove(old)
    inertial = ElementTree.SubElement(link, 'inertial')
    ElementTree.SubElement(inertial, 'mass', value=repr(mass))
    diagonal = {'ixx', 'iyy', 'izz'}
    ElementTree.SubElement(inertial, 'inertia', {
        field: repr(inertia if field in diagonal else 0.0) for field in INERTIA_FIELDS})


def with_massive_root(urdf_xml: str, model: RobotModel) -> str:
    """Return PyBullet's copy ``urdf_xml`` with a massless root link given a negligible mass.

    Unchanged when the root link has a mass (or when the text has no such link).
    """
    root_link = model.link(model.root) if model.root in model.link_names else None
    if root_link is None or (root_link.inertial is not None and root_link.inertial.mass > 0.0):
        return urdf_xml
    document = ElementTree.fromstring(urdf_xml)
    element = next((link for link in document.findall('link')
                    if link.get('name') == model.root), None)
    if element is None:
        return urdf_xml
    _set_inertial(element, MOVABLE_MASS, MOVABLE_INERTIA)
    return ElementTree.tostring(document, encoding='unicode')
