"""The description layer: a .urdf or .xacro file to a URDF string and joint facts.

Nothing here knows about PyBullet or ROS: it reads the file (running xacro
with the user's mappings when the file is a xacro), and extracts what the
rest of the simulator needs to know about each joint -- kind, limits,
dynamics, mimic -- and the ``robotNamespace`` of a gazebo_ros_control
plugin, which is where the seeds' robots keep their topic namespace.
"""

from __future__ import annotations

import dataclasses
import enum
import math
import os
import pathlib
import xml.etree.ElementTree as ElementTree
from collections.abc import Sequence
from xml.parsers.expat import ExpatError

from pan_tilt_sim import naming
from pan_tilt_sim.errors import DescriptionError, one_line
from pan_tilt_sim.resources import localize_meshes

XACRO_SUFFIX = '.xacro'
URDF_ROOT_TAG = 'robot'
MAPPING_SEPARATOR = ':='
# Converted meshes are kept between runs (keyed on content) under the user cache.
MESH_CACHE_SUBDIR = pathlib.Path('pan_tilt_sim', 'meshes')
# Gazebo plugins whose namespace element names the robot's topic namespace.
GAZEBO_ROS_CONTROL_PLUGINS = ('libgazebo_ros_control.so', 'libgazebo_ros2_control.so')


class JointKind(enum.Enum):
    """URDF joint types the simulator distinguishes."""

    REVOLUTE = 'revolute'
    CONTINUOUS = 'continuous'
    PRISMATIC = 'prismatic'
    FIXED = 'fixed'
    FLOATING = 'floating'
    PLANAR = 'planar'

    @property
    def is_actuated(self) -> bool:
        """Whether a one-degree-of-freedom motor can drive this kind of joint."""
        return self in (JointKind.REVOLUTE, JointKind.CONTINUOUS, JointKind.PRISMATIC)


@dataclasses.dataclass(frozen=True)
class Mimic:
    """A ``<mimic>`` element: position = multiplier * leader + offset."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclasses.dataclass(frozen=True)
class JointSpec:
    """What the URDF says about one joint.

    Limits that the URDF does not give are infinite.  A non-positive effort or
    velocity limit is taken as "no limit", since a zero limit would make the
    joint impossible to move and is almost always a placeholder.
    """

    name: str
    kind: JointKind
    lower: float = -math.inf
    upper: float = math.inf
    effort_limit: float = math.inf
    velocity_limit: float = math.inf
    damping: float = 0.0
    friction: float = 0.0
    mimic: Mimic | None = None

    @property
    def has_position_limits(self) -> bool:
        """Whether the position is bounded (not for continuous joints)."""
        return self.kind is not JointKind.CONTINUOUS and self.lower <= self.upper and (
            math.isfinite(self.lower) or math.isfinite(self.upper))

    def clamp_position(self, position: float) -> float:
        """Return ``position`` clamped into the joint's position limits."""
        if not self.has_position_limits:
            return position
        return min(max(position, self.lower), self.upper)

    @property
    def initial_position(self) -> float:
        """Zero, or the nearest limit when zero lies outside the limits."""
        return self.clamp_position(0.0)


