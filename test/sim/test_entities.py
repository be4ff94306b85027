"""Entities in the simulation's PyBullet client, without ROS: the physics of a physical world."""

from __future__ import annotations

import math

import pytest
from entity_fixtures import (
    RIG_CONTROLLERS,
    RIG_URDF,
    UNSPAWNABLE,
    box_urdf,
    flail_urdf,
    write_box,
)

from pan_tilt_sim.engine import make_simulation
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.model.world_file import World, WorldFileError, read_world_file
from pan_tilt_sim.share import DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.entities import (
    Category,
    Entities,
    EntityState,
    EntityStateError,
    NotDeletableError,
    Origin,
    SpawnError,
    SpawnProblem,
    spawn_world_objects,
)
from pan_tilt_sim.sim.world import TARGETS, build_world

TIME_STEP = 0.001
PAN_TILT = package_share() / DEFAULT_DESCRIPTION
ARM = package_share() / 'urdf' / 'three_joint_arm.xacro'


@pytest.fixture
def pan_tilt():
    simulation = make_simulation(PAN_TILT, None, TIME_STEP)
    targets = build_world(TARGETS, simulation.physics.client_id)
    entities = Entities(simulation.physics, simulation.description.name, targets=targets)
    yield simulation, entities
    entities.close()
    simulation.close()


def _rig_run(tmp_path, spawn_something: bool) -> tuple[float, float]:
    """Spin the rig's wheel with 0.5 N*m for 1 s, the plunger free; return (speed, height)."""
    urdf = tmp_path / 'rig.urdf'
    urdf.write_text(RIG_URDF)
    controllers = tmp_path / 'rig.yaml'
    controllers.write_text(RIG_CONTROLLERS)
    simulation = make_simulation(urdf, controllers, TIME_STEP)
    try:
        entities = Entities(simulation.physics, simulation.description.name)
        if spawn_something:  # the ground becomes a body with the first object
            entities.spawn('far', resource_string=box_urdf(), pose=Transform((5.0, 5.0, 0.1)))
            assert entities.has_ground
        simulation.controller('spin_effort').set_command(0.5)
        simulation.advance(1000)
        entities.close()
        return (simulation.joint_velocities()['spin'], simulation.joint_positions()['lift'])
    finally:
        simulation.close()


def test_robot_links_in_the_ground_at_start_never_touch_it_the_others_do(tmp_path):
    """The wheel, half in the ground from the start, turns as without a ground (not held);
    the plunger, clear of it at start, lands on it instead of falling to its limit."""
    without_speed, without_height = _rig_run(tmp_path, spawn_something=False)
    speed, height = _rig_run(tmp_path, spawn_something=True)
    assert speed == pytest.approx(without_speed) and speed > 10.0
    assert without_height == pytest.approx(-1.0, abs=1e-3)  # no ground: down to the limit
    assert height == pytest.approx(-0.25, abs=2e-3)  # resting on the ground (0.3 - 0.05)


def test_the_pan_tilt_examples_pan_moves_the_same_with_a_ground_body():
    """The pan/tilt example's pan cylinder reaches below z = 0."""
    runs = []
    for spawn_something in (False, True):
        simulation = make_simulation(PAN_TILT, None, TIME_STEP)
        try:
            entities = Entities(simulation.physics, simulation.description.name)
            if spawn_something:
                entities.spawn('far', resource_string=box_urdf(),
                               pose=Transform((5.0, 5.0, 0.1)))
            simulation.controller('joint1_position_controller').set_command(1.0)
            simulation.advance(2000)
            runs.append(simulation.joint_positions()['pan_joint'])
            entities.close()
        finally:
            simulation.close()
    assert runs[0] == runs[1]


def test_the_ground_is_added_with_the_first_object(pan_tilt):
    simulation, entities = pan_tilt
    assert not entities.has_ground
    bodies = pybullet.getNumBodies(physicsClientId=simulation.physics.client_id)
    entities.spawn('box', resource_string=box_urdf(), pose=Transform((1.0, 0.0, 0.5)))
    assert entities.has_ground
    # The box and the ground plane.
    assert pybullet.getNumBodies(physicsClientId=simulation.physics.client_id) == bodies + 2


def test_without_a_ground_an_object_falls_on(tmp_path):
    simulation = make_simulation(PAN_TILT, None, TIME_STEP)
    try:
        entities = Entities(simulation.physics, simulation.description.name, ground=False)
        entities.spawn('box', resource_string=box_urdf(), pose=Transform((1.0, 0.0, 0.5)))
        simulation.advance(1000)
        assert entities.state('box').pose.translation[2] < -3.0  # ~0.5 g t^2
        assert not entities.has_ground
        entities.close()
    finally:
        simulation.close()


