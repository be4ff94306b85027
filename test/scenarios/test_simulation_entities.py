"""simulation_interfaces' entities on sim_node: spawn, delete, states, info, bounds, resets.

Each call goes through a real rclpy client (sim_interfaces_client); the node
runs in-process, started paused (STOPPED) at real_time_factor 0, in the
targets world (the robot, four static target cubes, the ground).
"""

from __future__ import annotations

import math
import threading

import pytest
from entity_fixtures import UNSPAWNABLE, box_urdf, chain_urdf, write_box
from geometry_msgs.msg import Twist
from node_harness import PROBE_QUEUE, sim_node, stamp_s
from rosgraph_msgs.msg import Clock
from sim_interfaces_client import OK, Result, SimInterfaces, msg, pose, position, srv

from pan_tilt_sim.model.entity_resource import MAX_ENTITY_LINKS
from pan_tilt_sim.sim import entities as entities_module
from pan_tilt_sim.sim.bullet import pybullet

ROBOT = 'ex_urdf_pan_tilt'
TARGETS = ['target_red', 'target_green', 'target_blue', 'target_yellow']
TIME_STEP = 0.001
Spawn = srv.SpawnEntity.Response
Scope = srv.ResetSimulation.Request
Category = msg.EntityCategory
HALF = 0.1  # the test box's half size (a 0.2 m cube)
AABB_MARGIN = 2e-3  # PyBullet's boxes are a little larger than the shapes


@pytest.fixture
def world():
    with sim_node(paused=True) as under_test:
        yield SimInterfaces(under_test)


def _bodies(client: SimInterfaces) -> int:
    return pybullet.getNumBodies(physicsClientId=client.sim.simulation.physics.client_id)


def _spawn_box(client: SimInterfaces, name: str = 'box', x: float = 1.0, y: float = 0.0,
               z: float = 0.5, **kwargs) -> str:
    response = client.spawn(name, resource_string=box_urdf(**kwargs), at=pose(x, y, z))
    assert response.result.result == OK, response.result.error_message
    return response.entity_name


# --- what is there -------------------------------------------------------------------------

def test_the_world_holds_the_robot_and_the_targets(world):
    assert world.entities() == [ROBOT, *TARGETS]
    info = world.call('get_entity_info', srv.GetEntityInfo.Request(entity=ROBOT)).info
    assert info.category.category == Category.CATEGORY_ROBOT
    target = world.call('get_entity_info', srv.GetEntityInfo.Request(entity='target_red')).info
    assert target.category.category == Category.CATEGORY_STATIC_OBJECT
    state = world.entity_state('target_red')
    assert position(state) == pytest.approx((2.5, 0.0, 0.3))
    assert state.header.frame_id == 'world'


def test_unknown_entities_are_not_found(world):
    for leaf, request in (
            ('get_entity_state', srv.GetEntityState.Request(entity='nothing')),
            ('get_entity_info', srv.GetEntityInfo.Request(entity='nothing')),
            ('get_entity_bounds', srv.GetEntityBounds.Request(entity='nothing')),
            ('set_entity_state', srv.SetEntityState.Request(entity='nothing')),
            ('set_entity_info', srv.SetEntityInfo.Request(entity='nothing')),
            ('delete_entity', srv.DeleteEntity.Request(entity='nothing'))):
        result = world.call(leaf, request).result
        assert result.result == Result.RESULT_NOT_FOUND, leaf
        assert "'nothing'" in result.error_message


# --- spawning ------------------------------------------------------------------------------

def test_a_box_spawned_from_a_string_falls_and_rests_on_the_ground(world):
    name = _spawn_box(world, x=1.0, y=0.5, z=0.6)
    assert name == 'box'
    assert world.entities()[-1] == 'box'
    state = world.entity_state('box')
    assert position(state) == pytest.approx((1.0, 0.5, 0.6))
    info = world.call('get_entity_info', srv.GetEntityInfo.Request(entity='box')).info
    assert info.category.category == Category.CATEGORY_DYNAMIC_OBJECT
    assert world.step(200).result == OK  # 0.2 s: falling
    falling = world.entity_state('box')
    assert falling.twist.linear.z < -1.0
    assert falling.header.stamp.nanosec == 200_000_000  # stamped with sim time
    assert world.step(800).result == OK
    resting = world.entity_state('box')
    assert position(resting) == pytest.approx((1.0, 0.5, HALF), abs=2e-3)
    assert abs(resting.twist.linear.z) < 1e-3


