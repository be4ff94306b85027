"""What a robot looks like: each link's ``<visual>`` as triangles and a colour. No ROS.

For drawing a robot as its URDF draws it, by RViz's rules: every visual of
every link, its geometry as triangles in the link's frame (the visual's
``<origin>`` and a mesh's ``scale`` applied), in its ``<material>`` colour,
else :data:`DEFAULT_RGBA`.  Boxes, cylinders (along z, centred) and spheres
are built here; meshes are read from the file their URI names
(``package://`` resolved as for the physics, relative paths against the
description's folder) with :func:`~pan_tilt_sim.model.resources.read_mesh_triangles`.

A visual that cannot be drawn (a mesh file gone since start-up, a geometry
URDF does not define) is left out with one warning line: the view is an aid,
the simulation already accepted the description.
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
from collections.abc import Callable

import numpy as np

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.resources import read_mesh_triangles, resolve_resource
from pan_tilt_sim.model.robot import Geometry, Rgba, RobotModel
from pan_tilt_sim.model.transforms import Transform, rotation_matrix

DEFAULT_RGBA: Rgba = (0.7, 0.7, 0.7, 1.0)  # RViz's grey for a visual without a colour
CYLINDER_SEGMENTS = 32  # facets around a cylinder
SPHERE_RINGS = 12  # latitude bands of a sphere
SPHERE_SEGMENTS = 24  # longitude facets of a sphere
# The 12 triangles of the unit cube's corners (x, y, z bits of the corner index), outward.
_BOX_FACES = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
                       [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]],
                      dtype=np.uint32)

MeshReader = Callable[[pathlib.Path], np.ndarray]


@dataclasses.dataclass(frozen=True)
class VisualMesh:
    """One ``<visual>`` of a link as a triangle mesh in the link's frame (metres)."""

    link: str
    index: int  # its place among the link's visuals
    vertices: np.ndarray  # V x 3, float32
    faces: np.ndarray  # F x 3 vertex indices, uint32, counter-clockwise seen from outside
    rgba: Rgba

    @property
    def name(self) -> str:
        """A name unique within the robot: ``visual_<index>`` under the link."""
        return f'visual_{self.index}'


def robot_visuals(model: RobotModel, base_dir: pathlib.Path,
                  read_mesh: MeshReader = read_mesh_triangles
                  ) -> tuple[list[VisualMesh], list[str]]:
    """Return every link's visuals as meshes, and one warning line per visual left out.

    ``base_dir`` is the description file's folder (for relative mesh paths);
    ``read_mesh`` reads a mesh file's triangles (each file is read once).
    """
    meshes: list[VisualMesh] = []
    warnings: list[str] = []
    files: dict[pathlib.Path, np.ndarray] = {}
    for link in model.links:
        for index, shape in enumerate(link.visuals):
            try:
                vertices, faces = shape_mesh(shape.geometry, base_dir, read_mesh, files)
            except DescriptionError as err:
                warnings.append(f"link '{link.name}' visual {index}: not drawn: {err}")
                continue
            meshes.append(VisualMesh(link.name, index, placed(vertices, shape.origin), faces,
                                     shape.rgba or DEFAULT_RGBA))
    return meshes, warnings


