"""An SDF world file (``.sdf``, ``.world``, ``.sdf.xacro``) to a :class:`World`. No ROS.

What is read from ``<sdf><world>``:

* a ground plane (Gazebo's ``ground_plane``: a static model of planes through
  the origin facing up) becomes the simulator's own ground, z = 0;
* every other ``<model>`` and ``<include>`` (``model://``, a cached Fuel URI,
  ``file://``, a path), static or not, as an object placed by its ``<pose>``;
* ``<physics>``: ``max_step_size`` (s), ``real_time_factor``, and the solver
  settings PyBullet has a counterpart for (:class:`WorldPhysics`); the others
  are named in :attr:`WorldPhysics.unmatched`;
* lights, scene, GUI, atmosphere, gravity and the system plugins whose work
  the simulator does itself are accepted; any other world plugin, actors,
  populations and roads get one warning each.

Design notes: docs/design/model.md#sdf_worldpy.
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
import xml.etree.ElementTree as ElementTree

from pan_tilt_sim.errors import ConfigurationError, DescriptionError
from pan_tilt_sim.model import sdf_resources
from pan_tilt_sim.model.sdf import (
    ModelConverter,
    _included_model,
    model_path_text,
    parse_sdf,
    version_of,
)
from pan_tilt_sim.model.transforms import Quaternion, Vector
from pan_tilt_sim.model.xml_input import float_or_nan

SDF_WORLD_SUFFIXES = ('.sdf', '.world')
XACRO_SUFFIX = '.xacro'
# World elements with nothing for the simulator to do.
QUIET_ELEMENTS = ('light', 'scene', 'gui', 'atmosphere', 'gravity', 'magnetic_field',
                  'spherical_coordinates', 'wind', 'audio', 'physics', 'plugin', 'model',
                  'include', 'frame', 'state')
UNSIMULATED_ELEMENTS = ('actor', 'population', 'road')
# gz-sim systems (and Gazebo classic's ROS plugins) whose work the simulator does itself.
KNOWN_SYSTEMS = (
    'physics', 'sensors', 'user-commands', 'scene-broadcaster', 'imu', 'contact',
    'forcetorque', 'magnetometer', 'air-pressure', 'altimeter', 'navsat', 'logical-camera',
)
KNOWN_CLASSIC_PLUGINS = ('libgazebo_ros_init.so', 'libgazebo_ros_factory.so',
                         'libgazebo_ros_state.so', 'libgazebo_ros_properties.so',
                         'libgazebo_ros_api_plugin.so', 'libgazebo_ros_paths_plugin.so')
SYSTEM_PREFIXES = ('gz-sim-', 'libgz-sim-', 'ignition-gazebo-', 'libignition-gazebo-',
                   'gz-sim8-', 'gz-sim7-')
# Fuel models read by their name when not in the local cache (lower case).
FUEL_GROUND_PLANES = ('ground plane', 'ground_plane')
FUEL_LIGHTS = ('sun',)
GROUND_PLANE = object()  # what an <include> of a ground plane model reads as
GROUND_TOLERANCE = 1e-9  # m, rad: how close to z = 0, facing up, a ground plane must be
# By <physics type>: the engine section's elements PyBullet has a counterpart for.
PYBULLET_COUNTERPARTS = {
    'ode': ('solver/iters', 'constraints/erp', 'constraints/cfm',
            'constraints/contact_surface_layer'),
    'bullet': ('solver/iters', 'constraints/erp', 'constraints/cfm',
               'constraints/contact_surface_layer', 'constraints/split_impulse'),
}


class SdfWorldError(ConfigurationError):
    """The SDF world file cannot be used (the world file module reports it as its own)."""


@dataclasses.dataclass(frozen=True)
class SdfModel:
    """One model of the world, as URDF text, and where the world puts it."""

    name: str
    urdf_xml: str
    position: Vector
    orientation: Quaternion


@dataclasses.dataclass(frozen=True)
class WorldPhysics:
    """What an SDF world's ``<physics>`` asks for; None where it says nothing."""

    time_step: float | None = None  # s
    real_time_factor: float | None = None
    solver_iterations: int | None = None
    erp: float | None = None  # joints and contacts alike, 0..1
    cfm: float | None = None  # >= 0
    contact_slop: float | None = None  # m: <contact_surface_layer>
    split_impulse: bool | None = None
    # The elements it gives that PyBullet has no counterpart for, as <a><b> paths.
    unmatched: tuple[str, ...] = ()

    def settings(self) -> dict[str, float | int | bool]:
        """Return the sim_node physics parameters it sets, by name (see physics_settings)."""
        values = {'solver_iterations': self.solver_iterations, 'erp': self.erp,
                  'contact_erp': self.erp, 'cfm': self.cfm, 'contact_slop': self.contact_slop,
                  'split_impulse': self.split_impulse}
        return {name: value for name, value in values.items() if value is not None}


def is_sdf_world_path(path: pathlib.Path) -> bool:
    """Whether ``path`` names an SDF world by its suffix (``.sdf``, ``.world``, ``.sdf.xacro``)."""
    name = path.name.lower()
    if name.endswith(XACRO_SUFFIX):
        name = name[:-len(XACRO_SUFFIX)]
    return name.endswith(SDF_WORLD_SUFFIXES)


