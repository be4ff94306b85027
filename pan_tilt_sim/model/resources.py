"""Resolve resource URIs and make a URDF's meshes loadable by PyBullet.

PyBullet knows nothing of ``package://``, and its own mesh loaders fail in ways
a user cannot see (PyBullet 3.2.7, DIRECT mode):

- a missing file or an unknown extension makes ``loadURDF`` raise a bare
  ``error('Cannot load URDF file.')``; the reason only goes to stdout;
- an empty, garbage or truncated STL, an ASCII STL, a binary STL with trailing
  bytes, an OBJ without faces or an unparsable DAE loads *without* its shape,
  with a ``b3Warning`` on stdout and nothing else: the link silently has no
  collision geometry;
- a DAE without ``<asset>``, ``<library_geometries>`` or ``<vertices>`` crashes
  the process (SIGSEGV) in the visual and in the collision role.

So every mesh is checked here first, and what PyBullet cannot be trusted
with is converted into a binary STL in a cache folder (see the design notes).

Design notes: docs/design/model.md#resourcespy.
"""

from __future__ import annotations

import hashlib
import os
import pathlib
import re
import urllib.parse
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from ament_index_python.packages import PackageNotFoundError, get_package_share_directory

from pan_tilt_sim.errors import DescriptionError, one_line

PACKAGE_SCHEME = 'package://'
FILE_SCHEME = 'file://'
_FILE_LOCALHOST = 'localhost/'
_URI_SCHEME = re.compile(r'^([A-Za-z][A-Za-z0-9+.-]*)://')

MESH_ROLES = ('visual', 'collision')
"""Link children whose ``geometry/mesh`` elements are localized."""

STL_SUFFIX = '.stl'
OBJ_SUFFIX = '.obj'
DAE_SUFFIX = '.dae'
SUPPORTED_MESH_SUFFIXES = (STL_SUFFIX, OBJ_SUFFIX, DAE_SUFFIX)

STL_HEADER_BYTES = 80
STL_PREAMBLE_BYTES = 84
"""Binary STL: 80-byte header plus the uint32 triangle count."""
STL_TRIANGLE_BYTES = 50
_STL_ASCII_START = b'solid'
_STL_DTYPE = np.dtype([('normal', '<f4', (3,)), ('vertices', '<f4', (3, 3)),
                       ('attribute', '<u2')])
_STL_ASCII_END = b'endsolid'
STL_ASCII_END_WINDOW = 1024
"""Bytes at the end of an ASCII STL searched for ``endsolid`` (it may carry a long name)."""
_STL_ASCII_VERTEX = re.compile(rb'^[ \t]*vertex[ \t]+([^\r\n]*)', re.MULTILINE)
_OBJ_VERTEX = re.compile(rb'^[ \t]*v[ \t]', re.MULTILINE)
_OBJ_FACE = re.compile(rb'^[ \t]*f[ \t]+([^\r\n]*)', re.MULTILINE)
_OBJ_CORNER_TAIL = re.compile(rb'/\S*')

VECTOR3_LENGTH = 3
TRIANGLE_CORNERS = 3
HOMOGENEOUS_SIZE = 4
COLLADA_MATRIX_LENGTH = HOMOGENEOUS_SIZE * HOMOGENEOUS_SIZE
COLLADA_ROTATE_LENGTH = 4
"""``<rotate>``: axis x y z, then the angle in degrees."""
COLLADA_MAX_NODE_DEPTH = 64
"""Deeper ``<node>`` / ``<instance_node>`` nesting is taken for a reference cycle."""
_COLLADA_ROOT = 'COLLADA'
_COLLADA_POLYGON_PRIMITIVES = ('polylist', 'polygons', 'trifans', 'tristrips')

CONVERTER_VERSION = b'resources-1'
"""Part of every cache key: bump it when converted output changes."""
CACHE_DIGEST_CHARS = 16
# Converted meshes are kept between runs (keyed on content) under the user cache.
MESH_CACHE_SUBDIR = pathlib.Path('pan_tilt_sim', 'meshes')


class _UnusableError(Exception):
    """A resource cannot be used; the message says why, without naming it."""


