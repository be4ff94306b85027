"""SDF world files: ground, models and includes, physics, plugins, and what is left out."""

from __future__ import annotations

import pathlib
import re

import pytest
from mesh_fixtures import obj_text
from sdf_fixtures import box_model_sdf, cylinders_world, model_folder, write

from pan_tilt_sim.model.sdf_world import WorldPhysics, is_sdf_world_path
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.model.world_file import (
    EMPTY,
    GROUND,
    WorldFileError,
    read_sdf_world_file,
    world_from_parameter,
)


def world_file(folder: pathlib.Path, text: str, name: str = 'world.sdf') -> pathlib.Path:
    return write(folder / name, text)


def read(folder: pathlib.Path, text: str, name: str = 'world.sdf'):
    return world_from_parameter(str(world_file(folder, text, name)))


def world(body: str, version: str = '1.9') -> str:
    return f'<sdf version="{version}"><world name="w">{body}</world></sdf>'


@pytest.mark.parametrize(('name', 'sdf'), [('a.sdf', True), ('a.world', True),
                                           ('a.sdf.xacro', True), ('a.yaml', False),
                                           ('a.urdf.xacro', False)])
def test_sdf_worlds_are_known_by_their_suffix(name, sdf):
    assert is_sdf_world_path(pathlib.Path(name)) is sdf


def test_the_ground_plane_and_the_cylinders_with_their_poses(tmp_path):
    loaded = read(tmp_path, cylinders_world([(2.0, 0.0, 0.3), (0.0, -1.5, 0.2)]))
    assert loaded.scenery == GROUND
    assert [entity.name for entity in loaded.entities] == ['pillar_0', 'pillar_1']
    first = loaded.entities[0]
    assert first.position == (2.0, 0.0, 0.5)
    model = parse_urdf(first.resource_string, pathlib.Path('x'))
    (collision,) = model.links[0].collisions
    assert (collision.geometry.kind, collision.geometry.radius) == ('cylinder', 0.3)
    assert '<static>true</static>' in first.resource_string
    assert loaded.warnings == ()


def test_a_world_without_a_ground_plane_has_none(tmp_path):
    assert read(tmp_path, cylinders_world([(1.0, 0.0, 0.2)], ground=False)).scenery == EMPTY


def test_physics_gives_the_step_the_factor_and_the_solver_iterations(tmp_path):
    body = ('<physics name="slow" type="ode"><max_step_size>0.01</max_step_size></physics>'
            '<physics name="3ms" type="ode" default="true"><max_step_size>0.003</max_step_size>'
            '<real_time_factor>2</real_time_factor><ode><solver><iters>80</iters></solver></ode>'
            '</physics>')
    assert read(tmp_path, world(body)).physics == WorldPhysics(0.003, 2.0, 80)
    assert read(tmp_path, world('')).physics == WorldPhysics()


ODE_PHYSICS = ('<physics name="1ms" type="ode"><max_step_size>0.001</max_step_size>'
               '<real_time_update_rate>1000</real_time_update_rate>'
               '<ode><solver><type>quick</type><iters>20</iters><sor>1.3</sor></solver>'
               '<constraints><cfm>0.00001</cfm><erp>0.5</erp>'
               '<contact_max_correcting_vel>100</contact_max_correcting_vel>'
               '<contact_surface_layer>0.001</contact_surface_layer></constraints></ode>'
               '</physics>')


def test_physics_gives_pybullets_counterparts_of_odes_constraints_and_names_the_rest(tmp_path):
    physics = read(tmp_path, world(ODE_PHYSICS)).physics
    assert (physics.solver_iterations, physics.erp, physics.cfm, physics.contact_slop,
            physics.split_impulse) == (20, 0.5, 1e-5, 0.001, None)
    # ODE's one ERP corrects joints and contacts alike: PyBullet's erp and contact_erp.
    assert physics.settings() == {'solver_iterations': 20, 'erp': 0.5, 'contact_erp': 0.5,
                                  'cfm': 1e-5, 'contact_slop': 0.001}
    assert physics.unmatched == ('<real_time_update_rate>', '<ode><solver><type>',
                                 '<ode><solver><sor>',
                                 '<ode><constraints><contact_max_correcting_vel>')


def test_a_bullet_physics_reads_its_own_section_and_split_impulse(tmp_path):
    body = ('<physics type="bullet"><bullet><solver><iters>15</iters></solver><constraints>'
            '<erp>0.3</erp><split_impulse>false</split_impulse>'
            '<split_impulse_penetration_threshold>-0.02</split_impulse_penetration_threshold>'
            '</constraints></bullet><ode><solver><iters>99</iters></solver></ode></physics>')
    physics = read(tmp_path, world(body)).physics
    assert physics.settings() == {'solver_iterations': 15, 'erp': 0.3, 'contact_erp': 0.3,
                                  'split_impulse': False}
    assert physics.unmatched == (
        '<bullet><constraints><split_impulse_penetration_threshold>',
        '<ode><solver><iters>')  # the engine is Bullet: the ODE section is not read