def test_spawn_by_file_path_file_uri_and_package_uri(world, tmp_path):
    path = write_box(tmp_path, name='crate')
    by_path = world.spawn('a', uri=str(path), at=pose(1.0, 1.0, HALF))
    by_uri = world.spawn('b', uri=path.as_uri(), at=pose(1.0, -1.0, HALF))
    shipped = world.spawn('', uri='package://pan_tilt_sim/urdf/objects/box.urdf',
                        at=pose(-1.0, 1.0, 0.05))
    for response in (by_path, by_uri, shipped):
        assert response.result.result == OK, response.result.error_message
    assert shipped.entity_name == 'box'  # no name asked for: the URDF's
    assert world.entities()[-3:] == ['a', 'b', 'box']
    bounds = world.call('get_entity_bounds', srv.GetEntityBounds.Request(entity='box')).bounds
    assert bounds.type == msg.Bounds.TYPE_BOX
    assert (bounds.points[1].x - bounds.points[0].x) == pytest.approx(0.1, abs=AABB_MARGIN)


def test_a_name_clash_is_refused_or_renamed(world):
    _spawn_box(world, 'box')
    bodies = _bodies(world)
    clash = world.spawn('box', resource_string=box_urdf(), at=pose(2.0, 2.0, 0.5))
    assert clash.result.result == Spawn.NAME_NOT_UNIQUE
    assert 'allow_renaming' in clash.result.error_message
    assert _bodies(world) == bodies
    renamed = world.spawn('box', resource_string=box_urdf(), at=pose(2.0, 2.0, 0.5),
                        allow_renaming=True)
    assert renamed.result.result == OK
    assert renamed.entity_name == 'box_1'
    again = world.spawn('box', resource_string=box_urdf(), at=pose(2.0, -2.0, 0.5),
                      allow_renaming=True)
    assert again.entity_name == 'box_2'
    assert position(world.entity_state('box_1')) == pytest.approx((2.0, 2.0, 0.5))
    clash_with_robot = world.spawn(ROBOT, resource_string=box_urdf(), at=pose(3.0, 3.0, 0.5))
    assert clash_with_robot.result.result == Spawn.NAME_NOT_UNIQUE


def test_a_parse_error_is_answered_and_leaves_the_simulation_untouched(world):
    _spawn_box(world, 'box')
    assert world.step(100).result == OK
    entities, bodies, steps = world.entities(), _bodies(world), world.sim.simulation.steps
    box = position(world.entity_state('box'))
    for broken in ('<robot name="x"><link name="a"></robot>',  # not well-formed
                   '<robot name="x"><link name="a"/><joint name="j" type="revolute">'
                   '<parent link="a"/><child link="missing"/></joint></robot>'):
        refused = world.spawn('broken', resource_string=broken, at=pose(0.0, 0.0, 1.0),
                            allow_renaming=True)
        assert refused.result.result == Spawn.RESOURCE_PARSE_ERROR
        assert refused.result.error_message
        assert refused.entity_name == ''
    assert world.entities() == entities
    assert _bodies(world) == bodies
    assert world.sim.simulation.steps == steps
    assert position(world.entity_state('box')) == box
    # The failed attempts took no name: the next renamed spawn is still box_1.
    assert world.spawn('box', resource_string=box_urdf(), allow_renaming=True,
                     at=pose(3.0, 0.0, 0.5)).entity_name == 'box_1'


def test_an_object_pybullet_would_crash_on_is_refused_and_the_node_goes_on(world):
    # Each of these used to kill sim_node with a segmentation fault (or a double free).
    for case, (urdf, expected) in UNSPAWNABLE.items():
        refused = world.spawn('thing', resource_string=urdf, at=pose(1.0, 0.0, 0.5))
        assert refused.result.result == Spawn.RESOURCE_PARSE_ERROR, case
        assert expected in refused.result.error_message, case
        assert refused.entity_name == ''
    assert world.entities() == [ROBOT, *TARGETS]
    assert world.step(100).result == OK
    _spawn_box(world, 'box')


