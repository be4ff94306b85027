"""SDF robots read into the robot model the URDF path fills: frames, shapes, joints, sensors."""

from __future__ import annotations

import math
import pathlib

import pytest
from mesh_fixtures import obj_text
from sdf_fixtures import (
    CASTER_X,
    CHASSIS_HEIGHT,
    LIDAR_HEIGHT,
    WHEEL_RADIUS,
    WHEEL_SEPARATION,
    box_model_sdf,
    model_folder,
    rover_sdf,
    write,
)

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.description import description_from_text, load_description
from pan_tilt_sim.model.robot import JointKind
from pan_tilt_sim.model.sdf import is_sdf_text, sdf_robot_to_urdf
from pan_tilt_sim.model.sensors import SensorKind
from pan_tilt_sim.model.transforms import rotate
from pan_tilt_sim.plugins.gazebo_classic.diff_drive import GazeboDiffDrive
from pan_tilt_sim.plugins.gazebo_classic.joint_state_publisher import GazeboJointStatePublisher
from pan_tilt_sim.plugins.gz.diff_drive import GzDiffDrive
from pan_tilt_sim.plugins.registry import read_settings

SOURCE = pathlib.Path('robot.sdf')


def model_of(text: str, base: pathlib.Path | None = None):
    return description_from_text(text, str(SOURCE), base or pathlib.Path.cwd()).model


def world_position(model, link: str, point=(0.0, 0.0, 0.0), positions=None):
    """Where ``point`` of ``link``'s URDF frame is in the model frame."""
    return model.link_poses(positions or {})[link].apply(point)


def shape_centre(model, link: str, role: str = 'collisions', index: int = 0):
    found = next(item for item in model.links if item.name == link)
    shape = getattr(found, role)[index]
    return world_position(model, link, shape.origin.translation), shape


def sdf(body: str, version: str = '1.9', name: str = 'thing') -> str:
    return f'<sdf version="{version}"><model name="{name}">{body}</model></sdf>'


def link(name: str, body: str = '', pose: str = '') -> str:
    pose_element = f'<pose>{pose}</pose>' if pose else ''
    return (f'<link name="{name}">{pose_element}<inertial><mass>1</mass><inertia><ixx>0.01'
            f'</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>{body}</link>')


def joint(name: str, parent: str, child: str, kind: str = 'revolute', body: str = '') -> str:
    return (f'<joint name="{name}" type="{kind}"><parent>{parent}</parent><child>{child}'
            f'</child>{body}</joint>')


# --- recognising SDF ------------------------------------------------------------------------

def test_an_sdf_is_known_by_its_root_element_after_declaration_and_comments():
    assert is_sdf_text('<?xml version="1.0"?>\n<!-- a robot -->\n<sdf version="1.6"/>')
    assert not is_sdf_text('<?xml version="1.0"?><robot name="r"/>')
    assert not is_sdf_text('<!-- <sdf> --><robot name="r"/>')


def test_the_robot_is_named_after_the_model_and_rooted_at_the_link_no_joint_moves():
    model = model_of(rover_sdf())
    assert model.name == 'sdf_rover'
    assert model.root == 'chassis'


# --- frames ---------------------------------------------------------------------------------

def test_a_joint_away_from_its_child_link_origin_turns_the_wheel_about_its_own_axle():
    model = model_of(rover_sdf())
    wheel = model.joint('left_wheel_joint')
    assert wheel.kind is JointKind.CONTINUOUS  # revolute without limits
    assert wheel.axis == pytest.approx((0.0, 1.0, 0.0), abs=1e-9)
    # The axle passes through the wheel's centre: the tyre stays where it is as it turns.
    for angle in (0.0, 1.0, 2.5):
        centre, _shape = shape_centre(model, 'left_wheel')
        moved = model.link_poses({'left_wheel_joint': angle})['left_wheel'].apply(
            next(item for item in model.links if item.name == 'left_wheel')
            .collisions[0].origin.translation)
        assert moved == pytest.approx((0.0, WHEEL_SEPARATION / 2, WHEEL_RADIUS), abs=1e-9)
        assert centre == pytest.approx(moved, abs=1e-9)