def test_an_engine_pybullet_has_no_counterpart_for_gives_only_step_and_factor(tmp_path):
    body = ('<physics type="dart"><max_step_size>0.002</max_step_size>'
            '<dart><solver><solver_type>pgs</solver_type></solver></dart></physics>')
    physics = read(tmp_path, world(body)).physics
    assert (physics.time_step, physics.settings()) == (0.002, {})
    assert physics.unmatched == ('<dart><solver><solver_type>',)


@pytest.mark.parametrize(('element', 'named'), [
    ('<constraints><erp>1.5</erp></constraints>',
     '<ode><constraints><erp> must be from 0 to 1 (a share of the error per step), got 1.5'),
    ('<constraints><cfm>-1</cfm></constraints>', '<ode/constraints/cfm>-1</...> must be'),
    ('<constraints><contact_surface_layer>x</contact_surface_layer></constraints>',
     '<ode/constraints/contact_surface_layer>x</...> must be'),
    ('<solver><iters>2.5</iters></solver>', '<ode><solver><iters> must be a whole number'),
])
def test_a_physics_value_pybullet_cannot_take_names_the_element(tmp_path, element, named):
    with pytest.raises(WorldFileError, match='<physics name="p">: ' + re.escape(named)):
        read(tmp_path, world(f'<physics name="p"><ode>{element}</ode></physics>'))


def test_known_systems_lights_and_scene_are_quiet_and_other_plugins_warn_once(tmp_path):
    body = ('<plugin filename="gz-sim-physics-system" name="gz::sim::systems::Physics"/>'
            '<plugin filename="gz-sim-user-commands-system" name="x"/>'
            '<plugin filename="gz-sim-scene-broadcaster-system" name="x"/>'
            '<plugin filename="ignition-gazebo-imu-system" name="x"/>'
            '<plugin filename="libgazebo_ros_state.so" name="state"/>'
            '<plugin filename="gz-sim-wind-effects-system" name="gz::sim::systems::WindEffects"/>'
            '<light name="sun" type="directional"/><scene/><gui/>')
    (warning,) = read(tmp_path, world(body)).warnings
    assert 'gz-sim-wind-effects-system' in warning and 'not simulated' in warning


def test_an_include_is_found_in_every_model_path_and_reads_the_newest_sdf(tmp_path, monkeypatch):
    sdf = box_model_sdf()
    model_folder(tmp_path / 'gz', 'crate', sdf, versions=(('1.5', 'old.sdf'),
                                                          ('1.10', 'new.sdf'),
                                                          ('1.6', 'middle.sdf')))
    model_folder(tmp_path / 'classic', 'barrel', sdf)
    share = tmp_path / 'prefix' / 'share' / 'my_worlds'
    model_folder(share / 'exported', 'cone', sdf)
    write(share / 'package.xml', '<package format="3"><name>my_worlds</name><export>'
          '<gazebo_ros gazebo_model_path="${prefix}/exported"/></export></package>')
    model_folder(tmp_path / 'prefix' / 'share' / 'other_pkg' / 'models', 'drum', sdf)
    monkeypatch.setenv('GZ_SIM_RESOURCE_PATH', str(tmp_path / 'gz'))
    monkeypatch.setenv('GAZEBO_MODEL_PATH', str(tmp_path / 'classic'))
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(tmp_path / 'prefix'))
    body = ''.join(f'<include><uri>model://{name}</uri><pose>{index} 0 0 0 0 0</pose></include>'
                   for index, name in enumerate(('crate', 'barrel', 'cone', 'drum')))
    loaded = read(tmp_path, world(body))
    assert [entity.name for entity in loaded.entities] == [
        'crate_new', 'barrel_model', 'cone_model', 'drum_model']
    assert [entity.position[0] for entity in loaded.entities] == [0.0, 1.0, 2.0, 3.0]


def test_an_include_takes_its_name_and_static_and_a_model_may_wrap_one(tmp_path, monkeypatch):
    model_folder(tmp_path / 'models', 'crate', box_model_sdf(static=False))
    monkeypatch.setenv('GZ_SIM_RESOURCE_PATH', str(tmp_path / 'models'))
    body = ('<include><uri>model://crate</uri><name>held</name><static>true</static></include>'
            '<model name="wrapper"><static>1</static><pose>5 0 0 0 0 0</pose>'
            '<include><uri>model://crate</uri></include></model>')
    held, wrapper = read(tmp_path, world(body)).entities
    assert held.name == 'held' and '<static>true</static>' in held.resource_string
    assert wrapper.name == 'wrapper' and wrapper.position == (5.0, 0.0, 0.0)
    assert 'crate_model::box' in wrapper.resource_string


