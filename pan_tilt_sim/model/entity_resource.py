"""What an object to spawn is made of: a URDF from a URI or a string, read once. No ROS.

``simulation_interfaces/srv/SpawnEntity`` names its resource by ``uri``
(``package://``, ``file://`` or a path; a ``.xacro`` file is expanded without
arguments) or gives it inline as ``resource_string`` (URDF or SDF text; an
SDF model becomes URDF as the robot's does, :mod:`pan_tilt_sim.model.sdf`).  This
module reads it with the robot's own parser (:mod:`pan_tilt_sim.model.urdf`)
and makes PyBullet's copy the same way (:mod:`pan_tilt_sim.model.resources`),
but an object may have no movable joint at all (a box).  Every failure is an
:class:`EntityResourceError` whose :attr:`~EntityResourceError.problem` says
which of the standard's result codes it is (see the design notes).

Design notes: docs/design/model.md#entity_resourcepy.
"""

from __future__ import annotations

import dataclasses
import enum
import os
import pathlib
import xml.etree.ElementTree as ElementTree

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.description import (
    XACRO_SUFFIX,
    RobotDescription,
    physics_copy,
    read_description_xml,
)
from pan_tilt_sim.model.resources import mesh_elements, resolve_resource
from pan_tilt_sim.model.sdf import SDF_ROOT_TAG, sdf_robot_to_urdf
from pan_tilt_sim.model.urdf import URDF_ROOT_TAG, parse_xml, read_model

URDF_SUFFIX = '.urdf'
SDF_SUFFIX = '.sdf'
SUPPORTED_SUFFIXES = (URDF_SUFFIX, SDF_SUFFIX, XACRO_SUFFIX)
FORMATS = ('urdf', 'sdf')  # the standard's lower-case names of the formats spawned
STRING_SOURCE = pathlib.Path('<resource_string>')
TRUE_TEXTS = ('true', '1')
MAX_ENTITY_BYTES = 1 << 20  # 1 MiB of URDF text (UTF-8)
MAX_ENTITY_JOINTS = 127  # PyBullet 3.2.7 reports no state of a body with more
MAX_ENTITY_LINKS = MAX_ENTITY_JOINTS + 1  # a tree of that many joints


@dataclasses.dataclass(frozen=True)
class EntityLimits:
    """The most one object to spawn may be (see the module's design notes)."""

    max_bytes: int = MAX_ENTITY_BYTES
    max_links: int = MAX_ENTITY_LINKS
    max_joints: int = MAX_ENTITY_JOINTS


DEFAULT_LIMITS = EntityLimits()


class ResourceProblem(enum.Enum):
    """Why a resource cannot be spawned (each maps onto a SpawnEntity result code)."""

    NOT_FOUND = 'not found'
    UNSUPPORTED_FORMAT = 'unsupported format'
    PARSE_ERROR = 'parse error'
    MISSING_ASSETS = 'missing assets'
    UNSUPPORTED_ASSETS = 'unsupported assets'
    TOO_LARGE = 'too large'


class EntityResourceError(DescriptionError):
    """A resource to spawn cannot be used; :attr:`problem` says how, the text says why."""

    def __init__(self, problem: ResourceProblem, message: str) -> None:
        super().__init__(message)
        self.problem = problem


def read_entity_resource(uri: str = '', resource_string: str = '', *,
                         base_dir: pathlib.Path | None = None,
                         limits: EntityLimits = DEFAULT_LIMITS) -> RobotDescription:
    """Read the URDF that ``uri`` names, else ``resource_string``; raise EntityResourceError.

    ``uri`` wins when both are given (as the standard says).  Relative paths,
    in the URI and in the URDF's meshes, are taken from ``base_dir`` (default:
    the current folder) -- for a URI's meshes, from the file's own folder.
    Anything beyond ``limits`` is refused (``TOO_LARGE``) before it is read further.
    """
    base = pathlib.Path.cwd() if base_dir is None else base_dir
    if uri:
        path = _resolve(uri, base)
        if path.suffix.lower() not in SUPPORTED_SUFFIXES:
            raise EntityResourceError(
                ResourceProblem.UNSUPPORTED_FORMAT,
                f"'{uri}': only URDF and SDF can be spawned (.urdf, .sdf or .xacro), got "
                f"'{path.suffix or path.name}'")
        if not path.is_file():
            raise EntityResourceError(ResourceProblem.NOT_FOUND,
                                      f"'{uri}': no such file ({path})")
        _check_bytes(path.stat().st_size, path, limits)
        try:
            text, _warnings = read_description_xml(path)
        except DescriptionError as err:
            raise EntityResourceError(ResourceProblem.PARSE_ERROR, str(err)) from None
        _check_bytes(len(text.encode('utf-8')), path, limits)  # xacro's output
        return _describe(text, path, path.parent, limits)
    if not resource_string.strip():
        raise EntityResourceError(ResourceProblem.NOT_FOUND, 'neither uri nor resource_string')
    _check_bytes(len(resource_string.encode('utf-8')), STRING_SOURCE, limits)
    return _describe(resource_string, STRING_SOURCE, base, limits)


