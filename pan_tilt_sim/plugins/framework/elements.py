"""A plugin's element spec and its reading: numbers, flags, vectors, ``<ros>``, wheels, frames.

An :class:`ElementSpec` declares the child elements a plugin reads (name,
kind, default, check), as a controller's ``ParameterSpec`` declares its
parameters.  :class:`ElementReader` reads one
:class:`~pan_tilt_sim.model.plugin_elements.PluginElement`; a value that is
wrong ends start-up with a :class:`~pan_tilt_sim.errors.DescriptionError`
naming the file, the plugin and the element, as a driving controller's
checks do.  No ROS.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.frame_ids import frame_id_problem
from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.rates import rate_problem
from pan_tilt_sim.model.robot import RobotModel

GZ = 'gz'  # gz-sim's systems: SDF element names, gz-transport topics
RATE_KEYS = ('rate', 'frequency')  # elements (lower case) whose value is a rate in Hz
UNPLANAR_COVARIANCE = 1e12  # z, roll, pitch: what the planar plugins put there


class ElementReader:
    """Reads one ``<plugin>`` element's children; bad values name the plugin and the element."""

    def __init__(self, element: PluginElement, robot_name: str) -> None:
        self.element = element
        self.name = element.name or element.stem
        self.filename = element.filename
        self.source = element.source
        self.robot_name = robot_name
        self.texts: Mapping[str, tuple[str, ...]] = element.values

    def error(self, key: str, problem: str) -> DescriptionError:
        """Return the error that names the file, the plugin and element ``key``."""
        return DescriptionError(
            f"{self.source}: plugin '{self.name}' ({self.filename}): <{key}> {problem}")

    def text(self, key: str, default: str) -> str:
        """Return the first ``<key>``'s text, ``default`` if absent or empty."""
        values = self.texts.get(key)
        return values[0] if values and values[0] else default

    def all(self, key: str) -> list[str]:
        """Return every non-empty ``<key>`` text, in order."""
        return [value for value in self.texts.get(key, ()) if value]

    def number(self, key: str, default: float, *, positive: bool = False,
               non_negative: bool = False) -> float:
        """Return ``<key>`` as a finite number (a rate's period must be finite too)."""
        value = self.check(key, self.text(key, ''), default, positive, non_negative)
        if key.lower().endswith(RATE_KEYS):
            problem = rate_problem(value, zero_allowed=not positive)
            if problem:
                raise self.error(key, problem)
        return value

    def check(self, key: str, text: str, default: float, positive: bool = False,
              non_negative: bool = False) -> float:
        """Return ``text`` (of ``<key>``) as a finite number; empty: ``default``."""
        if not text:
            return default
        try:
            value = float(text)
        except ValueError:
            raise self.error(key, f"'{text}' is not a number") from None
        if not math.isfinite(value):
            raise self.error(key, f"'{text}' is not a finite number")
        if positive and value <= 0.0:
            raise self.error(key, f'must be > 0, got {value:g}')
        if non_negative and value < 0.0:
            raise self.error(key, f'must be >= 0, got {value:g}')
        return value

    def vector(self, key: str) -> tuple[float, float, float]:
        """Return ``<key>`` as three numbers (absent: zeros)."""
        text = self.text(key, '')
        if not text:
            return (0.0, 0.0, 0.0)
        words = text.split()
        if len(words) != 3:
            raise self.error(key, f"'{text}' is not three numbers")
        x, y, z = (self.check(key, word, 0.0) for word in words)
        return (x, y, z)

    def flag(self, key: str, default: bool) -> bool:
        """Return ``<key>`` as a boolean (true/false/1/0)."""
        text = self.text(key, '').lower()
        if not text:
            return default
        if text in ('true', '1'):
            return True
        if text in ('false', '0'):
            return False
        raise self.error(key, f"'{text}' is not a boolean (true/false)")

    def ros1_namespace(self) -> str:
        """Return ``robotNamespace``: absent the root, given empty the robot's name."""
        values = self.texts.get('robotNamespace')
        if values is None:
            return ''
        return values[0] or self.robot_name

    def ros(self) -> tuple[str, tuple[tuple[str, str], ...]]:
        """Return the ``<ros>`` block's namespace and its ``from:=to`` remappings."""
        rules = []
        for text in self.element.ros_remappings:
            source, separator, target = text.partition(':=')
            if not separator or not source.strip() or not target.strip():
                raise self.error('ros/remapping', f"'{text}' is not 'from:=to'")
            rules.append((source.strip(), target.strip()))
        return self.element.ros_namespace, tuple(rules)

    def has_any(self, keys: set[str]) -> bool:
        """Whether one of ``keys`` is an element of the plugin (tells a generation apart)."""
        return bool(set(self.texts) & keys)


