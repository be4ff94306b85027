"""What a robot looks like: each <visual> as triangles in its link's frame, in its colour."""

import math
import pathlib

import mesh_fixtures
import numpy as np
import pytest

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.resources import read_mesh_triangles
from pan_tilt_sim.model.robot import Geometry
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.model.visuals import (
    DEFAULT_RGBA,
    box_mesh,
    cylinder_mesh,
    robot_visuals,
    shape_mesh,
    sphere_mesh,
)
from pan_tilt_sim.share import DEFAULT_DESCRIPTION, package_share

SOURCE = pathlib.Path('/robots/test.urdf')


def urdf(links: str, materials: str = '') -> str:
    """A robot of the given links (the first is the root), chained by fixed joints."""
    return f'<robot name="r">{materials}{links}</robot>'


def signed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """The volume a closed mesh encloses: positive when every face points outwards."""
    a, b, c = (vertices[faces[:, i]].astype(float) for i in range(3))
    return float(np.einsum('ij,ij->i', a, np.cross(b, c)).sum() / 6.0)


# --- primitives ---------------------------------------------------------------------------

def test_a_box_has_its_size_centred_and_its_faces_outwards():
    vertices, faces = box_mesh((0.2, 0.4, 0.6))
    assert vertices.min(axis=0) == pytest.approx([-0.1, -0.2, -0.3])
    assert vertices.max(axis=0) == pytest.approx([0.1, 0.2, 0.3])
    assert signed_volume(vertices, faces) == pytest.approx(0.2 * 0.4 * 0.6, rel=1e-5)


def test_a_cylinder_runs_along_z_centred_with_its_faces_outwards():
    vertices, faces = cylinder_mesh(0.5, 2.0, segments=64)
    assert vertices[:, 2].min() == pytest.approx(-1.0)
    assert vertices[:, 2].max() == pytest.approx(1.0)
    assert np.hypot(vertices[:, 0], vertices[:, 1]).max() == pytest.approx(0.5)
    polygon_area = 0.5 * 64 * 0.25 * math.sin(2 * math.pi / 64)
    assert signed_volume(vertices, faces) == pytest.approx(polygon_area * 2.0, rel=1e-5)


def test_a_sphere_has_its_radius_with_its_faces_outwards():
    vertices, faces = sphere_mesh(0.3)
    assert np.linalg.norm(vertices, axis=1) == pytest.approx(np.full(len(vertices), 0.3))
    volume = signed_volume(vertices, faces)
    assert 0.9 * (4 / 3) * math.pi * 0.3 ** 3 < volume < (4 / 3) * math.pi * 0.3 ** 3


# --- a robot's visuals --------------------------------------------------------------------

def test_each_visual_is_placed_by_its_origin_in_its_own_links_frame():
    model = parse_urdf(urdf('''
        <link name="base"><visual><origin xyz="0 0 1" rpy="0 0 1.5707963"/>
          <geometry><box size="2 1 1"/></geometry></visual></link>'''), SOURCE)
    (mesh,), warnings = robot_visuals(model, SOURCE.parent)
    assert warnings == []
    assert (mesh.link, mesh.name) == ('base', 'visual_0')
    # The 2 m side along x is turned onto y, the box lifted by 1 m.
    assert mesh.vertices.min(axis=0) == pytest.approx([-0.5, -1.0, 0.5], abs=1e-6)
    assert mesh.vertices.max(axis=0) == pytest.approx([0.5, 1.0, 1.5], abs=1e-6)


def test_colours_come_from_the_visuals_material_or_the_robots_and_default_to_grey():
    model = parse_urdf(urdf('''
        <link name="base">
          <visual><geometry><sphere radius="1"/></geometry>
            <material name="own"><color rgba="1 0 0 1"/></material></visual>
          <visual><geometry><sphere radius="1"/></geometry><material name="blue"/></visual>
          <visual><geometry><sphere radius="1"/></geometry></visual>
          <visual><geometry><sphere radius="1"/></geometry><material name="unknown"/></visual>
        </link>''', '<material name="blue"><color rgba="0 0 1 0.5"/></material>'), SOURCE)
    meshes, _ = robot_visuals(model, SOURCE.parent)
    assert [mesh.rgba for mesh in meshes] == [(1.0, 0.0, 0.0, 1.0), (0.0, 0.0, 1.0, 0.5),
                                              DEFAULT_RGBA, DEFAULT_RGBA]


@pytest.mark.parametrize('rgba', ['1 0 0', '1 0 0 2', 'red'])
def test_a_malformed_colour_names_the_file_the_link_and_the_value(rgba):
    text = urdf(f'''<link name="base"><visual><geometry><sphere radius="1"/></geometry>
        <material name="m"><color rgba="{rgba}"/></material></visual></link>''')
    with pytest.raises(DescriptionError, match=f"test.urdf: link 'base': <color rgba=\"{rgba}\">"):
        parse_urdf(text, SOURCE)