def test_each_refusal_has_its_code(world, tmp_path):
    usd = tmp_path / 'model.usd'
    usd.write_text('#usda 1.0')
    cases = [
        (world.spawn('x'), Spawn.NO_RESOURCE),
        (world.spawn('x', uri=str(usd)), Spawn.UNSUPPORTED_FORMAT),
        (world.spawn('x', resource_string='<mujoco model="m"/>'), Spawn.UNSUPPORTED_FORMAT),
        (world.spawn('x', uri=str(tmp_path / 'missing.urdf')), Result.RESULT_NOT_FOUND),
        (world.spawn('x', uri='package://no_such_package/box.urdf'), Result.RESULT_NOT_FOUND),
        (world.spawn('x', resource_string=box_urdf(mesh=str(tmp_path / 'gone.stl'))),
         Spawn.MISSING_ASSETS),
        (world.spawn('x', resource_string=box_urdf(mesh=str(usd))), Spawn.UNSUPPORTED_ASSETS),
        (world.spawn('x', resource_string=box_urdf(),
                   at=pose(orientation=(0.0, 0.0, 0.0, 0.0))), Spawn.INVALID_POSE),
        (world.spawn('x', resource_string=box_urdf(), at=pose(float('nan'))), Spawn.INVALID_POSE),
        (world.spawn('x', resource_string=box_urdf(), at=pose(frame='nowhere')),
         Spawn.INVALID_POSE),
        (world.spawn('x', resource_string=box_urdf(), namespace='9bad'), Spawn.NAMESPACE_INVALID),
        (world.spawn('two words', resource_string=box_urdf()), Spawn.NAME_INVALID),
    ]
    for response, code in cases:
        assert response.result.result == code, response.result.error_message
        assert response.result.error_message
    assert world.entities() == [ROBOT, *TARGETS]


def test_the_initial_pose_may_be_given_in_an_entity_or_robot_link_frame(world):
    _spawn_box(world, 'base', x=1.0, y=1.0, z=HALF)
    on_top = world.spawn('top', resource_string=box_urdf(), at=pose(0.0, 0.0, 0.3, frame='base'))
    assert on_top.result.result == OK
    assert position(world.entity_state('top')) == pytest.approx((1.0, 1.0, HALF + 0.3))
    at_link = world.spawn('at_tilt', resource_string=box_urdf(), at=pose(frame='tilt_link'))
    assert at_link.result.result == OK
    tilt_z = position(world.entity_state('at_tilt'))[2]
    assert tilt_z > 0.1  # the tilt link is up on the pan link, not at the origin


def test_spawn_entities_spawns_each_and_reports_each(world):
    good = msg.SpawnEntity(name='one', initial_pose=pose(1.0, 1.0, 0.5))
    good.entity_resource.resource_string = box_urdf()
    bad = msg.SpawnEntity(name='two', initial_pose=pose(1.0, -1.0, 0.5))
    bad.entity_resource.resource_string = '<robot'
    response = world.call('spawn_entities', srv.SpawnEntities.Request(spawn_requests=[good, bad]))
    assert response.result.result == srv.SpawnEntities.Response.ENTITIES_SPAWN_FAILED
    assert [r.result.result for r in response.results] == [OK, msg.SpawnResult.RESOURCE_PARSE_ERROR]
    assert response.results[0].entity_name == 'one'
    assert world.entities()[-1] == 'one'


def test_get_spawnables_lists_the_shipped_objects_and_reports_unknown_sources(world, tmp_path):
    write_box(tmp_path, 'mine.urdf')
    shipped = world.call('get_spawnables')
    assert shipped.result.result == OK
    uris = [s.uri for s in shipped.spawnables]
    assert 'package://pan_tilt_sim/urdf/objects/box.urdf' in uris
    assert all(s.description for s in shipped.spawnables)
    mixed = world.call('get_spawnables', srv.GetSpawnables.Request(
        sources=[str(tmp_path), str(tmp_path / 'nowhere')]))
    assert mixed.result.result == OK
    assert [s.uri for s in mixed.spawnables] == [(tmp_path / 'mine.urdf').as_uri()]
    assert 'nowhere' in mixed.result.error_message
    spawned = world.spawn('', uri=mixed.spawnables[0].uri, at=pose(1.0, 1.0, 0.5))
    assert spawned.result.result == OK


# --- deleting ------------------------------------------------------------------------------

