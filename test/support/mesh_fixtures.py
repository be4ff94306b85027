"""Generate small meshes and temporary ament prefixes for tests.

Every mesh here is an axis-aligned box centred on the origin, so a test can
predict the exact bounding box PyBullet must report once the mesh is loaded.

Two layers:

- ``*_bytes`` / ``*_text`` functions return file content (for
  :func:`make_ament_prefix`, which takes a mapping of relative path to content);
- ``write_*`` functions write that content to a path and return the path.

:func:`make_my_robot_package` builds the ``my_robot_pkg`` layout the my_robot example's URDF
(``my_robot.urdf``) refers to, with the box sizes given by the ``MY_ROBOT_*``
constants, so tests can check the loaded links' sizes.
"""

from __future__ import annotations

import pathlib
import struct
from collections.abc import Mapping, Sequence

import numpy as np

Size = tuple[float, float, float]

UNIT_BOX: Size = (1.0, 1.0, 1.0)
"""A 1 m cube: the default size of every generated mesh."""

STL_HEADER_BYTES = 80
"""Binary STL: fixed header length before the triangle count."""

_STL_TRIANGLE = struct.Struct('<12fH')
"""Binary STL record: normal, three vertices (float32 each) and a uint16 attribute."""

STL_RECORD = np.dtype([('normal', '<f4', (3,)), ('vertices', '<f4', (3, 3)),
                       ('attribute', '<u2')])
"""The same record as a numpy dtype, to read binary STL triangles back."""

_STL_COUNT = struct.Struct('<I')

