"""sim_node started world-only (robot_from_spawn): the first SpawnEntity request is the robot.

What ros_gz_sim's create and gazebo_ros's spawn_entity.py stand-ins rely on: sim_node
serves simulation_interfaces' SpawnEntity on ``~/spawn_entity`` before it has a robot;
the first good request becomes the robot (its controller manager from its
gz_ros2_control plugin's file), answered once it is built; a bad one is refused with
the standard's code and sim_node keeps waiting; afterwards the same service spawns objects.
"""

from __future__ import annotations

import importlib.util

import pytest
from drop_in_fixtures import FORWARD, JSB, MANAGER_YAML
from mobile_fixtures import plugin_rover_urdf
from node_harness import SimUnderTest
from ros2_control_fixtures import write_arm
from spawner_client import Spawner
from stand_in_fixtures import SERVICE, spawn, srv, world_only

from pan_tilt_sim.model.description import load_description

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('simulation_interfaces') is None
    or importlib.util.find_spec('controller_manager_msgs') is None,
    reason='simulation_interfaces or controller_manager_msgs is not installed')

WAITING = 'No robot yet: waiting for one on'
BUILD_S = 10.0
BOX = ('<robot name="box"><link name="box"><inertial><mass value="1"/><inertia ixx="0.01" '
       'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>'
       '<box size="0.1 0.1 0.1"/></geometry></collision></link></robot>')


def arm_with_plugin_file(tmp_path) -> str:
    plugin_file = tmp_path / 'arm_controllers.yaml'
    return load_description(write_arm(tmp_path, MANAGER_YAML),
                            [f'controllers:={plugin_file}']).urdf_xml


def test_it_waits_and_the_first_spawn_becomes_the_robot_with_its_controller_manager(
        tmp_path, capfd):
    urdf = arm_with_plugin_file(tmp_path)
    with world_only() as (harness, node):
        harness.spin_for(0.5)
        assert node.simulation is None
        response = spawn(harness, name='arm', resource_string=urdf)
        assert (response.result.result, response.entity_name) == (1, 'arm'), response
        assert node.simulation is not None  # built before the answer
        assert node.simulation.description.name == 'arm'
        sim = SimUnderTest(harness, node)
        # gz_ros2_control's controller manager, /controller_manager, with the plugin's file.
        spawner = Spawner(sim)
        assert spawner.spawn(JSB) == 0 and spawner.spawn(FORWARD) == 0
        assert spawner.controllers()[FORWARD].claimed_interfaces == [
            'joint1/position', 'joint2/position']
        # One server of that name, and it now spawns objects.
        assert harness.spin_until(lambda: harness.probe.count_services(SERVICE) == 1)
        box = spawn(harness, name='box', resource_string=BOX)
        assert (box.result.result, box.entity_name) == (1, 'box'), box
        again = spawn(harness, name='arm', resource_string=urdf)
        assert again.result.result == srv().SpawnEntity.Response.NAME_NOT_UNIQUE
    waiting = [line for line in capfd.readouterr().err.splitlines() if WAITING in line]
    assert len(waiting) == 1 and f"'{SERVICE}'" in waiting[0], waiting


def test_a_refused_request_changes_nothing_and_it_keeps_waiting(tmp_path):
    codes = srv().SpawnEntity.Response
    with world_only() as (harness, node):
        refused = [
            spawn(harness).result.result,
            spawn(harness, resource_string='<robot name="x"><link').result.result,
            spawn(harness, uri=str(tmp_path / 'missing.urdf')).result.result,
            spawn(harness, resource_string=plugin_rover_urdf(), frame='base_link').result.result,
        ]
        assert refused == [codes.NO_RESOURCE, codes.RESOURCE_PARSE_ERROR, 2,  # NOT_FOUND
                           codes.INVALID_POSE]
        assert node.simulation is None
        assert spawn(harness, resource_string=plugin_rover_urdf()).result.result == 1
        assert node.simulation is not None


def test_the_robot_starts_at_the_requested_pose_and_a_world_objects_name_is_taken(tmp_path):
    world = tmp_path / 'world.yaml'
    world.write_text('scenery: ground\nentities:\n  - name: rover\n    shape: box\n'
                     '    size: [0.2, 0.2, 0.2]\n    pose: {position: [3.0, 3.0, 0.1]}\n')
    codes = srv().SpawnEntity.Response
    with world_only(world=str(world)) as (harness, node):
        taken = spawn(harness, name='rover', resource_string=plugin_rover_urdf())
        assert taken.result.result == codes.NAME_NOT_UNIQUE and node.simulation is None
        response = spawn(harness, name='rover', resource_string=plugin_rover_urdf(),
                         allow_renaming=True, frame='world', x=1.0, y=-0.5, yaw=0.3)
        assert (response.result.result, response.entity_name) == (1, 'rover_1')
        (x, y, heading), _twist = node.simulation.base_state()
        assert (x, y, heading) == pytest.approx((1.0, -0.5, 0.3), abs=1e-3)


def test_a_robot_that_reads_but_cannot_be_built_is_refused_then_ends_it():
    from mobile_fixtures import rover_urdf

    from pan_tilt_sim.errors import ConfigurationError

    with world_only() as (harness, _node):
        client = harness.probe.create_client(srv().SpawnEntity, SERVICE)
        assert harness.spin_until(client.service_is_ready)
        # <ros2_control> with no controllers file and no plugin: nothing could drive it.
        future = client.call_async(srv().SpawnEntity.Request(resource_string=rover_urdf()))
        with pytest.raises(ConfigurationError, match='no controllers file'):
            harness.spin_for(BUILD_S)  # the one line ends sim_node's spin
        assert harness.spin_until(future.done)  # answered all the same
        assert future.result().result.result == 4  # RESULT_OPERATION_FAILED
        assert 'no controllers file' in future.result().result.error_message