def test_delete_removes_a_spawned_object_and_refuses_the_robot_and_scenery(world):
    _spawn_box(world, 'box')
    bodies = _bodies(world)
    assert world.delete('box').result == OK
    assert 'box' not in world.entities()
    assert _bodies(world) == bodies - 1
    assert world.delete('box').result == Result.RESULT_NOT_FOUND
    reasons = {ROBOT: 'the robot sim_node was started with', 'target_red': 'is scenery'}
    for kept, reason in reasons.items():
        refused = world.delete(kept)
        assert refused.result == Result.RESULT_OPERATION_FAILED
        assert reason in refused.error_message
    assert world.entities() == [ROBOT, *TARGETS]


# --- states --------------------------------------------------------------------------------

def test_set_state_puts_an_object_at_a_pose_with_a_twist(world):
    _spawn_box(world, 'box', z=HALF)
    quarter_turn = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))
    twist = Twist()
    twist.linear.x, twist.angular.z = 0.5, 1.0
    assert world.set_entity_state('box', pose(0.0, 2.0, 1.0, quarter_turn), twist).result == OK
    state = world.entity_state('box')
    assert position(state) == pytest.approx((0.0, 2.0, 1.0))
    o = state.pose.orientation
    assert (o.x, o.y, o.z, o.w) == pytest.approx(quarter_turn)
    assert (state.twist.linear.x, state.twist.angular.z) == pytest.approx((0.5, 1.0))
    assert world.step(100).result == OK  # it flies on: x grows by ~0.05 m in 0.1 s
    assert position(world.entity_state('box'))[0] == pytest.approx(0.05, abs=5e-3)


def test_set_state_in_another_frame_and_of_a_static_object(world):
    _spawn_box(world, 'box', z=HALF)
    assert world.set_entity_state('box', pose(0.0, 0.0, 1.0, frame='target_red')).result == OK
    assert position(world.entity_state('box')) == pytest.approx((2.5, 0.0, 1.3))
    assert world.set_entity_state('target_red', pose(3.0, 0.0, 0.3)).result == OK  # moved
    assert position(world.entity_state('target_red')) == pytest.approx((3.0, 0.0, 0.3))
    moving = Twist()
    moving.linear.x = 1.0
    refused = world.set_entity_state('target_red', pose(3.0, 0.0, 0.3), moving)
    assert refused.result == Result.RESULT_OPERATION_FAILED
    assert 'static' in refused.error_message
    bad = world.set_entity_state('box', pose(orientation=(0.0, 0.0, 0.0, 0.0)))
    assert bad.result == srv.SetEntityState.Response.INVALID_POSE
    unknown_frame = world.set_entity_state('box', pose(frame='nowhere'))
    assert unknown_frame.result == srv.SetEntityState.Response.INVALID_POSE


def _twist(linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0)) -> Twist:
    twist = Twist()
    twist.linear.x, twist.linear.y, twist.linear.z = linear
    twist.angular.x, twist.angular.y, twist.angular.z = angular
    return twist


@pytest.mark.parametrize(('at', 'twist', 'code', 'reason'), [
    (pose(1e308, 0.0, 1.0), None, 'INVALID_POSE', 'the position must lie within'),
    (pose(0.0, 0.0, 1.0), _twist(linear=(1e308, 0.0, 0.0)), 'OPERATION_FAILED',
     'the linear velocity must be at most'),
    (pose(0.0, 0.0, 1.0), _twist(angular=(0.0, 0.0, 1e300)), 'OPERATION_FAILED',
     'the angular velocity must be at most'),
    (pose(0.0, 0.0, 1.0), _twist(linear=(1e308, 1e308, 1e308)), 'OPERATION_FAILED',
     'the linear velocity must be at most'),
    (pose(orientation=(1e-300, 0.0, 0.0, 0.0)), None, 'INVALID_POSE', 'length 0'),
], ids=['position 1e308', 'linear 1e308', 'angular 1e300', 'linear overflowing its length',
        'quaternion 1e-300'])
def test_a_state_physics_cannot_run_is_refused_and_the_entity_stays_sound(world, at, twist, code,
                                                                          reason):
    _spawn_box(world, 'box', z=HALF)
    before = position(world.entity_state('box'))
    refused = world.set_entity_state('box', at, twist)
    expected = (srv.SetEntityState.Response.INVALID_POSE if code == 'INVALID_POSE'
                else Result.RESULT_OPERATION_FAILED)
    assert refused.result == expected, refused.error_message
    assert reason in refused.error_message
    assert world.step(10).result == OK
    assert position(world.entity_state('box')) == pytest.approx(before, abs=1e-3)
    # Requests relative to it still work.
    assert world.set_entity_state('box', pose(0.0, 0.0, 1.0, frame='box')).result == OK
    assert all(math.isfinite(v) for v in position(world.entity_state('box')))


