"""Surface friction of links: ``<gazebo reference="LINK">`` ``<mu1>`` and ``<mu2>``.

Gazebo (classic, through urdf2sdf) turns these into the link's collision
friction: ``mu1`` along the first friction direction and ``mu2`` across it,
each 1.0 (SDF's default) where only the other one is given.  A reference
that is not a link (a joint's ``<gazebo>`` block) carries no surface and is
left alone, as Gazebo leaves it.  How the physics uses the pair is the
simulation's business (:mod:`pan_tilt_sim.sim.physics`).
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
import xml.etree.ElementTree as ElementTree
from collections.abc import Collection

from pan_tilt_sim.errors import DescriptionError

GAZEBO_DEFAULT_MU = 1.0  # SDF's <ode><mu> and <mu2> default


@dataclasses.dataclass(frozen=True)
class SurfaceFriction:
    """A link's Coulomb friction coefficients (dimensionless, >= 0)."""

    mu1: float = GAZEBO_DEFAULT_MU
    mu2: float = GAZEBO_DEFAULT_MU


def link_frictions(root: ElementTree.Element, links: Collection[str],
                   source: pathlib.Path) -> dict[str, SurfaceFriction]:
    """Return the friction that ``<gazebo reference>`` blocks give links of ``links``, by link.

    A link named by several blocks takes the last value of each tag (as
    urdf2sdf merges them).  A value that is not a finite number >= 0 is a
    :class:`DescriptionError` naming the file, the link and the tag.
    """
    given: dict[str, dict[str, float]] = {}
    for gazebo in root.findall('gazebo'):
        link = gazebo.get('reference')
        if link not in links:
            continue
        for tag in ('mu1', 'mu2'):
            element = gazebo.find(tag)
            if element is None:
                continue
            text = (element.text or '').strip()
            try:
                value = float(text)
            except ValueError:
                value = math.nan
            if not (math.isfinite(value) and value >= 0.0):
                raise DescriptionError(
                    f'{source}: <gazebo reference="{link}">: <{tag}>{text}</{tag}> must be a '
                    'number >= 0')
            given.setdefault(link, {})[tag] = value
    return {link: SurfaceFriction(**values) for link, values in given.items()}