@dataclass(frozen=True)
class LocalizedMesh:
    """One ``<mesh>`` element after :func:`localize_meshes` rewrote it."""

    link: str
    role: str
    uri: str
    """The ``filename`` attribute as the description gave it."""
    resolved: pathlib.Path
    """Where the URI points."""
    loadable: pathlib.Path
    """The file the ``filename`` attribute now names: ``resolved`` or a cached conversion."""


def resolve_resource(uri: str, base_dir: pathlib.Path) -> pathlib.Path:
    """Return the absolute, normalized path a resource URI names.

    - ``package://PKG/rel`` -> ``<share of PKG>/rel``, PKG looked up in the
      ament index (``AMENT_PREFIX_PATH``, read at call time);
    - ``file:///abs`` and ``file://localhost/abs`` -> ``/abs``
      (percent-escapes decoded); ``file://rel`` (not a valid URI, but seen in
      the wild) -> ``rel`` under ``base_dir``, like a plain relative path;
    - ``/abs`` -> itself; ``rel`` -> ``base_dir / rel`` (``base_dir`` is the
      folder of the description file).

    The file need not exist.  Raises :class:`DescriptionError` naming the URI
    for an unknown package, a malformed ``package://`` URI or any other
    scheme (``http://``, ``model://``...).
    """
    try:
        return _resolve(uri, base_dir)
    except _UnusableError as exc:
        raise DescriptionError(one_line(f"resource '{uri}': {exc}")) from None


def _resolve(uri: str, base_dir: pathlib.Path) -> pathlib.Path:
    if not uri.strip():
        raise _UnusableError('empty file name')
    if uri.startswith(PACKAGE_SCHEME):
        package, _, relpath = uri[len(PACKAGE_SCHEME):].partition('/')
        if not package or not relpath.strip('/'):
            raise _UnusableError('expected package://PACKAGE/PATH')
        path = pathlib.Path(_package_share(package)) / relpath
    elif uri.startswith(FILE_SCHEME):
        rest = urllib.parse.unquote(uri[len(FILE_SCHEME):])
        if rest.startswith(_FILE_LOCALHOST):
            rest = rest[len(_FILE_LOCALHOST) - 1:]
        path = pathlib.Path(rest)
    elif match := _URI_SCHEME.match(uri):
        raise _UnusableError(f"unsupported URI scheme '{match.group(1)}://' "
                             '(use package://, file:// or a file path)')
    else:
        path = pathlib.Path(uri)
    if not path.is_absolute():
        path = base_dir / path
    return pathlib.Path(os.path.normpath(os.path.abspath(path)))


def _package_share(package: str) -> str:
    searched = os.environ.get('AMENT_PREFIX_PATH', '')
    try:
        return get_package_share_directory(package, print_warning=False)
    except PackageNotFoundError:
        raise _UnusableError(
            f"package '{package}' is not in the ament index (AMENT_PREFIX_PATH={searched!r}); "
            'source the workspace that installs it') from None
    except ValueError:
        raise _UnusableError(f"'{package}' is not a valid package name") from None
    except OSError:  # ament_index_python raises EnvironmentError when the variable is unset
        raise _UnusableError(
            f"cannot look up package '{package}': AMENT_PREFIX_PATH is not set; "
            'source a ROS 2 workspace') from None


