"""Several robots in one world: each robot spawned after the first gets what the first gets.

Two rovers driven by gazebo_ros diff drive plugins, each with a lidar, spawned into one
world-only sim_node (robot_from_spawn) in namespaces robot1 and robot2: each drives on
its own cmd_vel, they collide, robot2's lidar sees robot1, DeleteEntity takes either
robot and its topics away (the world runs on), a later robot's pose may be relative to
another entity, a plugin's <controller_manager_name> names the robot's manager, a taken
name is refused, and a robot that cannot be simulated is refused while robot1 runs on.
In a bridged world a later robot waits for its own bridge, unless entries name its topics.
"""

from __future__ import annotations

import importlib.util
import math

import pytest
from geometry_msgs.msg import Twist
from mobile_fixtures import GZ_DIFF_DRIVE, P3D, ROS2_DIFF_DRIVE, rover_urdf
from node_harness import SimUnderTest
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from stand_in_fixtures import finish, spawn, srv, start, world_only

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('simulation_interfaces') is None,
    reason='simulation_interfaces is not installed')

# A lidar on a mast: the mast (a 4 cm box, inside the lidar's 5 cm range_min) is what
# the other rover's lidar, at the same height, sees of this one.
MAST_LIDAR = '''
  <joint name="lidar_joint" type="fixed">
    <parent link="base_link"/><child link="lidar_link"/><origin xyz="0.1 0 0.05"/>
  </joint>
  <link name="lidar_link">
    <inertial><mass value="0.05"/>
      <inertia ixx="0.00001" ixy="0" ixz="0" iyy="0.00001" iyz="0" izz="0.00001"/></inertial>
    <collision><geometry><box size="0.04 0.04 0.04"/></geometry></collision>
  </link>
  <gazebo reference="lidar_link">
    <sensor type="ray" name="lidar">
      <update_rate>20</update_rate>
      <ray><scan><horizontal><samples>91</samples><resolution>1</resolution>
        <min_angle>-1.5708</min_angle><max_angle>1.5708</max_angle></horizontal></scan>
        <range><min>0.05</min><max>8.0</max></range></ray>
      <plugin name="scan" filename="libgazebo_ros_ray_sensor.so">
        <ros><remapping>~/out:=scan</remapping></ros>
        <output_type>sensor_msgs/LaserScan</output_type>
      </plugin>
    </sensor>
  </gazebo>'''
SPEED = 0.3  # m/s forward
BUDGET_S = 60.0


def rover(drive: str = ROS2_DIFF_DRIVE) -> str:
    return rover_urdf('rover', ros2_control=False,
                      extra=f'<gazebo>{drive}{P3D}</gazebo>{MAST_LIDAR}')


def x_of(simulation) -> float:
    return simulation.base_state()[0][0]


class Drivers:
    """Twist publishers of the probe, one per cmd_vel topic, sending at every spin."""

    def __init__(self, harness) -> None:
        self._harness = harness
        self._publishers = {}

    def drive(self, topic: str, speed: float) -> None:
        publisher = self._publishers.get(topic)
        if publisher is None:
            publisher = self._publishers[topic] = self._harness.probe.create_publisher(
                Twist, topic, 10)
        message = Twist()
        message.linear.x = speed
        publisher.publish(message)


def spin_driving(harness, drivers: Drivers, commands: dict[str, float], condition,
                 budget_s: float = BUDGET_S) -> bool:
    """Spin, sending ``commands`` (topic -> speed) each turn, until ``condition()``."""
    def sent_and_checked() -> bool:
        for topic, speed in commands.items():
            drivers.drive(topic, speed)
        return condition()
    return harness.spin_until(sent_and_checked, budget_s)


def two_rovers(harness, *, robot2_x: float = 0.0, robot2_y: float = 1.0):
    first = spawn(harness, name='robot1', resource_string=rover(), namespace='robot1')
    second = spawn(harness, name='robot2', resource_string=rover(), namespace='robot2',
                   x=robot2_x, y=robot2_y)
    assert (first.result.result, first.entity_name) == (1, 'robot1'), first
    assert (second.result.result, second.entity_name) == (1, 'robot2'), second