def test_link_poses_are_model_relative_and_pose_relative_to_names_another_frame():
    model = model_of(rover_sdf())
    centre, _shape = shape_centre(model, 'chassis')
    assert centre == pytest.approx((0.0, 0.0, CHASSIS_HEIGHT))
    # The lidar link is 0.18 m above the chassis frame, its sensor 0.02 m above the link.
    (lidar,) = [sensor for sensor in model.sensors if sensor.kind is SensorKind.LIDAR]
    assert lidar.link == 'lidar'
    assert world_position(model, 'lidar', lidar.pose.translation) == pytest.approx(
        (0.0, 0.0, LIDAR_HEIGHT))
    caster, _shape = shape_centre(model, 'caster')
    assert caster == pytest.approx((CASTER_X, 0.0, 0.025))


def test_a_frame_element_and_a_joint_pose_relative_to_it():
    text = sdf(link('base') + '<frame name="mount" attached_to="base"><pose>0.5 0 0 0 0 '
               f'{math.pi / 2}</pose></frame>'
               + link('arm', '<collision name="c"><pose relative_to="mount">0.1 0 0 0 0 0'
                      '</pose><geometry><box><size>0.1 0.1 0.1</size></box></geometry>'
                      '</collision>', pose='0 0 0 0 0 0')
               + joint('j', 'base', 'arm', body='<pose relative_to="mount"/><axis>'
                       '<xyz expressed_in="mount">1 0 0</xyz></axis>'))
    model = model_of(text)
    j = model.joint('j')
    assert model.link_poses({})['arm'].translation == pytest.approx((0.5, 0.0, 0.0))
    # The mount is turned 90 degrees about z: its x is the model's y.
    assert rotate(model.link_poses({})['arm'].rotation, j.axis) == pytest.approx(
        (0.0, 1.0, 0.0), abs=1e-9)
    centre, _shape = shape_centre(model, 'arm')
    assert centre == pytest.approx((0.5, 0.1, 0.0), abs=1e-9)


@pytest.mark.parametrize(('version', 'axis'), [
    ('1.4', '<xyz>0 1 0</xyz>'),  # 1.4: axes in the model frame
    ('1.6', '<xyz>0 0 1</xyz>'),  # 1.5/1.6: in the joint frame ...
    ('1.6', '<xyz>0 1 0</xyz><use_parent_model_frame>1</use_parent_model_frame>'),  # ... or not
    ('1.9', '<xyz>0 0 1</xyz>'),  # 1.7+: in the joint frame ...
    ('1.9', '<xyz expressed_in="__model__">0 1 0</xyz>'),  # ... unless expressed_in says
])
def test_each_version_expresses_the_axis_where_it_says(version, axis):
    # The joint frame is turned -90 degrees about x: its z is the model's y.
    body = (link('base') + link('wheel')
            + joint('j', 'base', 'wheel', body='<pose>0 0 0 -1.5707963267948966 0 0</pose>'
                    f'<axis>{axis}</axis>'))
    model = model_of(sdf(body, version))
    in_model = rotate(model.link_poses({})['wheel'].rotation, model.joint('j').axis)
    assert in_model == pytest.approx((0.0, 1.0, 0.0), abs=1e-9)


def test_the_inertial_keeps_its_pose_and_a_link_without_one_weighs_sdformats_1_kg():
    text = sdf('<link name="base"/>' + link('arm', pose='1 0 0 0 0 0').replace(
        '<mass>1</mass>', '<pose>0.2 0 0 0 0 0</pose><mass>2</mass>')
        + joint('j', 'base', 'arm'))
    model = model_of(text)
    base = next(item for item in model.links if item.name == 'base')
    assert base.inertial.mass == 1.0 and base.inertial.ixx == 1.0
    arm = next(item for item in model.links if item.name == 'arm')
    assert arm.inertial.mass == 2.0
    assert world_position(model, 'arm', arm.inertial.origin.translation) == pytest.approx(
        (1.2, 0.0, 0.0))


# --- shapes ---------------------------------------------------------------------------------