def localize_meshes(robot: ET.Element, base_dir: pathlib.Path,
                    cache_dir: pathlib.Path) -> list[LocalizedMesh]:
    """Make every visual and collision ``<mesh>`` of a URDF loadable by PyBullet.

    For each ``robot/link/{visual,collision}/geometry/mesh``: resolve
    ``filename`` with :func:`resolve_resource` (relative paths against
    ``base_dir``), check the file (see the module's design notes), convert it into
    ``cache_dir`` when PyBullet cannot load it as it is, and rewrite
    ``filename`` to the absolute path of the loadable file.  ``scale`` is
    checked (three finite, non-zero numbers, as urdfdom requires) and left in
    place for PyBullet to apply.  Each distinct file is checked once per
    call, and a conversion already in ``cache_dir`` is not parsed again.

    ``cache_dir`` is created when first needed; file names there are derived
    from the source content, and written atomically, so the folder may be
    shared and kept between runs.

    Returns what was done per element.  Raises :class:`DescriptionError` with
    a one-line message naming the link, the role, the URI and (once resolved)
    the path, e.g. ``link 'base_link' visual: mesh
    'package://my_robot_pkg/meshes/visual/base.dae' (resolved to
    /ws/install/share/my_robot_pkg/meshes/visual/base.dae): file not found``.
    """
    done: dict[pathlib.Path, pathlib.Path] = {}
    localized = []
    for link, role, mesh in mesh_elements(robot):
        where = f"link '{link}' {role}: mesh"
        uri = mesh.get('filename')
        if uri is None:
            raise DescriptionError(f"link '{link}' {role}: <mesh> has no filename attribute")
        try:
            resolved = _resolve(uri, base_dir)
        except _UnusableError as exc:
            raise DescriptionError(one_line(f"{where} '{uri}': {exc}")) from None
        try:
            _check_scale(mesh.get('scale'))
            if resolved not in done:
                done[resolved] = _loadable_mesh(resolved, cache_dir)
        except _UnusableError as exc:
            raise DescriptionError(
                one_line(f"{where} '{uri}' (resolved to {resolved}): {exc}")) from None
        mesh.set('filename', str(done[resolved]))
        localized.append(LocalizedMesh(link, role, uri, resolved, done[resolved]))
    return localized


def mesh_elements(robot: ET.Element) -> Iterator[tuple[str, str, ET.Element]]:
    """Yield ``(link name, role, <mesh> element)`` for every visual and collision mesh."""
    for link in robot.findall('link'):
        for role in MESH_ROLES:
            for mesh in link.findall(f'{role}/geometry/mesh'):
                yield link.get('name', '?'), role, mesh


def _check_scale(scale: str | None) -> None:
    if scale is None:
        return
    try:
        values = [float(v) for v in scale.split()]
    except ValueError:
        values = []
    if len(values) != VECTOR3_LENGTH or not all(np.isfinite(v) and v != 0 for v in values):
        raise _UnusableError(f"scale '{scale}' must be three finite, non-zero numbers")


def _loadable_mesh(path: pathlib.Path, cache_dir: pathlib.Path) -> pathlib.Path:
    """Check the mesh at ``path``; return it, or a converted copy in ``cache_dir``.

    A conversion is looked up by the source's content first, so a file
    converted by an earlier run is neither parsed nor written again.
    """
    suffix = path.suffix.lower()
    if suffix not in SUPPORTED_MESH_SUFFIXES:
        raise _UnusableError(f"unsupported mesh format '{path.suffix}' "
                             f"(supported: {', '.join(SUPPORTED_MESH_SUFFIXES)})")
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise _UnusableError('file not found') from None
    except IsADirectoryError:
        raise _UnusableError('is a folder, not a file') from None
    except OSError as exc:
        raise _UnusableError(f'cannot read file: {exc.strerror}') from None
    if not data:
        raise _UnusableError('file is empty')
    if suffix == OBJ_SUFFIX:
        check_obj(data)
        return path
    if suffix == STL_SUFFIX and _is_loadable_binary_stl(data):
        return path
    digest = hashlib.sha256(CONVERTER_VERSION + data).hexdigest()[:CACHE_DIGEST_CHARS]
    target = cache_dir / f'{path.stem}-{digest}{STL_SUFFIX}'
    if target.is_file():  # written atomically, and only after the source parsed
        return target
    triangles = _stl_triangles(data) if suffix == STL_SUFFIX else read_collada(data)
    write_binary_stl(target, triangles)
    return target


