"""Hypothesis strategies for URDF robots: trees, and everything that makes one no tree.

:func:`robots` draws a :class:`FuzzRobot`: links and joints that mostly form
a tree, then perhaps mutated into cycles, links with two parents, joints
that are their own parent, orphan links and duplicate names; names of every
length around PyBullet's buffer (and beyond); every URDF joint type and a
few that are none; axes of every length down to zero; masses and inertias
from zero and tiny through the physical to the absurd, negative ones too;
origins out to where their squares overflow.  Its :meth:`FuzzRobot.request`
is what test/sim/load_worker.py takes: the URDF and a controllers file giving
every movable joint a controller (a PID on effort, the ideal actuator, or
plain effort) and a joint_state broadcaster.
"""

from __future__ import annotations

import dataclasses
import json
import xml.etree.ElementTree as ElementTree

from hypothesis import strategies as st

MAX_LINKS = 6
# Lengths in characters: around PyBullet's 1024-byte buffers (1023 bytes and the NUL),
# the 1,999 / 2,000 the first fuzzing found, and 2-byte characters across the limit.
LONG_NAME_LENGTHS = (511, 512, 1022, 1023, 1024, 1999, 2000)
NAME_CHARACTERS = 'abcxyz_-/ 0é日"<&'
JOINT_TYPES = ('revolute', 'revolute', 'revolute', 'continuous', 'prismatic', 'fixed',
               'planar', 'floating', 'ball')
MOVABLE_TYPES = ('revolute', 'continuous', 'prismatic')
AXES = ('0 0 1', '1 0 0', '0 1 0', '0 1 1', '0 3 4', '-1 0 0', '0 0 0', '0 0 1e-300',
        '0 0 1e-7', '0 0 2e-6', '0 0 5e-324', '1e200 0 0', '1e155 1e155 0', '1 0', 'nan 0 1')
MASSES = (0.0, 1.0, 0.05, 1e-6, 1e-9, 1e-300, 5e-324, -1.0, -1e-12, 1e6, 1.000001e6, 1e12,
          1e308, float('inf'), float('nan'))
INERTIAS = (0.0, 0.01, 1e-4, 1e-12, 1e8, 1.01e8, 1e300, -0.01, 1e-300)
OFFSETS = (0.0, 0.1, -0.3, 1e3, 1e154, 1e155, 1e200)
MUTATIONS = ('rewire', 'duplicate', 'own parent', 'drop', 'extra')
CONTROLLERS = ('pid', 'ideal', 'effort', 'none')
PID = '{p: 100.0, i: 0.0, d: 1.0}'


def _number(value: float) -> str:
    return repr(float(value))


@dataclasses.dataclass
class FuzzLink:
    """A ``<link>``: its inertial (None: no ``<inertial>``) as mass, tensor and centre."""

    name: str
    mass: float | None = 1.0
    inertia: tuple[float, ...] = (0.01, 0.0, 0.0, 0.01, 0.0, 0.01)  # ixx ixy ixz iyy iyz izz
    centre: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclasses.dataclass
class FuzzJoint:
    """A ``<joint>``; ``axis`` None leaves ``<axis>`` out, ``limits`` False leaves ``<limit>``."""

    name: str
    kind: str
    parent: str
    child: str
    axis: str | None = '0 0 1'
    origin: tuple[float, float, float] = (0.0, 0.0, 0.1)
    limits: bool = True