def test_every_geometry_becomes_a_shape(tmp_path):
    write(tmp_path / 'meshes' / 'cube.obj', obj_text())
    shapes = ''.join(f'<collision name="{tag}"><geometry>{geometry}</geometry></collision>'
                     for tag, geometry in [
                         ('box', '<box><size>1 2 3</size></box>'),
                         ('cylinder', '<cylinder><radius>0.5</radius><length>2</length>'
                                      '</cylinder>'),
                         ('sphere', '<sphere><radius>0.25</radius></sphere>'),
                         ('capsule', '<capsule><radius>0.1</radius><length>0.4</length>'
                                     '</capsule>'),
                         ('ellipsoid', '<ellipsoid><radii>0.1 0.2 0.3</radii></ellipsoid>'),
                         ('plane', '<plane><normal>0 0 1</normal><size>4 5</size></plane>'),
                         ('mesh', '<mesh><uri>meshes/cube.obj</uri><scale>2 2 2</scale></mesh>'),
                     ])
    model = model_of(sdf(link('base', shapes) + link('moving') + joint('j', 'base', 'moving')),
                     tmp_path)
    base = next(item for item in model.links if item.name == 'base')
    kinds = [shape.geometry for shape in base.collisions]
    assert [geometry.kind for geometry in kinds] == [
        'box', 'cylinder', 'sphere', 'capsule', 'mesh', 'box', 'mesh']
    box, cylinder, sphere, capsule, ellipsoid, plane, mesh = kinds
    assert box.size == (1.0, 2.0, 3.0)
    assert (cylinder.radius, cylinder.length) == (0.5, 2.0)
    assert sphere.radius == 0.25 and (capsule.radius, capsule.length) == (0.1, 0.4)
    assert ellipsoid.filename.endswith('.obj')
    assert plane.size == pytest.approx((4.0, 5.0, 0.01))
    # The plane is the slab's top face: its centre half a thickness below.
    assert base.collisions[5].origin.translation == pytest.approx((0.0, 0.0, -0.005))
    assert mesh.filename == str(tmp_path / 'meshes' / 'cube.obj') and mesh.scale == (2, 2, 2)


def test_a_visual_takes_its_diffuse_colour_and_a_material_script_is_ignored():
    model = model_of(rover_sdf())
    wheel = next(item for item in model.links if item.name == 'left_wheel')
    assert wheel.visuals[0].rgba == (0.1, 0.1, 0.1, 1.0)
    chassis = next(item for item in model.links if item.name == 'chassis')
    assert chassis.visuals[0].rgba is None


def test_mesh_uris_of_every_scheme_resolve(tmp_path, monkeypatch):
    models = tmp_path / 'models'
    write(models / 'parts' / 'meshes' / 'a.obj', obj_text())
    write(tmp_path / 'abs.obj', obj_text())
    monkeypatch.setenv('GZ_SIM_RESOURCE_PATH', str(models))
    shapes = ''.join(f'<collision name="c{index}"><geometry><mesh><uri>{uri}</uri></mesh>'
                     '</geometry></collision>' for index, uri in enumerate([
                         'model://parts/meshes/a.obj', f'file://{tmp_path}/abs.obj',
                         '../abs.obj']))
    model = model_of(sdf(link('base', shapes) + link('b') + joint('j', 'base', 'b')),
                     tmp_path / 'urdf')
    base = next(item for item in model.links if item.name == 'base')
    assert [shape.geometry.filename for shape in base.collisions] == [
        str(models / 'parts' / 'meshes' / 'a.obj'), str(tmp_path / 'abs.obj'),
        str(tmp_path / 'abs.obj')]


def test_a_missing_visual_mesh_is_a_warning_and_a_missing_collision_mesh_an_error(tmp_path):
    visual = '<visual name="v"><geometry><mesh><uri>model://nowhere/m.dae</uri></mesh>' \
             '</geometry></visual>'
    description = description_from_text(
        sdf(link('base', visual) + link('b') + joint('j', 'base', 'b')), str(SOURCE), tmp_path)
    base = next(item for item in description.model.links if item.name == 'base')
    assert base.visuals == ()
    (warning,) = [line for line in description.warnings if 'nowhere' in line]
    assert '<visual name="v">' in warning and 'left out' in warning
    collision = visual.replace('visual', 'collision')
    with pytest.raises(DescriptionError, match=r"robot\.sdf: <link name=\"base\">: "
                       r"<collision name=\"v\">: <mesh><uri>model://nowhere/m\.dae</uri>: "
                       r"model 'nowhere' is in no model path"):
        model_of(sdf(link('base', collision) + link('b') + joint('j', 'base', 'b')), tmp_path)


# --- joints ---------------------------------------------------------------------------------