def read_mesh_triangles(path: pathlib.Path) -> np.ndarray:
    """Return the triangles (N x 3 x 3, in the file's units) of an STL, OBJ or DAE file.

    For drawing a mesh: STL (binary or ASCII) and DAE as :func:`localize_meshes`
    reads them, OBJ faces fanned into triangles (materials and textures are
    not read).  Raises :class:`DescriptionError` naming the file and the problem.
    """
    try:
        data = path.read_bytes()
        if not data:
            raise _UnusableError('file is empty')
        suffix = path.suffix.lower()
        if suffix == STL_SUFFIX:
            _is_loadable_binary_stl(data)  # raises for what is no STL
            return _stl_triangles(data)
        if suffix == OBJ_SUFFIX:
            return read_obj(data)
        if suffix == DAE_SUFFIX:
            return read_collada(data)
        raise _UnusableError(f"unsupported mesh format '{path.suffix}' "
                             f"(supported: {', '.join(SUPPORTED_MESH_SUFFIXES)})")
    except OSError as exc:
        raise DescriptionError(one_line(f'mesh {path}: cannot read file: {exc.strerror}')) \
            from None
    except _UnusableError as exc:
        raise DescriptionError(one_line(f'mesh {path}: {exc}')) from None


def read_obj(data: bytes) -> np.ndarray:
    """Return the triangles (N x 3 x 3) of a Wavefront OBJ: each face fanned from its first corner.

    Faces are checked as :func:`check_obj` does; a negative (relative) index
    counts back from the vertices read so far, as the format says.
    """
    check_obj(data)
    vertices: list[list[float]] = []
    triangles: list[list[int]] = []
    for line in data.splitlines():
        fields = line.split()
        if not fields:
            continue
        if fields[0] == b'v' and len(fields) >= 1 + VECTOR3_LENGTH:
            try:
                vertices.append([float(value) for value in fields[1:1 + VECTOR3_LENGTH]])
            except ValueError:
                raise _UnusableError('OBJ with a non-numeric vertex') from None
        elif fields[0] == b'f':
            corners = [int(corner.split(b'/')[0]) for corner in fields[1:]]
            corners = [index - 1 if index > 0 else len(vertices) + index for index in corners]
            triangles.extend([corners[0], corners[i], corners[i + 1]]
                             for i in range(1, len(corners) - 1))
    points = np.array(vertices, dtype=float).reshape(-1, VECTOR3_LENGTH)
    indices = np.array(triangles, dtype=np.int64).reshape(-1, TRIANGLE_CORNERS)
    if indices.size and (indices.min() < 0 or indices.max() >= len(points)):
        raise _UnusableError('a face names a vertex the file does not define')
    _check_finite(points)
    return points[indices]


def _is_loadable_binary_stl(data: bytes) -> bool:
    """Tell whether PyBullet reads this STL as it is; raise if it is no STL at all.

    False means it needs converting: an ASCII STL, or a binary one with
    trailing bytes (PyBullet requires the exact size and otherwise drops the
    shape).
    """
    count = read_binary_stl_count(data)
    expected = STL_PREAMBLE_BYTES + STL_TRIANGLE_BYTES * count if count is not None else None
    if expected is not None and count and len(data) >= expected:
        _check_finite(np.frombuffer(data, _STL_DTYPE, count, STL_PREAMBLE_BYTES)['vertices'])
        return len(data) == expected
    if data.lstrip().startswith(_STL_ASCII_START):
        return False
    if count == 0:
        raise _UnusableError('binary STL without triangles')
    if expected is not None and (len(data) - STL_PREAMBLE_BYTES) % STL_TRIANGLE_BYTES == 0:
        raise _UnusableError(f'truncated binary STL: {count} triangles need {expected} bytes, '
                             f'the file has {len(data)}')
    announced = f', a binary header announcing {count} triangles needs {expected}' \
        if expected is not None else ''
    raise _UnusableError(f'neither ASCII STL (starts with "solid") nor binary STL '
                         f'({len(data)} bytes{announced})')


def _stl_triangles(data: bytes) -> np.ndarray:
    """Return the triangles (N x 3 x 3) of an STL that :func:`_is_loadable_binary_stl` passed."""
    count = read_binary_stl_count(data)
    if count and len(data) >= STL_PREAMBLE_BYTES + STL_TRIANGLE_BYTES * count:
        records = np.frombuffer(data, _STL_DTYPE, count, STL_PREAMBLE_BYTES)
        return records['vertices'].astype(float)
    return read_ascii_stl(data)


