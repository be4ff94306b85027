"""Resource resolution and mesh localization: what the description layer relies on.

Localized meshes are loaded into PyBullet to prove they load, quietly
(see mesh_loading.py).  What PyBullet itself does with meshes is pinned in
test/dependencies/.
"""

import os
import pathlib
import re
import xml.etree.ElementTree as ET

import mesh_fixtures as mf
import numpy as np
import pybullet
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from mesh_loading import (
    BOX_123,
    FLOAT32_TOLERANCE,
    MILLI_SCALE,
    MM,
    assert_quiet,
    collision_extent,
    load,
    mesh_robot,
    mesh_xml,
    one_link_robot,
)

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.resources import (
    LocalizedMesh,
    localize_meshes,
    read_ascii_stl,
    read_collada,
    resolve_resource,
    write_binary_stl,
)

# --- resolve_resource -------------------------------------------------------


def test_package_uri_resolves_through_the_ament_index(tmp_path, monkeypatch):
    """package://PKG/rel is <share of PKG>/rel, found through AMENT_PREFIX_PATH."""
    prefix = mf.make_ament_prefix(tmp_path, 'some_pkg', {'meshes/a.stl': mf.binary_stl_bytes()})
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(prefix))
    path = resolve_resource('package://some_pkg/meshes/a.stl', tmp_path / 'elsewhere')
    assert path == prefix / 'share' / 'some_pkg' / 'meshes' / 'a.stl'
    assert path.is_file()


def test_ament_index_reads_ament_prefix_path_at_call_time(tmp_path, monkeypatch):
    """A prefix added to AMENT_PREFIX_PATH later in the process is seen."""
    prefix = mf.make_ament_prefix(tmp_path, 'late_pkg')
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(tmp_path / 'empty'))
    with pytest.raises(DescriptionError):
        resolve_resource('package://late_pkg/x.stl', tmp_path)
    monkeypatch.setenv('AMENT_PREFIX_PATH', os.pathsep.join([str(tmp_path / 'empty'), str(prefix)]))
    assert resolve_resource('package://late_pkg/x.stl', tmp_path) == (
        prefix / 'share' / 'late_pkg' / 'x.stl')


@pytest.mark.parametrize(('uri', 'expected'), [
    ('meshes/a.stl', 'base/meshes/a.stl'),
    ('./meshes/../meshes/a.stl', 'base/meshes/a.stl'),
    ('../shared/a.stl', 'shared/a.stl'),
    ('file://meshes/a.stl', 'base/meshes/a.stl'),
])
def test_relative_paths_resolve_against_the_description_folder(tmp_path, uri, expected):
    """Relative paths (and file://rel) are taken from the description file's folder."""
    assert resolve_resource(uri, tmp_path / 'base') == tmp_path / expected


def test_relative_base_dir_still_gives_an_absolute_path(tmp_path, monkeypatch):
    """The result is absolute even when base_dir is relative."""
    monkeypatch.chdir(tmp_path)
    assert resolve_resource('a.stl', pathlib.Path('urdf')) == tmp_path / 'urdf' / 'a.stl'


@pytest.mark.parametrize('form', ['{path}', 'file://{path}', 'file://localhost{path}'])
def test_absolute_paths_and_file_uris(tmp_path, form):
    """Absolute paths, file:///abs and file://localhost/abs name the same file."""
    target = tmp_path / 'abs' / 'a.stl'
    assert resolve_resource(form.format(path=target), tmp_path / 'base') == target


def test_file_uri_percent_escapes_are_decoded(tmp_path):
    """file:// URIs are URIs: %20 is a space."""
    target = tmp_path / 'with space' / 'a.stl'
    uri = 'file://' + str(target).replace(' ', '%20')
    assert resolve_resource(uri, tmp_path) == target


def test_unknown_package_names_the_uri_and_the_ament_index(tmp_path, monkeypatch):
    """An unknown package names the URI, the package and AMENT_PREFIX_PATH."""
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(tmp_path))
    with pytest.raises(DescriptionError) as caught:
        resolve_resource('package://no_such_pkg/meshes/a.stl', tmp_path)
    message = str(caught.value)
    assert "'package://no_such_pkg/meshes/a.stl'" in message
    assert "package 'no_such_pkg' is not in the ament index" in message
    assert f'AMENT_PREFIX_PATH={str(tmp_path)!r}' in message


