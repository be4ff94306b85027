"""Contact surfaces of the links, as Gazebo reads them from ``<gazebo reference="LINK">``. No ROS.

A URDF gives a link's contact properties in Gazebo's extension tags::

    <gazebo reference="left_wheel">
      <mu1>1.2</mu1>  <mu2>1.2</mu2>    <!-- Coulomb friction, two directions -->
      <kp>1e6</kp>    <kd>100</kd>      <!-- contact stiffness (N/m), damping (N s/m) -->
    </gazebo>

Gazebo's defaults, for a link without them: ``mu1 = mu2 = 1``, ``kp =
1e12``, ``kd = 1`` -- a rigid contact.  Where two surfaces touch Gazebo
takes the smaller coefficient of each direction; its default ground plane
has 100 and 50, so on the ground a link's own values decide.  As Gazebo's
URDF parser, a ``value`` attribute (``<mu1 value="200.0"/>``, ROS 1 tutorials'
form) is read before the element's text.  Plain values;
the physics (:mod:`pan_tilt_sim.sim.physics`) turns them into PyBullet's.
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
import xml.etree.ElementTree as ElementTree
from collections.abc import Iterable

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.xml_input import float_or_nan

DEFAULT_MU = 1.0  # Gazebo's mu1 and mu2 where the URDF gives none
DEFAULT_KP = 1e12  # N/m: Gazebo's contact stiffness, effectively rigid
DEFAULT_KD = 1.0  # N s/m: Gazebo's contact damping
SURFACE_TAGS = ('mu1', 'mu2', 'kp', 'kd')


@dataclasses.dataclass(frozen=True)
class Surface:
    """One link's contact surface: friction per direction, and its contact spring if given.

    ``kp`` and ``kd`` are None where the URDF does not give them: Gazebo's
    default contact is rigid, which is also the physics' own.
    """

    link: str
    mu1: float = DEFAULT_MU
    mu2: float = DEFAULT_MU
    kp: float | None = None
    kd: float | None = None

    @property
    def friction(self) -> float:
        """The one Coulomb coefficient the physics applies in every direction (the smaller)."""
        return min(self.mu1, self.mu2)

    @property
    def isotropic(self) -> bool:
        """Whether both directions have the same coefficient (else only the smaller is used)."""
        return self.mu1 == self.mu2

    @property
    def spring(self) -> tuple[float, float] | None:
        """The contact stiffness and damping (N/m, N s/m) where the URDF gives kp, else None."""
        if self.kp is None:
            return None
        return (self.kp, DEFAULT_KD if self.kd is None else self.kd)


def read_surfaces(root: ElementTree.Element, source: pathlib.Path,
                  link_names: Iterable[str]) -> tuple[Surface, ...]:
    """Return the surfaces the ``<gazebo reference>`` tags give, one per link that has any.

    Several tags for one link add up (a later value wins).  A value that is
    not a number >= 0 (kp: > 0) is a :class:`DescriptionError` naming the
    file, the link and the tag; a reference that is no link is not ours.
    """
    links = set(link_names)
    values: dict[str, dict[str, float]] = {}
    for gazebo in root.findall('gazebo'):
        reference = gazebo.get('reference')
        tags = [gazebo.find(tag) for tag in SURFACE_TAGS]
        if reference is None or all(tag is None for tag in tags):
            continue
        if reference not in links:
            continue  # a joint's <gazebo> (its own tags), or a sensor mount checked elsewhere
        for name, element in zip(SURFACE_TAGS, tags, strict=True):
            if element is None:
                continue
            # Gazebo's URDF parser takes a value attribute before the text (<mu1 value="1"/>).
            text = (element.get('value') or element.text or '').strip()
            value = float_or_nan(text)
            positive = name == 'kp'  # a contact without stiffness holds nothing up
            if not (math.isfinite(value) and (value > 0.0 if positive else value >= 0.0)):
                raise DescriptionError(
                    f"{source}: <gazebo reference=\"{reference}\">: <{name}> '{text}' must be "
                    f"a number {'>' if positive else '>='} 0")
            values.setdefault(reference, {})[name] = value
    return tuple(Surface(link, **given) for link, given in values.items())