@pytest.mark.parametrize('scale', [1e300, 1e308, 1e-3])
def test_a_huge_or_small_quaternion_is_normalised(world, scale):
    _spawn_box(world, 'box', z=HALF)
    quarter_turn = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))
    at = pose(0.0, 2.0, 1.0, tuple(scale * q for q in quarter_turn))
    assert world.set_entity_state('box', at).result == OK
    o = world.entity_state('box').pose.orientation
    assert (o.x, o.y, o.z, o.w) == pytest.approx(quarter_turn)
    assert world.step(10).result == OK
    assert position(world.entity_state('box')) == pytest.approx((0.0, 2.0, 1.0), abs=1e-2)
    relative = world.set_entity_state('box', pose(0.0, 0.0, 0.5, frame='box'))
    assert relative.result == OK


def test_a_pose_beyond_the_bound_once_in_the_world_frame_is_refused(world):
    _spawn_box(world, 'box', z=HALF)
    assert world.set_entity_state('box', pose(9e5, 0.0, 1.0)).result == OK
    refused = world.set_entity_state('box', pose(9e5, 0.0, 0.0, frame='box'))
    assert refused.result == srv.SetEntityState.Response.INVALID_POSE
    assert 'the position must lie within' in refused.error_message


def test_a_pose_is_that_of_the_urdf_root_frame_not_the_centre_of_mass(world):
    _spawn_box(world, 'offset', x=0.0, y=2.0, z=1.0, com=(0.05, 0.0, 0.0))
    assert position(world.entity_state('offset')) == pytest.approx((0.0, 2.0, 1.0))
    assert world.set_entity_state('offset', pose(1.0, 2.0, 1.0)).result == OK
    assert position(world.entity_state('offset')) == pytest.approx((1.0, 2.0, 1.0))


def test_get_entities_states_gives_the_filtered_entities_states(world):
    _spawn_box(world, 'box', x=1.0, y=0.5, z=0.7)
    response = world.call('get_entities_states', srv.GetEntitiesStates.Request(
        filters=msg.EntityFilters(filter='box|target_red')))
    assert response.result.result == OK
    assert list(response.entities) == ['target_red', 'box']
    assert [position(s) for s in response.states] == [
        pytest.approx((2.5, 0.0, 0.3)), pytest.approx((1.0, 0.5, 0.7))]


# --- filters, info, bounds -----------------------------------------------------------------

def test_filters_by_name_category_tags_and_bounds(world):
    _spawn_box(world, 'box', x=-1.0, y=0.0, z=HALF)
    assert world.entities(filter='target_.*') == TARGETS
    assert world.entities(filter='target') == []  # a full match, as ros_gz_sim
    statics = [msg.EntityCategory(category=Category.CATEGORY_STATIC_OBJECT)]
    assert world.entities(categories=statics) == TARGETS
    robots_or_dynamic = [msg.EntityCategory(category=Category.CATEGORY_ROBOT),
                         msg.EntityCategory(category=Category.CATEGORY_DYNAMIC_OBJECT)]
    assert world.entities(categories=robots_or_dynamic) == [ROBOT, 'box']

    info = msg.EntityInfo(category=msg.EntityCategory(category=Category.CATEGORY_OBJECT),
                          description='to push', tags=['pushable', 'light'])
    assert world.call('set_entity_info', srv.SetEntityInfo.Request(
        entity='box', info=info)).result.result == OK
    got = world.call('get_entity_info', srv.GetEntityInfo.Request(entity='box')).info
    assert (got.description, list(got.tags)) == ('to push', ['pushable', 'light'])
    tags = msg.TagsFilter
    assert world.entities(tags=tags(tags=['light', 'heavy'], filter_mode=tags.FILTER_MODE_ANY)) \
        == ['box']
    assert world.entities(tags=tags(tags=['light', 'heavy'], filter_mode=tags.FILTER_MODE_ALL)) \
        == []

    sphere = msg.Bounds(type=msg.Bounds.TYPE_SPHERE, points=[_point(-1.3, 0.0, 0.1),
                                                             _point(0.25, 0.0, 0.0)])
    assert world.entities(bounds=sphere) == ['box']  # 0.2 m from the box's side
    box = msg.Bounds(type=msg.Bounds.TYPE_BOX, points=[_point(2.0, -0.5, 0.0),
                                                       _point(3.0, 0.5, 1.0)])
    assert world.entities(bounds=box) == ['target_red']
    both = world.call('get_entities', srv.GetEntities.Request(filters=msg.EntityFilters(
        filter='box', bounds=box)))
    assert list(both.entities) == []  # filters are ANDed


