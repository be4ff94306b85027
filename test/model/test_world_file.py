"""The world parameter: a scenery name, or a YAML world file whose problems name the field."""

from __future__ import annotations

import math
import re
import textwrap

import pytest

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.world_file import (
    MAX_WORLD_ENTITIES,
    SCENERIES,
    EntitySpec,
    WorldFileError,
    read_world_file,
    world_from_parameter,
)


def _world(tmp_path, text: str):
    path = tmp_path / 'world.yaml'
    path.write_text(textwrap.dedent(text))
    return path


@pytest.mark.parametrize('name', SCENERIES)
def test_a_scenery_name_is_a_world_without_objects(name):
    world = world_from_parameter(name)
    assert (world.scenery, world.entities, world.source) == (name, (), None)


def test_a_world_file_lists_objects_with_poses_tags_and_descriptions(tmp_path):
    path = _world(tmp_path, """\
        scenery: targets
        entities:
          - name: box
            uri: box.urdf
            pose: {position: [1, 2, 3], orientation: [0, 0, 2, 0]}
            description: a box
            tags: [a, b]
          - resource_string: <robot name="r"/>
            pose: {rpy: [0, 0, 1.0]}
        """)
    world = world_from_parameter(str(path))
    assert world.scenery == 'targets'
    assert world.source == path
    assert world.base_dir == tmp_path
    box, inline = world.entities
    assert box == EntitySpec(name='box', uri='box.urdf', position=(1.0, 2.0, 3.0),
                             orientation=(0.0, 0.0, 1.0, 0.0), description='a box',
                             tags=('a', 'b'))
    assert inline.resource_string == '<robot name="r"/>'
    assert inline.position == (0.0, 0.0, 0.0)
    assert inline.orientation == pytest.approx((0.0, 0.0, math.sin(0.5), math.cos(0.5)))


def test_a_world_file_by_file_uri_and_its_default_scenery(tmp_path):
    path = _world(tmp_path, 'entities: []\n')
    world = world_from_parameter(path.as_uri())
    assert world.scenery == 'ground'
    assert world.entities == ()


@pytest.mark.parametrize('text, message', [
    ('scenery: moon\n', r"scenery: must be one of empty, ground, targets, got 'moon'"),
    ('entities: {a: 1}\n', 'entities: must be a list, got a mapping'),
    ('entities: [3]\n', r'entities\[0\]: must be a mapping, got a number'),
    ('entities: [{name: a}]\n', r'entities\[0\]: give a uri, a resource_string or a shape'),
    ('entities: [{uri: a, texture: red}]\n', r"entities\[0\]: unknown key 'texture'"),
    ('entities: [{uri: a, colour: [1, 0, 0]}]\n',
     r"entities\[0\].colour: only a shape takes it \(no 'shape' given\)"),
    ('entities: [{uri: a, shape: box, size: [1, 1, 1]}]\n',
     r'entities\[0\]: give a shape, a uri or a resource_string, only one'),
    ('entities: [{shape: cone, size: [1]}]\n',
     r"entities\[0\].shape: must be one of box, cylinder, sphere, got 'cone'"),
    ('entities: [{shape: box}]\n', r'entities\[0\].size: a box needs its size \[x, y, z\]'),
    ('entities: [{shape: cylinder, size: [1]}]\n',
     r'entities\[0\].size: must be 2 finite numbers'),
    ('entities: [{shape: sphere, size: [0]}]\n',
     r'entities\[0\].size: \[radius\] must all be > 0'),
    ('entities: [{shape: sphere, size: [1], colour: [2, 0, 0]}]\n',
     r'entities\[0\].colour: each of r, g, b, a must be in 0..1'),
    ('entities: [{shape: sphere, size: [1], static: maybe}]\n',
     r'entities\[0\].static: must be true or false'),
    ('entities: [{shape: sphere, size: [1], static: false, mass: 0}]\n',
     r'entities\[0\].mass: must be a number > 0'),
    ('entities: [{uri: a, name: 3}]\n', r'entities\[0\].name: must be a string'),
    ('entities: [{uri: a, pose: {position: [1, 2]}}]\n',
     r'entities\[0\].pose.position: must be 3 finite numbers'),
    ('entities: [{uri: a, pose: {position: [1, 2, .nan]}}]\n',
     r'entities\[0\].pose.position: must be 3 finite numbers'),
    ('entities: [{uri: a, pose: {orientation: [0, 0, 0, 0]}}]\n',
     r'entities\[0\].pose.orientation: a quaternion of length 0'),
    ('entities: [{uri: a, pose: {rpy: [0, 0, 0], orientation: [0, 0, 0, 1]}}]\n',
     r'entities\[0\].pose: give orientation or rpy, not both'),
    ('entities: [{uri: a, tags: a}]\n', r'entities\[0\].tags: must be a list of strings'),
    ('entities: [{uri: a, name: x}, {uri: b, name: x}]\n', "the name 'x' is used twice"),
    ('entities: [\n', r'world.yaml:\d+: YAML syntax error'),
    ('other: 1\n', "the file: unknown key 'other'"),
    ('a: &a [*a]\n', 'world.yaml:1: an alias refers to the node that holds it'),
    ('[' * 500 + ']' * 500 + '\n', 'world.yaml:1: nested deeper than 64 levels'),
    ('a0: &a0 [x, x, x, x, x, x, x, x, x]\n' + ''.join(
        f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]\n" for i in range(1, 10)),
     'its aliases expand it to more than'),
], ids=lambda value: value[:40] if isinstance(value, str) else None)
def test_every_problem_names_the_file_and_the_field(tmp_path, text, message):
    path = _world(tmp_path, text)
    with pytest.raises(WorldFileError, match=message) as error:
        read_world_file(path)
    assert str(error.value).startswith(str(path))
    assert '\n' not in str(error.value)