def test_a_missing_model_is_one_warning_and_the_world_loads_without_it(tmp_path):
    body = ('<include><uri>model://no_such_model</uri></include>'
            '<model name="kept"><static>1</static><link name="l"><collision name="c">'
            '<geometry><box><size>1 1 1</size></box></geometry></collision></link></model>')
    loaded = read(tmp_path, world(body))
    assert [entity.name for entity in loaded.entities] == ['kept']
    (warning,) = loaded.warnings
    assert "model 'no_such_model' is in no model path" in warning and 'skipped' in warning


def test_a_fuel_uri_is_read_from_the_local_cache_or_named_where_it_belongs(tmp_path,
                                                                        monkeypatch):
    monkeypatch.setenv('GZ_FUEL_CACHE_PATH', str(tmp_path / 'fuel'))
    cached = tmp_path / 'fuel' / 'fuel.gazebosim.org' / 'openrobotics' / 'models' / 'crate'
    model_folder(cached, '3', box_model_sdf())
    model_folder(cached, '1', box_model_sdf())
    body = ('<include><uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/Crate</uri>'
            '</include><include><uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/Table'
            '</uri></include>')
    loaded = read(tmp_path, world(body))
    assert [entity.name for entity in loaded.entities] == ['3_model']  # the newest version
    (warning,) = loaded.warnings
    expected = tmp_path / 'fuel' / 'fuel.gazebosim.org' / 'openrobotics' / 'models' / 'table'
    assert f'put the model in {expected}' in warning


def test_a_static_mesh_collides_as_triangles_and_a_moving_one_as_a_hull_said_once(tmp_path):
    write(tmp_path / 'u.obj', obj_text())

    def mesh_model(name: str, static: str) -> str:
        return (f'<model name="{name}"><static>{static}</static><link name="l">'
                '<collision name="c"><geometry><mesh><uri>u.obj</uri></mesh></geometry>'
                '</collision></link></model>')

    loaded = read(tmp_path, world(mesh_model('wall', 'true') + mesh_model('toy', 'false')))
    wall, toy = loaded.entities
    assert 'concave="yes"' in wall.resource_string
    assert 'concave' not in toy.resource_string
    (warning,) = loaded.warnings
    assert '<model name="toy">' in warning and 'convex hulls' in warning


def test_an_sdf_xacro_world_is_expanded(tmp_path):
    text = world('<xacro:arg name="pillars" default="true"/><xacro:if value="$(arg pillars)">'
                 '<model name="p"><static>1</static><link name="l"><collision name="c">'
                 '<geometry><sphere><radius>1</radius></sphere></geometry></collision></link>'
                 '</model></xacro:if>').replace(
        '<sdf version="1.9">', '<sdf version="1.9" xmlns:xacro="http://www.ros.org/wiki/xacro">')
    assert [entity.name for entity in read(tmp_path, text, 'w.sdf.xacro').entities] == ['p']


@pytest.mark.parametrize(('text', 'message'), [
    ('<sdf version="1.9"><world name="w">', r'world\.sdf:1: not well-formed XML'),
    ('<sdf version="2.0"><world name="w"/></sdf>', r'SDFormat version 2\.0 is not supported'),
    ('<sdf version="1.9"><model name="m"/></sdf>', r'world\.sdf: <sdf>: has no <world>'),
    (world('<physics><max_step_size>-1</max_step_size></physics>'),
     r'world\.sdf: <physics name="">: <max_step_size>-1'),
])
def test_a_bad_world_file_ends_start_up_with_one_line(tmp_path, text, message):
    with pytest.raises(WorldFileError, match=message) as caught:
        read(tmp_path, text)
    assert '\n' not in str(caught.value)


def test_yaml_worlds_and_sceneries_still_work(tmp_path):
    assert world_from_parameter('ground').scenery == GROUND
    path = write(tmp_path / 'w.yaml', 'scenery: empty\nentities: []\n')
    assert world_from_parameter(str(path)).scenery == EMPTY


def test_fuels_ground_plane_and_sun_are_known_without_the_cache(tmp_path, monkeypatch):
    monkeypatch.setenv('GZ_FUEL_CACHE_PATH', str(tmp_path / 'empty_cache'))
    body = ('<include><uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/Ground Plane</uri>'
            '</include><include><uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/Sun'
            '</uri></include>')
    loaded = read(tmp_path, world(body))
    assert (loaded.scenery, loaded.entities, loaded.warnings) == (GROUND, (), ())


def test_an_sdf_world_past_the_object_limit_ends_start_up_naming_the_limit(tmp_path):
    path = world_file(tmp_path, cylinders_world([(1.0, 0.0, 0.2), (2.0, 0.0, 0.2),
                                                 (3.0, 0.0, 0.2)]))
    assert len(read_sdf_world_file(path, max_entities=3).entities) == 3
    with pytest.raises(WorldFileError, match='3 models; a world file may hold at most 2'):
        read_sdf_world_file(path, max_entities=2)