def test_bad_filters_are_refused_with_the_reason(world):
    for filters, code in (
            (msg.EntityFilters(filter='('), Result.RESULT_OPERATION_FAILED),
            (msg.EntityFilters(tags=msg.TagsFilter(tags=['a'], filter_mode=7)),
             Result.RESULT_OPERATION_FAILED),
            (msg.EntityFilters(bounds=msg.Bounds(type=msg.Bounds.TYPE_CONVEX_HULL, points=[
                _point(0, 0, 0), _point(1, 0, 0), _point(0, 1, 0)])),
             Result.RESULT_FEATURE_UNSUPPORTED),
            (msg.EntityFilters(bounds=msg.Bounds(type=msg.Bounds.TYPE_SPHERE)),
             Result.RESULT_OPERATION_FAILED)):
        response = world.call('get_entities', srv.GetEntities.Request(filters=filters))
        assert response.result.result == code
        assert response.result.error_message


def test_bounds_are_a_box_in_the_entity_frame(world):
    _spawn_box(world, 'box', x=1.0, y=1.0, z=HALF, size=(0.2, 0.4, 0.2))
    bounds = world.call('get_entity_bounds', srv.GetEntityBounds.Request(entity='box')).bounds
    assert bounds.type == msg.Bounds.TYPE_BOX
    low, high = bounds.points
    assert (low.x, low.y, low.z) == pytest.approx((-0.1, -0.2, -0.1), abs=AABB_MARGIN)
    assert (high.x, high.y, high.z) == pytest.approx((0.1, 0.2, 0.1), abs=AABB_MARGIN)


def _point(x: float, y: float, z: float):
    from geometry_msgs.msg import Vector3
    return Vector3(x=float(x), y=float(y), z=float(z))


# --- reset scopes --------------------------------------------------------------------------

@pytest.fixture
def moved(world):
    """The robot's pan turned, a box spawned and moved, 1.5 s of sim time gone."""
    from std_msgs.msg import Float64
    _spawn_box(world, 'box', x=1.0, y=0.0, z=HALF)
    world.sim.command('joint1_position_controller', Float64(data=0.3))
    assert world.step(1000).result == OK
    assert world.set_entity_state('box', pose(1.5, 0.0, HALF)).result == OK
    assert world.step(500).result == OK
    assert world.sim.simulation.joint_positions()['pan_joint'] > 0.05
    return world


def _pan(world) -> float:
    return world.sim.simulation.joint_positions()['pan_joint']


def test_reset_time_puts_the_clock_back_and_nothing_else(moved):
    pan, box = _pan(moved), position(moved.entity_state('box'))
    assert moved.reset(Scope.SCOPE_TIME).result == OK
    assert moved.sim.simulation.time == 0.0
    assert _pan(moved) == pytest.approx(pan)
    assert position(moved.entity_state('box')) == pytest.approx(box)
    assert 'box' in moved.entities()


def test_reset_state_puts_joints_and_entities_back_and_keeps_time(moved):
    time = moved.sim.simulation.time
    assert moved.set_entity_state('target_red', pose(3.0, 0.0, 0.3)).result == OK
    assert moved.reset(Scope.SCOPE_STATE).result == OK
    assert moved.sim.simulation.time == time
    assert _pan(moved) == 0.0
    assert position(moved.entity_state('box')) == pytest.approx((1.0, 0.0, HALF))
    assert position(moved.entity_state('target_red')) == pytest.approx((2.5, 0.0, 0.3))


def test_reset_spawned_deletes_the_spawned_objects_only(moved):
    time, pan = moved.sim.simulation.time, _pan(moved)
    assert moved.reset(Scope.SCOPE_SPAWNED).result == OK
    assert moved.entities() == [ROBOT, *TARGETS]
    assert moved.sim.simulation.time == time
    assert _pan(moved) == pytest.approx(pan)