def is_static(description: RobotDescription) -> bool:
    """Whether the URDF says ``<gazebo><static>true</static></gazebo>`` (fixed in the world)."""
    root = ElementTree.fromstring(description.urdf_xml)
    return any((element.findtext('static') or '').strip().lower() in TRUE_TEXTS
               for element in root.findall('gazebo') if element.get('reference') is None)


def _resolve(uri: str, base: pathlib.Path) -> pathlib.Path:
    try:
        return resolve_resource(uri, base)
    except DescriptionError as err:  # an unknown package or scheme
        raise EntityResourceError(ResourceProblem.NOT_FOUND, str(err)) from None


def _check_bytes(size: int, source: pathlib.Path, limits: EntityLimits) -> None:
    if size > limits.max_bytes:
        raise EntityResourceError(
            ResourceProblem.TOO_LARGE,
            f'{source}: {size} bytes of URDF: an object to spawn may have at most '
            f'{limits.max_bytes} bytes (reading it would hold the simulation up; see '
            'docs/simulator-control.md)')


def _check_size(root: ElementTree.Element, source: pathlib.Path, limits: EntityLimits) -> None:
    """Refuse more links or joints than ``limits`` allow, before anything reads them."""
    for kind, most in (('link', limits.max_links), ('joint', limits.max_joints)):
        count = len(root.findall(kind))
        if count > most:
            raise EntityResourceError(
                ResourceProblem.TOO_LARGE,
                f'{source}: {count} {kind}s: an object to spawn may have at most {most} '
                f'(PyBullet cannot report the state of a body of more than '
                f'{MAX_ENTITY_JOINTS} joints, and its cost per step grows faster than '
                'linearly with them; see docs/simulator-control.md)')


def _describe(text: str, source: pathlib.Path, base: pathlib.Path,
              limits: EntityLimits = DEFAULT_LIMITS) -> RobotDescription:
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError:
        root = None  # parse_xml says where
    if root is not None and root.tag == SDF_ROOT_TAG:
        try:
            text = sdf_robot_to_urdf(text, source, base).urdf_xml
        except DescriptionError as err:
            problem = (ResourceProblem.MISSING_ASSETS if 'no model path' in str(err)
                       or 'no such file' in str(err) else ResourceProblem.PARSE_ERROR)
            raise EntityResourceError(problem, str(err)) from None
        root = ElementTree.fromstring(text)
    if root is not None and root.tag != URDF_ROOT_TAG:
        raise EntityResourceError(
            ResourceProblem.UNSUPPORTED_FORMAT,
            f'{source}: only URDF and SDF can be spawned: the root element is <{root.tag}>, '
            f'expected <{URDF_ROOT_TAG}> or <{SDF_ROOT_TAG}>')
    if root is not None:
        _check_size(root, source, limits)
    try:
        root = parse_xml(text, source)
        model = read_model(root, source)
    except DescriptionError as err:
        raise EntityResourceError(ResourceProblem.PARSE_ERROR, str(err)) from None
    if not model.name:  # urdfdom and PyBullet refuse it too
        raise EntityResourceError(ResourceProblem.PARSE_ERROR,
                                  f'{source}: <robot> has no name attribute (URDF requires one)')
    if not model.links:
        raise EntityResourceError(ResourceProblem.PARSE_ERROR, f'{source}: the URDF has no link')
    for link, role, mesh in mesh_elements(root):
        uri = mesh.get('filename')
        if uri is None:
            raise EntityResourceError(
                ResourceProblem.PARSE_ERROR,
                f"{source}: link '{link}' {role}: <mesh> has no filename attribute")
        try:
            path = resolve_resource(uri, base)
        except DescriptionError as err:
            raise EntityResourceError(ResourceProblem.MISSING_ASSETS,
                                      f"{source}: link '{link}' {role}: {err}") from None
        if not os.path.isfile(path):
            raise EntityResourceError(
                ResourceProblem.MISSING_ASSETS,
                f"{source}: link '{link}' {role}: mesh '{uri}' (resolved to {path}): "
                'file not found')
    try:
        physics_urdf, warnings = physics_copy(root, model, base, source)
    except DescriptionError as err:
        raise EntityResourceError(ResourceProblem.UNSUPPORTED_ASSETS, str(err)) from None
    return RobotDescription(model=model, urdf_xml=text, physics_urdf=physics_urdf,
                            source=source, warnings=warnings)