_CUBE_CORNERS = np.array(
    [[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
"""The eight corners of a unit cube centred on the origin; index = 4x + 2y + z."""

_CUBE_FACES = np.array([
    # Two counter-clockwise (outward-facing) triangles per side.
    [0, 1, 3], [0, 3, 2],  # x = -0.5
    [4, 6, 7], [4, 7, 5],  # x = +0.5
    [0, 4, 5], [0, 5, 1],  # y = -0.5
    [2, 3, 7], [2, 7, 6],  # y = +0.5
    [0, 2, 6], [0, 6, 4],  # z = -0.5
    [1, 5, 7], [1, 7, 3],  # z = +0.5
])
"""Twelve triangles over :data:`_CUBE_CORNERS`."""

MY_ROBOT_PACKAGE = 'my_robot_pkg'
"""Package name the my_robot example's URDF's ``package://`` URIs use."""

MY_ROBOT_BASE_SIZE_M: Size = (0.2, 0.2, 0.1)
"""Size of the generated base meshes in metres (the DAE holds millimetres)."""

MY_ROBOT_ARM_SIZE_M: Size = (0.05, 0.05, 0.2)
"""Size of the generated arm meshes in metres (the DAE holds millimetres)."""

MILLIMETRES_PER_METRE = 1000.0

MY_ROBOT_URDF_RELPATH = 'urdf/my_robot.urdf'
"""Where :func:`make_my_robot_package` puts the URDF inside the package's share folder."""

MY_ROBOT_MESHES: dict[str, str] = {
    'base_visual': 'meshes/visual/base.dae',
    'arm_visual': 'meshes/visual/arm.dae',
    'base_collision': 'meshes/collision/base.stl',
    'arm_collision': 'meshes/collision/arm.stl',
}
"""Mesh files of the my_robot example's package, relative to its share folder."""


def box_corners(size: Size = UNIT_BOX) -> np.ndarray:
    """Return the eight corners (8x3) of a box of ``size`` centred on the origin."""
    return _CUBE_CORNERS * np.asarray(size, dtype=float)


def box_triangles(size: Size = UNIT_BOX) -> np.ndarray:
    """Return the twelve outward-facing triangles (12x3x3) of a box of ``size``."""
    return box_corners(size)[_CUBE_FACES]


def _normals(triangles: np.ndarray) -> np.ndarray:
    cross = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    return cross / np.linalg.norm(cross, axis=1, keepdims=True)


def binary_stl_bytes(size: Size = UNIT_BOX, header: bytes = b'mesh_fixtures box') -> bytes:
    """Return a binary STL of a box of ``size`` (12 triangles, 684 bytes)."""
    triangles = box_triangles(size)
    parts = [header.ljust(STL_HEADER_BYTES, b'\0')[:STL_HEADER_BYTES],
             _STL_COUNT.pack(len(triangles))]
    for normal, triangle in zip(_normals(triangles), triangles, strict=True):
        parts.append(_STL_TRIANGLE.pack(*normal, *triangle.ravel(), 0))
    return b''.join(parts)


def ascii_stl_text(size: Size = UNIT_BOX, name: str = 'box') -> str:
    """Return an ASCII STL of a box of ``size``."""
    triangles = box_triangles(size)
    lines = [f'solid {name}']
    for normal, triangle in zip(_normals(triangles), triangles, strict=True):
        lines.append(f'  facet normal {normal[0]:g} {normal[1]:g} {normal[2]:g}')
        lines.append('    outer loop')
        lines.extend(f'      vertex {x:.9g} {y:.9g} {z:.9g}' for x, y, z in triangle)
        lines.append('    endloop')
        lines.append('  endfacet')
    lines.append(f'endsolid {name}')
    return '\n'.join(lines) + '\n'


def obj_text(size: Size = UNIT_BOX) -> str:
    """Return a Wavefront OBJ of a box of ``size`` (8 vertices, 12 faces)."""
    lines = ['# mesh_fixtures box', 'o box']
    lines.extend(f'v {x:.9g} {y:.9g} {z:.9g}' for x, y, z in box_corners(size))
    lines.extend(f'f {a + 1} {b + 1} {c + 1}' for a, b, c in _CUBE_FACES)
    return '\n'.join(lines) + '\n'


def _join(values: np.ndarray) -> str:
    return ' '.join(f'{v:.9g}' for v in np.asarray(values).ravel())


def dae_text(size: Size = UNIT_BOX, *, unit_meter: float = 1.0, primitive: str = 'triangles',
             node_matrix: Sequence[float] | None = None, up_axis: str = 'Z_UP') -> str:
    """Return a Collada 1.4.1 document of a box of ``size``, shaped like a Blender export.

    ``size`` is in the document's own units; ``unit_meter`` goes into
    ``<asset><unit meter=...>`` (Blender writes ``1``).  ``primitive`` is
    ``'triangles'`` (Blender's default) or ``'polylist'`` (older exporters).
    ``node_matrix`` (16 numbers, row-major) becomes the scene node's
    ``<matrix>``; the identity when omitted.  Positions and normals use
    separate index offsets, as exporters write them.
    """
    triangles = box_triangles(size)
    normals = _normals(triangles)
    # One normal per triangle: index pairs (position, normal) per corner.
    index_pairs = [f'{corner} {tri}' for tri, face in enumerate(_CUBE_FACES) for corner in face]
    face_count = len(_CUBE_FACES)
    if primitive == 'triangles':
        prim = (f'<triangles material="mat" count="{face_count}">'
                '<input semantic="VERTEX" source="#box-mesh-vertices" offset="0"/>'
                '<input semantic="NORMAL" source="#box-mesh-normals" offset="1"/>'
                f'<p>{" ".join(index_pairs)}</p></triangles>')
    elif primitive == 'polylist':
        prim = (f'<polylist material="mat" count="{face_count}">'
                '<input semantic="VERTEX" source="#box-mesh-vertices" offset="0"/>'
                '<input semantic="NORMAL" source="#box-mesh-normals" offset="1"/>'
                f'<vcount>{" ".join(["3"] * face_count)}</vcount>'
                f'<p>{" ".join(index_pairs)}</p></polylist>')
    else:
        raise ValueError(f'primitive must be triangles or polylist, not {primitive!r}')
    matrix = np.eye(4).ravel() if node_matrix is None else np.asarray(node_matrix, dtype=float)
    corners = box_corners(size)
    return f'''<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>
    <contributor><authoring_tool>mesh_fixtures</authoring_tool></contributor>
    <created>2024-01-01T00:00:00</created>
    <modified>2024-01-01T00:00:00</modified>
    <unit name="meter" meter="{unit_meter:g}"/>
    <up_axis>{up_axis}</up_axis>
  </asset>
  <library_geometries>
    <geometry id="box-mesh" name="box">
      <mesh>
        {_dae_source('box-mesh-positions', corners)}
        {_dae_source('box-mesh-normals', normals)}
        <vertices id="box-mesh-vertices">
          <input semantic="POSITION" source="#box-mesh-positions"/>
        </vertices>
        {prim}
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">
      <node id="box" name="box" type="NODE">
        <matrix sid="transform">{_join(matrix)}</matrix>
        <instance_geometry url="#box-mesh" name="box"/>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene>
    <instance_visual_scene url="#Scene"/>
  </scene>
</COLLADA>
'''


def _dae_source(source_id: str, points: np.ndarray) -> str:
    """Return a Collada ``<source>`` of 3-vectors with an XYZ accessor."""
    params = ''.join(f'<param name="{axis}" type="float"/>' for axis in 'XYZ')
    return (f'<source id="{source_id}">'
            f'<float_array id="{source_id}-array" count="{points.size}">{_join(points)}'
            '</float_array><technique_common>'
            f'<accessor source="#{source_id}-array" count="{len(points)}" stride="3">{params}'
            '</accessor></technique_common></source>')


def write_file(path: pathlib.Path, content: bytes | str) -> pathlib.Path:
    """Write ``content`` (bytes, or text as UTF-8) to ``path``, creating folders; return it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content, encoding='utf-8')
    return path


def write_binary_stl(path: pathlib.Path, size: Size = UNIT_BOX) -> pathlib.Path:
    """Write a binary STL box to ``path`` and return ``path``."""
    return write_file(path, binary_stl_bytes(size))


def write_ascii_stl(path: pathlib.Path, size: Size = UNIT_BOX) -> pathlib.Path:
    """Write an ASCII STL box to ``path`` and return ``path``."""
    return write_file(path, ascii_stl_text(size))


def write_obj(path: pathlib.Path, size: Size = UNIT_BOX) -> pathlib.Path:
    """Write an OBJ box to ``path`` and return ``path``."""
    return write_file(path, obj_text(size))


def write_dae(path: pathlib.Path, size: Size = UNIT_BOX, *, unit_meter: float = 1.0,
              primitive: str = 'triangles', node_matrix: Sequence[float] | None = None,
              up_axis: str = 'Z_UP') -> pathlib.Path:
    """Write a Collada box to ``path`` and return ``path``; see :func:`dae_text`."""
    return write_file(path, dae_text(size, unit_meter=unit_meter, primitive=primitive,
                                 node_matrix=node_matrix, up_axis=up_axis))


def package_xml_text(package: str) -> str:
    """Return a minimal format-3 ``package.xml`` for ``package``."""
    return f'''<?xml version="1.0"?>
<package format="3">
  <name>{package}</name>
  <version>0.0.0</version>
  <description>Generated by mesh_fixtures for tests.</description>
  <maintainer email="test@example.com">test</maintainer>
  <license>Apache-2.0</license>
  <export><build_type>ament_cmake</build_type></export>
</package>
'''


def make_ament_prefix(tmp_path: pathlib.Path, package: str,
                      files: Mapping[str, bytes | str] | None = None) -> pathlib.Path:
    """Create an install prefix holding ``package`` and return the prefix.

    Lays out ``<prefix>/share/ament_index/resource_index/packages/<package>``
    (the marker ``ament_index_python`` looks for),
    ``<prefix>/share/<package>/package.xml`` and each of ``files`` (relative
    path inside the share folder -> content).  The prefix is
    ``tmp_path / 'install'``; calling again with another package adds it to
    the same prefix.  Put the prefix on ``AMENT_PREFIX_PATH`` (e.g. with
    ``monkeypatch.setenv``); the ament index reads that variable on every
    look-up.
    """
    prefix = tmp_path / 'install'
    write_file(prefix / 'share' / 'ament_index' / 'resource_index' / 'packages' / package, '')
    share = prefix / 'share' / package
    write_file(share / 'package.xml', package_xml_text(package))
    for relpath, content in (files or {}).items():
        write_file(share / relpath, content)
    return prefix


def _scaled(size: Size, factor: float) -> Size:
    return (size[0] * factor, size[1] * factor, size[2] * factor)


def my_robot_mesh_files() -> dict[str, bytes | str]:
    """Return the my_robot example's meshes: relative path -> content.

    Visual DAEs hold millimetres under ``<unit meter="1"/>`` (as a CAD export
    re-saved by Blender does), which is why the my_robot example's URDF scales them by
    0.001; collision STLs hold metres and are not scaled.
    """
    return {
        MY_ROBOT_MESHES['base_visual']:
            dae_text(_scaled(MY_ROBOT_BASE_SIZE_M, MILLIMETRES_PER_METRE)),
        MY_ROBOT_MESHES['arm_visual']:
            dae_text(_scaled(MY_ROBOT_ARM_SIZE_M, MILLIMETRES_PER_METRE)),
        MY_ROBOT_MESHES['base_collision']: binary_stl_bytes(MY_ROBOT_BASE_SIZE_M),
        MY_ROBOT_MESHES['arm_collision']: binary_stl_bytes(MY_ROBOT_ARM_SIZE_M),
    }


def make_my_robot_package(tmp_path: pathlib.Path, urdf_source: pathlib.Path) -> pathlib.Path:
    """Create ``my_robot_pkg`` in a temporary ament prefix and return the prefix.

    The package holds the meshes of :func:`my_robot_mesh_files` and a copy of
    ``urdf_source`` at :data:`MY_ROBOT_URDF_RELPATH`.
    """
    files: dict[str, bytes | str] = my_robot_mesh_files()
    files[MY_ROBOT_URDF_RELPATH] = urdf_source.read_bytes()
    return make_ament_prefix(tmp_path, MY_ROBOT_PACKAGE, files)