def read_binary_stl_count(data: bytes) -> int | None:
    """Return the triangle count of a binary STL header, or None if ``data`` is too short."""
    if len(data) < STL_PREAMBLE_BYTES:
        return None
    return int(np.frombuffer(data, '<u4', 1, STL_HEADER_BYTES)[0])


def read_ascii_stl(data: bytes) -> np.ndarray:
    """Return the triangles (N x 3 x 3) of an ASCII STL; raise if it holds none or is cut."""
    lines = _STL_ASCII_VERTEX.findall(data)
    if not lines:
        raise _UnusableError('ASCII STL without any facet')
    if len(lines) % TRIANGLE_CORNERS:
        raise _UnusableError(f'ASCII STL with {len(lines)} vertices, not a multiple of 3')
    if _STL_ASCII_END not in data[-STL_ASCII_END_WINDOW:]:
        raise _UnusableError("ASCII STL without 'endsolid' at its end (truncated?)")
    try:
        coords = np.array(b' '.join(lines).split(), dtype=float)
    except ValueError:
        raise _UnusableError('ASCII STL with a non-numeric vertex') from None
    if len(coords) != VECTOR3_LENGTH * len(lines):
        raise _UnusableError('ASCII STL with a vertex of other than 3 coordinates')
    triangles = coords.reshape(-1, TRIANGLE_CORNERS, VECTOR3_LENGTH)
    _check_finite(triangles)
    return triangles


def _check_finite(values: np.ndarray) -> None:
    if not np.isfinite(values).all():
        raise _UnusableError('vertex coordinates include NaN or infinity')


def check_obj(data: bytes) -> None:
    """Check a Wavefront OBJ: it has faces of 3+ corners, all naming existing vertices.

    Vertex coordinates are counted, not parsed (that would cost about a
    second per 100 000 vertices; PyBullet parses them anyway).  A negative
    (relative) index is checked against the whole file's vertex count.
    """
    vertex_count = len(_OBJ_VERTEX.findall(data))
    faces = _OBJ_FACE.findall(data)
    if not faces:
        raise _UnusableError('OBJ without faces')
    fewest = min(map(len, map(bytes.split, faces)))
    if fewest < TRIANGLE_CORNERS:
        raise _UnusableError(f'a face with {fewest} corners')
    # Keep each corner's vertex index: drop '/texture/normal' parts.
    try:
        indices = np.array(_OBJ_CORNER_TAIL.sub(b'', b' '.join(faces)).split(), dtype=np.int64)
    except ValueError:
        raise _UnusableError('a face corner is not a vertex index') from None
    if (indices == 0).any():
        raise _UnusableError('a face names vertex 0 (OBJ counts from 1)')
    highest = int(np.abs(indices).max())
    if highest > vertex_count:
        raise _UnusableError(f'a face names vertex {highest}, the file has {vertex_count}')


def read_collada(data: bytes) -> np.ndarray:
    """Return the triangles (N x 3 x 3, metres) a Collada document's scene shows.

    Geometry: ``<triangles>``, ``<polylist>``, ``<polygons>`` (outer
    boundaries; holes are ignored), ``<trifans>`` and ``<tristrips>`` of
    ``<mesh>`` geometries, through their ``VERTEX`` input.  Lines and skinned
    meshes (``<instance_controller>``) are ignored.

    Placement: the nodes of the instanced visual scene (else the first visual
    scene; else every geometry, untransformed), with ``<matrix>``,
    ``<translate>``, ``<rotate>`` and ``<scale>`` composed in document order
    through nested ``<node>`` and ``<instance_node>``.

    Units, as Gazebo does: ``<asset><unit meter=...>`` is applied (a file in
    millimetres that says ``meter="0.001"`` comes out in metres); a URDF
    ``scale`` then applies on top.  PyBullet's own Collada loader does the
    same.  ``<up_axis>`` is ignored, like Gazebo classic and PyBullet's
    collision loader (a ``Y_UP`` box is not rotated).
    """
    try:
        root = ET.fromstring(data)
    except (ET.ParseError, LookupError, ValueError) as exc:
        # LookupError / ValueError: an unknown or multi-byte encoding in the declaration.
        raise _UnusableError(f'not valid XML: {exc}') from None
    if _local(root.tag) != _COLLADA_ROOT:
        raise _UnusableError(f'not a Collada file (root element <{_local(root.tag)}>)')
    return _ColladaReader(root).triangles()