def test_neither_a_scenery_nor_a_file_lists_the_choices(tmp_path):
    with pytest.raises(ParameterError, match=r"'moon' is none of empty, ground, targets, "
                                             r'and no world file \(.*moon: no such file\)'):
        world_from_parameter('moon')
    with pytest.raises(ParameterError, match="parameter 'world': .*no_such_package"):
        world_from_parameter('package://no_such_package/world.yaml')
    with pytest.raises(ParameterError, match="parameter 'world' must be one of"):
        world_from_parameter('')


def test_a_huge_quaternion_is_normalised_not_zeroed(tmp_path):
    world = read_world_file(_world(
        tmp_path, 'entities: [{uri: a, pose: {orientation: [0, 0, 1.0e+300, 1.0e+300]}}]\n'))
    assert world.entities[0].orientation == pytest.approx((0.0, 0.0, 0.5 ** 0.5, 0.5 ** 0.5))


@pytest.mark.parametrize('device', ['/dev/null', '/dev/zero'])
def test_a_device_given_as_the_world_is_not_a_regular_file(device):
    with pytest.raises(WorldFileError, match=f'{device}: not a regular file'):
        world_from_parameter(device)


def test_the_shipped_world_file_reads(repo_root):
    world = read_world_file(repo_root / 'config' / 'worlds' / 'tabletop.yaml')
    assert [entity.name for entity in world.entities] == ['table', 'box', 'can']


def test_a_shape_becomes_a_one_link_urdf_of_its_size_colour_and_staticness(tmp_path):
    world = read_world_file(_world(tmp_path, """\
        entities:
          - name: wall
            shape: box
            size: [0.1, 4, 0.5]
            colour: [1, 0, 0]
            pose: {position: [2, 0, 0.25]}
          - shape: sphere
            size: [0.2]
            static: false
            mass: 2
        """))
    wall, ball = world.entities
    assert wall.name == 'wall' and wall.position == (2.0, 0.0, 0.25)
    assert '<box size="0.1 4.0 0.5"/>' in wall.resource_string
    assert '<color rgba="1.0 0.0 0.0 1.0"/>' in wall.resource_string
    assert '<static>true</static>' in wall.resource_string
    assert '<robot name="sphere_1">' in ball.resource_string
    assert '<static>' not in ball.resource_string
    assert '<mass value="2.0"/>' in ball.resource_string
    ixx = float(re.search(r'ixx="([^"]+)"', ball.resource_string).group(1))
    assert ixx == pytest.approx(2 / 5 * 2.0 * 0.2 ** 2)


def test_the_shipped_room_reads(repo_root):
    world = read_world_file(repo_root / 'config' / 'worlds' / 'room.yaml')
    assert [entity.name for entity in world.entities] == [
        'wall_east', 'wall_west', 'wall_north', 'wall_south', 'crate', 'pillar', 'ball']


def _boxes(count: int, named: bool = False) -> str:
    return 'entities:\n' + ''.join(
        f"  - {{{f'name: b{index}, ' if named else ''}shape: box, size: [0.1, 0.1, 0.1], "
        f"pose: {{position: [{index}, 0, 0.05]}}}}\n" for index in range(count))


def test_a_world_file_of_more_objects_than_the_limit_is_refused_naming_file_and_limit(tmp_path):
    path = _world(tmp_path, _boxes(MAX_WORLD_ENTITIES + 1))
    with pytest.raises(WorldFileError) as error:
        read_world_file(path)
    message = str(error.value)
    assert message.startswith(f'{path}: entities: {MAX_WORLD_ENTITIES + 1} objects')
    assert f'at most {MAX_WORLD_ENTITIES}' in message
    assert '\n' not in message


def test_a_world_file_at_the_limit_reads_and_the_limit_can_be_given(tmp_path):
    assert len(read_world_file(_world(tmp_path, _boxes(3)), max_entities=3).entities) == 3
    with pytest.raises(WorldFileError, match='at most 2 '):
        read_world_file(_world(tmp_path, _boxes(3)), max_entities=2)


def test_names_used_twice_are_found_among_many(tmp_path):
    text = _boxes(MAX_WORLD_ENTITIES - 1, named=True) + (
        '  - {name: b0, shape: sphere, size: [0.1]}\n')
    with pytest.raises(WorldFileError, match="the name 'b0' is used twice"):
        read_world_file(_world(tmp_path, text))
