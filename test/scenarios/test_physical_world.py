"""A physical world: spawned objects land on the ground, the arm pushes them, the camera sees them.

Everything the test does to the simulation goes through simulation_interfaces
(spawn, step, entity states); the arm is commanded on its trajectory topic,
as a user would.
"""

from __future__ import annotations

import math
import textwrap

import numpy
import pytest
from entity_fixtures import BOX_RGBA, box_urdf
from node_harness import sim_node, stamp_s
from sensor_msgs.msg import Image
from sim_interfaces_client import OK, SimInterfaces, msg, pose, position
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from pan_tilt_sim.model.world_file import MAX_WORLD_ENTITIES, WorldFileError
from pan_tilt_sim.share import package_share
from pan_tilt_sim.sim.camera import CameraSettings, intrinsics

ARM = str(package_share() / 'urdf' / 'three_joint_arm.xacro')
ARM_JOINTS = ['shoulder_joint', 'extend_joint', 'wrist_joint']
PUSHED = (0.2, 0.2, 0.5)  # a tall box the boom and the hand can reach (m)
PUSHED_MU = 0.125  # slippery on the ground: pushed by the sweeping boom, it slides rather than tips
CHROMA_TOLERANCE = 0.08


def _chroma_matches(pixel, rgba) -> bool:
    wanted = numpy.array(rgba[:3]) / sum(rgba[:3])
    values = numpy.asarray(pixel, dtype=float)
    return bool(numpy.abs(values / max(values.sum(), 1.0) - wanted).max() < CHROMA_TOLERANCE)


def _upright(state) -> bool:
    o = state.pose.orientation
    # The box's z axis in the world: its z component is 1 - 2 (x^2 + y^2).
    return 1.0 - 2.0 * (o.x * o.x + o.y * o.y) > math.cos(math.radians(5.0))


def test_start_paused_spawn_step_read_push_read_through_simulation_interfaces():
    """The issue's "done": start paused, spawn a box, step, read it, push it with the arm."""
    with sim_node(robot_description_file=ARM, world='ground', paused=True) as sim:
        client = SimInterfaces(sim)
        assert client.state() == msg.SimulationState.STATE_STOPPED

        spawned = client.spawn('box', resource_string=box_urdf(size=PUSHED, mass=1.0,
                                                               mu=PUSHED_MU),
                               at=pose(0.3, 0.3, PUSHED[2] / 2 + 0.03))
        assert spawned.result.result == OK, spawned.result.error_message
        assert client.step(500).result == OK
        assert sim.simulation.time == pytest.approx(0.5)
        resting = client.entity_state('box')
        x0, y0, z0 = position(resting)
        assert (x0, y0) == pytest.approx((0.3, 0.3), abs=5e-3)
        assert z0 == pytest.approx(PUSHED[2] / 2, abs=2e-3)  # on the ground
        assert math.hypot(resting.twist.linear.x, resting.twist.linear.z) < 1e-2
        assert _upright(resting)

        # Swing the boom (reaching out 0.1 m) from 0 to 1.5 rad through the box.
        trajectory = JointTrajectory(joint_names=ARM_JOINTS, points=[JointTrajectoryPoint(
            positions=[1.5, 0.1, 0.0], time_from_start=_duration(3.0))])
        sim.command('arm_controller', trajectory)
        assert client.step(4000).result == OK
        assert sim.simulation.joint_positions()['shoulder_joint'] == pytest.approx(1.5,
                                                                                    abs=0.02)
        pushed = client.entity_state('box')
        x1, y1, z1 = position(pushed)
        assert math.hypot(x1 - x0, y1 - y0) > 0.1  # pushed aside ...
        assert y1 > y0 + 0.1  # ... the way the boom swept (towards +y)
        assert z1 == pytest.approx(PUSHED[2] / 2, abs=5e-3)  # and still on the ground
        assert _upright(pushed)


def _duration(seconds: float):
    from builtin_interfaces.msg import Duration
    return Duration(sec=int(seconds), nanosec=int(round(seconds % 1 * 1e9)))