@dataclasses.dataclass(frozen=True)
class RobotDescription:
    """A processed robot description, ready for the physics layer."""

    name: str
    urdf_xml: str
    joints: tuple[JointSpec, ...]
    source: pathlib.Path
    plugin_namespace: str | None = None

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of all joints, in file order."""
        return tuple(joint.name for joint in self.joints)

    @property
    def actuated_joints(self) -> tuple[JointSpec, ...]:
        """Joints a one-degree-of-freedom controller can drive (non-fixed)."""
        return tuple(joint for joint in self.joints if joint.kind.is_actuated)

    def joint(self, name: str) -> JointSpec:
        """Return the joint called ``name``; KeyError if there is none."""
        for joint in self.joints:
            if joint.name == name:
                return joint
        raise KeyError(name)


def parse_xacro_args(xacro_args: Sequence[str]) -> dict[str, str]:
    """Turn ``['name:=value', ...]`` into xacro mappings."""
    mappings = {}
    for item in xacro_args:
        name, separator, value = item.partition(MAPPING_SEPARATOR)
        if not separator or not name:
            raise DescriptionError(
                f"xacro_args: '{item}' is not of the form name:=value")
        mappings[name] = value
    return mappings


def run_xacro(path: pathlib.Path, mappings: dict[str, str]) -> str:
    """Expand a xacro file with ``mappings``; errors name the file and line."""
    import xacro  # deferred: only xacro files need it

    try:
        document = xacro.process_file(str(path), mappings=mappings)
    except ExpatError as err:
        raise DescriptionError(
            f'{path}:{err.lineno}: not well-formed XML: {_expat_reason(err)}') from None
    except xacro.XacroException as err:
        raise DescriptionError(f'{path}: xacro error: {one_line(str(err))}') from None
    except Exception as err:  # xacro surfaces NameError, KeyError... from user expressions
        raise DescriptionError(
            f'{path}: xacro error: {type(err).__name__}: {one_line(str(err))}') from None
    return document.toprettyxml(indent='  ')


def read_description_xml(path: pathlib.Path, xacro_args: Sequence[str] = ()) -> str:
    """Return the URDF text of a .urdf or .xacro file."""
    if path.is_dir():
        raise DescriptionError(f'robot description file {path}: is a directory, not a file')
    if not path.is_file():
        raise DescriptionError(f'robot description file {path}: no such file')
    mappings = parse_xacro_args(xacro_args)
    if path.suffix == XACRO_SUFFIX or mappings:
        return run_xacro(path, mappings)
    try:
        text = path.read_text(encoding='utf-8')
    except (OSError, UnicodeDecodeError) as err:
        raise DescriptionError(f'robot description file {path}: cannot read: {err}') from None
    if 'xmlns:xacro' in text and '<xacro:' in text:
        # A URDF-named file that uses xacro macros: expand it, as `xacro` would.
        return run_xacro(path, mappings)
    return text


def parse_urdf(urdf_xml: str, source: pathlib.Path) -> ElementTree.Element:
    """Parse URDF text, requiring a ``<robot>`` root."""
    try:
        root = ElementTree.fromstring(urdf_xml)
    except ElementTree.ParseError as err:
        line, _column = err.position
        raise DescriptionError(f'{source}:{line}: not well-formed XML: {err.msg}') from None
    if root.tag != URDF_ROOT_TAG:
        raise DescriptionError(
            f'{source}: not a URDF: the root element is <{root.tag}>, expected <{URDF_ROOT_TAG}>')
    return root


def load_description(path: pathlib.Path | str, xacro_args: Sequence[str] = ()) -> RobotDescription:
    """Read a .urdf/.xacro file into a :class:`RobotDescription`."""
    path = pathlib.Path(path).expanduser().resolve()
    urdf_xml = read_description_xml(path, xacro_args)
    root = parse_urdf(urdf_xml, path)
    try:
        localize_meshes(root, path.parent, mesh_cache_dir())
    except DescriptionError as err:
        raise DescriptionError(f'{path}: {err}') from None
    joints = tuple(_parse_joint(element, path) for element in root.findall('joint'))
    if not any(joint.kind.is_actuated for joint in joints):
        raise DescriptionError(f'{path}: the robot has no movable joints to control')
    for joint in joints:
        if joint.mimic is not None and joint.mimic.joint not in {j.name for j in joints}:
            raise DescriptionError(
                f"{path}: joint '{joint.name}' mimics '{joint.mimic.joint}', "
                'which is not a joint of this robot')
    plugin_namespace = _plugin_namespace(root)
    if plugin_namespace and not naming.is_valid_namespace(naming.normalize(plugin_namespace)):
        raise DescriptionError(
            f"{path}: the gazebo_ros_control plugin's namespace '{plugin_namespace}' is not a "
            f'valid ROS namespace ({naming.NAMESPACE_RULE})')
    return RobotDescription(
        name=root.get('name', ''),
        urdf_xml=ElementTree.tostring(root, encoding='unicode'),
        joints=joints,
        source=path,
        plugin_namespace=plugin_namespace,
    )


def mesh_cache_dir() -> pathlib.Path:
    """Return where converted meshes are cached (``$XDG_CACHE_HOME`` or ``~/.cache``)."""
    base = os.environ.get('XDG_CACHE_HOME') or pathlib.Path.home() / '.cache'
    return pathlib.Path(base) / MESH_CACHE_SUBDIR


def _parse_joint(element: ElementTree.Element, source: pathlib.Path) -> JointSpec:
    name = element.get('name')
    if not name:
        raise DescriptionError(f'{source}: a <joint> has no name')
    type_name = element.get('type', '')
    try:
        kind = JointKind(type_name)
    except ValueError:
        raise DescriptionError(
            f"{source}: joint '{name}' has unknown type '{type_name}'") from None
    fields = {}
    limit = element.find('limit')
    if limit is not None:
        if kind is not JointKind.CONTINUOUS:
            fields['lower'] = _float_attr(limit, 'lower', 0.0, source, name)
            fields['upper'] = _float_attr(limit, 'upper', 0.0, source, name)
        fields['effort_limit'] = _positive_or_inf(_float_attr(limit, 'effort', 0.0, source, name))
        fields['velocity_limit'] = _positive_or_inf(
            _float_attr(limit, 'velocity', 0.0, source, name))
    dynamics = element.find('dynamics')
    if dynamics is not None:
        fields['damping'] = _float_attr(dynamics, 'damping', 0.0, source, name)
        fields['friction'] = _float_attr(dynamics, 'friction', 0.0, source, name)
    mimic = element.find('mimic')
    if mimic is not None:
        fields['mimic'] = Mimic(
            joint=mimic.get('joint', ''),
            multiplier=_float_attr(mimic, 'multiplier', 1.0, source, name),
            offset=_float_attr(mimic, 'offset', 0.0, source, name))
    return JointSpec(name=name, kind=kind, **fields)


def _float_attr(element: ElementTree.Element, attribute: str, default: float,
                source: pathlib.Path, joint: str) -> float:
    text = element.get(attribute)
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise DescriptionError(
            f"{source}: joint '{joint}': <{element.tag} {attribute}=\"{text}\"> is not a number")
    return value


def _positive_or_inf(value: float) -> float:
    return value if value > 0.0 else math.inf


def _plugin_namespace(root: ElementTree.Element) -> str | None:
    for plugin in root.iterfind('gazebo/plugin'):
        if plugin.get('filename') not in GAZEBO_ROS_CONTROL_PLUGINS:
            continue
        for path in ('robotNamespace', 'ros/namespace'):
            namespace = plugin.findtext(path)
            if namespace and namespace.strip():
                return namespace.strip()
    return None


def _expat_reason(err: ExpatError) -> str:
    from xml.parsers.expat import ErrorString
    return ErrorString(err.code)