@dataclasses.dataclass(frozen=True)
class SdfWorld:
    """What an SDF world file holds for the simulator."""

    ground: bool
    models: tuple[SdfModel, ...]
    physics: WorldPhysics
    warnings: tuple[str, ...] = ()


def read_sdf_world(path: pathlib.Path) -> SdfWorld:
    """Read an SDF world file; raise :class:`SdfWorldError` naming the file and element."""
    from pan_tilt_sim.model.description import read_description_xml  # xacro, as for robots
    try:
        text, xacro_warnings = read_description_xml(path)
    except DescriptionError as err:
        raise SdfWorldError(str(err).replace('robot description file', 'world file')) from None
    try:
        root = parse_sdf(text, path)
    except DescriptionError as err:
        raise SdfWorldError(str(err)) from None
    world = root.find('world')
    if world is None:
        found = root[0].tag if len(root) else 'nothing'
        raise SdfWorldError(f'{path}: <sdf>: has no <world> (found <{found}>): a world file '
                             'holds a <world>; a robot <model> is robot_description_file')
    reader = _WorldReader(path, version_of(root))
    entities, ground = reader.models(world)
    reader.other_elements(world)
    physics = reader.physics(world)
    return SdfWorld(ground, tuple(entities), physics,
                    tuple(xacro_warnings) + tuple(reader.warnings))


class _WorldReader:
    def __init__(self, path: pathlib.Path, version: tuple[int, int]) -> None:
        self.path = path
        self.version = version
        self.warnings: list[str] = []

    def error(self, where: str, problem: str) -> SdfWorldError:
        return SdfWorldError(f'{self.path}: {where}: {problem}')

    def models(self, world: ElementTree.Element) -> tuple[list[SdfModel], bool]:
        entities: list[SdfModel] = []
        ground = False
        names: set[str] = set()
        for element in world:
            if element.tag == 'model':
                if _is_ground_plane(element):
                    ground = True
                    continue
                spec = self.model(element, element, self.path.parent, self.version, None)
            elif element.tag == 'include':
                spec = self.include(element)
                if spec is GROUND_PLANE:
                    ground = True
                    continue
            else:
                continue
            if spec is None:
                continue
            if spec.name in names:
                raise self.error(f'<model name="{spec.name}">', 'the name is used twice')
            names.add(spec.name)
            entities.append(spec)
        return entities, ground

    def include(self, element: ElementTree.Element) -> SdfModel | object | None:
        """Return the included model's spec, GROUND_PLANE, or None (skipped, with a warning)."""
        uri = (element.findtext('uri') or '').strip()
        where = f'<include><uri>{uri}</uri>'
        if sdf_resources.is_fuel_uri(uri) and sdf_resources.resolve_fuel_uri(uri) is None:
            # Gazebo's own two, which every Fuel-based world includes: known without a download.
            name = sdf_resources.fuel_model_name(uri)
            if name in FUEL_GROUND_PLANES and element.find('pose') is None:
                return GROUND_PLANE
            if name in FUEL_LIGHTS:
                return None
        try:
            model, folder, version = _included_model(element, self.path, self.path.parent)
        except DescriptionError as err:
            self.skip(where, self.missing_reason(uri, err))
            return None
        if _is_ground_plane(model) and element.find('pose') is None:
            return GROUND_PLANE
        return self.model(model, element, folder, version, uri)

    def missing_reason(self, uri: str, err: DescriptionError) -> str:
        if uri.startswith(sdf_resources.MODEL_SCHEME):
            name, _rest = sdf_resources.split_model_uri(uri)
            return f"model '{name}' is in no model path ({model_path_text()})"
        if sdf_resources.is_fuel_uri(uri):
            return (f'not in the local Fuel cache: put the model in '
                    f'{sdf_resources.fuel_cache_folder(uri)} (nothing is downloaded)')
        return str(err).split(': ', 1)[-1]

    def skip(self, where: str, why: str) -> None:
        self.warnings.append(f'{self.path}: {where}: skipped: {why}')

    def model(self, model: ElementTree.Element, placement: ElementTree.Element,
              base_dir: pathlib.Path, version: tuple[int, int],
              uri: str | None) -> SdfModel | None:
        """Convert one world model (``placement``: its ``<include>``, or the model itself)."""
        converter = ModelConverter(self.path, version)
        name = (placement.findtext('name') or '').strip() if placement is not model else ''
        name = name or model.get('name', '')
        where = f'<model name="{name}">' if uri is None else f'<include><uri>{uri}</uri>'
        static_text = placement.findtext('static') if placement is not model else None
        static = None if static_text is None else static_text.strip().lower() in ('1', 'true')
        try:
            pose = converter.pose(placement.find('pose'), where) if (
                placement.find('pose') is not None) else converter.pose(model.find('pose'),
                                                                        where)
            if static is None and _true(model.findtext('static')):
                static = True
            conversion = converter.convert(model, base_dir, name=name, static=bool(static),
                                           pose=pose)
        except DescriptionError as err:
            self.skip(where, str(err))
            return None
        self.warnings += conversion.warnings
        return SdfModel(conversion.name, conversion.urdf_xml, pose.translation, pose.rotation)

    def other_elements(self, world: ElementTree.Element) -> None:
        for element in world:
            if element.tag in UNSIMULATED_ELEMENTS:
                self.skip(f'<{element.tag} name="{element.get("name", "")}">',
                          f'<{element.tag}> is not simulated')
            elif element.tag == 'plugin':
                filename = element.get('filename', '')
                if not _known_plugin(filename):
                    self.warnings.append(
                        f"{self.path}: <plugin filename=\"{filename}\" name=\""
                        f"{element.get('name', '')}\">: a world plugin that is not simulated: "
                        'left out')

    def physics(self, world: ElementTree.Element) -> WorldPhysics:
        elements = world.findall('physics')
        if not elements:
            return WorldPhysics()
        chosen = next((element for element in elements
                       if _true(element.get('default'))), elements[0])
        where = f'<physics name="{chosen.get("name", "")}">'
        engine = (chosen.get('type') or 'ode').strip().lower()
        used = {'max_step_size', 'real_time_factor'}
        step = self.number(chosen, 'max_step_size', where, positive=True)
        factor = self.number(chosen, 'real_time_factor', where, positive=False)
        iterations = erp = cfm = layer = split = None
        if engine in PYBULLET_COUNTERPARTS:
            used |= {f'{engine}/{path}' for path in PYBULLET_COUNTERPARTS[engine]}
            iterations = self.number(chosen, f'{engine}/solver/iters', where, positive=True)
            if iterations is not None and iterations != int(iterations):
                raise self.error(where, f'<{engine}><solver><iters> must be a whole number, '
                                 f'got {iterations:g}')
            erp = self.number(chosen, f'{engine}/constraints/erp', where, positive=False)
            if erp is not None and erp > 1.0:
                raise self.error(where, f'<{engine}><constraints><erp> must be from 0 to 1 (a '
                                 f'share of the error per step), got {erp:g}')
            cfm = self.number(chosen, f'{engine}/constraints/cfm', where, positive=False)
            layer = self.number(chosen, f'{engine}/constraints/contact_surface_layer', where,
                                positive=False)
            split_text = (chosen.findtext(f'{engine}/constraints/split_impulse') or '').strip()
            if split_text:
                if split_text.lower() not in ('1', '0', 'true', 'false'):
                    raise self.error(where, f'<{engine}><constraints><split_impulse> must be '
                                     f'true or false, got {split_text!r}')
                split = _true(split_text)
        unmatched = tuple(
            ''.join(f'<{tag}>' for tag in path.split('/')) for path in _leaf_paths(chosen)
            if path not in used)
        return WorldPhysics(step, factor, None if iterations is None else int(iterations),
                            erp, cfm, layer, split, unmatched)

    def number(self, element: ElementTree.Element, path: str, where: str, *,
               positive: bool) -> float | None:
        text = (element.findtext(path) or '').strip()
        if not text:
            return None
        value = float_or_nan(text)
        if not math.isfinite(value) or value < 0.0 or (positive and value == 0.0):
            raise self.error(where, f"<{path}>{text}</...> must be a number "
                             f"{'>' if positive else '>='} 0")
        return value