def _local(tag: str) -> str:
    return tag.rpartition('}')[2]


def _floats(element: ET.Element | None, what: str) -> np.ndarray:
    text = element.text if element is not None else None
    try:
        return np.array((text or '').split(), dtype=float)
    except ValueError:
        raise _UnusableError(f'non-numeric values in {what}') from None


def _ints(element: ET.Element | None, what: str) -> np.ndarray:
    text = element.text if element is not None else None
    try:
        return np.array((text or '').split(), dtype=np.int64)
    except ValueError:
        raise _UnusableError(f'non-integer values in {what}') from None


def _fan(polygon: np.ndarray) -> np.ndarray:
    """Triangulate a convex polygon given as corner indices into a fan (M x 3)."""
    if len(polygon) < TRIANGLE_CORNERS:
        return np.empty((0, TRIANGLE_CORNERS), dtype=np.int64)
    return np.column_stack([np.full(len(polygon) - 2, polygon[0]), polygon[1:-1], polygon[2:]])


def _strip(strip: np.ndarray) -> np.ndarray:
    """Triangulate a triangle strip (M x 3), keeping a consistent winding."""
    if len(strip) < TRIANGLE_CORNERS:
        return np.empty((0, TRIANGLE_CORNERS), dtype=np.int64)
    tris = np.column_stack([strip[:-2], strip[1:-1], strip[2:]])
    tris[1::2, [0, 1]] = tris[1::2, [1, 0]]
    return tris