def test_an_object_lands_on_the_ground_and_on_a_target(pan_tilt):
    simulation, entities = pan_tilt
    entities.spawn('floor', resource_string=box_urdf(), pose=Transform((1.0, 1.0, 0.5)))
    entities.spawn('on_red', resource_string=box_urdf(), pose=Transform((2.5, 0.0, 1.0)))
    simulation.advance(1500)
    assert entities.state('floor').pose.translation[2] == pytest.approx(0.1, abs=2e-3)
    assert entities.state('on_red').pose.translation[2] == pytest.approx(0.7, abs=2e-3)


def test_the_robot_pushes_an_object():
    """The arm's boom sweeps through a box standing on the ground: the box moves."""
    simulation = make_simulation(ARM, None, TIME_STEP)
    try:
        entities = Entities(simulation.physics, simulation.description.name)
        entities.spawn('box', resource_string=box_urdf(size=(0.2, 0.2, 0.5)),
                       pose=Transform((0.3, 0.3, 0.26)))
        simulation.advance(500)
        before = entities.state('box').pose.translation
        controller = simulation.controller('arm_controller')
        from pan_tilt_sim.controllers.trajectory.trajectory import JointTrajectory, TrajectoryPoint
        controller.set_command(JointTrajectory(
            ('shoulder_joint', 'extend_joint', 'wrist_joint'),
            (TrajectoryPoint(3.0, (1.5, 0.1, 0.0)),)))
        simulation.advance(4000)
        after = entities.state('box').pose.translation
        assert math.dist(before[:2], after[:2]) > 0.1
        entities.close()
    finally:
        simulation.close()


def test_a_pose_is_the_root_link_frame_whatever_the_centre_of_mass(pan_tilt):
    _simulation, entities = pan_tilt
    entities.spawn('offset', resource_string=box_urdf(com=(0.05, 0.02, 0.0)),
                   pose=Transform((0.0, 2.0, 1.0), (0.0, 0.0, math.sin(0.4), math.cos(0.4))))
    state = entities.state('offset')
    assert state.pose.translation == pytest.approx((0.0, 2.0, 1.0))
    assert state.pose.rotation == pytest.approx((0.0, 0.0, math.sin(0.4), math.cos(0.4)))
    # Spinning about the root frame's z: its origin stands still, the CoM circles.
    entities.set_state('offset', EntityState(Transform((0.0, 2.0, 1.0)), (0.0, 0.0, 0.0),
                                             (0.0, 0.0, 2.0)))
    state = entities.state('offset')
    assert state.linear == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)
    assert state.angular == pytest.approx((0.0, 0.0, 2.0))
    low, high = entities.bounds('offset')
    assert low == pytest.approx((-0.1, -0.1, -0.1), abs=2e-3)
    assert high == pytest.approx((0.1, 0.1, 0.1), abs=2e-3)


def test_static_objects_stay_put_and_take_no_velocity(pan_tilt, tmp_path):
    simulation, entities = pan_tilt
    entities.spawn('shelf', resource_string=box_urdf(static=True),
                   pose=Transform((1.0, 1.0, 1.0)))
    assert entities.get('shelf').static
    assert entities.get('shelf').info.category is Category.STATIC_OBJECT
    simulation.advance(500)
    assert entities.state('shelf').pose.translation == pytest.approx((1.0, 1.0, 1.0))
    with pytest.raises(EntityStateError, match='static'):
        entities.set_state('shelf', EntityState(Transform((1.0, 1.0, 1.0)), (1.0, 0.0, 0.0)))
    with pytest.raises(EntityStateError, match='static'):
        entities.set_state(entities.robot_name, EntityState(Transform(), (0.0, 0.0, 0.0),
                                                             (0.0, 0.0, 1.0)))


def test_passive_joints_of_an_object_move_freely(pan_tilt):
    simulation, entities = pan_tilt
    door = """<robot name="door">
      <link name="frame"><inertial><mass value="5"/>
        <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
        <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
      <link name="leaf"><inertial><origin xyz="0.3 0 0"/><mass value="1"/>
        <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="hinge" type="revolute"><parent link="frame"/><child link="leaf"/>
        <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="5"/></joint>
      <gazebo><static>true</static></gazebo>
    </robot>"""
    entities.spawn('door', resource_string=door, pose=Transform((0.0, -2.0, 1.0)))
    body = entities.get('door').body
    simulation.advance(300)
    angle = pybullet.getJointState(body, 0, physicsClientId=simulation.physics.client_id)[0]
    assert angle > 0.3  # the leaf swings down under gravity: no motor holds it
    entities.reset_state()
    assert pybullet.getJointState(
        body, 0, physicsClientId=simulation.physics.client_id)[0] == 0.0