def test_unset_ament_prefix_path_is_reported(tmp_path, monkeypatch):
    """Without AMENT_PREFIX_PATH the error says so."""
    monkeypatch.delenv('AMENT_PREFIX_PATH', raising=False)
    with pytest.raises(DescriptionError, match='AMENT_PREFIX_PATH is not set'):
        resolve_resource('package://some_pkg/a.stl', tmp_path)


@pytest.mark.parametrize('uri', ['package://', 'package://pkg_only', 'package://pkg/',
                                 'package:///meshes/a.stl'])
def test_malformed_package_uris(tmp_path, uri):
    """package:// needs both a package and a path inside it."""
    with pytest.raises(DescriptionError, match=re.escape(f"'{uri}'") + '.*PACKAGE/PATH'):
        resolve_resource(uri, tmp_path)


@pytest.mark.parametrize('uri', ['http://example.com/a.stl', 'https://example.com/a.dae',
                                 'model://my_model/meshes/a.dae', 'ftp://host/a.stl'])
def test_other_schemes_are_refused(tmp_path, uri):
    """Schemes other than package:// and file:// are refused by name."""
    scheme = uri.split('://')[0]
    with pytest.raises(DescriptionError) as caught:
        resolve_resource(uri, tmp_path)
    assert f"'{uri}'" in str(caught.value)
    assert f"'{scheme}://'" in str(caught.value)


def test_empty_filename_is_refused(tmp_path):
    """An empty filename is an error, not the description folder."""
    with pytest.raises(DescriptionError, match='empty file name'):
        resolve_resource('', tmp_path)


# --- localize_meshes: errors ---------------------------------------------


def test_missing_mesh_names_uri_and_resolved_path(tmp_path, monkeypatch, cache_dir):
    """A missing mesh names the link, role, URI and resolved path on one line."""
    prefix = mf.make_ament_prefix(tmp_path, 'my_robot_pkg')
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(prefix))
    uri = 'package://my_robot_pkg/meshes/visual/base.dae'
    robot = ET.fromstring(f'<robot name="r"><link name="base_link"><visual>{mesh_xml(uri)}'
                          '</visual></link></robot>')
    with pytest.raises(DescriptionError) as caught:
        localize_meshes(robot, tmp_path, cache_dir)
    resolved = prefix / 'share' / 'my_robot_pkg' / 'meshes' / 'visual' / 'base.dae'
    assert str(caught.value) == (
        f"link 'base_link' visual: mesh '{uri}' (resolved to {resolved}): file not found")


def test_unknown_package_in_a_mesh_names_link_and_uri(tmp_path, monkeypatch, cache_dir):
    """An unresolvable mesh URI names the link and role too."""
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(tmp_path))
    robot = mesh_robot('package://ghost_pkg/a.stl', 'collision')
    with pytest.raises(DescriptionError, match=re.escape(
            "link 'm' collision: mesh 'package://ghost_pkg/a.stl': package 'ghost_pkg' is not "
            'in the ament index')):
        localize_meshes(robot, tmp_path, cache_dir)


def _without(pattern: str, text: str) -> str:
    return re.sub(pattern, '', text, flags=re.S)