def test_joint_types_limits_and_dynamics():
    axis = ('<axis><xyz>1 0 0</xyz><limit><lower>-0.5</lower><upper>1.5</upper>'
            '<effort>7</effort><velocity>2</velocity></limit>'
            '<dynamics><damping>0.3</damping><friction>0.1</friction></dynamics></axis>')
    body = (link('base') + ''.join(link(name) for name in ('r', 'c', 'p', 'f', 'b'))
            + joint('revolute', 'base', 'r', body=axis)
            + joint('continuous', 'base', 'c', 'continuous', '<axis><xyz>0 1 0</xyz></axis>')
            + joint('prismatic', 'base', 'p', 'prismatic', axis)
            + joint('fixed', 'base', 'f', 'fixed') + joint('ball', 'base', 'b', 'ball'))
    model = model_of(sdf(body))
    revolute = model.joint('revolute')
    assert revolute.kind is JointKind.REVOLUTE
    assert (revolute.lower, revolute.upper) == (-0.5, 1.5)
    assert (revolute.effort_limit, revolute.velocity_limit) == (7.0, 2.0)
    assert (revolute.damping, revolute.friction) == (0.3, 0.1)
    assert model.joint('continuous').kind is JointKind.CONTINUOUS
    assert model.joint('prismatic').kind is JointKind.PRISMATIC
    assert model.joint('fixed').kind is JointKind.FIXED
    assert model.joint('ball').kind is JointKind.SPHERICAL
    assert not JointKind.SPHERICAL.is_actuated


def test_a_ball_joint_is_published_fixed_for_robot_state_publisher():
    description = description_from_text(rover_sdf(), str(SOURCE))
    assert 'type="spherical"' in description.physics_urdf
    assert 'spherical' not in description.urdf_xml
    assert 'name="caster_joint" type="fixed"' in description.urdf_xml


def test_friction_of_the_collisions_becomes_the_links_surface():
    model = model_of(rover_sdf())
    surfaces = {surface.link: surface for surface in model.surfaces}
    assert (surfaces['caster'].mu1, surfaces['caster'].mu2) == (0.1, 0.1)
    assert surfaces['left_wheel'].friction == 1.0


# --- sensors and plugins --------------------------------------------------------------------

def test_sensors_keep_their_kind_topic_and_frame():
    model = model_of(rover_sdf())
    by_kind = {sensor.kind: sensor for sensor in model.sensors}
    lidar = by_kind[SensorKind.LIDAR]
    assert (lidar.type, lidar.topic, lidar.frame_id) == ('gpu_lidar', 'scan', 'lidar')
    assert lidar.ray.horizontal.samples == 360 and lidar.ray.range_max == 10.0
    imu = by_kind[SensorKind.IMU]
    assert (imu.link, imu.topic, imu.frame_id, imu.update_rate) == ('chassis', 'imu',
                                                                    'chassis', 100.0)
    assert model.sensor_warnings == ()


def test_camera_depth_and_force_torque_sensors():
    camera = ('<sensor name="cam" type="camera"><pose>0.1 0 0 0 0 0</pose><topic>image</topic>'
              '<camera><horizontal_fov>1.0</horizontal_fov><image><width>64</width><height>48'
              '</height></image><clip><near>0.1</near><far>10</far></clip></camera></sensor>'
              '<sensor name="depth" type="depth"><camera><image><width>32</width><height>24'
              '</height></image></camera></sensor>')
    ft = ('<sensor name="ft" type="force_torque"><topic>wrench</topic><force_torque>'
          '<frame>child</frame></force_torque></sensor>')
    body = (link('base', camera) + link('arm')
            + joint('j', 'base', 'arm', 'revolute', '<axis><xyz>0 0 1</xyz></axis>' + ft))
    model = model_of(sdf(body))
    by_name = {sensor.name: sensor for sensor in model.sensors}
    assert by_name['cam'].kind is SensorKind.CAMERA and by_name['cam'].camera.width == 64
    assert by_name['cam'].pose.translation == pytest.approx((0.1, 0.0, 0.0))
    assert by_name['depth'].kind is SensorKind.DEPTH
    assert (by_name['ft'].kind, by_name['ft'].joint) == (SensorKind.FORCE_TORQUE, 'j')