def test_each_rover_drives_on_its_own_cmd_vel():
    with world_only() as (harness, node):
        two_rovers(harness)
        robot1, robot2 = node.simulation, node.spawned_robots['robot2'].simulation
        assert robot2.physics.client_id == robot1.physics.client_id  # one world
        drivers = Drivers(harness)
        assert spin_driving(harness, drivers, {'/robot2/cmd_vel': SPEED},
                            lambda: x_of(robot2) > 0.3)
        assert abs(x_of(robot1)) < 0.01  # robot1 had no command
        assert spin_driving(harness, drivers, {'/robot2/cmd_vel': 0.0, '/robot1/cmd_vel': SPEED},
                            lambda: x_of(robot1) > 0.3)
        stopped = x_of(robot2)
        assert spin_driving(harness, drivers, {'/robot2/cmd_vel': 0.0, '/robot1/cmd_vel': SPEED},
                            lambda: x_of(robot1) > 0.6)
        assert abs(x_of(robot2) - stopped) < 0.01
        # One /clock for the world: both robots at the same sim time.
        assert robot2.steps == robot1.steps


def test_one_driven_into_the_other_is_stopped_by_it_never_passing_through():
    with world_only() as (harness, node):
        two_rovers(harness, robot2_x=-0.8, robot2_y=0.0)
        robot1, robot2 = node.simulation, node.spawned_robots['robot2'].simulation
        drivers = Drivers(harness)
        overlaps = []

        def driven_far_enough() -> bool:
            if x_of(robot2) > x_of(robot1) - 0.29:  # bodies 0.3 m long: overlapping
                overlaps.append((x_of(robot2), x_of(robot1)))
            return robot2.time > 5.0  # long enough to drive 1.5 m, through robot1's place
        assert spin_driving(harness, drivers, {'/robot2/cmd_vel': SPEED}, driven_far_enough)
        assert not overlaps, overlaps[:3]
        assert x_of(robot2) > -0.35  # it drove up to robot1, which stopped it (or moved on)