class Kind(enum.Enum):
    """What an element's text is read as."""

    NUMBER = 'number'  # a finite float (a rate: its period finite too)
    TEXT = 'text'  # the text, stripped (empty: the default)
    FLAG = 'flag'  # true/false/1/0
    VECTOR = 'vector'  # three numbers (absent: zeros)


@dataclasses.dataclass(frozen=True)
class Element:
    """One child element a plugin reads: its name, kind, default and check."""

    name: str
    default: Any = None
    kind: Kind = Kind.NUMBER
    positive: bool = False
    non_negative: bool = False

    def read(self, reader: ElementReader) -> Any:
        """Return the element's value in ``reader``'s plugin (DescriptionError if wrong)."""
        if self.kind is Kind.NUMBER:
            return reader.number(self.name, self.default, positive=self.positive,
                                 non_negative=self.non_negative)
        if self.kind is Kind.TEXT:
            return reader.text(self.name, self.default)
        if self.kind is Kind.FLAG:
            return reader.flag(self.name, self.default)
        return reader.vector(self.name)


class ElementSpec:
    """The elements a plugin (of one generation) reads, in the order they are checked."""

    def __init__(self, *elements: Element) -> None:
        self.elements = elements
        self.names = tuple(element.name for element in elements)

    def read(self, reader: ElementReader) -> dict[str, Any]:
        """Return every element's value by name; the first wrong one raises."""
        return {element.name: element.read(reader) for element in self.elements}


def check_wheels(reader: ElementReader, keyed: tuple[tuple[str, tuple[str, ...]], ...],
                 joints: Mapping[str, object]) -> None:
    """Refuse a wheel that is no joint, no movable one, a mimic, or named twice.

    The checks a driving controller makes of its wheels (distinct, movable,
    commandable), the error naming the file, the plugin and the element.
    """
    seen: dict[str, str] = {}
    for key, wheels in keyed:
        for wheel in wheels:
            joint = joints.get(wheel)
            if joint is None:
                raise reader.error(key, f"'{wheel}' is not a joint of this robot")
            kind = getattr(joint, 'kind', None)
            if kind is not None and not kind.is_actuated:
                raise reader.error(key, f"'{wheel}' is a {kind.value} joint: a wheel must be a "
                                   'movable (revolute or continuous) joint')
            mimic = getattr(joint, 'mimic', None)
            if mimic is not None:
                raise reader.error(key, f"'{wheel}' mimics '{mimic.joint}': it follows that "
                                   'joint and cannot be driven')
            if wheel in seen:
                raise reader.error(key, f"'{wheel}' is already a wheel (<{seen[wheel]}>): each "
                                   'wheel needs its own joint')
            seen[wheel] = key


def check_frames(reader: ElementReader, keyed: tuple[tuple[str, str], ...]) -> None:
    """Refuse a frame that is no valid frame id, and an odometry frame equal to the base's."""
    for key, frame in keyed:
        problem = frame_id_problem(frame)
        if problem:
            raise reader.error(key, problem)
    (parent_key, parent), (child_key, child) = keyed
    if parent.removeprefix('/') == child.removeprefix('/'):
        raise reader.error(child_key, f"'{child}' is <{parent_key}> too: the odometry's "
                           'transform needs two different frames')


def gz_topic(name: str) -> str:
    """Return a gz-transport topic as ROS sees it through the bridge: absolute, one '/' each."""
    parts = [part for part in name.strip().split('/') if part]
    return '/' + '/'.join(parts)


def joints_by_name(model: RobotModel) -> dict[str, object]:
    """Return the robot's joints by name (what :func:`check_wheels` checks against)."""
    return {joint.name: joint for joint in model.joints}


def movable_joints(model: RobotModel) -> list[str]:
    """Return the robot's movable joints' names, in the URDF's order."""
    return [joint.name for joint in model.joints if joint.kind.is_actuated]


def root_link(model: RobotModel) -> str:
    """Return the robot's root link (the canonical link gz-sim names frames after)."""
    children = {joint.child for joint in model.joints}
    return next((link.name for link in model.links if link.name not in children), '')