def test_gz_sim_systems_and_classic_plugins_are_read():
    model = model_of(rover_sdf())
    (drive,) = read_settings(model, GzDiffDrive)
    assert drive.left_joints == ('left_wheel_joint',)
    assert drive.wheel_separation == WHEEL_SEPARATION
    assert read_settings(model, GazeboJointStatePublisher)
    classic = ('<plugin name="drive" filename="libgazebo_ros_diff_drive.so">'
               '<left_joint>left_wheel_joint</left_joint><right_joint>right_wheel_joint'
               '</right_joint><wheel_separation>0.3</wheel_separation>'
               '<wheel_diameter>0.1</wheel_diameter></plugin>')
    model = model_of(rover_sdf(extra=classic))
    (classic_drive,) = read_settings(model, GazeboDiffDrive)
    assert classic_drive.left_joints == ('left_wheel_joint',)


# --- nested models and includes -------------------------------------------------------------

def test_nested_models_and_includes_are_flattened_with_scoped_names(tmp_path, monkeypatch):
    model_folder(tmp_path / 'models', 'crate', box_model_sdf(static=False),
                 versions=(('1.5', 'old.sdf'), ('1.9', 'model.sdf')))
    monkeypatch.setenv('GZ_SIM_RESOURCE_PATH', str(tmp_path / 'models'))
    body = (link('base')
            + '<model name="arm"><pose>1 0 0 0 0 0</pose>' + link('upper', pose='0 0 1 0 0 0')
            + '</model>'
            + '<include><uri>model://crate</uri><name>cargo</name><pose>0 2 0 0 0 0</pose>'
            '</include>'
            + joint('to_arm', 'base', 'arm::upper') + joint('to_cargo', 'base', 'cargo::box',
                                                            'fixed'))
    model = model_of(sdf(body))
    poses = model.link_poses({})
    assert poses['arm::upper'].translation == pytest.approx((1.0, 0.0, 1.0))
    assert poses['cargo::box'].translation == pytest.approx((0.0, 2.0, 0.25))


# --- what ends start-up ---------------------------------------------------------------------

@pytest.mark.parametrize(('text', 'message'), [
    ('<sdf version="1.9"><model name="m">', r'robot\.sdf:1: not well-formed XML'),
    ('<sdf version="1.3"><model name="m"/></sdf>',
     r'robot\.sdf: <sdf version="1\.3">: SDFormat version 1\.3 is not supported'),
    (sdf(link('a') + joint('j', 'a', 'ghost')),
     r'robot\.sdf: <joint name="j">: <child>ghost</child> is not a link of the model'),
    ('<sdf version="1.9"><model name="a">' + link('x') + '</model><model name="b">'
     + link('y') + '</model></sdf>',
     r"robot\.sdf: <sdf>: a robot is one top-level <model>, found 2 \('a', 'b'\)"),
    (sdf(link('a') + '<include><uri>model://no_such_model</uri></include>'),
     r"robot\.sdf: <include><uri>model://no_such_model</uri>: model 'no_such_model' is in "
     'no model path'),
    ('<sdf version="1.9"><world name="w"/></sdf>', r'robot\.sdf: <sdf> holds a <world>'),
    (sdf(link('a') + link('b') + joint('j', 'a', 'b', 'screw')),
     r"robot\.sdf: <joint name=\"j\">: type 'screw' is not simulated"),
    (sdf(link('a', pose='1 2 3')), r'robot\.sdf: <link name="a">: <pose>1 2 3</pose> is not '
     'six numbers'),
])
def test_bad_input_ends_start_up_with_one_line_naming_file_element_and_problem(text, message):
    with pytest.raises(DescriptionError, match=message) as caught:
        sdf_robot_to_urdf(text, SOURCE, pathlib.Path.cwd())
    assert '\n' not in str(caught.value)


def test_an_sdf_xacro_file_is_expanded_then_read(tmp_path):
    path = write(tmp_path / 'rover.sdf.xacro', rover_sdf().replace(
        '<sdf version="1.9">', '<sdf version="1.9" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:arg name="namespace" default="/robot1"/>').replace(
        '<topic>scan</topic>', '<topic>$(arg namespace)/scan</topic>'))
    description = load_description(path)
    (lidar,) = [sensor for sensor in description.model.sensors if sensor.kind is SensorKind.LIDAR]
    assert lidar.topic == '/robot1/scan'
    description = load_description(path, ['namespace:=/other'])
    (lidar,) = [sensor for sensor in description.model.sensors if sensor.kind is SensorKind.LIDAR]
    assert lidar.topic == '/other/scan'