BROKEN_MESHES = {
    'garbage.stl': (b'this is not an stl file at all' * 10, 'neither ASCII STL'),
    'empty.stl': (b'', 'file is empty'),
    'truncated.stl': (mf.binary_stl_bytes()[:334],
                      'truncated binary STL: 12 triangles need 684 bytes, the file has 334'),
    'no_triangles.stl': (mf.binary_stl_bytes()[:mf.STL_HEADER_BYTES] + bytes(4),
                         'binary STL without triangles'),
    'nan.stl': (mf.binary_stl_bytes().replace(
        np.float32(0.5).tobytes(), np.float32('nan').tobytes(), 1), 'NaN or infinity'),
    'no_facets.stl': ('solid empty\nendsolid empty\n', 'ASCII STL without any facet'),
    'cut.stl': (mf.ascii_stl_text()[:300], "without 'endsolid' at its end (truncated?)"),
    'two_corners.stl': ('solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n'
                        'endloop\nendfacet\nendsolid x\n', '2 vertices, not a multiple of 3'),
    'no_geometry.dae': (_without(r'<library_geometries>.*</library_geometries>', mf.dae_text()),
                        "<geometry> '#box-mesh' not found"),
    'empty_scene.dae': (_without(r'<node .*</node>', mf.dae_text()),
                        'no triangle geometry in the scene'),
    'no_vertices.dae': (_without(r'<vertices.*?</vertices>', mf.dae_text()),
                        "vertex positions '#box-mesh-vertices' not found"),
    'half.dae': (mf.dae_text()[:len(mf.dae_text()) // 2], 'not valid XML'),
    'not_collada.dae': ('<robot name="x"/>', 'not a Collada file (root element <robot>)'),
    'bad_index.dae': (mf.dae_text().replace('<p>0 0 ', '<p>99 0 '), 'index out of range'),
    'bad_unit.dae': (mf.dae_text(unit_meter=0), "<unit meter='0'> is not a positive number"),
    'no_faces.obj': (''.join(line for line in mf.obj_text().splitlines(keepends=True)
                             if not line.startswith('f ')), 'OBJ without faces'),
    'bad_index.obj': (mf.obj_text() + 'f 1 2 99\n', 'a face names vertex 99, the file has 8'),
    'relative_index.obj': (mf.obj_text() + 'f -1 -2 -9\n', 'a face names vertex 9'),
    'zero_index.obj': (mf.obj_text() + 'f 0 1 2\n', 'a face names vertex 0 (OBJ counts from 1)'),
    'word_index.obj': (mf.obj_text() + 'f 1/1 2/2 x/3\n', 'a face corner is not a vertex index'),
    'short_face.obj': (mf.obj_text() + 'f 1 2\n', 'a face with 2 corners'),
    'box.ply': ('ply\nformat ascii 1.0\nend_header\n', "unsupported mesh format '.ply'"),
}


@pytest.mark.parametrize('name', sorted(BROKEN_MESHES))
@pytest.mark.parametrize('role', ['visual', 'collision'])
def test_unloadable_mesh_is_a_one_line_description_error(tmp_path, cache_dir, name, role):
    """Each broken file is refused with its URI, resolved path and the reason."""
    content, reason = BROKEN_MESHES[name]
    mf.write_file(tmp_path / 'meshes' / name, content)
    robot = mesh_robot(f'meshes/{name}', role)
    with pytest.raises(DescriptionError) as caught:
        localize_meshes(robot, tmp_path, cache_dir)
    message = str(caught.value)
    assert message.startswith(f"link 'm' {role}: mesh 'meshes/{name}' "
                              f"(resolved to {tmp_path / 'meshes' / name}): ")
    assert reason in message
    assert '\n' not in message


def test_a_folder_is_not_a_mesh(tmp_path, cache_dir):
    """A folder with a mesh-like name is refused."""
    (tmp_path / 'dir.stl').mkdir()
    with pytest.raises(DescriptionError, match='is a folder, not a file'):
        localize_meshes(mesh_robot('dir.stl', 'collision'), tmp_path, cache_dir)


@pytest.mark.parametrize('scale', ['0.001', '0.001 0.001', 'a b c', '0 0 0', '1,1,1',
                                   '1 1 nan'])
def test_bad_scale_is_refused(tmp_path, cache_dir, scale):
    """A scale must be three finite non-zero numbers (urdfdom's rule; PyBullet guesses)."""
    mf.write_binary_stl(tmp_path / 'a.stl')
    with pytest.raises(DescriptionError, match=re.escape(
            f"scale '{scale}' must be three finite, non-zero numbers")):
        localize_meshes(mesh_robot('a.stl', 'collision', scale), tmp_path, cache_dir)


def test_mesh_without_filename_is_refused(tmp_path, cache_dir):
    """A <mesh> without filename is refused."""
    robot = one_link_robot(collision='<collision><geometry><mesh/></geometry></collision>')
    with pytest.raises(DescriptionError, match="link 'm' collision: <mesh> has no filename"):
        localize_meshes(robot, tmp_path, cache_dir)


# --- localize_meshes: what PyBullet gets ---------------------------------

LOADABLE = {
    'binary.stl': lambda path, size: mf.write_binary_stl(path, size),
    'ascii.stl': lambda path, size: mf.write_ascii_stl(path, size),
    'upper_case.STL': lambda path, size: mf.write_binary_stl(path, size),
    'trailing_bytes.stl': lambda path, size: mf.write_file(
        path, mf.binary_stl_bytes(size) + b'\0' * 16),
    'solid_header_binary.stl': lambda path, size: mf.write_file(
        path, mf.binary_stl_bytes(size, header=b'solid but binary')),
    'box.obj': lambda path, size: mf.write_obj(path, size),
    'triangles.dae': lambda path, size: mf.write_dae(path, size),
    'polylist.dae': lambda path, size: mf.write_dae(path, size, primitive='polylist'),
    'y_up.dae': lambda path, size: mf.write_dae(path, size, up_axis='Y_UP'),
    'millimetre_unit.dae': lambda path, size: mf.write_dae(
        path, tuple(v / MM for v in size), unit_meter=MM),
    'no_asset.dae': lambda path, size: mf.write_file(
        path, _without(r'<asset>.*</asset>', mf.dae_text(size))),
    'no_scene.dae': lambda path, size: mf.write_file(
        path, _without(r'<library_visual_scenes>.*</scene>', mf.dae_text(size))),
}
"""Mesh files that must load, each written as a box of a given size in metres."""


@pytest.mark.parametrize('name', sorted(LOADABLE))
def test_collision_mesh_loads_with_its_scaled_size(tmp_path, cache_dir, client, capfd, name):
    """Every supported file gives PyBullet a collision hull of the scaled size, quietly."""
    LOADABLE[name](tmp_path / 'meshes' / name, BOX_123)
    robot = mesh_robot(f'meshes/{name}', 'collision', MILLI_SCALE)
    (done,) = localize_meshes(robot, tmp_path, cache_dir)
    mesh = robot.find('link/collision/geometry/mesh')
    assert mesh.get('filename') == str(done.loadable)
    assert pathlib.Path(mesh.get('filename')).is_absolute()
    assert mesh.get('scale') == MILLI_SCALE
    body = load(client, robot, tmp_path)
    extent = collision_extent(client, body)
    np.testing.assert_allclose(extent, np.array(BOX_123) * MM, rtol=FLOAT32_TOLERANCE)
    assert_quiet(capfd)


@pytest.mark.parametrize('name', sorted(LOADABLE))
def test_visual_mesh_loads_quietly(tmp_path, cache_dir, client, capfd, name):
    """Every supported file loads as a visual with the URDF scale kept, quietly."""
    LOADABLE[name](tmp_path / 'meshes' / name, BOX_123)
    robot = mesh_robot(f'meshes/{name}', 'visual', MILLI_SCALE)
    (done,) = localize_meshes(robot, tmp_path, cache_dir)
    body = load(client, robot, tmp_path)
    (shape,) = pybullet.getVisualShapeData(body, physicsClientId=client)
    assert shape[2] == pybullet.GEOM_MESH
    assert shape[3] == pytest.approx((MM, MM, MM))
    assert shape[4].decode() == str(done.loadable)
    assert_quiet(capfd)








def test_collada_node_transforms_are_applied(tmp_path, cache_dir, client):
    """A DAE node's <matrix> turns and moves the converted hull."""
    quarter_turn_about_z_then_shift_x = [0, -1, 0, 5, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    mf.write_dae(tmp_path / 'turned.dae', BOX_123, node_matrix=quarter_turn_about_z_then_shift_x)
    robot = mesh_robot('turned.dae', 'collision')
    localize_meshes(robot, tmp_path, cache_dir)
    body = load(client, robot, tmp_path)
    _, vertices = pybullet.getMeshData(body, -1, physicsClientId=client)
    points = np.array(vertices)
    np.testing.assert_allclose(points.max(axis=0) - points.min(axis=0), [2, 1, 3], atol=1e-6)
    np.testing.assert_allclose(points.mean(axis=0), [5, 0, 0], atol=1e-6)


def test_untouched_formats_keep_their_path_and_conversions_go_to_the_cache(tmp_path, cache_dir):
    """Binary STL and OBJ stay where they are; ASCII STL and DAE go to the cache."""
    mf.write_binary_stl(tmp_path / 'a.stl')
    mf.write_obj(tmp_path / 'b.obj')
    mf.write_ascii_stl(tmp_path / 'c.stl')
    mf.write_dae(tmp_path / 'd.dae')
    robot = one_link_robot(
        visual=''.join(f'<visual>{mesh_xml(n)}</visual>' for n in ('a.stl', 'b.obj')),
        collision=''.join(f'<collision>{mesh_xml(n)}</collision>' for n in ('c.stl', 'd.dae')))
    done = localize_meshes(robot, tmp_path, cache_dir)
    assert [(m.role, m.uri) for m in done] == [
        ('visual', 'a.stl'), ('visual', 'b.obj'), ('collision', 'c.stl'), ('collision', 'd.dae')]
    assert done[0].loadable == tmp_path / 'a.stl'
    assert done[1].loadable == tmp_path / 'b.obj'
    assert done[2].loadable.parent == cache_dir
    assert done[3].loadable.parent == cache_dir
    assert all(isinstance(m, LocalizedMesh) and m.resolved.is_file() for m in done)


def test_a_mesh_used_twice_is_converted_once_and_the_cache_is_reused(tmp_path, cache_dir):
    """One conversion per distinct file; a later run reuses it without rewriting."""
    mf.write_dae(tmp_path / 'a.dae')
    snippet = mesh_xml('a.dae')
    first = localize_meshes(one_link_robot(f'<visual>{snippet}</visual>',
                                           f'<collision>{snippet}</collision>'),
                            tmp_path, cache_dir)
    assert first[0].loadable == first[1].loadable
    assert list(cache_dir.iterdir()) == [first[0].loadable]
    written = first[0].loadable.stat().st_mtime_ns
    again = localize_meshes(mesh_robot('a.dae', 'visual'), tmp_path, cache_dir)
    assert again[0].loadable == first[0].loadable
    assert again[0].loadable.stat().st_mtime_ns == written


def test_changed_source_gets_a_new_cache_entry(tmp_path, cache_dir):
    """The cache is keyed on content, so an edited mesh is converted again."""
    mf.write_dae(tmp_path / 'a.dae')
    before = localize_meshes(mesh_robot('a.dae', 'visual'), tmp_path, cache_dir)
    mf.write_dae(tmp_path / 'a.dae', BOX_123)
    after = localize_meshes(mesh_robot('a.dae', 'visual'), tmp_path, cache_dir)
    assert before[0].loadable != after[0].loadable


def test_meshes_outside_links_visual_and_collision_are_left_alone(tmp_path, cache_dir):
    """Only link visual/collision meshes are touched."""
    robot = ET.fromstring('<robot name="r"><link name="a"/><gazebo><mesh filename="nowhere.stl"/>'
                          '</gazebo></robot>')
    assert localize_meshes(robot, tmp_path, cache_dir) == []
    assert robot.find('gazebo/mesh').get('filename') == 'nowhere.stl'


FUZZ_SEEDS = {
    '.stl': [mf.binary_stl_bytes(), mf.ascii_stl_text().encode()],
    '.obj': [mf.obj_text().encode()],
    '.dae': [mf.dae_text().encode(), mf.dae_text(primitive='polylist').encode()],
}


@st.composite
def damaged_meshes(draw: st.DrawFn) -> tuple[str, bytes]:
    """Draw a valid mesh file with a random slice replaced by random bytes."""
    suffix = draw(st.sampled_from(sorted(FUZZ_SEEDS)))
    data = draw(st.sampled_from(FUZZ_SEEDS[suffix]))
    start = draw(st.integers(0, len(data)))
    end = draw(st.integers(start, min(len(data), start + 64)))
    return suffix, data[:start] + draw(st.binary(max_size=64)) + data[end:]


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(mesh=damaged_meshes())
def test_damaged_files_give_a_description_error_or_a_loadable_mesh(tmp_path, client, capfd,
                                                                   mesh):
    """Whatever the damage: a one-line DescriptionError, or a file PyBullet loads quietly."""
    suffix, data = mesh
    path = mf.write_file(tmp_path / f'fuzz{suffix}', data)
    robot = mesh_robot(path.name, 'collision')
    try:
        localize_meshes(robot, tmp_path, tmp_path / 'cache')
    except DescriptionError as exc:
        assert '\n' not in str(exc)
        event(f'{suffix} refused')
        return
    event(f'{suffix} loaded')
    body = load(client, robot, tmp_path)
    pybullet.removeBody(body, physicsClientId=client)
    assert_quiet(capfd)


@settings(max_examples=50, deadline=None)
@given(triangles=st.lists(
    st.lists(st.lists(st.floats(-1e6, 1e6, width=32), min_size=3, max_size=3),
             min_size=3, max_size=3), min_size=1, max_size=20))
def test_binary_stl_writer_round_trips(tmp_path_factory, triangles):
    """What write_binary_stl writes reads back identically (float32) and is sized exactly."""
    target = tmp_path_factory.mktemp('stl') / 'out.stl'
    expected = np.array(triangles)
    write_binary_stl(target, expected)
    data = target.read_bytes()
    assert len(data) == mf.STL_HEADER_BYTES + 4 + 50 * len(expected)
    records = np.frombuffer(data, mf.STL_RECORD, offset=mf.STL_HEADER_BYTES + 4)
    np.testing.assert_array_equal(records['vertices'], expected.astype(np.float32))


def test_ascii_stl_reader_matches_the_binary_fixture():
    """The ASCII and binary fixtures describe the same triangles."""
    binary = np.frombuffer(mf.binary_stl_bytes(BOX_123), mf.STL_RECORD,
                           offset=mf.STL_HEADER_BYTES + 4)['vertices']
    np.testing.assert_allclose(read_ascii_stl(mf.ascii_stl_text(BOX_123).encode()), binary)


# --- read_collada: primitives beyond <triangles> ------------------------------

SQUARE_POSITIONS = '0 0 0  1 0 0  1 1 0  0 1 0'


def square_dae(primitive: str) -> bytes:
    """Return a Collada document whose only primitive is ``primitive`` (a unit square)."""
    return f'''<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
      <library_geometries><geometry id="g"><mesh>
        <source id="pos"><float_array id="pos-a" count="12">{SQUARE_POSITIONS}</float_array>
          <technique_common><accessor source="#pos-a" count="4" stride="3"/></technique_common>
        </source>
        <vertices id="v"><input semantic="POSITION" source="#pos"/></vertices>
        {primitive}
        <lines count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 2</p></lines>
      </mesh></geometry></library_geometries>
    </COLLADA>'''.encode()


VERTEX_INPUT = '<input semantic="VERTEX" source="#v" offset="0"/>'


@pytest.mark.parametrize('primitive', [
    f'<triangles count="2">{VERTEX_INPUT}<p>0 1 2 0 2 3</p></triangles>',
    f'<polylist count="1">{VERTEX_INPUT}<vcount>4</vcount><p>0 1 2 3</p></polylist>',
    f'<polygons count="1">{VERTEX_INPUT}<p>0 1 2 3</p></polygons>',
    f'<polygons count="1">{VERTEX_INPUT}<ph><p>0 1 2 3</p><h>0 1 2</h></ph></polygons>',
    f'<trifans count="1">{VERTEX_INPUT}<p>0 1 2 3</p></trifans>',
    f'<tristrips count="1">{VERTEX_INPUT}<p>1 2 0 3</p></tristrips>',
])
def test_collada_primitives_cover_the_square(primitive):
    """Every polygon primitive triangulates to the same square, lines ignored."""
    triangles = read_collada(square_dae(primitive))
    assert triangles.shape == (2, 3, 3)
    edges = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    # Both triangles face +z (consistent winding) and together cover the unit square.
    np.testing.assert_allclose(edges[:, 2], [1, 1])
    np.testing.assert_allclose(edges[:, :2], 0)


def test_collada_unit_is_applied_and_up_axis_ignored():
    """<unit meter> scales the file (as Gazebo); <up_axis> does not rotate it."""
    triangles = read_collada(mf.dae_text(BOX_123, unit_meter=0.0254, up_axis='Y_UP').encode())
    extent = triangles.reshape(-1, 3).max(axis=0) - triangles.reshape(-1, 3).min(axis=0)
    np.testing.assert_allclose(extent, np.array(BOX_123) * 0.0254)


def test_collada_nested_and_instanced_nodes_compose_transforms():
    """Nested nodes compose translate/scale/rotate; instance_node reuses a node."""
    document = mf.dae_text().replace(
        '<node id="box" name="box" type="NODE">',
        '<node id="outer"><translate>0 0 10</translate><scale>2 2 2</scale>'
        '<node id="box" name="box" type="NODE"><rotate>0 0 1 90</rotate>',
    ).replace('</node>', '</node></node><node id="again"><translate>100 0 0</translate>'
                         '<instance_node url="#box"/></node>')
    points = read_collada(document.encode()).reshape(-1, 3)
    first, second = points[: len(points) // 2], points[len(points) // 2:]
    np.testing.assert_allclose(first.mean(axis=0), [0, 0, 10], atol=1e-9)
    np.testing.assert_allclose(first.max(axis=0) - first.min(axis=0), [2, 2, 2], atol=1e-9)
    np.testing.assert_allclose(second.mean(axis=0), [100, 0, 0], atol=1e-9)


def test_collada_reference_cycle_is_an_error(tmp_path, cache_dir):
    """A node that instances itself is reported, not followed forever."""
    document = mf.dae_text().replace('<instance_geometry', '<instance_node url="#box"/>'
                                     '<instance_geometry')
    mf.write_file(tmp_path / 'cycle.dae', document)
    with pytest.raises(DescriptionError, match='a cycle'):
        localize_meshes(mesh_robot('cycle.dae', 'visual'), tmp_path, cache_dir)


# --- the my_robot example -----------------------------------------------------





def test_my_robot_urdf_loads_with_both_links_and_their_sizes(my_robot_share, tmp_path, cache_dir,
                                                              client, capfd):
    """The my_robot URDF with generated meshes loads: two links, right sizes, no warnings."""
    urdf = my_robot_share / mf.MY_ROBOT_URDF_RELPATH
    robot = ET.parse(urdf).getroot()
    done = localize_meshes(robot, urdf.parent, cache_dir)
    assert {(m.link, m.role, m.uri.rsplit('/', 1)[1]) for m in done} == {
        ('base_link', 'visual', 'base.dae'), ('base_link', 'collision', 'base.stl'),
        ('arm_link', 'visual', 'arm.dae'), ('arm_link', 'collision', 'arm.stl')}
    body = load(client, robot, tmp_path)
    assert pybullet.getNumJoints(body, physicsClientId=client) == 1
    joint = pybullet.getJointInfo(body, 0, physicsClientId=client)
    assert joint[1] == b'arm_joint'
    assert joint[12] == b'arm_link'
    np.testing.assert_allclose(collision_extent(client, body, -1), mf.MY_ROBOT_BASE_SIZE_M,
                               rtol=FLOAT32_TOLERANCE)
    np.testing.assert_allclose(collision_extent(client, body, 0), mf.MY_ROBOT_ARM_SIZE_M,
                               rtol=FLOAT32_TOLERANCE)
    visuals = {shape[1]: shape for shape in pybullet.getVisualShapeData(
        body, physicsClientId=client)}
    assert visuals[-1][3] == pytest.approx((MM, MM, MM))
    # The visual DAE holds millimetres; the URDF scale brings it to metres.
    converted = read_collada((my_robot_share / mf.MY_ROBOT_MESHES['base_visual']).read_bytes())
    extent = converted.reshape(-1, 3).max(axis=0) - converted.reshape(-1, 3).min(axis=0)
    np.testing.assert_allclose(extent * MM, mf.MY_ROBOT_BASE_SIZE_M)
    assert_quiet(capfd)


def test_my_robot_example_missing_visual_names_uri_and_resolved_path(my_robot_share, cache_dir):
    """A my_robot example mesh missing from the package gives the documented message."""
    missing = my_robot_share / mf.MY_ROBOT_MESHES['base_visual']
    missing.unlink()
    urdf = my_robot_share / mf.MY_ROBOT_URDF_RELPATH
    with pytest.raises(DescriptionError) as caught:
        localize_meshes(ET.parse(urdf).getroot(), urdf.parent, cache_dir)
    assert str(caught.value) == (
        "link 'base_link' visual: mesh 'package://my_robot_pkg/meshes/visual/base.dae' "
        f'(resolved to {missing}): file not found')


# --- xacro $(find PKG) ----------------------------------------------------





