"""A URDF to spawn, from a URI or a string: read once, failures sorted into the standard's codes."""

from __future__ import annotations

import pytest
from entity_fixtures import box_urdf, chain_urdf, write_box

from pan_tilt_sim.model.entity_resource import (
    MAX_ENTITY_BYTES,
    MAX_ENTITY_JOINTS,
    MAX_ENTITY_LINKS,
    EntityLimits,
    EntityResourceError,
    ResourceProblem,
    is_static,
    read_entity_resource,
)


def _problem(**kwargs) -> ResourceProblem:
    with pytest.raises(EntityResourceError) as error:
        read_entity_resource(**kwargs)
    assert '\n' not in str(error.value)
    return error.value.problem


def test_a_string_and_a_file_give_the_same_model(tmp_path):
    path = write_box(tmp_path, name='crate')
    from_file = read_entity_resource(uri=str(path))
    from_uri = read_entity_resource(uri=path.as_uri())
    from_string = read_entity_resource(resource_string=box_urdf(name='crate'))
    assert from_file.model == from_uri.model == from_string.model
    assert from_file.name == 'crate'
    assert from_file.source == path
    assert not from_file.model.actuated_joints  # an object need not move


def test_the_uri_wins_over_the_resource_string(tmp_path):
    path = write_box(tmp_path, name='from_file')
    assert read_entity_resource(uri=str(path), resource_string=box_urdf(name='s')).name == (
        'from_file')


def test_a_xacro_file_is_expanded(tmp_path):
    path = tmp_path / 'thing.urdf.xacro'
    path.write_text('<robot name="thing" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                    '<xacro:property name="s" value="0.3"/><link name="a"><collision>'
                    '<geometry><box size="${s} ${s} ${s}"/></geometry></collision></link></robot>')
    description = read_entity_resource(uri=str(path))
    assert description.model.link('a').collisions[0].geometry.size == (0.3, 0.3, 0.3)


def test_meshes_are_made_loadable_relative_to_the_file(tmp_path, repo_root):
    meshes = tmp_path / 'meshes'
    meshes.mkdir()
    # A one-triangle binary STL (84 + 50 bytes).
    import struct
    data = b'\0' * 80 + struct.pack('<I', 1) + struct.pack('<12fH', *([0.0] * 3),
                                                             0, 0, 0, 1, 0, 0, 0, 1, 0, 0)
    (meshes / 'tri.stl').write_bytes(data)
    path = tmp_path / 'm.urdf'
    path.write_text(box_urdf(mesh='meshes/tri.stl'))
    description = read_entity_resource(uri=str(path))
    assert str(meshes / 'tri.stl') in description.physics_urdf


def test_each_failure_has_its_problem(tmp_path):
    usd = tmp_path / 'model.usd'
    usd.write_text('#usda 1.0')
    garbage = tmp_path / 'garbage.stl'
    garbage.write_bytes(b'not a mesh')
    assert _problem() is ResourceProblem.NOT_FOUND
    assert _problem(uri=str(tmp_path / 'missing.urdf')) is ResourceProblem.NOT_FOUND
    assert _problem(uri='package://no_such_package/x.urdf') is ResourceProblem.NOT_FOUND
    assert _problem(uri='http://example.com/x.urdf') is ResourceProblem.NOT_FOUND
    assert _problem(uri=str(usd)) is ResourceProblem.UNSUPPORTED_FORMAT
    assert _problem(resource_string='<mujoco model="m"/>') is ResourceProblem.UNSUPPORTED_FORMAT
    assert _problem(resource_string='<sdf version="1.3"><model name="m"/></sdf>') is (
        ResourceProblem.PARSE_ERROR)
    assert _problem(resource_string='<sdf version="1.9"><model name="m"><link name="l">'
                    '<collision name="c"><geometry><mesh><uri>model://gone/m.stl</uri></mesh>'
                    '</geometry></collision></link></model></sdf>') is (
        ResourceProblem.MISSING_ASSETS)
    assert _problem(resource_string='<robot name="x"><link') is ResourceProblem.PARSE_ERROR
    assert _problem(resource_string='<robot><link name="a"/></robot>') is (
        ResourceProblem.PARSE_ERROR)  # no name
    assert _problem(resource_string='<robot name="x"/>') is ResourceProblem.PARSE_ERROR
    assert _problem(resource_string=box_urdf(mesh=str(tmp_path / 'gone.stl'))) is (
        ResourceProblem.MISSING_ASSETS)
    assert _problem(resource_string=box_urdf(mesh='package://no_such_package/m.stl')) is (
        ResourceProblem.MISSING_ASSETS)
    assert _problem(resource_string=box_urdf(mesh=str(garbage))) is (
        ResourceProblem.UNSUPPORTED_ASSETS)