def shape_mesh(geometry: Geometry, base_dir: pathlib.Path,
               read_mesh: MeshReader = read_mesh_triangles,
               files: dict[pathlib.Path, np.ndarray] | None = None
               ) -> tuple[np.ndarray, np.ndarray]:
    """Return a geometry's vertices (V x 3) and faces (F x 3) in its own frame.

    ``files`` caches mesh files' triangles by resolved path.  Raises
    :class:`DescriptionError` for a geometry that cannot be drawn.
    """
    if geometry.kind == 'box':
        return box_mesh(geometry.size)
    if geometry.kind == 'cylinder':
        return cylinder_mesh(geometry.radius, geometry.length)
    if geometry.kind == 'sphere':
        return sphere_mesh(geometry.radius)
    if geometry.kind == 'capsule':  # a cylinder and a sphere on each end
        parts = [cylinder_mesh(geometry.radius, geometry.length)]
        for end in (-0.5, 0.5):
            vertices, faces = sphere_mesh(geometry.radius)
            parts.append((vertices + np.array([0.0, 0.0, end * geometry.length],
                                              dtype=vertices.dtype), faces))
        offsets = np.cumsum([0] + [len(vertices) for vertices, _faces in parts[:-1]])
        return (np.concatenate([vertices for vertices, _faces in parts]),
                np.concatenate([faces + offset for (_v, faces), offset in zip(
                    parts, offsets, strict=True)]).astype(np.uint32))
    if geometry.kind == 'mesh':
        path = resolve_resource(geometry.filename, base_dir)
        cache = {} if files is None else files
        if path not in cache:
            cache[path] = np.asarray(read_mesh(path), dtype=float).reshape(-1, 3, 3)
        triangles = cache[path] * np.asarray(geometry.scale)
        faces = np.arange(len(triangles) * 3, dtype=np.uint32).reshape(-1, 3)
        if np.prod(geometry.scale) < 0:  # a mirroring scale turns the faces inside out
            faces = faces[:, ::-1].copy()
        return triangles.reshape(-1, 3).astype(np.float32), faces
    raise DescriptionError(f'<{geometry.kind}> is not a URDF geometry (box, cylinder, '
                           'sphere, capsule, mesh)')


def placed(vertices: np.ndarray, origin: Transform) -> np.ndarray:
    """Return ``vertices`` (V x 3) moved by ``origin`` (rotated, then translated)."""
    rotation = np.array(rotation_matrix(origin.rotation))
    return (vertices @ rotation.T + np.array(origin.translation)).astype(np.float32)


def box_mesh(size: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Return a box of ``size`` (x, y, z), centred: 8 corners, 12 triangles."""
    corners = np.array([[(i >> 0) & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)],
                       dtype=float) - 0.5
    return (corners * np.asarray(size)).astype(np.float32), _BOX_FACES.copy()


def cylinder_mesh(radius: float, length: float,
                  segments: int = CYLINDER_SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    """Return a cylinder along z, centred: ``segments`` side facets and two capped ends."""
    angles = np.linspace(0.0, 2.0 * math.pi, segments, endpoint=False)
    ring = np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])
    half = length / 2.0
    bottom = np.column_stack([ring, np.full(segments, -half)])
    top = np.column_stack([ring, np.full(segments, half)])
    centres = np.array([[0.0, 0.0, -half], [0.0, 0.0, half]])
    vertices = np.vstack([bottom, top, centres])
    i = np.arange(segments)
    j = (i + 1) % segments
    low, high = 2 * segments, 2 * segments + 1
    faces = np.vstack([
        np.column_stack([i, j, segments + j]), np.column_stack([i, segments + j, segments + i]),
        np.column_stack([np.full(segments, low), j, i]),
        np.column_stack([np.full(segments, high), segments + i, segments + j])])
    return vertices.astype(np.float32), faces.astype(np.uint32)


def sphere_mesh(radius: float, rings: int = SPHERE_RINGS,
                segments: int = SPHERE_SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    """Return a latitude-longitude sphere about the origin."""
    polar = np.linspace(0.0, math.pi, rings + 1)
    azimuth = np.linspace(0.0, 2.0 * math.pi, segments, endpoint=False)
    p, a = np.meshgrid(polar, azimuth, indexing='ij')
    vertices = radius * np.stack([np.sin(p) * np.cos(a), np.sin(p) * np.sin(a), np.cos(p)],
                                 axis=-1).reshape(-1, 3)
    row = np.arange(rings)[:, None] * segments
    column = np.arange(segments)[None, :]
    right = (column + 1) % segments
    a00, a01 = row + column, row + right
    b00, b01 = a00 + segments, a01 + segments
    faces = np.concatenate([np.stack([a00, b00, b01], axis=-1).reshape(-1, 3),
                            np.stack([a00, b01, a01], axis=-1).reshape(-1, 3)])
    return vertices.astype(np.float32), faces.astype(np.uint32)