@pytest.mark.parametrize(('state', 'problem'), [
    (EntityState(Transform((0.0, 0.0, 1e308))), 'the position must lie within'),
    (EntityState(Transform((0.0, 0.0, 1.0)), (1e308, 0.0, 0.0)), 'the linear velocity'),
    (EntityState(Transform((0.0, 0.0, 1.0)), (0.0, 0.0, 0.0), (1e300, 1e300, 0.0)),
     'the angular velocity'),
    (EntityState(Transform((0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1e-9))), 'length 0'),
], ids=['position', 'linear', 'angular', 'degenerate quaternion'])
def test_a_state_beyond_the_physics_bounds_is_refused_and_changes_nothing(pan_tilt, state, problem):
    simulation, entities = pan_tilt
    entities.spawn('ball', resource_string=box_urdf(), pose=Transform((0.0, 3.0, 1.0)))
    with pytest.raises(EntityStateError, match=problem):
        entities.set_state('ball', state)
    simulation.advance(100)
    after = entities.state('ball')
    assert all(math.isfinite(v) for v in (*after.pose.translation, *after.pose.rotation,
                                          *after.linear, *after.angular))
    assert after.pose.translation[:2] == pytest.approx((0.0, 3.0), abs=1e-3)


@pytest.mark.parametrize('scale', [1e308, 1e300, 1e-5])
def test_any_quaternion_of_finite_non_zero_length_is_normalised(pan_tilt, scale):
    simulation, entities = pan_tilt
    turned = (0.0, 0.0, math.sin(0.4), math.cos(0.4))
    entities.spawn('ball', resource_string=box_urdf(),
                   pose=Transform((0.0, 3.0, 1.0), tuple(scale * q for q in turned)))
    assert entities.state('ball').pose.rotation == pytest.approx(turned)
    entities.set_state('ball', EntityState(Transform((0.0, 2.0, 1.0),
                                                     tuple(scale * q for q in turned))))
    simulation.advance(10)
    assert entities.state('ball').pose.rotation == pytest.approx(turned, abs=1e-6)


def test_a_spawn_beyond_the_position_bound_is_refused(pan_tilt):
    _simulation, entities = pan_tilt
    with pytest.raises(SpawnError, match='the position must lie within') as refused:
        entities.spawn('far', resource_string=box_urdf(), pose=Transform((2e6, 0.0, 0.0)))
    assert refused.value.problem is SpawnProblem.INVALID_POSE
    assert 'far' not in entities


def test_names_renaming_and_refusals(pan_tilt):
    _simulation, entities = pan_tilt
    assert entities.spawn('', resource_string=box_urdf(name='crate')) == 'crate'
    assert entities.spawn('crate', resource_string=box_urdf(), allow_renaming=True) == 'crate_1'
    with pytest.raises(SpawnError) as clash:
        entities.spawn('crate', resource_string=box_urdf())
    assert clash.value.problem is SpawnProblem.NAME_NOT_UNIQUE
    assert entities.spawn('bad name', resource_string=box_urdf(),
                          allow_renaming=True) == 'bad_name'
    with pytest.raises(SpawnError) as invalid:
        entities.spawn('bad name', resource_string=box_urdf())
    assert invalid.value.problem is SpawnProblem.NAME_INVALID
    assert entities.spawn(' ', resource_string=box_urdf(), allow_renaming=True) == 'entity'
    assert entities.spawn(' ', resource_string=box_urdf(), allow_renaming=True) == 'entity_1'
    unnamed = box_urdf(name='x').replace('<robot name="x">', '<robot>')
    with pytest.raises(SpawnError) as nameless:
        entities.spawn('', resource_string=unnamed, allow_renaming=True)
    assert nameless.value.problem is SpawnProblem.RESOURCE_PARSE_ERROR


def test_the_robot_sim_node_started_with_and_the_scenery_cannot_be_deleted(pan_tilt):
    _simulation, entities = pan_tilt
    with pytest.raises(NotDeletableError, match='the robot sim_node was started with'):
        entities.delete(entities.robot_name)
    with pytest.raises(NotDeletableError, match='is scenery'):
        entities.delete('target_red')
    with pytest.raises(KeyError):
        entities.delete('nothing')