def test_a_mesh_is_read_from_its_package_uri_and_scaled(tmp_path, monkeypatch):
    prefix = mesh_fixtures.make_ament_prefix(tmp_path, 'look_pkg', {
        'meshes/box.stl': mesh_fixtures.binary_stl_bytes((1.0, 2.0, 3.0))})
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(prefix))
    model = parse_urdf(urdf('''<link name="base"><visual><geometry>
        <mesh filename="package://look_pkg/meshes/box.stl" scale="0.5 0.5 2"/>
        </geometry></visual></link>'''), SOURCE)
    (mesh,), warnings = robot_visuals(model, SOURCE.parent)
    assert warnings == []
    assert mesh.vertices.max(axis=0) == pytest.approx([0.25, 0.5, 3.0])
    assert signed_volume(mesh.vertices, mesh.faces) == pytest.approx(0.5 * 1.0 * 6.0, rel=1e-5)


def test_a_mirroring_scale_keeps_the_faces_outwards(tmp_path):
    mesh_fixtures.write_binary_stl(tmp_path / 'box.stl')
    vertices, faces = shape_mesh(Geometry('mesh', filename='box.stl', scale=(-1.0, 1.0, 1.0)),
                                 tmp_path)
    assert signed_volume(vertices, faces) == pytest.approx(1.0, rel=1e-5)


def test_a_file_used_by_several_visuals_is_read_once(tmp_path):
    mesh_fixtures.write_obj(tmp_path / 'box.obj')
    model = parse_urdf(urdf(''.join(
        f'<link name="l{i}"><visual><geometry><mesh filename="box.obj"/></geometry></visual>'
        '</link>' for i in range(3)) + ''.join(
        f'<joint name="j{i}" type="fixed"><parent link="l0"/><child link="l{i}"/></joint>'
        for i in (1, 2))), tmp_path / 'robot.urdf')
    reads = []

    def counting_reader(path):
        reads.append(path)
        return read_mesh_triangles(path)

    meshes, _ = robot_visuals(model, tmp_path, counting_reader)
    assert len(meshes) == 3
    assert reads == [tmp_path / 'box.obj']


def test_a_visual_that_cannot_be_drawn_is_left_out_with_a_warning_naming_it(tmp_path):
    model = parse_urdf(urdf('''<link name="base">
        <visual><geometry><mesh filename="gone.stl"/></geometry></visual>
        <visual><geometry><box size="1 1 1"/></geometry></visual></link>'''), tmp_path / 'r.urdf')
    meshes, warnings = robot_visuals(model, tmp_path)
    assert [mesh.index for mesh in meshes] == [1]
    assert len(warnings) == 1
    assert warnings[0].startswith("link 'base' visual 0: not drawn: ")
    assert 'gone.stl' in warnings[0]


def test_the_pan_tilt_example_is_drawn_in_its_urdfs_colours():
    description = load_description(package_share() / DEFAULT_DESCRIPTION)
    meshes, warnings = robot_visuals(description.model, description.source.parent)
    assert warnings == []
    assert {mesh.link: mesh.rgba for mesh in meshes} == {
        'base_link': (1.0, 1.0, 0.0, 1.0), 'pan_link': (0.0, 0.0, 1.0, 1.0),
        'tilt_link': (1.0, 0.0, 0.0, 1.0)}


# --- reading mesh files -------------------------------------------------------------------

@pytest.mark.parametrize('write', [mesh_fixtures.write_binary_stl, mesh_fixtures.write_ascii_stl,
                                   mesh_fixtures.write_obj, mesh_fixtures.write_dae])
def test_every_supported_mesh_format_reads_as_its_triangles(tmp_path, write):
    path = write(tmp_path / f'box.{write.__name__.rpartition("_")[2]}', (1.0, 2.0, 4.0))
    triangles = read_mesh_triangles(path)
    assert triangles.shape == (12, 3, 3)
    assert triangles.reshape(-1, 3).max(axis=0) == pytest.approx([0.5, 1.0, 2.0])


def test_obj_polygons_are_fanned_and_relative_indices_count_back(tmp_path):
    path = tmp_path / 'quad.obj'
    path.write_text('v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n')
    triangles = read_mesh_triangles(path)
    assert triangles.tolist() == [[[0, 0, 0], [1, 0, 0], [1, 1, 0]],
                                  [[0, 0, 0], [1, 1, 0], [0, 1, 0]]]


def test_an_unreadable_mesh_is_one_line_naming_the_file(tmp_path):
    path = tmp_path / 'bad.obj'
    path.write_text('v 0 0 0\nf 1 2 3\n')
    with pytest.raises(DescriptionError, match=r'^mesh .*bad\.obj: a face names vertex 3'):
        read_mesh_triangles(path)
