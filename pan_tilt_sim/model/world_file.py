"""The ``world`` parameter: a scenery name, or a YAML world file listing objects to spawn.

A scenery name is one of :data:`SCENERIES`: ``empty`` (nothing), ``ground``
(a ground plane) or ``targets`` (the ground plane and four coloured cubes).
Anything else is a world file -- a path, ``file://`` or ``package://`` URI:
an SDF world (``.sdf``, ``.world``, ``.sdf.xacro``; :mod:`pan_tilt_sim.model.sdf_world`),
or YAML, one entry per object, each what a ``SpawnEntity`` request would
give (see the design notes).

Design notes: docs/design/model.md#world_filepy.
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.errors import ConfigurationError, ParameterError
from pan_tilt_sim.model import yaml_input
from pan_tilt_sim.model.resources import resolve_resource
from pan_tilt_sim.model.sdf_world import (
    SdfWorldError,
    WorldPhysics,
    is_sdf_world_path,
    read_sdf_world,
)
from pan_tilt_sim.model.transforms import (
    IDENTITY_ROTATION,
    ZERO_VECTOR,
    Quaternion,
    Vector,
    quaternion_from_rpy,
)

EMPTY = 'empty'
GROUND = 'ground'
TARGETS = 'targets'
SCENERIES = (EMPTY, GROUND, TARGETS)
DEFAULT_FILE_SCENERY = GROUND
WORLD_KEYS = ('scenery', 'entities')
ENTITY_KEYS = ('name', 'uri', 'resource_string', 'pose', 'description', 'tags', 'shape', 'size',
               'colour', 'static', 'mass')
SHAPE_KEYS = ('shape', 'size', 'colour', 'static', 'mass')
SHAPE_SIZES = {'box': ('x', 'y', 'z'), 'cylinder': ('radius', 'length'), 'sphere': ('radius',)}
DEFAULT_COLOUR = (0.7, 0.7, 0.7, 1.0)
DEFAULT_SHAPE_MASS = 1.0  # kg, for a shape that is not static
POSE_KEYS = ('position', 'orientation', 'rpy')
NORM_TOLERANCE = 1e-6  # a quaternion whose norm is this close to 0 is no rotation
MAX_WORLD_ENTITIES = 1000  # objects in one world file


class WorldFileError(ConfigurationError):
    """The world file cannot be used (a bad ``world`` value itself is a ParameterError)."""


@dataclasses.dataclass(frozen=True)
class EntitySpec:
    """One object a world file asks for, as a SpawnEntity request would."""

    name: str = ''
    uri: str = ''
    resource_string: str = ''
    position: Vector = ZERO_VECTOR
    orientation: Quaternion = IDENTITY_ROTATION
    description: str = ''
    tags: tuple[str, ...] = ()


@dataclasses.dataclass(frozen=True)
class World:
    """What the ``world`` parameter asks for: a scenery and the objects to spawn at start."""

    scenery: str
    entities: tuple[EntitySpec, ...] = ()
    source: pathlib.Path | None = None  # the world file, if one was given
    physics: WorldPhysics | None = None  # an SDF world's <physics>; None for the others
    # What reading it left out (an SDF world's missing models, unknown plugins), one line each.
    warnings: tuple[str, ...] = ()

    @property
    def base_dir(self) -> pathlib.Path:
        """The folder relative URIs in the file are taken from."""
        return self.source.parent if self.source is not None else pathlib.Path.cwd()


def world_from_parameter(value: str) -> World:
    """Return the world a ``world`` parameter value names (a scenery or a world file)."""
    if value in SCENERIES:
        return World(value)
    if not value.strip():
        raise ParameterError(
            f"parameter 'world' must be one of {', '.join(SCENERIES)} or a world file, got ''")
    try:
        path = resolve_resource(value, pathlib.Path.cwd())
    except ConfigurationError as err:
        raise ParameterError(f"parameter 'world': {err}") from None
    if not path.exists():  # a folder, device or FIFO: read_world_file says what it is
        raise ParameterError(
            f"parameter 'world': '{value}' is none of {', '.join(SCENERIES)}, and no world "
            f'file ({path}: no such file)')
    if is_sdf_world_path(path):
        return read_sdf_world_file(path)
    return read_world_file(path)


def read_sdf_world_file(path: pathlib.Path, max_entities: int = MAX_WORLD_ENTITIES) -> World:
    """Read an SDF world file of at most ``max_entities`` models into a :class:`World`."""
    try:
        found = read_sdf_world(path)
    except SdfWorldError as err:
        raise WorldFileError(str(err)) from None
    if len(found.models) > max_entities:
        raise WorldFileError(
            f'{path}: <world>: {len(found.models)} models; a world file may hold at most '
            f'{max_entities} (see docs/simulator-control.md)')
    entities = tuple(EntitySpec(name=model.name, resource_string=model.urdf_xml,
                                position=model.position, orientation=model.orientation)
                     for model in found.models)
    return World(GROUND if found.ground else EMPTY, entities, path, physics=found.physics,
                 warnings=found.warnings)


def read_world_file(path: pathlib.Path, max_entities: int = MAX_WORLD_ENTITIES) -> World:
    """Read and check a YAML world file of at most ``max_entities`` objects."""
    try:
        document = yaml_input.load_file(path)
    except yaml_input.YamlInputError as err:
        raise WorldFileError(f'{path}{err.where}: {err}') from None
    if document is None:
        document = {}
    _check_mapping(document, WORLD_KEYS, path, 'the file')
    scenery = document.get('scenery', DEFAULT_FILE_SCENERY)
    if scenery not in SCENERIES:
        raise WorldFileError(
            f"{path}: scenery: must be one of {', '.join(SCENERIES)}, got {scenery!r}")
    entries = document.get('entities') or []
    if not isinstance(entries, list):
        raise WorldFileError(f'{path}: entities: must be a list, got {_kind(entries)}')
    if len(entries) > max_entities:
        raise WorldFileError(
            f'{path}: entities: {len(entries)} objects; a world file may list at most '
            f'{max_entities} (start-up and every physics step grow with them; see '
            'docs/simulator-control.md)')
    entities = tuple(_entity(entry, path, f'entities[{index}]')
                     for index, entry in enumerate(entries))
    seen: set[str] = set()
    for entity in entities:
        if entity.name in seen:
            raise WorldFileError(f"{path}: entities: the name '{entity.name}' is used twice")
        if entity.name:
            seen.add(entity.name)
    return World(scenery, entities, path)


def _entity(entry: Any, path: pathlib.Path, where: str) -> EntitySpec:
    _check_mapping(entry, ENTITY_KEYS, path, where)
    texts = {}
    for key in ('name', 'uri', 'resource_string', 'description'):
        value = entry.get(key, '')
        if not isinstance(value, str):
            raise WorldFileError(f'{path}: {where}.{key}: must be a string, got {_kind(value)}')
        texts[key] = value
    if 'shape' in entry:
        if texts['uri'] or texts['resource_string']:
            raise WorldFileError(f'{path}: {where}: give a shape, a uri or a resource_string, '
                                 'only one')
        index = ''.join(character for character in where if character.isdigit())
        texts['resource_string'] = _shape(entry, path, where,
                                          texts['name'] or f"{entry['shape']}_{index}")
    else:
        extra = [key for key in SHAPE_KEYS if key in entry]
        if extra:
            raise WorldFileError(f"{path}: {where}.{extra[0]}: only a shape takes it (no "
                                 "'shape' given)")
    if not texts['uri'] and not texts['resource_string']:
        raise WorldFileError(f'{path}: {where}: give a uri, a resource_string or a shape')
    tags = entry.get('tags', [])
    if not isinstance(tags, list) or not all(isinstance(tag, str) for tag in tags):
        raise WorldFileError(f'{path}: {where}.tags: must be a list of strings')
    position, orientation = _pose(entry.get('pose', {}), path, f'{where}.pose')
    return EntitySpec(position=position, orientation=orientation, tags=tuple(tags), **texts)


def _shape(entry: Mapping[str, Any], path: pathlib.Path, where: str, name: str) -> str:
    """Check a shape entry; return its URDF."""
    shape = entry['shape']
    if shape not in SHAPE_SIZES:
        raise WorldFileError(f"{path}: {where}.shape: must be one of {', '.join(SHAPE_SIZES)}, "
                             f'got {shape!r}')
    names = SHAPE_SIZES[shape]
    if 'size' not in entry:
        raise WorldFileError(f"{path}: {where}.size: a {shape} needs its size "
                             f"[{', '.join(names)}] (m)")
    size = _numbers(entry['size'], len(names), path, f'{where}.size')
    if not all(value > 0.0 for value in size):
        raise WorldFileError(f"{path}: {where}.size: [{', '.join(names)}] must all be > 0, "
                             f'got {list(size)!r}')
    colour = entry.get('colour', list(DEFAULT_COLOUR))
    if isinstance(colour, list) and len(colour) == 3:
        colour = [*colour, 1.0]
    rgba = _numbers(colour, 4, path, f'{where}.colour')
    if not all(0.0 <= value <= 1.0 for value in rgba):
        raise WorldFileError(f'{path}: {where}.colour: each of r, g, b, a must be in 0..1, '
                             f'got {colour!r}')
    static = entry.get('static', True)
    if not isinstance(static, bool):
        raise WorldFileError(f'{path}: {where}.static: must be true or false, got {static!r}')
    mass = entry.get('mass', DEFAULT_SHAPE_MASS)
    if isinstance(mass, bool) or not isinstance(mass, int | float) or not (
            math.isfinite(mass) and mass > 0.0):
        raise WorldFileError(f'{path}: {where}.mass: must be a number > 0 (kg), got {mass!r}')
    return shape_urdf(name, shape, size, rgba, static=static, mass=float(mass))


def shape_urdf(name: str, shape: str, size: tuple[float, ...], rgba: tuple[float, ...], *,
               static: bool = True, mass: float = DEFAULT_SHAPE_MASS) -> str:
    """Return a one-link URDF of a box, cylinder or sphere (m, kg), centred on its frame.

    ``size``: a box's [x, y, z], a cylinder's [radius, length] (axis z), a
    sphere's [radius].  ``static``: ``<gazebo><static>`` (fixed where it is put).
    """
    if shape == 'box':
        x, y, z = size
        geometry = f'<box size="{x!r} {y!r} {z!r}"/>'
        inertia = (mass * (y * y + z * z) / 12, mass * (x * x + z * z) / 12,
                   mass * (x * x + y * y) / 12)
    elif shape == 'cylinder':
        radius, length = size
        geometry = f'<cylinder radius="{radius!r}" length="{length!r}"/>'
        side = mass * (3 * radius * radius + length * length) / 12
        inertia = (side, side, mass * radius * radius / 2)
    else:
        (radius,) = size
        geometry = f'<sphere radius="{radius!r}"/>'
        inertia = (2 * mass * radius * radius / 5,) * 3
    ixx, iyy, izz = inertia
    colour = ' '.join(repr(value) for value in rgba)
    static_tag = '<gazebo><static>true</static></gazebo>' if static else ''
    return (f'<robot name="{name}"><link name="{name}_link">'
            f'<inertial><mass value="{mass!r}"/><inertia ixx="{ixx!r}" ixy="0" ixz="0" '
            f'iyy="{iyy!r}" iyz="0" izz="{izz!r}"/></inertial>'
            f'<visual><geometry>{geometry}</geometry><material name="{name}_colour">'
            f'<color rgba="{colour}"/></material></visual>'
            f'<collision><geometry>{geometry}</geometry></collision></link>'
            f'{static_tag}</robot>')


def _pose(pose: Any, path: pathlib.Path, where: str) -> tuple[Vector, Quaternion]:
    _check_mapping(pose, POSE_KEYS, path, where)
    if 'orientation' in pose and 'rpy' in pose:
        raise WorldFileError(f'{path}: {where}: give orientation or rpy, not both')
    position = _numbers(pose.get('position', list(ZERO_VECTOR)), 3, path, f'{where}.position')
    if 'rpy' in pose:
        orientation = quaternion_from_rpy(*_numbers(pose['rpy'], 3, path, f'{where}.rpy'))
    else:
        x, y, z, w = _numbers(pose.get('orientation', list(IDENTITY_ROTATION)), 4, path,
                              f'{where}.orientation')
        norm = math.hypot(x, y, z, w)  # no overflow for huge components
        if norm < NORM_TOLERANCE:
            raise WorldFileError(f'{path}: {where}.orientation: a quaternion of length 0 is '
                                 'no rotation')
        orientation = (x / norm, y / norm, z / norm, w / norm)
    return position, orientation  # type: ignore[return-value]


def _numbers(value: Any, count: int, path: pathlib.Path, where: str) -> tuple[float, ...]:
    if (not isinstance(value, list) or len(value) != count
            or not all(isinstance(v, int | float) and not isinstance(v, bool)
                       and math.isfinite(v) for v in value)):
        raise WorldFileError(f'{path}: {where}: must be {count} finite numbers, got {value!r}')
    return tuple(float(v) for v in value)


def _check_mapping(value: Any, keys: tuple[str, ...], path: pathlib.Path, where: str) -> None:
    if not isinstance(value, Mapping):
        raise WorldFileError(f'{path}: {where}: must be a mapping, got {_kind(value)}')
    unknown = [key for key in value if key not in keys]
    if unknown:
        raise WorldFileError(f"{path}: {where}: unknown key '{unknown[0]}' (known: "
                             f"{', '.join(keys)})")


def _kind(value: Any) -> str:
    return {dict: 'a mapping', list: 'a list', str: 'a string', bool: 'a bool', int: 'a number',
            float: 'a number', type(None): 'nothing'}.get(type(value), type(value).__name__)