@dataclasses.dataclass
class FuzzRobot:
    """A robot description to load, and how its movable joints are driven."""

    name: str
    links: list[FuzzLink]
    joints: list[FuzzJoint]
    controllers: str = 'ideal'

    def urdf(self) -> str:
        """Return the URDF text (ElementTree escapes every name)."""
        robot = ElementTree.Element('robot', name=self.name)
        for link in self.links:
            element = ElementTree.SubElement(robot, 'link', name=link.name)
            if link.mass is None:
                continue
            inertial = ElementTree.SubElement(element, 'inertial')
            ElementTree.SubElement(inertial, 'origin',
                                   xyz=' '.join(_number(v) for v in link.centre))
            ElementTree.SubElement(inertial, 'mass', value=_number(link.mass))
            ElementTree.SubElement(inertial, 'inertia', dict(zip(
                ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz'),
                (_number(v) for v in link.inertia), strict=True)))
        for joint in self.joints:
            element = ElementTree.SubElement(robot, 'joint', name=joint.name, type=joint.kind)
            ElementTree.SubElement(element, 'parent', link=joint.parent)
            ElementTree.SubElement(element, 'child', link=joint.child)
            ElementTree.SubElement(element, 'origin',
                                   xyz=' '.join(_number(v) for v in joint.origin))
            if joint.axis is not None:
                ElementTree.SubElement(element, 'axis', xyz=joint.axis)
            if joint.limits:
                ElementTree.SubElement(element, 'limit', lower='-1', upper='1', effort='10',
                                       velocity='2')
        return ElementTree.tostring(robot, encoding='unicode')

    def controllers_yaml(self) -> str:
        """Return a controllers file: a broadcaster, and one controller per movable joint."""
        lines = ['jsb: {type: joint_state_broadcaster/JointStateBroadcaster}']
        movable = dict.fromkeys(joint.name for joint in self.joints
                                if joint.kind in MOVABLE_TYPES)
        for number, name in enumerate(movable):
            joint = json.dumps(name)  # JSON strings are YAML strings
            if self.controllers == 'pid':
                lines.append(f'c{number}: {{type: effort_controllers/JointPositionController, '
                             f'joint: {joint}, pid: {PID}}}')
            elif self.controllers == 'ideal':
                lines.append(f'c{number}: {{type: position_controllers/JointPositionController, '
                             f'joint: {joint}}}')
            elif self.controllers == 'effort':
                lines.append(f'c{number}: {{type: effort_controllers/JointEffortController, '
                             f'joint: {joint}}}')
        return '\n'.join(lines) + '\n'

    def request(self, steps: int) -> dict:
        """Return the request test/sim/load_worker.py takes."""
        return {'urdf': self.urdf(), 'controllers': self.controllers_yaml(), 'steps': steps}


class _Odds:
    """How often one robot's values are unusual: each choice is, ``percent`` times in 100.

    Each robot draws its own percent (0 for about a quarter of them: wholly
    usual robots, which should load), so that both sides of the property are
    exercised.  Shrinking goes towards the usual.
    """

    def __init__(self, draw, percent: int) -> None:
        self.draw = draw
        self.percent = percent

    def pick(self, usual: st.SearchStrategy, unusual: st.SearchStrategy):
        """Draw from ``unusual`` ``percent`` times in 100, else from ``usual``."""
        odd = self.draw(st.integers(0, 99)) >= 100 - self.percent
        return self.draw(unusual if odd else usual)


def _long_names() -> st.SearchStrategy[str]:
    return st.builds(lambda character, length: character * length,
                     st.sampled_from('né日'), st.sampled_from(LONG_NAME_LENGTHS))


def _name(odds: _Odds, default: str, taken: list[str]) -> str:
    """``default`` usually; else a name already taken, a long one, or odd characters."""
    unusual = [_long_names(), st.text(NAME_CHARACTERS, min_size=1, max_size=12)]
    if taken:
        unusual.append(st.sampled_from(taken))
    return odds.pick(st.just(default), st.one_of(unusual))


def _value(odds: _Odds, specials: tuple[float, ...], low: float, high: float) -> float:
    """A number in [low, high] usually, else one of ``specials``."""
    return odds.pick(st.floats(low, high), st.sampled_from(specials))