def test_the_camera_sees_a_spawned_box_where_its_intrinsics_project_it():
    """The pan/tilt camera looks along -x: a box put down in front of it shows up there."""
    with sim_node(paused=True) as sim:
        client = SimInterfaces(sim)
        topic = sim.node.topic('camera', 'image_raw')
        images = sim.collect(Image, topic)
        sim.wait_for_subscribers(topic)
        centre = numpy.array((-1.2, 0.25, 0.1))  # on the ground, a little to the left

        assert client.step(100).result == OK
        assert sim.spin_until(lambda: images)
        before = _pixels(images[-1])

        spawned = client.spawn('box', resource_string=box_urdf(size=(0.2, 0.2, 0.2)),
                               at=pose(*(centre + (0.0, 0.0, 0.05))))
        assert spawned.result.result == OK
        assert client.step(1000).result == OK  # it lands, and frames are taken
        assert position(client.entity_state('box')) == pytest.approx(tuple(centre), abs=3e-3)
        count = len(images)
        assert client.step(100).result == OK
        assert sim.spin_until(lambda: len(images) > count)
        after = _pixels(images[-1])
        assert stamp_s(images[-1]) == pytest.approx(sim.simulation.time, abs=0.1)

        eye, forward, up = (numpy.array(v) for v in sim.node.features.camera.optical_axes())
        camera = intrinsics(CameraSettings())
        right = numpy.cross(forward, up)

        def project(point):
            ray = numpy.array(point) - eye
            depth = ray @ forward
            return (camera.cx + camera.fx * (ray @ right) / depth,
                    camera.cy + camera.fy * (ray @ -up) / depth)

        u, v = (round(c) for c in project(centre + (0.1, 0.0, 0.0)))  # the facing side
        assert _chroma_matches(after[v, u], BOX_RGBA), after[v, u]
        assert not _chroma_matches(before[v, u], BOX_RGBA)  # the box made the difference
        corners = [project(centre + (dx, dy, dz)) for dx in (-0.1, 0.1)
                   for dy in (-0.1, 0.1) for dz in (-0.1, 0.1)]
        mask = numpy.array([[_chroma_matches(p, BOX_RGBA) for p in row] for row in after])
        rows, columns = numpy.nonzero(mask)
        assert columns.min() == pytest.approx(min(c[0] for c in corners) + 0.5, abs=1.5)
        assert columns.max() == pytest.approx(max(c[0] for c in corners) - 0.5, abs=1.5)
        assert rows.min() == pytest.approx(min(c[1] for c in corners) + 0.5, abs=1.5)
        assert rows.max() == pytest.approx(max(c[1] for c in corners) - 0.5, abs=1.5)


def _pixels(image: Image) -> numpy.ndarray:
    return numpy.frombuffer(image.data, numpy.uint8).reshape(image.height, image.width, 3)


# --- world files ---------------------------------------------------------------------------

def test_a_world_file_spawns_its_objects_at_start_and_a_full_reset_brings_them_back(tmp_path):
    (tmp_path / 'crate.urdf').write_text(box_urdf(name='crate'))
    world = tmp_path / 'world.yaml'
    world.write_text(textwrap.dedent(f"""\
        scenery: ground
        entities:
          - name: crate
            uri: crate.urdf
            pose: {{position: [1.0, 0.0, 0.3], rpy: [0.0, 0.0, 0.5]}}
            tags: [heavy]
          - resource_string: '{box_urdf(name="inline", size=(0.1, 0.1, 0.1))}'
            pose: {{position: [-1.0, 0.0, 0.05]}}
        """))
    with sim_node(world=str(world), paused=True) as sim:
        client = SimInterfaces(sim)
        assert client.entities() == ['ex_urdf_pan_tilt', 'crate', 'inline']  # no targets
        o = client.entity_state('crate').pose.orientation
        assert 2.0 * math.atan2(o.z, o.w) == pytest.approx(0.5)
        assert client.step(1000).result == OK
        assert position(client.entity_state('crate'))[2] == pytest.approx(0.1, abs=2e-3)
        info = client.call('get_entity_info', _info_request('crate')).info
        assert list(info.tags) == ['heavy']

        assert client.delete('crate').result == OK
        spawned = client.spawn('extra', resource_string=box_urdf(), at=pose(0.0, 2.0, 0.1))
        assert spawned.result.result == OK
        assert client.reset(msg_scope('SCOPE_SPAWNED')).result == OK
        assert client.entities() == ['ex_urdf_pan_tilt', 'inline']  # world objects stay
        assert client.reset(msg_scope('SCOPE_ALL')).result == OK
        assert client.entities() == ['ex_urdf_pan_tilt', 'inline', 'crate']
        assert position(client.entity_state('crate')) == pytest.approx((1.0, 0.0, 0.3))


def _info_request(entity: str):
    from sim_interfaces_client import srv
    return srv.GetEntityInfo.Request(entity=entity)


def msg_scope(name: str) -> int:
    from sim_interfaces_client import srv
    return getattr(srv.ResetSimulation.Request, name)


def test_a_world_file_past_the_object_limit_ends_start_up_at_once_naming_the_limit(tmp_path):
    world = tmp_path / 'world.yaml'
    world.write_text('entities:\n' + ''.join(
        f'  - {{shape: box, size: [0.1, 0.1, 0.1], pose: {{position: [{index}, 5, 0.05]}}}}\n'
        for index in range(MAX_WORLD_ENTITIES + 1)))
    with pytest.raises(WorldFileError, match=rf'world.yaml: entities: {MAX_WORLD_ENTITIES + 1} '
                                             rf'objects; a world file may list at most '
                                             rf'{MAX_WORLD_ENTITIES} '):
        with sim_node(world=str(world)):
            pass


def test_a_bad_world_file_ends_start_up_naming_the_file_and_entry(tmp_path):
    world = tmp_path / 'world.yaml'
    world.write_text('entities:\n  - name: ghost\n    uri: missing.urdf\n')
    with pytest.raises(WorldFileError, match=r"world.yaml: entities\[0\] \('ghost'\): .*"
                                             r'missing.urdf.*no such file'):
        with sim_node(world=str(world)):
            pass