def test_gazebo_static_marks_an_object_fixed():
    assert is_static(read_entity_resource(resource_string=box_urdf(static=True)))
    assert not is_static(read_entity_resource(resource_string=box_urdf()))


def test_an_sdf_model_is_spawned_as_the_urdf_it_becomes(tmp_path):
    path = tmp_path / 'crate.sdf'
    path.write_text('<sdf version="1.9"><model name="crate"><static>true</static>'
                    '<link name="box"><collision name="c"><geometry><box><size>1 1 1</size>'
                    '</box></geometry></collision></link></model></sdf>')
    for description in (read_entity_resource(uri=str(path)),
                        read_entity_resource(resource_string=path.read_text())):
        assert description.model.name == 'crate'
        assert description.model.links[0].collisions[0].geometry.size == (1.0, 1.0, 1.0)
        assert is_static(description)


# --- limits: what one object may be --------------------------------------------------------

def _refusal(**kwargs) -> str:
    with pytest.raises(EntityResourceError) as error:
        read_entity_resource(**kwargs)
    assert error.value.problem is ResourceProblem.TOO_LARGE
    assert '\n' not in str(error.value)
    return str(error.value)


def test_an_object_at_the_limits_is_read():
    at_limit = read_entity_resource(resource_string=chain_urdf(MAX_ENTITY_JOINTS))
    assert len(at_limit.model.actuated_joints) == MAX_ENTITY_JOINTS
    assert len(at_limit.model.links) == MAX_ENTITY_LINKS


@pytest.mark.parametrize('joint_type', ['revolute', 'fixed'])
def test_one_link_past_the_limit_is_refused_naming_it(joint_type):
    message = _refusal(resource_string=chain_urdf(MAX_ENTITY_LINKS, joint_type))
    assert f'{MAX_ENTITY_LINKS + 1} links' in message
    assert f'at most {MAX_ENTITY_LINKS}' in message


def test_text_past_the_byte_limit_is_refused_before_it_is_parsed(tmp_path):
    padding = ' ' * MAX_ENTITY_BYTES  # well-formed: a box and blank space
    message = _refusal(resource_string=box_urdf() + padding)
    assert f'at most {MAX_ENTITY_BYTES} bytes' in message
    path = tmp_path / 'big.urdf'
    path.write_text(box_urdf() + padding)
    assert f'at most {MAX_ENTITY_BYTES} bytes' in _refusal(uri=str(path))
    assert str(path) in _refusal(uri=str(path))


def test_the_limits_can_be_given():
    small = EntityLimits(max_bytes=10_000, max_links=3, max_joints=2)
    assert read_entity_resource(resource_string=chain_urdf(2), limits=small).name == 'chain'
    assert '4 links' in _refusal(resource_string=chain_urdf(3, 'fixed'), limits=small)
    joints = EntityLimits(max_links=10, max_joints=1)
    assert '2 joints: an object to spawn may have at most 1' in _refusal(
        resource_string=chain_urdf(2), limits=joints)
    assert 'at most 10000 bytes' in _refusal(resource_string=chain_urdf(30), limits=small)