def _link(odds: _Odds, default: str, taken: list[str]) -> FuzzLink:
    draw = odds.draw
    name = _name(odds, default, taken)
    if draw(st.integers(0, 5)) == 5:
        return FuzzLink(name, mass=None)
    if not odds.pick(st.just(False), st.just(True)):  # a solid box's inertia
        mass = draw(st.floats(0.01, 10.0))
        x, y, z = draw(st.tuples(*[st.floats(0.01, 0.5)] * 3))
        return FuzzLink(name, mass, (mass * (y * y + z * z) / 12, 0.0, 0.0,
                                     mass * (x * x + z * z) / 12, 0.0,
                                     mass * (x * x + y * y) / 12),
                        draw(st.tuples(*[st.floats(-0.3, 0.3)] * 3)))
    diagonal = [_value(odds, INERTIAS, 0.0, 1.0) for _ in range(3)]
    off = [odds.pick(st.just(0.0), st.sampled_from(INERTIAS)) for _ in range(3)]
    centre = tuple(_value(odds, OFFSETS, -0.5, 0.5) for _ in range(3))
    return FuzzLink(name, _value(odds, MASSES, 0.0, 10.0),
                    (diagonal[0], off[0], off[1], diagonal[1], off[2], diagonal[2]),
                    centre)  # type: ignore[arg-type]


def _joint(odds: _Odds, default: str, taken: list[str], parent: str, child: str) -> FuzzJoint:
    axis = odds.pick(st.sampled_from(('0 0 1', '0 1 0', '1 0 0')), st.one_of(
        st.sampled_from((*AXES, None)), st.builds(
            lambda *xyz: ' '.join(_number(v) for v in xyz), *[st.floats(-2.0, 2.0)] * 3)))
    kind = odds.pick(st.sampled_from(MOVABLE_TYPES), st.sampled_from(JOINT_TYPES))
    origin = tuple(_value(odds, OFFSETS, -0.5, 0.5) for _ in range(3))
    return FuzzJoint(_name(odds, default, taken), kind, parent, child, axis,
                     origin,  # type: ignore[arg-type]
                     limits=not odds.pick(st.just(False), st.just(True)))


@st.composite
def robots(draw) -> FuzzRobot:
    """Draw a robot: a tree of up to MAX_LINKS links, perhaps mutated, and its controllers."""
    odds = _Odds(draw, draw(st.sampled_from((0, 2, 5, 15, 40))))
    links: list[FuzzLink] = []
    for number in range(draw(st.integers(2, MAX_LINKS))):
        links.append(_link(odds, f'link{number}', [link.name for link in links]))
    joints: list[FuzzJoint] = []
    for number in range(1, len(links)):
        parent = links[draw(st.integers(0, number - 1))].name
        joints.append(_joint(odds, f'joint{number}', [joint.name for joint in joints], parent,
                             links[number].name))
    names = [link.name for link in links]
    # A quarter of the robots are made no tree, whatever their odds.
    mutations = draw(st.lists(st.sampled_from(MUTATIONS), min_size=1, max_size=2)) \
        if draw(st.integers(0, 3)) == 3 else []
    for mutation in mutations:
        if mutation == 'extra' or not joints:
            joints.append(_joint(odds, f'extra{len(joints)}', [j.name for j in joints],
                                 draw(st.sampled_from(names)), draw(st.sampled_from(names))))
            continue
        index = draw(st.integers(0, len(joints) - 1))
        joint = joints[index]
        if mutation == 'rewire':  # to any link: a descendant makes a cycle
            joint.parent = draw(st.sampled_from(names))
        elif mutation == 'duplicate':  # the same name, elsewhere or the same joint again
            joints.append(dataclasses.replace(joint, child=draw(st.sampled_from(names))))
        elif mutation == 'own parent':
            joint.parent = joint.child
        else:  # drop: its child becomes a second root
            joints.pop(index)
    return FuzzRobot(odds.pick(st.just('fuzz'), _long_names()), links, joints,
                     draw(st.sampled_from(CONTROLLERS)))