def test_robot2s_lidar_sees_robot1():
    with world_only() as (harness, node):
        two_rovers(harness, robot2_x=-1.0, robot2_y=0.0)
        sim = SimUnderTest(harness, node)
        scans = sim.collect(LaserScan, '/robot2/scan')
        assert harness.spin_until(lambda: len(scans) >= 2)
        ahead = scans[-1].ranges[len(scans[-1].ranges) // 2]
        # robot2's lidar at x -0.9, robot1's mast's near face at x 0.08.
        assert ahead == pytest.approx(0.98, abs=0.03)


def delete(harness, name: str) -> None:
    """DeleteEntity ``name`` through sim_node's service; it must succeed."""
    response = harness.call(srv().DeleteEntity, '/sim_node/delete_entity',
                            srv().DeleteEntity.Request(entity=name))
    assert response.result.result == 1, response.result.error_message


def topics_under(sim: SimUnderTest, name: str) -> list[str]:
    """sim_node's own topics (published or subscribed) under ``/name/``."""
    published, subscribed = sim.own_topics()
    return [topic for topic in [*published, *subscribed] if topic.startswith(f'/{name}/')]


def test_delete_entity_takes_robot2_and_its_topics_away():
    with world_only() as (harness, node):
        two_rovers(harness)
        sim = SimUnderTest(harness, node)
        published, subscribed = sim.own_topics()
        assert {'/robot2/scan', '/robot2/ground_truth', '/robot2/odom'} <= set(published)
        assert '/robot2/cmd_vel' in subscribed
        delete(harness, 'robot2')
        assert not topics_under(sim, 'robot2')
        assert 'robot2' not in node.spawned_robots and not node.simulation.guests
        entities = harness.call(srv().GetEntities, '/sim_node/get_entities').entities
        assert 'robot2' not in entities and 'robot1' in entities
        drivers = Drivers(harness)  # robot1 runs on
        assert spin_driving(harness, drivers, {'/robot1/cmd_vel': SPEED},
                            lambda: x_of(node.simulation) > 0.2)


def test_delete_entity_takes_the_first_robot_away_and_the_world_runs_on():
    from std_srvs.srv import Empty

    # Gazebo deletes any model: the one the world began with too.  robot1 holds the world's
    # PyBullet client; robot2 and /clock run on without it, and a robot spawned later works.
    # sim_node's own camera rides on robot1 (camera.link): it goes with it.
    with world_only(**{'camera.link': 'lidar_link'}) as (harness, node):
        two_rovers(harness)
        sim = SimUnderTest(harness, node)
        published, subscribed = sim.own_topics()
        assert {'/robot1/scan', '/robot1/odom', '/robot1/camera/image_raw'} <= set(published)
        assert '/robot1/cmd_vel' in subscribed
        delete(harness, 'robot1')
        assert not topics_under(sim, 'robot1')
        assert not node.simulation.has_robot
        entities = harness.call(srv().GetEntities, '/sim_node/get_entities').entities
        assert 'robot1' not in entities and 'robot2' in entities
        robot2 = node.spawned_robots['robot2'].simulation
        drivers = Drivers(harness)
        assert spin_driving(harness, drivers, {'/robot2/cmd_vel': SPEED},
                            lambda: x_of(robot2) > 0.3)
        assert robot2.steps == node.simulation.steps  # one clock, still the world's
        clocks = sim.collect(Clock, '/clock')
        assert harness.spin_until(lambda: len(clocks) >= 2)
        # Its name is free again: a robot spawned under it is a new one, and drives.
        again = spawn(harness, name='robot1', resource_string=rover(), namespace='robot3',
                      y=-1.0)
        assert (again.result.result, again.entity_name) == (1, 'robot1'), again
        robot3 = node.spawned_robots['robot1'].simulation
        assert spin_driving(harness, drivers, {'/robot3/cmd_vel': SPEED},
                            lambda: x_of(robot3) > 0.3)
        node.set_paused(True)  # a world reset puts the robots left back, on one clock
        harness.call(Empty, '/reset_simulation')
        assert robot2.steps == robot3.steps == node.simulation.steps == 0
        assert abs(x_of(robot2)) < 0.01 and abs(x_of(robot3)) < 0.01


def managers(node) -> list[tuple[str, str]]:
    """The controller manager nodes of the ROS graph, as ``ros2 node list`` shows them."""
    return [(name, namespace) for name, namespace in node.get_node_names_and_namespaces()
            if name == 'controller_manager']


def test_robots_their_gazebo_plugins_run_have_no_controller_manager_first_or_later():
    # As in Gazebo, where only gz_ros2_control's plugin makes one; the second rover has a
    # <ros2_control> block but no such plugin, which makes none either.
    if importlib.util.find_spec('controller_manager_msgs') is None:
        pytest.skip('controller_manager_msgs is not installed')
    with world_only() as (harness, node):
        first = spawn(harness, name='robot1', resource_string=rover(), namespace='robot1')
        with_block = rover_urdf('rover', extra=f'<gazebo>{ROS2_DIFF_DRIVE}</gazebo>')
        second = spawn(harness, name='robot2', resource_string=with_block, namespace='robot2',
                       y=1.0)
        assert first.result.result == 1 and second.result.result == 1, second
        assert node.controller_manager is None
        assert node.spawned_robots['robot2'].controller_manager is None
        assert managers(node) == []
        drivers = Drivers(harness)  # and they run as before
        assert spin_driving(harness, drivers, {'/robot2/cmd_vel': SPEED},
                            lambda: x_of(node.spawned_robots['robot2'].simulation) > 0.3)


def test_deleting_a_first_robot_with_ros2_control_takes_its_controller_manager(tmp_path):
    from drop_in_fixtures import MANAGER_YAML
    from ros2_control_fixtures import write_arm

    from pan_tilt_sim.model.description import load_description

    if importlib.util.find_spec('controller_manager_msgs') is None:
        pytest.skip('controller_manager_msgs is not installed')
    arm = load_description(write_arm(tmp_path, MANAGER_YAML),
                           [f"controllers:={tmp_path / 'arm_controllers.yaml'}"]).urdf_xml
    with world_only() as (harness, node):
        first = spawn(harness, name='arm1', resource_string=arm, namespace='arm1')
        second = spawn(harness, name='robot2', resource_string=rover(), namespace='robot2',
                       y=1.0)
        assert first.result.result == 1 and second.result.result == 1, first
        assert ('controller_manager', '/arm1') in node.get_node_names_and_namespaces()
        delete(harness, 'arm1')
        assert harness.spin_until(lambda: ('controller_manager', '/arm1') not in
                                  node.get_node_names_and_namespaces())
        drivers = Drivers(harness)
        assert spin_driving(harness, drivers, {'/robot2/cmd_vel': SPEED},
                            lambda: x_of(node.spawned_robots['robot2'].simulation) > 1.3)


def test_a_later_robot_is_placed_relative_to_the_frame_its_pose_names():
    # simulation_interfaces: initial_pose's header names a frame known to the simulator, e.g.
    # an entity spawned earlier.  robot2 is 1 m ahead of robot1 (turned by 90 degrees),
    # itself turned by 90 degrees: at (0, 1) in the world, facing -x.
    codes = srv().SpawnEntity.Response
    with world_only() as (harness, node):
        first = spawn(harness, name='robot1', resource_string=rover(), namespace='robot1',
                      yaw=math.pi / 2)
        assert first.result.result == 1, first
        second = spawn(harness, name='robot2', resource_string=rover(), namespace='robot2',
                       frame='robot1', x=1.0, yaw=math.pi / 2)
        assert second.result.result == 1, second.result.error_message
        (x, y, heading), _ = node.spawned_robots['robot2'].simulation.base_state()
        assert (x, y) == (pytest.approx(0.0, abs=1e-3), pytest.approx(1.0, abs=1e-3))
        assert abs(abs(heading) - math.pi) < 1e-3
        # A link of the first robot is a frame too; a frame nobody knows is refused.
        third = spawn(harness, name='robot3', resource_string=rover(), namespace='robot3',
                      frame='lidar_link', x=-1.0)
        assert third.result.result == 1, third.result.error_message
        (x, y, _), _ = node.spawned_robots['robot3'].simulation.base_state()
        # robot1's lidar_link is 0.1 m ahead of its base (+y in the world); 1 m behind it.
        assert (x, y) == (pytest.approx(0.0, abs=1e-3), pytest.approx(-0.9, abs=1e-3))
        unknown = spawn(harness, name='robot4', resource_string=rover(), namespace='robot4',
                        frame='nowhere')
        assert unknown.result.result == codes.INVALID_POSE
        assert "initial_pose frame 'nowhere': no such frame" in unknown.result.error_message
        assert sorted(node.spawned_robots) == ['robot2', 'robot3']


def test_a_taken_name_is_refused_unless_renaming_is_allowed():
    codes = srv().SpawnEntity.Response
    with world_only() as (harness, node):
        two_rovers(harness)
        taken = spawn(harness, name='robot2', resource_string=rover(), namespace='robot3',
                      y=2.0)
        assert taken.result.result == codes.NAME_NOT_UNIQUE
        assert 'already exists' in taken.result.error_message
        assert sorted(node.spawned_robots) == ['robot2']
        renamed = spawn(harness, name='robot2', resource_string=rover(), namespace='robot3',
                        y=2.0, allow_renaming=True)
        assert (renamed.result.result, renamed.entity_name) == (1, 'robot2_1')
        assert sorted(node.spawned_robots) == ['robot2', 'robot2_1']


def test_a_robot_that_cannot_be_simulated_is_refused_and_the_others_run_on():
    with world_only() as (harness, node):
        two_rovers(harness)
        # <ros2_control> with no controllers file and no plugin: nothing could drive it.
        refused = spawn(harness, name='robot3', resource_string=rover_urdf('robot3'),
                        y=-1.0)
        assert refused.result.result == 4  # RESULT_OPERATION_FAILED
        assert 'no controllers file' in refused.result.error_message
        assert sorted(node.spawned_robots) == ['robot2']
        assert len(node.simulation.guests) == 1
        drivers = Drivers(harness)
        assert spin_driving(harness, drivers, {'/robot2/cmd_vel': SPEED},
                            lambda: x_of(node.spawned_robots['robot2'].simulation) > 1.2)


def test_gz_diff_drive_rovers_take_their_topics_from_their_model_names():
    with world_only() as (harness, node):
        for name, y in (('robot1', 0.0), ('robot2', 1.0)):
            response = spawn(harness, name=name, resource_string=rover(GZ_DIFF_DRIVE), y=y)
            assert response.result.result == 1, response
        robot2 = node.spawned_robots['robot2'].simulation
        drivers = Drivers(harness)
        assert spin_driving(harness, drivers, {'/model/robot2/cmd_vel': SPEED},
                            lambda: x_of(robot2) > 1.3)
        assert abs(x_of(node.simulation)) < 0.01


def test_a_second_robot_with_ros2_control_gets_a_controller_manager_of_its_own(tmp_path):
    from drop_in_fixtures import FORWARD, JSB, MANAGER_YAML
    from ros2_control_fixtures import write_arm
    from spawner_client import Spawner
    from std_msgs.msg import Float64MultiArray

    from pan_tilt_sim.model.description import load_description

    if importlib.util.find_spec('controller_manager_msgs') is None:
        pytest.skip('controller_manager_msgs is not installed')
    arm = load_description(write_arm(tmp_path, MANAGER_YAML),
                           [f"controllers:={tmp_path / 'arm_controllers.yaml'}"]).urdf_xml
    with world_only() as (harness, node):
        first = spawn(harness, name='robot1', resource_string=rover(), namespace='robot1')
        second = spawn(harness, name='arm2', resource_string=arm, namespace='arm2', y=1.0)
        assert first.result.result == 1 and second.result.result == 1, second
        sim = SimUnderTest(harness, node)
        spawner = Spawner(sim, manager='/arm2/controller_manager')
        assert spawner.spawn(JSB) == 0 and spawner.spawn(FORWARD) == 0
        assert spawner.controllers()[FORWARD].claimed_interfaces == [
            'joint1/position', 'joint2/position']
        arm2 = node.spawned_robots['arm2'].simulation
        publisher = harness.probe.create_publisher(
            Float64MultiArray, f'/arm2/{FORWARD}/commands', 10)

        def commanded_and_there() -> bool:
            publisher.publish(Float64MultiArray(data=[0.5, -0.5]))
            positions = arm2.joint_positions()
            return abs(positions['joint1'] - 0.5) < 0.02 and abs(positions['joint2'] + 0.5) < 0.02
        assert harness.spin_until(commanded_and_there, BUDGET_S)
        # The only one: the first robot (its plugins run it) has none, as in Gazebo.
        assert managers(node) == [('controller_manager', '/arm2')]
        # DeleteEntity takes its controller manager away with it.
        delete(harness, 'arm2')
        assert harness.spin_until(lambda: ('controller_manager', '/arm2') not in
                                  node.get_node_names_and_namespaces())


def named_manager_arm(tmp_path, name: str) -> str:
    """The two-link arm whose gz_ros2_control plugin names its manager ``name``.

    Its controllers file keys the manager's section by that name, as the real
    plugin's manager node reads it (update_rate 25 Hz there).
    """
    from drop_in_fixtures import MANAGER_YAML
    from ros2_control_fixtures import write_arm

    from pan_tilt_sim.model.description import load_description

    yaml = MANAGER_YAML.replace('controller_manager:', f'{name}:').replace(
        'update_rate: 50', 'update_rate: 25')
    assert f'{name}:' in yaml and 'update_rate: 25' in yaml
    urdf = load_description(write_arm(tmp_path, yaml),
                            [f"controllers:={tmp_path / 'arm_controllers.yaml'}"]).urdf_xml
    return urdf.replace('<parameters>', f'<controller_manager_name>{name}'
                                        '</controller_manager_name><parameters>', 1)


@pytest.mark.parametrize('first', [False, True], ids=['later robot', 'first robot'])
def test_a_robot_whose_plugin_names_its_manager_gets_that_name_in_its_namespace(tmp_path,
                                                                              first):
    from drop_in_fixtures import FORWARD, JSB
    from spawner_client import Spawner

    if importlib.util.find_spec('controller_manager_msgs') is None:
        pytest.skip('controller_manager_msgs is not installed')
    arm = named_manager_arm(tmp_path, 'arm_manager')
    with world_only() as (harness, node):
        if not first:
            spawn(harness, name='robot1', resource_string=rover(), namespace='robot1')
        second = spawn(harness, name='arm2', resource_string=arm, namespace='arm2', y=1.0)
        assert second.result.result == 1, second
        names = node.get_node_names_and_namespaces()
        assert ('arm_manager', '/arm2') in names
        assert ('controller_manager', '/arm2') not in names
        sim = SimUnderTest(harness, node)
        spawner = Spawner(sim, manager='/arm2/arm_manager')
        assert spawner.spawn(JSB) == 0 and spawner.spawn(FORWARD) == 0
        assert sorted(spawner.controllers()) == sorted([JSB, FORWARD])
        # Its section of the file is the manager's: the update rate comes from there.
        arm2 = node.simulation if first else node.spawned_robots['arm2'].simulation
        assert arm2.manager.update_rate == 25


def test_a_controller_manager_name_that_is_no_node_name_is_refused_and_the_others_run_on(
        tmp_path):
    arm = named_manager_arm(tmp_path, 'arm_manager').replace(
        '>arm_manager<', '>arm manager<')
    with world_only() as (harness, node):
        spawn(harness, name='robot1', resource_string=rover(), namespace='robot1')
        refused = spawn(harness, name='arm2', resource_string=arm, namespace='arm2', y=1.0)
        assert refused.result.result != 1
        assert "<controller_manager_name>: 'arm manager' is not a valid node name" in (
            refused.result.error_message)
        assert node.spawned_robots == {}
        steps = node.simulation.steps
        assert harness.spin_until(lambda: node.simulation.steps > steps)


def test_each_rovers_odometry_tf_goes_where_its_plugin_remaps_it():
    # Nav2's classic multi-robot robots remap /tf into their namespace: robot2 does, robot1 not.
    if importlib.util.find_spec('tf2_msgs') is None:
        pytest.skip('tf2_msgs is not installed')
    from tf2_msgs.msg import TFMessage

    remapped = ROS2_DIFF_DRIVE.replace('<left_joint>',
                                       '<ros><remapping>/tf:=tf</remapping></ros><left_joint>')
    with world_only() as (harness, node):
        spawn(harness, name='robot1', resource_string=rover(), namespace='robot1')
        second = spawn(harness, name='robot2', resource_string=rover(remapped),
                       namespace='robot2', y=1.0)
        assert second.result.result == 1, second
        sim = SimUnderTest(harness, node)
        robot2_tf = sim.collect(TFMessage, '/robot2/tf')
        assert harness.spin_until(lambda: robot2_tf)
        assert [(t.header.frame_id, t.child_frame_id) for t in robot2_tf[-1].transforms] == [
            ('odom', 'base_link')]
        published, _ = sim.own_topics()
        assert {'/tf', '/robot2/tf'} <= set(published)


def test_a_world_reset_puts_every_robot_back_joints_and_all():
    from std_srvs.srv import Empty

    with world_only() as (harness, node):
        two_rovers(harness)
        robot2 = node.spawned_robots['robot2'].simulation
        drivers = Drivers(harness)
        assert spin_driving(harness, drivers, {'/robot2/cmd_vel': SPEED},
                            lambda: x_of(robot2) > 0.3)
        assert max(abs(angle) for angle in robot2.joint_positions().values()) > 5.0
        node.set_paused(True)  # the state right after the reset stays to be read
        harness.call(Empty, '/reset_simulation')
        assert robot2.steps == node.simulation.steps == 0  # one clock, back to 0
        assert abs(x_of(robot2)) < 0.01
        assert max(abs(angle) for angle in robot2.joint_positions().values()) < 0.1


def test_spawn_entity_py_with_a_robot_namespace_brings_a_second_robot(tmp_path):
    urdf = tmp_path / 'rover.urdf'
    urdf.write_text(rover())
    with world_only() as (harness, node):
        spawn(harness, name='robot1', resource_string=rover(), namespace='robot1')
        code, output = finish(harness, start('spawn_entity.py', '-entity', 'robot2', '-file',
                                             str(urdf), '-robot_namespace', 'robot2',
                                             '-y', '1.0'))
        assert code == 0, output
        assert sorted(node.spawned_robots) == ['robot2']
        _published, subscribed = SimUnderTest(harness, node).own_topics()
        assert {'/robot1/cmd_vel', '/robot2/cmd_vel'} <= set(subscribed)
        robot2 = node.spawned_robots['robot2'].simulation
        assert robot2.base_state()[0][1] == pytest.approx(1.0, abs=1e-3)


def test_a_free_robot_in_a_world_without_ground_is_refused_and_the_first_runs_on(tmp_path):
    from drop_in_fixtures import MANAGER_YAML
    from ros2_control_fixtures import write_arm

    from pan_tilt_sim.model.description import load_description

    arm = load_description(write_arm(tmp_path, MANAGER_YAML),
                           [f"controllers:={tmp_path / 'arm_controllers.yaml'}"]).urdf_xml
    with world_only(world='empty') as (harness, node):
        assert spawn(harness, name='arm', resource_string=arm).result.result == 1
        bodies = node.features.entities.names()
        refused = spawn(harness, name='robot2', resource_string=rover(), y=1.0)
        assert refused.result.result == 4  # RESULT_OPERATION_FAILED
        assert "'empty' has no ground for the free base of 'robot2'" in (
            refused.result.error_message)
        assert node.spawned_robots == {} and node.simulation.guests == []
        assert node.features.entities.names() == bodies
        steps = node.simulation.steps
        assert harness.spin_until(lambda: node.simulation.steps > steps)


def test_a_second_robot_asked_for_while_the_first_waits_for_its_bridge_follows_it():
    from std_msgs.msg import Empty

    from pan_tilt_sim.ros.bridged_topics import ANNOUNCE_TOPIC

    with world_only() as (harness, node):
        # A bridge that announced itself and has not handed over: the first robot waits.
        announce = harness.probe.create_publisher(Empty, ANNOUNCE_TOPIC, 1)
        assert harness.spin_until(lambda: node.bridged_topics.pending())
        client = harness.probe.create_client(srv().SpawnEntity, '/sim_node/spawn_entity')
        assert harness.spin_until(client.service_is_ready)
        futures = [client.call_async(srv().SpawnEntity.Request(
            name=name, resource_string=rover(), entity_namespace=name))
            for name in ('robot1', 'robot2')]
        assert harness.spin_until(lambda: node._robot_spawn._busy)
        harness.probe.destroy_publisher(announce)  # the bridge went: the robot is built
        assert harness.spin_until(lambda: all(future.done() for future in futures))
        assert [future.result().result.result for future in futures] == [1, 1], [
            future.result().result.error_message for future in futures]
        assert node.simulation.description.name == 'robot1'
        assert sorted(node.spawned_robots) == ['robot2']


def hand_over(node, bridge: str, entries: list) -> bool:
    """Set sim_node's gz_bridge parameter as the bridge stand-in named ``bridge`` does."""
    from rclpy.parameter import Parameter

    from pan_tilt_sim.model.gz_bridge import encode
    from pan_tilt_sim.ros import bridged_topics

    value = encode(bridge, entries)
    return node.set_parameters([Parameter(bridged_topics.PARAMETER, value=value)])[0].successful


def cmd_vel_entry(robot: str):
    """The entry of a bridge giving gz DiffDrive's ``/model/<robot>/cmd_vel`` its ROS name."""
    from pan_tilt_sim.model.gz_bridge import ROS_TO_GZ, BridgeEntry

    return BridgeEntry(f'/{robot}/cmd_vel', f'/model/{robot}/cmd_vel',
                       'geometry_msgs/msg/Twist', 'gz.msgs.Twist', ROS_TO_GZ)


def test_a_later_robot_in_a_bridged_world_waits_for_its_own_bridge_to_appear():
    # Nav2's multi-robot launch starts each robot's bridge with its create: a later robot's
    # request can come before its bridge is in the graph, and is built after it hands over.
    from std_msgs.msg import Empty

    from pan_tilt_sim.ros import bridged_topics

    with world_only() as (harness, node):
        assert hand_over(node, '/robot1/parameter_bridge', [])
        first = spawn(harness, name='robot1', resource_string=rover(GZ_DIFF_DRIVE))
        assert first.result.result == 1, first
        client = harness.probe.create_client(srv().SpawnEntity, '/sim_node/spawn_entity')
        assert harness.spin_until(client.service_is_ready)
        future = client.call_async(srv().SpawnEntity.Request(
            name='robot2', resource_string=rover(GZ_DIFF_DRIVE)))
        # robot2's bridge comes after its request: announced, then handing over a rename.
        assert harness.spin_until(lambda: node._robot_spawn.awaiting_bridge)
        announce = harness.probe.create_publisher(Empty, bridged_topics.ANNOUNCE_TOPIC, 1)
        assert harness.spin_until(lambda: node.bridged_topics.pending())
        assert not future.done(), 'robot2 was built before its bridge handed over'
        assert hand_over(node, '/probe', [cmd_vel_entry('robot2')])
        harness.probe.destroy_publisher(announce)
        assert harness.spin_until(future.done)
        assert future.result().result.result == 1, future.result().result.error_message
        assert harness.spin_until(lambda: node.count_subscribers('/robot2/cmd_vel') > 0)


def test_a_later_robot_whose_bridge_handed_over_first_is_built_at_once():
    # Each robot's bridge started with its create and handed over before either robot
    # was spawned: robot2's entries name its gz topics, so nothing is left to wait for.
    from pan_tilt_sim.ros.robot_spawn import NEW_BRIDGE_WAIT_S

    with world_only(real_time_factor=1.0) as (harness, node):
        assert hand_over(node, '/robot1/parameter_bridge', [cmd_vel_entry('robot1')])
        assert hand_over(node, '/robot2/parameter_bridge', [cmd_vel_entry('robot2')])
        first = spawn(harness, name='robot1', resource_string=rover(GZ_DIFF_DRIVE))
        assert first.result.result == 1, first
        client = harness.probe.create_client(srv().SpawnEntity, '/sim_node/spawn_entity')
        assert harness.spin_until(client.service_is_ready)
        assert harness.spin_until(lambda: node.simulation.time > 0.0)
        asked_at = node.simulation.time
        future = client.call_async(srv().SpawnEntity.Request(
            name='robot2', resource_string=rover(GZ_DIFF_DRIVE)))
        assert harness.spin_until(future.done)
        waited = node.simulation.time - asked_at
        assert future.result().result.result == 1, future.result().result.error_message
        assert waited < NEW_BRIDGE_WAIT_S / 3, f'robot2 waited {waited:.2f} s of sim time'
        assert harness.spin_until(lambda: node.count_subscribers('/robot2/cmd_vel') > 0)
        assert not node.bridged_topics.relays  # renamed as it was created


def test_a_topic_the_robots_share_does_not_pass_for_a_later_robots_bridge():
    # robot1's bridge names /scan, which robot2 (no namespace) has too: that entry is
    # robot1's bridge's, so robot2 still waits for a bridge of its own to appear.
    from pan_tilt_sim.model.gz_bridge import GZ_TO_ROS, BridgeEntry

    scan = BridgeEntry('/robot1/scan', '/scan', 'sensor_msgs/msg/LaserScan', 'gz.msgs.LaserScan',
                       GZ_TO_ROS)
    with world_only() as (harness, node):
        assert hand_over(node, '/robot1/parameter_bridge', [scan])
        first = spawn(harness, name='robot1', resource_string=rover(GZ_DIFF_DRIVE))
        assert first.result.result == 1, first
        client = harness.probe.create_client(srv().SpawnEntity, '/sim_node/spawn_entity')
        assert harness.spin_until(client.service_is_ready)
        future = client.call_async(srv().SpawnEntity.Request(
            name='robot2', resource_string=rover(GZ_DIFF_DRIVE)))
        assert harness.spin_until(lambda: node._robot_spawn.awaiting_bridge or future.done())
        assert not future.done(), "robot2 took robot1's /scan entry for its own bridge's"
        assert hand_over(node, '/robot2/parameter_bridge', [cmd_vel_entry('robot2')])
        assert harness.spin_until(future.done)
        assert future.result().result.result == 1, future.result().result.error_message


def test_a_later_robots_own_topics_are_the_topics_its_plugins_and_sensors_create():
    # What a later robot's bridge entries are matched against, before the robot is built.
    from pan_tilt_sim.model import naming
    from pan_tilt_sim.model.description import description_from_text
    from pan_tilt_sim.ros.robot_spawn import renamed
    from pan_tilt_sim.ros.spawned_robots import own_topics

    with world_only() as (harness, node):
        assert spawn(harness, name='robot1', resource_string=rover(),
                     namespace='robot1').result.result == 1
        sim = SimUnderTest(harness, node)

        def topics() -> set[str]:
            published, subscribed = sim.own_topics()
            return set(published) | set(subscribed)

        for name, drive, namespace in (('robot2', ROS2_DIFF_DRIVE, 'robot2'),
                                       ('robot3', GZ_DIFF_DRIVE, '')):
            before = topics()
            assert spawn(harness, name=name, resource_string=rover(drive), y=1.0,
                         namespace=namespace).result.result == 1
            created = topics() - before
            predicted = own_topics(renamed(description_from_text(rover(drive), 'test'), name),
                                   naming.normalize(namespace))
            assert created <= predicted <= topics(), (name, created, predicted)