def _rotation(axis: np.ndarray, degrees: float) -> np.ndarray:
    norm = np.linalg.norm(axis)
    matrix = np.eye(HOMOGENEOUS_SIZE)
    if norm == 0:
        return matrix
    x, y, z = axis / norm
    angle = np.radians(degrees)
    c, s, t = np.cos(angle), np.sin(angle), 1 - np.cos(angle)
    matrix[:3, :3] = [[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
                      [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
                      [t * x * z - s * y, t * y * z + s * x, t * z * z + c]]
    return matrix


class _ColladaReader:
    """Collect the triangles of one parsed Collada document."""

    def __init__(self, root: ET.Element) -> None:
        self.root = root
        self.ids = {el.get('id'): el for el in root.iter() if el.get('id')}
        self.geometry_cache: dict[str, np.ndarray] = {}

    def _target(self, url: str | None, kind: str) -> ET.Element:
        element = self.ids.get((url or '').removeprefix('#'))
        if element is None or _local(element.tag) != kind:
            raise _UnusableError(f"<{kind}> '{url}' not found")
        return element

    def triangles(self) -> np.ndarray:
        unit = self.root.find('{*}asset/{*}unit')
        meter_text = unit.get('meter', '1') if unit is not None else '1'
        try:
            meter = float(meter_text)
        except ValueError:
            meter = float('nan')
        if not np.isfinite(meter) or meter <= 0:
            raise _UnusableError(f"<unit meter='{meter_text}'> is not a positive number")
        parts = list(self._scene_parts())
        if not parts:
            raise _UnusableError('no triangle geometry in the scene')
        triangles = np.concatenate(parts) * meter
        _check_finite(triangles)
        return triangles

    def _scene_parts(self) -> Iterator[np.ndarray]:
        instance = self.root.find('{*}scene/{*}instance_visual_scene')
        if instance is not None:
            scene = self._target(instance.get('url'), 'visual_scene')
        else:
            scene = self.root.find('{*}library_visual_scenes/{*}visual_scene')
        if scene is None:
            for geometry in self.root.iterfind('{*}library_geometries/{*}geometry'):
                yield from self._geometry_parts(geometry, np.eye(HOMOGENEOUS_SIZE))
            return
        for node in scene.iterfind('{*}node'):
            yield from self._node_parts(node, np.eye(HOMOGENEOUS_SIZE), 0)

    def _node_parts(self, node: ET.Element, parent: np.ndarray,
                    depth: int) -> Iterator[np.ndarray]:
        if depth > COLLADA_MAX_NODE_DEPTH:
            raise _UnusableError(f'<node> nesting deeper than {COLLADA_MAX_NODE_DEPTH} (a cycle?)')
        transform = parent @ self._node_transform(node)
        for child in node:
            tag = _local(child.tag)
            if tag == 'instance_geometry':
                geometry = self._target(child.get('url'), 'geometry')
                yield from self._geometry_parts(geometry, transform)
            elif tag == 'instance_node':
                yield from self._node_parts(
                    self._target(child.get('url'), 'node'), transform, depth + 1)
            elif tag == 'node':
                yield from self._node_parts(child, transform, depth + 1)

    def _node_transform(self, node: ET.Element) -> np.ndarray:
        transform = np.eye(HOMOGENEOUS_SIZE)
        for child in node:
            tag = _local(child.tag)
            if tag == 'matrix':
                values = _floats(child, '<matrix>')
                if len(values) != COLLADA_MATRIX_LENGTH:
                    raise _UnusableError(f'<matrix> with {len(values)} values, expected 16')
                step = values.reshape(HOMOGENEOUS_SIZE, HOMOGENEOUS_SIZE)
            elif tag == 'translate':
                step = np.eye(HOMOGENEOUS_SIZE)
                step[:3, 3] = self._vector(child, VECTOR3_LENGTH)
            elif tag == 'scale':
                step = np.diag([*self._vector(child, VECTOR3_LENGTH), 1.0])
            elif tag == 'rotate':
                values = self._vector(child, COLLADA_ROTATE_LENGTH)
                step = _rotation(values[:3], values[3])
            else:  # <lookat> and <skew> are camera tools; Gazebo ignores them too.
                continue
            transform = transform @ step
        return transform

    @staticmethod
    def _vector(element: ET.Element, length: int) -> np.ndarray:
        values = _floats(element, f'<{_local(element.tag)}>')
        if len(values) != length:
            raise _UnusableError(f'<{_local(element.tag)}> with {len(values)} values, '
                                 f'expected {length}')
        return values

    def _geometry_parts(self, geometry: ET.Element,
                        transform: np.ndarray) -> Iterator[np.ndarray]:
        key = geometry.get('id', str(id(geometry)))
        if key not in self.geometry_cache:
            self.geometry_cache[key] = self._geometry_triangles(geometry)
        local = self.geometry_cache[key]
        if len(local):
            homogeneous = np.concatenate([local, np.ones((*local.shape[:2], 1))], axis=2)
            yield (homogeneous @ transform.T)[..., :3]

    def _geometry_triangles(self, geometry: ET.Element) -> np.ndarray:
        parts = []
        for mesh in geometry.iterfind('{*}mesh'):
            for primitive in mesh:
                tag = _local(primitive.tag)
                if tag == 'triangles' or tag in _COLLADA_POLYGON_PRIMITIVES:
                    parts.append(self._primitive_triangles(primitive, tag))
        if not parts:
            return np.empty((0, TRIANGLE_CORNERS, VECTOR3_LENGTH))
        return np.concatenate(parts)

    def _primitive_triangles(self, primitive: ET.Element, tag: str) -> np.ndarray:
        inputs = primitive.findall('{*}input')
        try:
            stride = max(int(i.get('offset', '0')) for i in inputs) + 1 if inputs else 1
            vertex = next(i for i in inputs if i.get('semantic') == 'VERTEX')
            vertex_offset = int(vertex.get('offset', '0'))
        except StopIteration:
            raise _UnusableError(f'<{tag}> without a VERTEX input') from None
        except ValueError:
            raise _UnusableError(f'<{tag}> input with a non-integer offset') from None
        positions = self._positions(vertex.get('source'))

        def corners(p: ET.Element | None) -> np.ndarray:
            indices = _ints(p, f'<{tag}><p>')
            if len(indices) % stride:
                raise _UnusableError(f'<{tag}><p> length {len(indices)} is not a multiple of '
                                     f'the {stride} inputs')
            return indices.reshape(-1, stride)[:, vertex_offset]

        if tag == 'triangles':
            ps = primitive.findall('{*}p')
            flat = np.concatenate([corners(p) for p in ps]) if ps else np.empty(0, np.int64)
            if len(flat) % TRIANGLE_CORNERS:
                raise _UnusableError(f'<triangles> with {len(flat)} corners, not a multiple of 3')
            index_triangles = flat.reshape(-1, TRIANGLE_CORNERS)
        elif tag == 'polylist':
            flat = corners(primitive.find('{*}p'))
            counts = _ints(primitive.find('{*}vcount'), '<polylist><vcount>')
            if counts.sum() != len(flat) or (counts < 0).any():
                raise _UnusableError(f'<polylist> <vcount> sums to {counts.sum()}, '
                                     f'<p> has {len(flat)} corners')
            polygons = np.split(flat, np.cumsum(counts)[:-1]) if len(counts) else []
            index_triangles = self._joined([_fan(polygon) for polygon in polygons])
        else:
            # <polygons>: one <p> per polygon, or <ph> (outer <p> plus ignored <h> holes).
            ps = [*primitive.findall('{*}p'), *primitive.findall('{*}ph/{*}p')]
            triangulate = _strip if tag == 'tristrips' else _fan
            index_triangles = self._joined([triangulate(corners(p)) for p in ps])
        if index_triangles.size and (index_triangles.min() < 0
                                     or index_triangles.max() >= len(positions)):
            raise _UnusableError(f'<{tag}> index out of range (0..{len(positions) - 1})')
        return positions[index_triangles]

    @staticmethod
    def _joined(parts: list[np.ndarray]) -> np.ndarray:
        if not parts:
            return np.empty((0, TRIANGLE_CORNERS), dtype=np.int64)
        return np.concatenate(parts)

    def _positions(self, url: str | None) -> np.ndarray:
        source = self.ids.get((url or '').removeprefix('#'))
        if source is not None and _local(source.tag) == 'vertices':
            position = next((i for i in source.iterfind('{*}input')
                             if i.get('semantic') == 'POSITION'), None)
            if position is None:
                raise _UnusableError(f"<vertices> '{url}' without a POSITION input")
            source = self.ids.get((position.get('source') or '').removeprefix('#'))
        if source is None or _local(source.tag) != 'source':
            raise _UnusableError(f"vertex positions '{url}' not found")
        values = _floats(source.find('{*}float_array'), '<float_array>')
        accessor = source.find('{*}technique_common/{*}accessor')
        try:
            stride = int(accessor.get('stride', '1')) if accessor is not None else VECTOR3_LENGTH
        except ValueError:
            stride = 0
        if stride < VECTOR3_LENGTH or len(values) % stride:
            raise _UnusableError(f"positions '{url}': {len(values)} values do not fit "
                                 f'stride {stride}')
        return values.reshape(-1, stride)[:, :VECTOR3_LENGTH]


def write_binary_stl(target: pathlib.Path, triangles: np.ndarray) -> None:
    """Write ``triangles`` (N x 3 x 3) to ``target`` as a binary STL, atomically.

    The file appears complete or not at all, so concurrent writers of the
    same content (nodes sharing a cache folder) do not harm each other.
    """
    records = np.zeros(len(triangles), _STL_DTYPE)
    records['vertices'] = triangles
    edges = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    lengths = np.linalg.norm(edges, axis=1, keepdims=True)
    records['normal'] = np.divide(edges, lengths, out=np.zeros_like(edges), where=lengths > 0)
    header = f'pan_tilt_sim {target.stem}'.encode()[:STL_HEADER_BYTES]
    target.parent.mkdir(parents=True, exist_ok=True)
    partial = target.with_name(f'.{target.name}.{os.getpid()}.part')
    with partial.open('wb') as out:
        out.write(header.ljust(STL_HEADER_BYTES, b'\0'))
        out.write(np.uint32(len(triangles)).tobytes())
        out.write(records.tobytes())
    os.replace(partial, target)


def mesh_cache_dir() -> pathlib.Path:
    """Return where converted meshes are cached (``$XDG_CACHE_HOME`` or ``~/.cache``)."""
    base = os.environ.get('XDG_CACHE_HOME') or pathlib.Path.home() / '.cache'
    return pathlib.Path(base) / MESH_CACHE_SUBDIR