def _leaf_paths(element: ElementTree.Element, prefix: str = '') -> list[str]:
    """Return the paths (``a/b``) of the elements under ``element`` that hold no others."""
    paths = []
    for child in element:
        path = f'{prefix}{child.tag}'
        paths.extend(_leaf_paths(child, f'{path}/') if len(child) else [path])
    return paths


def _true(text: str | None) -> bool:
    return (text or '').strip().lower() in ('1', 'true')


def _known_plugin(filename: str) -> bool:
    if filename in KNOWN_CLASSIC_PLUGINS:
        return True
    stem = filename.rsplit('/', 1)[-1]
    for suffix in ('.so',):
        stem = stem.removesuffix(suffix)
    for prefix in SYSTEM_PREFIXES:
        if stem.startswith(prefix):
            return stem[len(prefix):].removesuffix('-system') in KNOWN_SYSTEMS
    return False


def _is_ground_plane(model: ElementTree.Element) -> bool:
    """Whether ``model`` is a ground plane: static, its collisions all planes z = 0 facing up."""
    if not _true(model.findtext('static')) or model.find('model') is not None or (
            model.find('include') is not None):
        return False
    collisions = model.findall('link/collision')
    if not collisions:
        return False
    for element in [model, *model.findall('link'), *collisions]:
        pose = (element.findtext('pose') or '').split()
        if pose and any(abs(float(value)) > GROUND_TOLERANCE for value in pose
                        if _is_number(value)):
            return False
    for collision in collisions:
        plane = collision.find('geometry/plane')
        if plane is None:
            return False
        normal = (plane.findtext('normal') or '0 0 1').split()
        if [float_or_nan(value) for value in normal] != [0.0, 0.0, 1.0]:
            return False
    return True


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True

