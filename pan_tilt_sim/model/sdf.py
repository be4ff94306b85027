"""SDF text to the URDF the robot model is read from: Gazebo's own format, read once. No ROS.

An SDF robot (``<sdf><model>``) becomes a URDF that says the same thing, which
the one URDF parser (:mod:`pan_tilt_sim.model.urdf`) then reads, so the
controllers, sensors, plugins, TF, the view and recording see an SDF robot as
they see a URDF one.  What is read (SDFormat 1.4 to 1.11) (see the design notes).

Design notes: docs/design/model.md#sdfpy.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import math
import os
import pathlib
import re
import xml.etree.ElementTree as ElementTree

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model import sdf_resources
from pan_tilt_sim.model.resources import mesh_cache_dir, resolve_resource
from pan_tilt_sim.model.transforms import (
    Transform,
    Vector,
    quaternion_from_rpy,
    quaternion_multiply,
    rotate,
    rotation_matrix,
)
from pan_tilt_sim.model.xml_input import float_or_nan, parse_root

SDF_ROOT_TAG = 'sdf'
SUPPORTED_VERSIONS = ('1.4', '1.5', '1.6', '1.7', '1.8', '1.9', '1.10', '1.11')
MODEL_FRAME = '__model__'
WORLD_FRAME = 'world'
SCOPE = '::'
# SDFormat's defaults for a link without <inertial>, or an <inertial> without them.
DEFAULT_MASS = 1.0  # kg
DEFAULT_INERTIA = 1.0  # kg m^2, each principal moment
DEFAULT_AXIS = (0.0, 0.0, 1.0)  # SDF's joint axis default
NO_LIMIT = 1e16  # SDFormat's default joint limits: a bound this large is none
SPHERICAL = 'spherical'  # PyBullet's URDF joint type for SDF's ball joint
JOINT_TYPES = {'revolute': 'revolute', 'continuous': 'continuous', 'prismatic': 'prismatic',
               'fixed': 'fixed', 'ball': SPHERICAL}
PLANE_THICKNESS = 0.01  # m: a plane in a model is a slab this thick, its top face the plane
ELLIPSOID_RINGS = 12  # latitude bands of the mesh an ellipsoid becomes
ELLIPSOID_SEGMENTS = 24  # longitude segments of that mesh
SHAPE_ROLES = ('collision', 'visual')
POSE_LENGTH = 6
VECTOR_LENGTH = 3
_POSE_SEPARATOR = re.compile(r'[\s,]+')
# A generated mesh (an ellipsoid) is cached under this folder of the mesh cache.
GENERATED_SUBDIR = 'sdf_shapes'


@dataclasses.dataclass(frozen=True)
class SdfConversion:
    """An SDF model as URDF: the text to read and publish, and what could not be used."""

    urdf_xml: str  # ball joints are PyBullet's 'spherical'
    name: str
    static: bool
    pose: Transform  # the model's own <pose> (where a world places it)
    warnings: tuple[str, ...] = ()


def is_sdf_text(text: str) -> bool:
    """Whether ``text`` is an SDF document (its root element is ``<sdf>``)."""
    match = re.search(r'<\s*([A-Za-z_][\w:.-]*)', _strip_prolog(text))
    return match is not None and match.group(1) == SDF_ROOT_TAG


def _strip_prolog(text: str) -> str:
    """Drop the XML declaration, comments and processing instructions before the root."""
    text = text.lstrip('\ufeff')
    while True:
        stripped = text.lstrip()
        if stripped.startswith('<?'):
            text = stripped[stripped.find('?>') + 2:]
        elif stripped.startswith('<!--'):
            end = stripped.find('-->')
            text = stripped[end + 3:] if end >= 0 else ''
        elif stripped.startswith('<!'):
            text = stripped[stripped.find('>') + 1:]
        else:
            return stripped


def parse_sdf(text: str, source: pathlib.Path) -> ElementTree.Element:
    """Parse SDF text; require an ``<sdf>`` root of a supported version."""
    root = parse_root(text, source)
    if root.tag != SDF_ROOT_TAG:
        raise DescriptionError(f'{source}: not an SDF: the root element is <{root.tag}>, '
                               f'expected <{SDF_ROOT_TAG}>')
    version = (root.get('version') or '').strip()
    if version not in SUPPORTED_VERSIONS:
        raise DescriptionError(
            f'{source}: <sdf version="{version}">: SDFormat version {version or "(none)"} is '
            f"not supported (supported: {', '.join(SUPPORTED_VERSIONS)})")
    return root


def sdf_robot_to_urdf(text: str, source: pathlib.Path, base_dir: pathlib.Path) -> SdfConversion:
    """Convert an SDF robot (one top-level ``<model>``) to URDF; errors name ``source``.

    Relative URIs are taken from ``base_dir`` (the SDF file's folder).
    """
    root = parse_sdf(text, source)
    models = root.findall('model')
    if root.find('world') is not None and not models:
        raise DescriptionError(f'{source}: <sdf> holds a <world>, not a robot <model>: give it '
                               "as the 'world' parameter")
    if not models and root.find('include') is not None:
        models = [_included_model(root.find('include'), source, base_dir)[0]]
    if len(models) != 1:
        names = ', '.join(repr(model.get('name', '')) for model in models)
        raise DescriptionError(
            f'{source}: <sdf>: a robot is one top-level <model>, found {len(models)}'
            + (f' ({names})' if names else ''))
    return ModelConverter(source, version_of(root)).convert(models[0], base_dir)


def version_of(root: ElementTree.Element) -> tuple[int, int]:
    """Return ``(major, minor)`` of an ``<sdf version>``."""
    major, _, minor = (root.get('version') or '1.11').partition('.')
    try:
        return int(major), int(minor or 0)
    except ValueError:
        return (1, 11)


def _included_model(include: ElementTree.Element, source: pathlib.Path,
                    base_dir: pathlib.Path) -> tuple[ElementTree.Element, pathlib.Path,
                                                     tuple[int, int]]:
    """Read the ``<model>`` an ``<include><uri>`` names; return it, its folder and SDF version."""
    uri = (include.findtext('uri') or '').strip()
    if not uri:
        raise DescriptionError(f'{source}: <include>: has no <uri>')
    folder = locate_model(uri, source, base_dir)
    path = sdf_resources.model_sdf_file(folder) if folder.is_dir() else folder
    try:
        text = path.read_text(encoding='utf-8')
    except (OSError, UnicodeDecodeError) as err:
        raise DescriptionError(f'{source}: <include><uri>{uri}</uri>: cannot read {path}: '
                               f'{err}') from None
    root = parse_sdf(text, path)
    model = root.find('model')
    if model is None:
        raise DescriptionError(f'{path}: <sdf>: has no <model> to include (from {source})')
    return model, path.parent, version_of(root)


def locate_model(uri: str, source: pathlib.Path, base_dir: pathlib.Path) -> pathlib.Path:
    """Return the folder (or file) an include's URI names; a missing one is an error."""
    if uri.startswith(sdf_resources.MODEL_SCHEME):
        found = sdf_resources.resolve_model_uri(uri)
        if found is None or not found.exists():
            name, _rest = sdf_resources.split_model_uri(uri)
            raise DescriptionError(
                f"{source}: <include><uri>{uri}</uri>: model '{name}' is in no model path "
                f'({model_path_text()})')
        return found
    if sdf_resources.is_fuel_uri(uri):
        found = sdf_resources.resolve_fuel_uri(uri)
        if found is None:
            raise DescriptionError(
                f'{source}: <include><uri>{uri}</uri>: not in the local Fuel cache '
                f'({sdf_resources.fuel_cache_folder(uri)}); nothing is downloaded')
        return found
    try:
        path = resolve_resource(uri, base_dir)
    except DescriptionError as err:
        raise DescriptionError(f'{source}: <include><uri>: {err}') from None
    if not path.exists():
        raise DescriptionError(f'{source}: <include><uri>{uri}</uri>: no such file or folder '
                               f'({path})')
    return path


def model_path_text() -> str:
    """Say which folders ``model://`` was looked up in, for an error message."""
    paths = sdf_resources.model_paths()
    searched = ', '.join(str(path) for path in paths) if paths else 'none'
    return (f'searched: {searched}; set {sdf_resources.RESOURCE_PATH_VARIABLES[0]} to the '
            'folder that holds the model')


# --- transforms -------------------------------------------------------------------------------

def inverse(transform: Transform) -> Transform:
    """Return the inverse of a rigid transform."""
    x, y, z, w = transform.rotation
    conjugate = (-x, -y, -z, w)
    tx, ty, tz = rotate(conjugate, transform.translation)
    return Transform((-tx, -ty, -tz), conjugate)


def rpy_from_quaternion(q: tuple[float, float, float, float]) -> Vector:
    """Return URDF's fixed-axis roll, pitch, yaw of a rotation."""
    rows = rotation_matrix(q)
    pitch = math.asin(max(-1.0, min(1.0, -rows[2][0])))
    if abs(rows[2][0]) < 1.0 - 1e-12:
        roll = math.atan2(rows[2][1], rows[2][2])
        yaw = math.atan2(rows[1][0], rows[0][0])
    else:  # gimbal lock: the yaw carries the whole turn about z
        roll = 0.0
        yaw = math.atan2(-rows[0][1], rows[1][1])
    return (roll, pitch, yaw)


def origin_element(parent: ElementTree.Element, transform: Transform,
                   tag: str = 'origin') -> None:
    """Add ``<origin xyz rpy>`` of ``transform`` to ``parent``."""
    ElementTree.SubElement(parent, tag, xyz=_numbers(transform.translation),
                           rpy=_numbers(rpy_from_quaternion(transform.rotation)))


def _numbers(values) -> str:
    return ' '.join(repr(float(value)) for value in values)


# --- one model --------------------------------------------------------------------------------

@dataclasses.dataclass
class _Frame:
    relative_to: str | None  # full name of the frame the pose is in; None: the top model frame
    pose: Transform
    element: ElementTree.Element | None = None
    scope: str = ''
    base_dir: pathlib.Path = pathlib.Path()
    version: tuple[int, int] = (1, 11)
    kind: str = 'frame'  # link, joint, frame, model


class ModelConverter:
    """Flattens one SDF ``<model>`` (nested models and includes too) into a URDF."""

    def __init__(self, source: pathlib.Path, version: tuple[int, int]) -> None:
        self.source = source
        self.version = version
        self.frames: dict[str, _Frame] = {}
        self.links: list[str] = []
        self.joints: list[str] = []
        self.plugins: list[ElementTree.Element] = []
        self.extra: list[ElementTree.Element] = []  # <ros2_control> blocks, as in a URDF
        self.warnings: list[str] = []
        self.static = False
        self.hulls: list[str] = []  # links of a moving model with collision meshes
        self._resolved: dict[str, Transform] = {}
        self._resolving: set[str] = set()

    def error(self, where: str, problem: str) -> DescriptionError:
        """Return the error naming the file, ``where`` and ``problem``."""
        return DescriptionError(f'{self.source}: {where}: {problem}')

    # --- reading the tree ---------------------------------------------------------------

    def convert(self, model: ElementTree.Element, base_dir: pathlib.Path,
                name: str | None = None, static: bool | None = None,
                pose: Transform | None = None) -> SdfConversion:
        """Convert ``model``; ``name``, ``static`` and ``pose`` override its own (an include's)."""
        name = name or model.get('name', '')
        if not name:
            raise self.error('<model>', 'has no name attribute')
        if pose is None:
            pose = self.pose(model.find('pose'), f'<model name="{name}">')
        is_static = static if static is not None else _true(model.findtext('static'))
        self.static = is_static
        self.frames[MODEL_FRAME] = _Frame(None, Transform(), kind='model')
        self.read_model(model, '', base_dir, self.version)
        if not self.links:
            raise self.error(f'<model name="{name}">', 'has no <link>')
        robot = self.urdf(name, is_static)
        if self.hulls:
            self.warnings.append(
                f"{self.source}: <model name=\"{name}\">: collision meshes of links "
                f"{', '.join(repr(link) for link in self.hulls)} collide as their convex hulls "
                '(PyBullet collides a mesh as its triangles only on a static body)')
        ElementTree.indent(robot)
        return SdfConversion(ElementTree.tostring(robot, encoding='unicode'), name,
                             is_static, pose, tuple(self.warnings))

    def read_model(self, model: ElementTree.Element, scope: str, base_dir: pathlib.Path,
                   version: tuple[int, int]) -> None:
        """Record the links, joints, frames and plugins of ``model``, named under ``scope``."""
        model_frame = scope + MODEL_FRAME
        for element in model.findall('link'):
            self.add_frame(element, scope, base_dir, version, 'link', model_frame)
        for element in model.findall('frame'):
            attached = element.get('attached_to') or MODEL_FRAME
            self.add_frame(element, scope, base_dir, version, 'frame',
                           self.scoped(attached, scope))
        for element in model.findall('model'):
            self.nested(element, element, scope, base_dir, version)
        for element in model.findall('include'):
            included, folder, included_version = _included_model(element, self.source, base_dir)
            self.nested(included, element, scope, folder, included_version)
        for element in model.findall('joint'):
            name = self.add_frame(element, scope, base_dir, version, 'joint', None)
            self.joints.append(name)
        for element in model.findall('plugin'):
            self.plugins.append(copy.deepcopy(element))
        for element in model.findall('ros2_control'):
            self.extra.append(copy.deepcopy(element))

    def nested(self, model: ElementTree.Element, placement: ElementTree.Element, scope: str,
               base_dir: pathlib.Path, version: tuple[int, int]) -> None:
        """Read a nested ``<model>``, or an included one placed by its ``<include>``."""
        name = (placement.findtext('name') or '').strip() if placement is not model else ''
        name = name or model.get('name', '')
        if not name:
            raise self.error('<model>', 'a nested model has no name')
        inner = f'{scope}{name}{SCOPE}'
        pose_element = placement.find('pose')
        if pose_element is None:
            pose_element = model.find('pose')
        where = f'<model name="{name}">'
        relative_to = pose_element.get('relative_to') if pose_element is not None else None
        self.frames[inner + MODEL_FRAME] = _Frame(
            self.scoped(relative_to, scope) if relative_to else scope + MODEL_FRAME,
            self.pose(pose_element, where), model, scope, base_dir, version, 'model')
        self.read_model(model, inner, base_dir, version)

    def add_frame(self, element: ElementTree.Element, scope: str, base_dir: pathlib.Path,
                  version: tuple[int, int], kind: str, default: str | None) -> str:
        """Record a link's, joint's or frame's pose and what it is relative to; return its name."""
        name = element.get('name', '')
        if not name:
            raise self.error(f'<{kind}>', 'has no name attribute')
        full = scope + name
        if full in self.frames:
            raise self.error(f'<{kind} name="{name}">', 'the name is taken by another link, '
                             'joint or frame of the model')
        pose_element = element.find('pose')
        relative_to = pose_element.get('relative_to') if pose_element is not None else None
        if kind == 'joint' and not relative_to:
            relative_to = self.joint_link(element, 'child', scope)
            target = relative_to
        else:
            target = self.scoped(relative_to, scope) if relative_to else default
        self.frames[full] = _Frame(target, self.pose(pose_element, f'<{kind} name="{name}">'),
                                   element, scope, base_dir, version, kind)
        if kind == 'link':
            self.links.append(full)
        return full

    def joint_link(self, element: ElementTree.Element, role: str, scope: str) -> str:
        """Return the full name of the link a joint's ``<parent>`` or ``<child>`` names."""
        text = (element.findtext(role) or '').strip()
        if not text:
            raise self.error(f'<joint name="{element.get("name", "")}">', f'has no <{role}>')
        if text == WORLD_FRAME:
            return WORLD_FRAME
        return self.scoped(text, scope)

    @staticmethod
    def scoped(name: str, scope: str) -> str:
        """Return the full name of a frame named ``name`` inside the model of ``scope``."""
        return name if name.startswith(scope) and scope else scope + name

    def pose(self, element: ElementTree.Element | None, where: str) -> Transform:
        """Read a ``<pose>`` (six numbers, or ``rotation_format="quat_xyzw"``; ``degrees``)."""
        if element is None or not (element.text or '').strip():
            return Transform()
        text = element.text.strip()
        try:
            values = [float(value) for value in _POSE_SEPARATOR.split(text)]
        except ValueError:
            values = []
        degrees = element.get('degrees', 'false').strip().lower() in ('true', '1')
        rotation_format = element.get('rotation_format', 'euler_rpy')
        if rotation_format == 'quat_xyzw' and len(values) == POSE_LENGTH + 1 and all(
                math.isfinite(value) for value in values):
            x, y, z, w = values[3:]
            norm = math.sqrt(x * x + y * y + z * z + w * w)
            if norm > 0.0:
                return Transform(tuple(values[:3]), (x / norm, y / norm, z / norm, w / norm))
        if len(values) != POSE_LENGTH or not all(math.isfinite(value) for value in values):
            raise self.error(where, f'<pose>{text}</pose> is not six numbers (x y z roll pitch '
                             'yaw)')
        angles = [math.radians(value) if degrees else value for value in values[3:]]
        return Transform(tuple(values[:3]), quaternion_from_rpy(*angles))

    # --- frames -------------------------------------------------------------------------

    def in_model(self, name: str, where: str) -> Transform:
        """Return the pose of frame ``name`` in the top model's frame."""
        if name in self._resolved:
            return self._resolved[name]
        frame = self.frames.get(name)
        if frame is None:
            raise self.error(where, f"'{name.rpartition(SCOPE)[2] or name}' is not a link, "
                             'joint or frame of the model')
        if name in self._resolving:
            raise self.error(where, f"the poses of frame '{name}' are relative to each other "
                             'in a cycle')
        self._resolving.add(name)
        if frame.relative_to is None:
            result = frame.pose
        elif frame.relative_to == WORLD_FRAME:
            result = frame.pose  # a robot's world frame is where it is placed: its model frame
        else:
            result = self.in_model(frame.relative_to, where).then(frame.pose)
        self._resolving.discard(name)
        self._resolved[name] = result
        return result

    # --- writing the URDF ---------------------------------------------------------------

    def urdf(self, name: str, static: bool) -> ElementTree.Element:
        """Return the ``<robot>`` element of the flattened model."""
        robot = ElementTree.Element('robot', name=name)
        joints = {}
        for full in self.joints:
            element = self.frames[full].element
            where = f'<joint name="{full}">'
            parent = self.joint_link(element, 'parent', self.frames[full].scope)
            child = self.joint_link(element, 'child', self.frames[full].scope)
            for role, link in (('parent', parent), ('child', child)):
                if link != WORLD_FRAME and link not in self.links:
                    raise self.error(where, f'<{role}>{link}</{role}> is not a link of the '
                                     'model')
            if child == WORLD_FRAME:
                raise self.error(where, '<child>world</child>: the world cannot be a child')
            joints[full] = (parent, child)
        moved_by = {child: full for full, (_parent, child) in joints.items()}
        frames = {}
        for link in self.links:
            link_pose = self.in_model(link, f'<link name="{link}">')
            joint = moved_by.get(link)
            if joint is None:
                frames[link] = link_pose
            else:
                joint_pose = self.in_model(joint, f'<joint name="{joint}">')
                frames[link] = Transform(joint_pose.translation, link_pose.rotation)
        if any(parent == WORLD_FRAME for parent, _child in joints.values()):
            ElementTree.SubElement(robot, 'link', name=WORLD_FRAME)
            frames[WORLD_FRAME] = Transform()
        for link in self.links:
            self.link(robot, link, frames[link])
        for full, (parent, child) in joints.items():
            self.joint(robot, full, parent, child, frames)
        if static:  # a static model's free links stay where they are: welded to the first
            roots = [link for link in self.links if link not in moved_by]
            for link in roots[1:]:
                joint = ElementTree.SubElement(robot, 'joint', name=f'{link}_weld', type='fixed')
                origin_element(joint, inverse(frames[roots[0]]).then(frames[link]))
                ElementTree.SubElement(joint, 'parent', link=roots[0])
                ElementTree.SubElement(joint, 'child', link=link)
        for link in self.links:
            self.sensors(robot, link, frames[link], 'link')
        for full, (_parent, child) in joints.items():
            self.sensors(robot, full, frames[child], 'joint')
        for link in self.links:
            self.surface(robot, link)
        model_gazebo = ElementTree.SubElement(robot, 'gazebo')
        if static:
            ElementTree.SubElement(model_gazebo, 'static').text = 'true'
        for plugin in self.plugins:
            model_gazebo.append(plugin)
        if not len(model_gazebo):
            robot.remove(model_gazebo)
        for element in self.extra:
            robot.append(element)
        return robot

    def link(self, robot: ElementTree.Element, name: str, frame: Transform) -> None:
        """Add a link: its inertial and shapes moved into its URDF frame ``frame``."""
        info = self.frames[name]
        element = info.element
        link_pose = self.in_model(name, f'<link name="{name}">')
        contents = inverse(frame).then(link_pose)  # the SDF link frame in the URDF one
        out = ElementTree.SubElement(robot, 'link', name=name)
        inertial = element.find('inertial')
        mass, moments = DEFAULT_MASS, {'ixx': DEFAULT_INERTIA, 'iyy': DEFAULT_INERTIA,
                                       'izz': DEFAULT_INERTIA, 'ixy': 0.0, 'ixz': 0.0,
                                       'iyz': 0.0}
        origin = contents
        where = f'<link name="{name}">'
        if inertial is not None:
            mass = self.number(inertial, 'mass', DEFAULT_MASS, f'{where}: <inertial>')
            inertia = inertial.find('inertia')
            for field in moments:
                moments[field] = self.number(inertia, field, moments[field],
                                             f'{where}: <inertial><inertia>')
            origin = self.placed(inertial.find('pose'), contents, frame, info.scope,
                                 f'{where}: <inertial>')
        if self.static:  # PyBullet's static body: mass 0 (its meshes collide as triangles)
            mass, moments = 0.0, dict.fromkeys(moments, 0.0)
        out_inertial = ElementTree.SubElement(out, 'inertial')
        origin_element(out_inertial, origin)
        ElementTree.SubElement(out_inertial, 'mass', value=repr(mass))
        ElementTree.SubElement(out_inertial, 'inertia',
                               **{field: repr(value) for field, value in moments.items()})
        for role in SHAPE_ROLES:
            for shape in element.findall(role):
                self.shape(out, shape, role, contents, frame, info, name)

    def placed(self, pose: ElementTree.Element | None, contents: Transform, frame: Transform,
               scope: str, where: str) -> Transform:
        """Return where a link's child element's ``<pose>`` puts it in the URDF link frame."""
        transform = self.pose(pose, where)
        relative_to = pose.get('relative_to') if pose is not None else None
        if not relative_to:
            return contents.then(transform)
        other = self.in_model(self.scoped(relative_to, scope), where)
        return inverse(frame).then(other).then(transform)

    def shape(self, out: ElementTree.Element, element: ElementTree.Element, role: str,
              contents: Transform, frame: Transform, info: _Frame, link: str) -> None:
        """Add one ``<collision>`` or ``<visual>`` to the URDF link ``out``."""
        name = element.get('name', '')
        where = f'<link name="{link}">: <{role} name="{name}">'
        origin = self.placed(element.find('pose'), contents, frame, info.scope, where)
        geometry = element.find('geometry')
        if geometry is None or not len(geometry):
            self.warnings.append(f'{self.source}: {where}: has no <geometry>: left out')
            return
        shape = geometry[0]
        made = ElementTree.Element('geometry')
        kind = shape.tag
        if kind == 'box':
            ElementTree.SubElement(made, 'box', size=_numbers(self.vector(
                shape, 'size', (1.0, 1.0, 1.0), where)))
        elif kind in ('cylinder', 'capsule'):
            ElementTree.SubElement(made, kind, radius=repr(self.number(shape, 'radius', 0.5,
                                                                       where)),
                                   length=repr(self.number(shape, 'length', 1.0, where)))
        elif kind == 'sphere':
            ElementTree.SubElement(made, 'sphere', radius=repr(self.number(shape, 'radius', 1.0,
                                                                           where)))
        elif kind == 'ellipsoid':
            radii = self.vector(shape, 'radii', (1.0, 1.0, 1.0), where)
            if not all(value > 0.0 for value in radii):
                raise self.error(where, f'<ellipsoid><radii> must all be > 0, got {radii}')
            ElementTree.SubElement(made, 'mesh', filename=str(ellipsoid_mesh(radii)))
        elif kind == 'plane':
            normal = self.vector(shape, 'normal', (0.0, 0.0, 1.0), where)
            size = self.numbers(shape, 'size', (1.0, 1.0), 2, where)
            origin = origin.then(_plane_slab(normal))
            ElementTree.SubElement(made, 'box', size=_numbers((*size, PLANE_THICKNESS)))
        elif kind == 'mesh':
            filename = self.mesh_file(shape, role, where, info.base_dir)
            if filename is None:
                return
            scale = self.vector(shape, 'scale', (1.0, 1.0, 1.0), where)
            ElementTree.SubElement(made, 'mesh', filename=filename, scale=_numbers(scale))
            if role == 'collision' and not self.static and link not in self.hulls:
                self.hulls.append(link)
            if shape.find('submesh') is not None:
                self.warnings.append(f'{self.source}: {where}: <mesh><submesh> is not read: '
                                     'the whole mesh is used')
        else:
            self.warnings.append(f'{self.source}: {where}: <{kind}> geometry is not simulated '
                                 '(box, cylinder, sphere, capsule, ellipsoid, plane and mesh '
                                 'are): left out')
            return
        out_shape = ElementTree.SubElement(out, role, name=name) if name else \
            ElementTree.SubElement(out, role)
        if role == 'collision' and self.static and made[0].tag == 'mesh':
            # PyBullet's triangle mesh, exact and concave: only for a static body.
            out_shape.set('concave', 'yes')
        origin_element(out_shape, origin)
        out_shape.append(made)
        if role == 'visual':
            rgba = self.colour(element.find('material'), where)
            if rgba is not None:
                material = ElementTree.SubElement(out_shape, 'material', name=f'{link}_{name}')
                ElementTree.SubElement(material, 'color', rgba=_numbers(rgba))

    def mesh_file(self, shape: ElementTree.Element, role: str, where: str,
                  base_dir: pathlib.Path) -> str | None:
        """Return the ``filename`` a URDF mesh gets; None (with a warning) for a lost visual."""
        uri = (shape.findtext('uri') or '').strip()
        problem = ''
        filename = uri
        if not uri:
            problem = 'has no <uri>'
        elif uri.startswith(sdf_resources.MODEL_SCHEME):
            found = sdf_resources.resolve_model_uri(uri)
            if found is None or not found.is_file():
                name, _rest = sdf_resources.split_model_uri(uri)
                problem = (f"model '{name}' is in no model path ({model_path_text()})"
                           if found is None else f'no such file ({found})')
            else:
                filename = str(found)
        elif sdf_resources.is_fuel_uri(uri) or uri.startswith(sdf_resources.FUEL_SCHEMES):
            problem = 'a web URI: nothing is downloaded'
        else:
            try:
                path = resolve_resource(uri, base_dir)
            except DescriptionError as err:
                problem = str(err)
            else:
                if not path.is_file():
                    problem = f'no such file ({path})'
                elif not uri.startswith('package://'):
                    filename = str(path)
        if not problem:
            return filename
        text = f'<mesh><uri>{uri}</uri>: {problem}'
        if role == 'collision':
            raise self.error(where, text)
        self.warnings.append(f'{self.source}: {where}: {text}: the visual is left out (only '
                             'cameras and the view show visuals)')
        return None

    def colour(self, material: ElementTree.Element | None, where: str):
        """Return a visual's ``<material>`` colour (diffuse, else ambient), or None."""
        if material is None:
            return None
        for tag in ('diffuse', 'ambient'):
            text = (material.findtext(tag) or '').strip()
            if not text:
                continue
            try:
                values = [float(value) for value in text.split()]
            except ValueError:
                values = []
            if len(values) == VECTOR_LENGTH:
                values.append(1.0)
            if len(values) != VECTOR_LENGTH + 1 or not all(math.isfinite(v) for v in values):
                raise self.error(where, f'<material><{tag}>{text}</{tag}> is not three or four '
                                 'numbers')
            return tuple(min(max(value, 0.0), 1.0) for value in values)
        return None  # a <script> (Gazebo's material files) is ignored

    def joint(self, robot: ElementTree.Element, full: str, parent: str, child: str,
              frames: dict[str, Transform]) -> None:
        """Add the URDF joint of SDF joint ``full``."""
        info = self.frames[full]
        element = info.element
        where = f'<joint name="{full}">'
        sdf_type = element.get('type', '')
        if sdf_type not in JOINT_TYPES:
            raise self.error(where, f"type '{sdf_type}' is not simulated (revolute, continuous, "
                             'prismatic, fixed and ball are)')
        kind = JOINT_TYPES[sdf_type]
        axis_element = element.find('axis')
        limit = axis_element.find('limit') if axis_element is not None else None
        lower = self.number(limit, 'lower', -NO_LIMIT, f'{where}: <axis><limit>')
        upper = self.number(limit, 'upper', NO_LIMIT, f'{where}: <axis><limit>')
        limited = abs(lower) < NO_LIMIT and abs(upper) < NO_LIMIT
        if kind == 'revolute' and not limited:
            kind = 'continuous'
        out = ElementTree.SubElement(robot, 'joint', name=full, type=kind)
        origin_element(out, inverse(frames[parent]).then(frames[child]))
        ElementTree.SubElement(out, 'parent', link=parent)
        ElementTree.SubElement(out, 'child', link=child)
        if kind == SPHERICAL:  # no axis of its own; PyBullet's reader warns without one
            ElementTree.SubElement(out, 'axis', xyz='0 0 1')
        if kind in ('fixed', SPHERICAL):
            return
        axis = self.axis(axis_element, full, info, where)
        child_rotation = frames[child].rotation
        x, y, z, w = child_rotation
        local = rotate((-x, -y, -z, w), axis)
        ElementTree.SubElement(out, 'axis', xyz=_numbers(local))
        effort = self.number(limit, 'effort', -1.0, f'{where}: <axis><limit>')
        velocity = self.number(limit, 'velocity', -1.0, f'{where}: <axis><limit>')
        attributes = {'effort': repr(max(effort, 0.0)), 'velocity': repr(max(velocity, 0.0))}
        if kind != 'continuous':
            attributes['lower'] = repr(max(lower, -NO_LIMIT))
            attributes['upper'] = repr(min(upper, NO_LIMIT))
        ElementTree.SubElement(out, 'limit', **attributes)
        dynamics = axis_element.find('dynamics') if axis_element is not None else None
        if dynamics is not None:
            ElementTree.SubElement(out, 'dynamics', damping=repr(self.number(
                dynamics, 'damping', 0.0, f'{where}: <axis><dynamics>')), friction=repr(
                self.number(dynamics, 'friction', 0.0, f'{where}: <axis><dynamics>')))

    def axis(self, element: ElementTree.Element | None, full: str, info: _Frame,
             where: str) -> Vector:
        """Return the joint's axis in the top model's frame (a unit vector)."""
        xyz = element.find('xyz') if element is not None else None
        vector = self.vector(element, 'xyz', DEFAULT_AXIS, f'{where}: <axis>')
        length = math.sqrt(sum(value * value for value in vector))
        if length <= 1e-6:
            raise self.error(where, f'<axis><xyz>{xyz.text.strip()}</xyz> has no direction')
        vector = tuple(value / length for value in vector)
        model_frame = info.scope + MODEL_FRAME
        if info.version < (1, 5):
            expressed = model_frame  # SDFormat 1.4: axes are in the model frame
        elif info.version < (1, 7):
            use_model = _true(element.findtext('use_parent_model_frame')) if (
                element is not None) else False
            expressed = model_frame if use_model else full
        else:
            given = xyz.get('expressed_in') if xyz is not None else None
            expressed = self.scoped(given, info.scope) if given else full
        rotation = self.in_model(expressed, where).rotation
        return rotate(rotation, vector)

    def sensors(self, robot: ElementTree.Element, full: str, frame: Transform, kind: str) -> None:
        """Add a link's or joint's ``<sensor>`` elements as ``<gazebo reference>`` sensors."""
        info = self.frames[full]
        where_owner = f'<{kind} name="{full}">'
        owner_pose = self.in_model(full, where_owner)
        contents = inverse(frame).then(owner_pose)
        sensors = info.element.findall('sensor')
        if not sensors:
            return
        gazebo = ElementTree.SubElement(robot, 'gazebo', reference=full)
        for sensor in sensors:
            where = f'{where_owner}: <sensor name="{sensor.get("name", "")}">'
            made = copy.deepcopy(sensor)
            pose = made.find('pose')
            placed = self.placed(sensor.find('pose'), contents, frame, info.scope, where)
            if pose is None:
                pose = ElementTree.SubElement(made, 'pose')
            pose.attrib.clear()
            pose.text = _numbers((*placed.translation, *rpy_from_quaternion(placed.rotation)))
            gazebo.append(made)

    def surface(self, robot: ElementTree.Element, link: str) -> None:
        """Add a link's friction and contact tags from its collisions' ``<surface>``."""
        found: dict[str, float] = {}
        where = f'<link name="{link}">'
        for collision in self.frames[link].element.findall('collision'):
            surface = collision.find('surface')
            if surface is None:
                continue
            owner = f'{where}: <collision name="{collision.get("name", "")}">: <surface>'
            for tag, path in (('mu1', 'friction/ode/mu'), ('mu2', 'friction/ode/mu2'),
                              ('kp', 'contact/ode/kp'), ('kd', 'contact/ode/kd')):
                text = (surface.findtext(path) or '').strip()
                if not text:
                    continue
                value = self.float_text(text, f'{owner}: <{path}>')
                found[tag] = min(found.get(tag, value), value)
        if not found:
            return
        gazebo = ElementTree.SubElement(robot, 'gazebo', reference=link)
        for tag, value in found.items():
            ElementTree.SubElement(gazebo, tag).text = repr(value)

    # --- values -------------------------------------------------------------------------

    def float_text(self, text: str, where: str) -> float:
        """Return ``text`` as a finite number, else raise naming ``where``."""
        value = float_or_nan(text)
        if not math.isfinite(value):
            raise self.error(where, f"'{text}' is not a number")
        return value

    def number(self, element: ElementTree.Element | None, tag: str, default: float,
               where: str) -> float:
        """Return the number in ``element``'s ``<tag>``, or ``default``."""
        text = (element.findtext(tag) or '').strip() if element is not None else ''
        return self.float_text(text, f'{where}: <{tag}>') if text else default

    def numbers(self, element: ElementTree.Element | None, tag: str, default: tuple,
                count: int, where: str) -> tuple[float, ...]:
        """Return ``count`` numbers from ``element``'s ``<tag>``, or ``default``."""
        text = (element.findtext(tag) or '').strip() if element is not None else ''
        if not text:
            return default
        try:
            values = tuple(float(value) for value in text.split())
        except ValueError:
            values = ()
        if len(values) != count or not all(math.isfinite(value) for value in values):
            raise self.error(where, f'<{tag}>{text}</{tag}> is not {count} numbers')
        return values

    def vector(self, element: ElementTree.Element | None, tag: str, default: Vector,
               where: str) -> Vector:
        """Return three numbers from ``element``'s ``<tag>``, or ``default``."""
        return self.numbers(element, tag, default, VECTOR_LENGTH, where)  # type: ignore[return-value]


def _true(text: str | None) -> bool:
    return (text or '').strip().lower() in ('1', 'true')


def _plane_slab(normal: Vector) -> Transform:
    """Return the pose of a slab whose top face is the plane through 0 with this normal."""
    length = math.sqrt(sum(value * value for value in normal))
    nx, ny, nz = (value / length for value in normal) if length > 0 else (0.0, 0.0, 1.0)
    # The rotation taking +z to the normal: about z x n, by the angle between them.
    axis = (-ny, nx, 0.0)
    sine = math.hypot(*axis)
    angle = math.atan2(sine, nz)
    if sine < 1e-12:
        rotation = (0.0, 0.0, 0.0, 1.0) if nz > 0 else (1.0, 0.0, 0.0, 0.0)
    else:
        half = angle / 2.0
        rotation = (axis[0] / sine * math.sin(half), axis[1] / sine * math.sin(half), 0.0,
                    math.cos(half))
    offset = (-nx * PLANE_THICKNESS / 2, -ny * PLANE_THICKNESS / 2, -nz * PLANE_THICKNESS / 2)
    return Transform(offset, quaternion_multiply(rotation, (0.0, 0.0, 0.0, 1.0)))


def ellipsoid_mesh(radii: Vector) -> pathlib.Path:
    """Return an OBJ file of the ellipsoid of these radii (m), made once into the mesh cache."""
    text = _ellipsoid_obj(radii)
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    folder = mesh_cache_dir() / GENERATED_SUBDIR
    target = folder / f'ellipsoid-{digest}.obj'
    if not target.is_file():
        folder.mkdir(parents=True, exist_ok=True)
        partial = target.with_suffix(f'.{os.getpid()}.tmp')
        partial.write_text(text, encoding='utf-8')
        partial.replace(target)
    return target


def _ellipsoid_obj(radii: Vector) -> str:
    rx, ry, rz = radii
    lines = [f'v 0 0 {rz!r}']
    for ring in range(1, ELLIPSOID_RINGS):
        polar = math.pi * ring / ELLIPSOID_RINGS
        for segment in range(ELLIPSOID_SEGMENTS):
            azimuth = 2 * math.pi * segment / ELLIPSOID_SEGMENTS
            lines.append(f'v {rx * math.sin(polar) * math.cos(azimuth)!r} '
                         f'{ry * math.sin(polar) * math.sin(azimuth)!r} '
                         f'{rz * math.cos(polar)!r}')
    bottom = 2 + (ELLIPSOID_RINGS - 1) * ELLIPSOID_SEGMENTS
    lines.append(f'v 0 0 {-rz!r}')

    def vertex(ring: int, segment: int) -> int:  # 1-based OBJ index of a ring vertex
        return 2 + (ring - 1) * ELLIPSOID_SEGMENTS + segment % ELLIPSOID_SEGMENTS

    for segment in range(ELLIPSOID_SEGMENTS):
        lines.append(f'f 1 {vertex(1, segment)} {vertex(1, segment + 1)}')
        for ring in range(1, ELLIPSOID_RINGS - 1):
            a, b = vertex(ring, segment), vertex(ring, segment + 1)
            c, d = vertex(ring + 1, segment), vertex(ring + 1, segment + 1)
            lines.append(f'f {a} {c} {d}')
            lines.append(f'f {a} {d} {b}')
        last = ELLIPSOID_RINGS - 1
        lines.append(f'f {vertex(last, segment)} {bottom} {vertex(last, segment + 1)}')
    return '\n'.join(lines) + '\n'