def test_reset_all_is_a_restart_and_reads_stopped(moved):
    assert moved.reset(Scope.SCOPE_ALL).result == OK
    assert moved.entities() == [ROBOT, *TARGETS]
    assert moved.sim.simulation.time == 0.0
    assert _pan(moved) == 0.0
    assert moved.state() == msg.SimulationState.STATE_STOPPED
    _spawn_box(moved, 'again')
    assert moved.reset(Scope.SCOPE_DEFAULT).result == OK  # the same
    assert moved.entities() == [ROBOT, *TARGETS]


def test_reset_time_and_spawned_together(moved):
    pan = _pan(moved)
    assert moved.reset(Scope.SCOPE_TIME | Scope.SCOPE_SPAWNED).result == OK
    assert moved.sim.simulation.time == 0.0
    assert moved.entities() == [ROBOT, *TARGETS]
    assert _pan(moved) == pytest.approx(pan)


def test_unknown_reset_scopes_are_unsupported(moved):
    time = moved.sim.simulation.time
    result = moved.reset(8)
    assert result.result == Result.RESULT_FEATURE_UNSUPPORTED
    assert result.error_message
    assert moved.sim.simulation.time == time
    assert 'box' in moved.entities()


# --- a big spawn does not stop the simulation ------------------------------------------------

HELD_S = 20.0  # the longest a test holds a spawn's preparation
CLOCK_ADVANCE_S = 0.05  # sim time /clock must gain while a spawn is being prepared


def test_a_chain_at_the_limit_is_spawned_and_its_state_reported(world):
    assert world.spawn('chain', resource_string=chain_urdf(MAX_ENTITY_LINKS - 1),
                     at=pose(1.0, 1.0, 0.5)).result.result == OK
    assert world.step(10).result == OK
    assert position(world.entity_state('chain'))[0] == pytest.approx(1.0, abs=0.1)
    assert len(world.sim.node.features.entities.joint_positions('chain')) == MAX_ENTITY_LINKS - 1


def test_clock_keeps_ticking_while_a_spawn_is_read_and_then_the_answer_comes(monkeypatch):
    # The preparation (reading, checking, trying the object) is held until the test has
    # seen /clock advance: it runs off the executor's thread, or the node would stand still.
    reading, release = threading.Event(), threading.Event()
    read = entities_module.read_entity_resource

    def held_read(*args, **kwargs):
        reading.set()
        release.wait(HELD_S)
        return read(*args, **kwargs)

    monkeypatch.setattr(entities_module, 'read_entity_resource', held_read)
    with sim_node() as under_test:  # playing, as fast as it goes
        sim = SimInterfaces(under_test)
        clock = under_test.collect(Clock, '/clock', PROBE_QUEUE)
        future = sim.spawn_async('chain', resource_string=chain_urdf(20), at=pose(1.0, 1.0, 0.5))
        try:
            assert under_test.spin_until(reading.is_set, HELD_S)
            assert under_test.spin_until(lambda: bool(clock))
            started = stamp_s(clock[-1])
            advanced = under_test.spin_until(
                lambda: stamp_s(clock[-1]) >= started + CLOCK_ADVANCE_S, HELD_S)
            assert advanced and not future.done(), '/clock stood still while a spawn was read'
        finally:
            release.set()
        assert under_test.spin_until(future.done), 'the spawn was never answered'
        response = future.result()
        assert response.result.result == OK, response.result.error_message
        assert response.entity_name == 'chain'
        assert 'chain' in sim.entities()
        joints = sim.sim.node.features.entities.joint_positions('chain')
        assert len(joints) == 20


def test_a_chain_one_link_past_the_limit_is_refused_and_the_simulation_runs_on(world):
    bodies, entities = _bodies(world), world.entities()
    refused = world.spawn('chain', resource_string=chain_urdf(MAX_ENTITY_LINKS))
    assert refused.result.result == Result.RESULT_OPERATION_FAILED
    message = refused.result.error_message
    assert f'at most {MAX_ENTITY_LINKS}' in message and '\n' not in message
    assert refused.entity_name == ''
    assert (_bodies(world), world.entities()) == (bodies, entities)
    steps = world.sim.simulation.steps
    assert world.step(10).result == OK
    assert world.sim.simulation.steps == steps + 10
