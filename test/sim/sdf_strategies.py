"""Hypothesis strategies for SDF robots: chains of links with SDF's own ways to go wrong.

Each drawn robot is a chain of links joined by SDF joints (ball joints and
revolute ones without limits among them), poses relative to the model, a
link, a joint or a ``<frame>``, axes expressed in another frame, and --
with the robot's own odds -- SDF's malformations: an unknown version, a
joint naming a link the model lacks, a pose of five numbers, a frame cycle,
a negative mass, a zero axis, a missing ``model://`` include.
"""

from __future__ import annotations

import dataclasses

from hypothesis import strategies as st

VERSIONS = ('1.4', '1.5', '1.6', '1.7', '1.8', '1.9', '1.10', '1.11')
BAD_VERSIONS = ('1.3', '2.0', '', 'one')
JOINT_TYPES = ('revolute', 'continuous', 'prismatic', 'fixed', 'ball')
BAD_JOINT_TYPES = ('screw', 'universal', 'gearbox', '')
MASSES = (1.0, 0.5, 0.01)
BAD_MASSES = (-1.0, 0.0, 1e7, float('nan'))
AXES = ('0 0 1', '0 1 0', '1 0 0', '0 1 1')
BAD_AXES = ('0 0 0', '1 2', 'x y z')
POSE_NUMBERS = st.floats(-0.5, 0.5)
MAX_LINKS = 5
CONTROLLERS = 'jsb: {type: joint_state_broadcaster/JointStateBroadcaster}\n'


@dataclasses.dataclass(frozen=True)
class FuzzSdf:
    """One drawn SDF robot as text."""

    text: str

    def request(self, steps: int) -> dict:
        """Return the request test/sim/load_worker.py takes (an SDF where it takes a URDF)."""
        return {'urdf': self.text, 'controllers': CONTROLLERS, 'steps': steps}


def _pose(draw, attributes: str = '', numbers: int = 6) -> str:
    values = ' '.join(repr(draw(POSE_NUMBERS)) for _ in range(numbers))
    return f'<pose{attributes}>{values}</pose>'


@st.composite
def sdf_robots(draw) -> FuzzSdf:
    """Draw an SDF robot: a chain of links, perhaps with one of SDF's malformations."""
    odd = draw(st.sampled_from((0, 5, 20)))

    def pick(usual, unusual):
        return draw(st.sampled_from(unusual)) if draw(st.integers(0, 99)) < odd else \
            draw(st.sampled_from(usual))

    version = pick(VERSIONS, BAD_VERSIONS)
    modern = version in VERSIONS[3:]
    count = draw(st.integers(2, MAX_LINKS))
    names = [f'link{index}' for index in range(count)]
    parts = []
    for index, name in enumerate(names):
        relative = f' relative_to="{names[index - 1]}"' if modern and index and draw(
            st.booleans()) else ''
        numbers = 5 if pick((False,), (True,)) else 6
        parts.append(
            f'<link name="{name}">{_pose(draw, relative, numbers)}<inertial>'
            f'{_pose(draw)}<mass>{pick(MASSES, BAD_MASSES)}</mass><inertia><ixx>0.01</ixx>'
            '<iyy>0.01</iyy><izz>0.01</izz></inertia></inertial><collision name="c">'
            '<geometry><box><size>0.1 0.1 0.1</size></box></geometry></collision></link>')
    if modern and draw(st.booleans()):
        attached = draw(st.sampled_from(names))
        parts.append(f'<frame name="mount" attached_to="{attached}">{_pose(draw)}</frame>')
        if pick((False,), (True,)):  # a frame posed relative to itself
            parts[-1] = parts[-1].replace('<pose>', '<pose relative_to="mount">')
    for index in range(1, count):
        kind = pick(JOINT_TYPES, BAD_JOINT_TYPES)
        child = pick((names[index],), ('ghost',))
        expressed = ' expressed_in="__model__"' if modern and draw(st.booleans()) else ''
        limit = ('<limit><lower>-1</lower><upper>1</upper></limit>'
                 if draw(st.booleans()) else '')
        parts.append(
            f'<joint name="joint{index}" type="{kind}"><parent>{names[index - 1]}</parent>'
            f'<child>{child}</child>{_pose(draw) if draw(st.booleans()) else ""}'
            f'<axis><xyz{expressed}>{pick(AXES, BAD_AXES)}</xyz>{limit}</axis></joint>')
    if pick((False,), (True,)):
        parts.append('<include><uri>model://no_such_model</uri></include>')
    return FuzzSdf(f'<sdf version="{version}"><model name="fuzz">{"".join(parts)}'
                   '</model></sdf>')