def test_the_first_robot_goes_through_its_remover_once_let_delete_allowed_it(pan_tilt):
    simulation, entities = pan_tilt
    name = entities.robot_name
    removed = []
    entities.let_delete(name, lambda gone: (removed.append(gone), simulation.remove_robot()))
    entities.delete(name)
    assert removed == [name] and name not in entities.names()
    with pytest.raises(KeyError):  # its links are no frames any more
        entities.frame_pose('tilt_link')
    assert entities.frame_pose('target_red') is not None
    # Its name names no entity now, never the next one (a cube drawn as the robot).
    assert entities.robot_name == name and entities.robot_name not in entities


def test_world_file_objects_survive_delete_spawned_and_come_back_on_restore(pan_tilt, tmp_path):
    _simulation, entities = pan_tilt
    write_box(tmp_path, 'crate.urdf', name='crate')
    world_file = tmp_path / 'world.yaml'
    world_file.write_text('entities:\n  - uri: crate.urdf\n    pose: {position: [1, 1, 0.1]}\n'
                          '    tags: [a]\n')
    world = read_world_file(world_file)
    assert spawn_world_objects(entities, world) == ['crate']
    assert entities.get('crate').origin is Origin.WORLD_FILE
    entities.spawn('extra', resource_string=box_urdf())
    assert entities.delete_spawned() == ['extra']
    assert 'crate' in entities
    entities.set_info('crate', entities.get('crate').info.__class__(Category.OBJECT, 'x', ('b',)))
    entities.delete('crate')
    entities.restore()
    assert 'crate' in entities
    assert entities.get('crate').info.tags == ('a',)
    assert entities.state('crate').pose.translation == pytest.approx((1.0, 1.0, 0.1))


def test_a_world_file_entry_that_cannot_be_spawned_names_the_file_and_entry(pan_tilt, tmp_path):
    _simulation, entities = pan_tilt
    world = World('ground', (read_world_file(_write(tmp_path, 'entities:\n  - name: a\n'
                                                    '    resource_string: "<robot"\n'))
                             .entities), tmp_path / 'w.yaml')
    with pytest.raises(WorldFileError, match=r"w.yaml: entities\[0\] \('a'\): .*not well-formed"):
        spawn_world_objects(entities, world)


@pytest.mark.parametrize('case', list(UNSPAWNABLE))
def test_an_object_pybullet_would_crash_on_is_refused_and_the_world_goes_on(pan_tilt, case):
    simulation, entities = pan_tilt
    urdf, expected = UNSPAWNABLE[case]
    before = entities.names()
    with pytest.raises(SpawnError) as refused:
        entities.spawn('thing', resource_string=urdf)
    assert refused.value.problem is SpawnProblem.RESOURCE_PARSE_ERROR
    assert expected in str(refused.value)
    assert '\n' not in str(refused.value)
    assert entities.names() == before
    assert entities.spawn('box', resource_string=box_urdf()) == 'box'
    simulation.advance(100)
    assert all(math.isfinite(v) for v in simulation.joint_positions().values())


def test_an_object_pybullet_cannot_integrate_is_refused_before_it_enters_the_world(pan_tilt):
    # A link's centre of mass so far out that its square overflows: NaN at the first step.
    simulation, entities = pan_tilt
    before = (entities.names(), pybullet.getNumBodies(
        physicsClientId=simulation.physics.client_id))
    with pytest.raises(SpawnError) as refused:
        entities.spawn('far', resource_string=flail_urdf(1e155))
    assert refused.value.problem is SpawnProblem.RESOURCE_PARSE_ERROR
    message = str(refused.value)
    assert 'its base pose is not finite after 1 physics step alone' in message
    assert "likely cause: link 'flail' <inertial><origin xyz> 1e+155" in message
    assert (entities.names(), pybullet.getNumBodies(
        physicsClientId=simulation.physics.client_id)) == before
    near = entities.spawn('near', resource_string=flail_urdf(1e3), pose=Transform((1, 1, 1)))
    simulation.advance(200)
    assert all(math.isfinite(v) for v in entities.state(near).pose.translation)


def test_a_world_file_object_pybullet_would_crash_on_ends_start_up_naming_it(pan_tilt, tmp_path):
    _simulation, entities = pan_tilt
    urdf, expected = UNSPAWNABLE['two joints with one child']
    (tmp_path / 'thing.urdf').write_text(urdf)
    world = read_world_file(_write(tmp_path, 'entities:\n  - uri: thing.urdf\n'))
    with pytest.raises(WorldFileError) as refused:
        spawn_world_objects(entities, world)
    assert str(refused.value).startswith(f'{tmp_path / "w.yaml"}: entities[0]: ')
    assert expected in str(refused.value)


def _write(folder, text):
    path = folder / 'w.yaml'
    path.write_text(text)
    return path


def test_the_ground_body_is_not_drawn_by_the_camera():
    """The camera paints the ground itself; TinyRenderer would shade a drawn plane pixelwise."""
    from pan_tilt_sim.sim.camera import CameraSettings, Renderer

    simulation = make_simulation(PAN_TILT, None, TIME_STEP)
    try:
        build_world(TARGETS, simulation.physics.client_id)
        renderer = Renderer(simulation.physics, simulation.description.model, CameraSettings())
        before = renderer.render()
        entities = Entities(simulation.physics, simulation.description.name)
        entities.spawn('behind', resource_string=box_urdf(), pose=Transform((5.0, 0.0, 0.1)))
        assert entities.has_ground
        assert renderer.render() == before
        entities.close()
    finally:
        simulation.close()


def test_an_object_in_flight_keeps_its_horizontal_speed(pan_tilt):
    """No drag: PyBullet's default 0.04 would take 0.8 % off in 0.2 s."""
    simulation, entities = pan_tilt
    entities.spawn('ball', resource_string=box_urdf(), pose=Transform((0.0, 3.0, 5.0)))
    entities.set_state('ball', EntityState(Transform((0.0, 3.0, 5.0)), (1.0, 0.0, 0.0),
                                           (0.0, 0.0, 0.5)))
    simulation.advance(200)
    state = entities.state('ball')
    assert state.linear[0] == pytest.approx(1.0, abs=1e-9)
    assert state.linear[2] == pytest.approx(-9.81 * 0.2, abs=1e-6)
    assert state.angular == pytest.approx((0.0, 0.0, 0.5), abs=1e-9)


def test_the_robot_can_be_moved_and_a_reset_puts_it_back(pan_tilt):
    simulation, entities = pan_tilt
    robot = entities.robot_name
    turned = (0.0, 0.0, math.sin(0.25), math.cos(0.25))
    entities.set_state(robot, EntityState(Transform((1.0, 2.0, 0.0), turned)))
    assert entities.state(robot).pose.translation == pytest.approx((1.0, 2.0, 0.0))
    link = pybullet.getLinkState(simulation.physics.body_id, 0,
                                 physicsClientId=simulation.physics.client_id)[4]
    assert link[:2] == pytest.approx((1.0, 2.0), abs=0.05)  # its links went along
    entities.reset_state()
    assert entities.state(robot).pose.translation == pytest.approx((0.0, 0.0, 0.0))


def test_a_static_sdf_mesh_is_hit_where_its_triangles_are_not_on_its_hull(pan_tilt, tmp_path):
    # Two parallel walls 2 m apart as one mesh: a convex hull would fill the gap between them.
    (tmp_path / 'walls.obj').write_text(
        'v -1 -1 0\nv 1 -1 0\nv 1 -1 1\nv -1 -1 1\nv -1 1 0\nv 1 1 0\nv 1 1 1\nv -1 1 1\n'
        'f 1 2 3\nf 1 3 4\nf 5 7 6\nf 5 8 7\n')
    sdf = ('<sdf version="1.9"><model name="walls"><static>true</static><link name="l">'
           '<collision name="c"><geometry><mesh><uri>walls.obj</uri></mesh></geometry>'
           '</collision></link></model></sdf>')
    simulation, entities = pan_tilt
    entities.spawn('walls', resource_string=sdf, base_dir=tmp_path,
                   pose=Transform((10.0, 0.0, 0.0)))
    client = simulation.physics.client_id
    hit = pybullet.rayTest((10.0, 0.0, 0.5), (10.0, 5.0, 0.5), physicsClientId=client)[0]
    assert hit[0] == entities.get('walls').body
    assert hit[3] == pytest.approx((10.0, 1.0, 0.5), abs=1e-3)


def test_an_object_with_a_malformed_gazebo_plugin_is_refused_naming_the_element(pan_tilt):
    simulation, entities = pan_tilt
    before = entities.names()
    plugin = ('<gazebo><plugin name="truth" filename="libgazebo_ros_p3d.so">'
              '<body_name>nowhere</body_name></plugin></gazebo></robot>')
    with pytest.raises(SpawnError) as refused:
        entities.spawn('thing', resource_string=box_urdf().replace('</robot>', plugin))
    assert refused.value.problem is SpawnProblem.RESOURCE_PARSE_ERROR
    assert "plugin 'truth' (libgazebo_ros_p3d.so): <body_name> 'nowhere' is not a link" in str(
        refused.value)
    assert entities.names() == before
