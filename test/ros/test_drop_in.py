"""sim_node named controller_manager: what a ros2_control launch file asks of ros2_control_node.

The robot comes from the ``robot_description`` topic (a stand-in
robot_state_publisher publishes it, transient local), controllers from the
node's parameters in the controller manager's own layout or from spawners
with ``--param-file`` and ``--controller-ros-args`` (a client playing jazzy's
spawner), as in ros2_control_demos' launch files.
"""

from __future__ import annotations

import importlib.util

import pytest
import yaml
from drop_in_fixtures import (
    FORWARD,
    FORWARD_PARAMETERS_YAML,
    FORWARD_TYPE,
    JSB,
    MANAGER_YAML,
    SPAWNER_YAML,
    arm_urdf,
    drop_in_node,
    write_yaml,
)
from geometry_msgs.msg import TwistStamped
from mobile_fixtures import drive_parameters, rover_urdf
from nav_msgs.msg import Odometry
from node_harness import NodeHarness, SimUnderTest
from rclpy.parameter import Parameter
from robot_state_publisher_stand_in import RobotStatePublisherStandIn
from spawner_client import Spawner, spawner_main
from std_msgs.msg import Float64MultiArray

from pan_tilt_sim.errors import DescriptionError, ParameterError
from pan_tilt_sim.ros.sim_node import SimNode

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('controller_manager_msgs') is None,
    reason='controller_manager_msgs is not installed')

WAITING = 'Waiting for the robot description on'
LATE_S = 2.0
BUILD_BUDGET_S = 20.0


def publish_description(harness, urdf: str, namespace: str | None = None):
    """Start the stand-in robot_state_publisher on the harness; return it."""
    return harness.add(RobotStatePublisherStandIn(urdf, context=harness.context,
                                                  namespace=namespace))


def wait_built(harness, node) -> SimUnderTest:
    assert harness.spin_until(lambda: node.simulation is not None, BUILD_BUDGET_S), (
        'the simulation never started from robot_description')
    return SimUnderTest(harness, node)


def test_it_waits_for_robot_description_with_one_line_and_starts_when_it_arrives_late(
        tmp_path, capfd):
    urdf = arm_urdf(tmp_path)
    with drop_in_node() as (harness, node):
        harness.spin_for(LATE_S)
        assert node.simulation is None
        assert list(node.timers) == []  # nothing polls while it waits
        (subscription,) = [s for s in node.subscriptions if s.topic_name == '/robot_description']
        publish_description(harness, urdf)
        sim = wait_built(harness, node)
        assert sim.simulation.description.name == 'two_link_arm'
        assert str(sim.simulation.description.source) == '/robot_description'
        # robot_state_publisher owns the topic and TF: sim_node publishes neither.
        publishers, _subscriptions = sim.own_topics()
        assert '/robot_description' not in publishers and '/tf' not in publishers
    lines = capfd.readouterr().err.splitlines()
    waiting = [line for line in lines if WAITING in line]
    assert len(waiting) == 1 and waiting[0].startswith('[INFO]'), lines
    assert "'/robot_description'" in waiting[0]
    assert any("Received robot description from topic '/robot_description'" in line
               for line in lines)


def test_a_description_published_before_it_started_is_still_received(tmp_path):
    harness = NodeHarness()
    try:
        publish_description(harness, arm_urdf(tmp_path))
        harness.spin_for(0.2)  # the description is out before sim_node exists
        node = harness.add(SimNode(
            context=harness.context, cli_args=['--ros-args', '-r', '__node:=controller_manager'],
            parameter_overrides=[Parameter('real_time_factor', value=0.0)]))
        wait_built(harness, node)
    finally:
        harness.close()


def test_nothing_is_active_until_spawned_and_the_joints_are_held(tmp_path):
    with drop_in_node() as (harness, node):
        publish_description(harness, arm_urdf(tmp_path))
        sim = wait_built(harness, node)
        assert Spawner(sim).controllers() == {}
        held = dict(sim.simulation.joint_positions())
        sim.run_for(0.5)
        assert sim.states == []  # no broadcaster yet
        moved = sim.simulation.joint_positions()
        assert all(abs(moved[joint] - held[joint]) < 1e-3 for joint in held)


def test_spawners_with_param_file_and_controller_ros_args_drive_the_remapped_topic(tmp_path):
    controllers = write_yaml(tmp_path, 'rrbot_controllers.yaml', SPAWNER_YAML)
    with drop_in_node() as (harness, node):
        publish_description(harness, arm_urdf(tmp_path))
        sim = wait_built(harness, node)
        assert spawner_main(sim, [JSB, '--param-file', controllers]) == 0
        remap = '-r ~/commands:=/position_commands'
        assert spawner_main(sim, [FORWARD, '--param-file', controllers,
                                  '--controller-ros-args', remap]) == 0
        listed = Spawner(sim).controllers()
        assert {name: c.state for name, c in listed.items()} == {JSB: 'active', FORWARD: 'active'}
        assert listed[JSB].update_rate == 50  # its own section's
        _publishers, subscriptions = sim.own_topics()
        assert '/position_commands' in subscriptions
        assert f'/{FORWARD}/commands' not in subscriptions
        publisher = sim.probe.create_publisher(Float64MultiArray, '/position_commands', 10)
        assert sim.spin_until(lambda: publisher.get_subscription_count() > 0)
        publisher.publish(Float64MultiArray(data=[0.5, -0.5]))
        assert sim.spin_until(lambda: sim.setpoints(FORWARD) == [0.5, -0.5])
        sim.run_for(2.0)
        assert sim.position('joint1') == pytest.approx(0.5, abs=1e-3)
        assert sim.position('joint2') == pytest.approx(-0.5, abs=1e-3)


def test_controllers_given_as_node_parameters_in_the_managers_layout_need_no_param_file(
        tmp_path, capfd):
    controllers = write_yaml(tmp_path, 'controllers.yaml', MANAGER_YAML)
    with drop_in_node('--params-file', str(controllers), '-p', 'real_time_factor:=0.0') as (
            harness, node):
        assert node.get_parameter(f'{FORWARD}.type').value == FORWARD_TYPE
        assert node.get_parameter('update_rate').value == 50
        publish_description(harness, arm_urdf(tmp_path))
        sim = wait_built(harness, node)
        spawner = Spawner(sim)
        assert spawner.spawn(JSB) == 0 and spawner.spawn(FORWARD) == 0
        listed = spawner.controllers()
        assert listed[FORWARD].update_rate == 50  # the controller_manager's
        assert listed[FORWARD].claimed_interfaces == ['joint1/position', 'joint2/position']
    # The node's own parameters stay its own: no controller is given them (nor warns of them).
    assert f'{FORWARD}.real_time_factor: unknown parameter' not in capfd.readouterr().err


def own_parameters(node) -> dict:
    """Return the parameters a built drop-in sim_node declares for itself, by name.

    Not the controllers' fields (``<controller>.type``...) nor gains, named
    after the controllers, nor those declared without a value.
    """
    controllers = set(node.simulation.manager.declared) | {
        controller.name for controller in node.simulation.manager.controllers}
    return {name: parameter.value for name, parameter in
            node.get_parameters_by_prefix('').items()
            if name.split('.')[0] not in controllers and parameter.value is not None}


def test_none_of_its_own_parameters_given_to_every_node_is_handed_to_a_controller(
        tmp_path, capfd):
    # As a launch file's `parameters=[{'world': ...}]` for the controller manager: launch_ros
    # writes them under `/**`, which every controller's node matches too.
    controllers = write_yaml(tmp_path, 'controllers.yaml', MANAGER_YAML)
    with drop_in_node('--params-file', str(controllers)) as (harness, node):
        publish_description(harness, arm_urdf(tmp_path))
        wait_built(harness, node)
        own = own_parameters(node)
    assert {'world', 'publish_tf', 'camera.rate', 'real_time_factor'} <= set(own)
    wildcard = write_yaml(tmp_path, 'launch_params.yaml',
                          yaml.safe_dump({'/**': {'ros__parameters': own}}))
    capfd.readouterr()
    with drop_in_node('--params-file', str(controllers), '--params-file', str(wildcard)) as (
            harness, node):
        publish_description(harness, arm_urdf(tmp_path))
        sim = wait_built(harness, node)
        spawner = Spawner(sim)
        assert spawner.spawn(JSB) == 0 and spawner.spawn(FORWARD) == 0
        for name in (JSB, FORWARD):
            assert node.simulation.manager.controller(name).config_warnings == []
    assert 'unknown parameter' not in capfd.readouterr().err


def test_a_gazebo_robots_plugin_file_gives_the_controller_manager_its_controllers(
        tmp_path, capfd):
    from ros2_control_fixtures import write_arm

    from pan_tilt_sim.model.description import load_description

    # A gz_ros2_control launch file with its spawn step dropped: the URDF's plugin names
    # the controllers YAML, which Gazebo's controller_manager would have been given.
    plugin_file = tmp_path / 'arm_controllers.yaml'
    urdf = load_description(write_arm(tmp_path, MANAGER_YAML),
                            [f'controllers:={plugin_file}']).urdf_xml
    with drop_in_node() as (harness, node):
        publish_description(harness, urdf)
        sim = wait_built(harness, node)
        spawner = Spawner(sim)
        assert spawner.spawn(JSB) == 0 and spawner.spawn(FORWARD) == 0
        listed = spawner.controllers()
        assert listed[FORWARD].update_rate == 50  # the plugin file's controller_manager's
        assert listed[FORWARD].claimed_interfaces == ['joint1/position', 'joint2/position']
    # The start-up line names the file the controllers came from.
    assert f'(declared in {plugin_file} + the parameters of /controller_manager: ' in (
        capfd.readouterr().err)


def test_a_params_file_given_to_the_controller_manager_is_loaded(tmp_path):
    extra = write_yaml(tmp_path, 'forward.yaml', FORWARD_PARAMETERS_YAML)
    with drop_in_node('-p', f'{FORWARD}.type:={FORWARD_TYPE}',
                      '-p', f'{FORWARD}.params_file:={extra}') as (harness, node):
        publish_description(harness, arm_urdf(tmp_path))
        sim = wait_built(harness, node)
        spawner = Spawner(sim)
        assert spawner.spawn(FORWARD) == 0
        assert spawner.controllers()[FORWARD].claimed_interfaces == ['joint2/position']


def test_a_second_description_is_ignored_with_a_warning(tmp_path, capfd):
    urdf = arm_urdf(tmp_path)
    with drop_in_node() as (harness, node):
        first = publish_description(harness, urdf)
        sim = wait_built(harness, node)
        simulation = sim.simulation
        first.publisher.publish(first.publisher.msg_type(data=urdf.replace('two_link_arm',
                                                                           'other_arm')))
        assert harness.spin_until(
            lambda: 'ignoring a new one' in capfd.readouterr().err, BUILD_BUDGET_S)
        assert node.simulation is simulation
        assert simulation.description.name == 'two_link_arm'


def test_in_a_namespace_it_reads_that_namespaces_description_and_serves_there(tmp_path):
    with drop_in_node(namespace='/rrbot') as (harness, node):
        publish_description(harness, arm_urdf(tmp_path), namespace='/rrbot')
        sim = wait_built(harness, node)
        assert node.get_fully_qualified_name() == '/rrbot/controller_manager'
        assert sim.node.topic('joint_states') == '/rrbot/joint_states'
        controllers = write_yaml(tmp_path, 'rrbot_controllers.yaml', SPAWNER_YAML)
        assert spawner_main(sim, [JSB, FORWARD, '--param-file', controllers],
                            namespace='/rrbot') == 0
        _publishers, subscriptions = sim.own_topics()
        assert f'/rrbot/{FORWARD}/commands' in subscriptions
        assert sim.spin_until(lambda: sim.states), 'no /rrbot/joint_states'


def test_the_description_topic_follows_the_nodes_remap_rules(tmp_path):
    with drop_in_node('-r', 'robot_description:=/arm/robot_description') as (harness, node):
        publish_description(harness, arm_urdf(tmp_path), namespace='/arm')
        sim = wait_built(harness, node)
        assert str(sim.simulation.description.source) == '/arm/robot_description'


def test_a_description_that_cannot_be_simulated_ends_it_naming_the_topic():
    with drop_in_node() as (harness, node):
        publish_description(harness, '<robot name="x"><link name="a"/></robot>')
        with pytest.raises(DescriptionError, match='^/robot_description: the robot has no '):
            harness.spin_until(lambda: node.simulation is not None, BUILD_BUDGET_S)


@pytest.mark.parametrize(('name', 'value'), [('controllers_file', 'c.yaml'),
                                             ('robot_namespace', 'arm')])
def test_parameters_that_ros2_control_node_takes_otherwise_are_refused(name, value):
    with pytest.raises(ParameterError, match=f"^parameter '{name}' is not used by sim_node "
                                             "named 'controller_manager'"):
        with drop_in_node(**{name: value}):
            pass


def test_an_unknown_hardware_component_in_its_initial_state_is_warned_about(tmp_path, capfd):
    with drop_in_node('-p', 'hardware_components_initial_state.inactive:=[NoSuchArm]') as (
            harness, node):
        publish_description(harness, arm_urdf(tmp_path))
        wait_built(harness, node)
    err = capfd.readouterr().err
    assert "Hardware component 'NoSuchArm' is unknown, therefore not set in 'inactive' state." in (
        err)


def test_ros2_control_node_s_real_time_settings_are_taken_with_one_warning_each(capfd):
    with drop_in_node('-p', 'thread_priority:=90', '-p', 'cpu_affinity:=1',
                      lock_memory=False):
        pass
    err = capfd.readouterr().err
    for name in ('thread_priority', 'cpu_affinity', 'lock_memory'):
        assert err.count(f"parameter '{name}' is not honoured") == 1, err


def test_named_sim_node_an_empty_description_file_also_means_the_topic(tmp_path):
    controllers = write_yaml(tmp_path, 'c.yaml', MANAGER_YAML)
    harness = NodeHarness()
    try:
        node = harness.add(SimNode(context=harness.context, parameter_overrides=[
            Parameter('robot_description_file', value=''),
            Parameter('controllers_file', value=str(controllers))]))
        assert node.simulation is None and node.get_name() == 'sim_node'
        publish_description(harness, arm_urdf(tmp_path))
        sim = wait_built(harness, node)
        # Its own controller_manager node comes with the simulation, and spins.
        assert sim.node.controller_manager is not None
        assert Spawner(sim).controllers()[JSB].state == 'active'
    finally:
        harness.close()


def test_a_diffbot_launch_drives_from_cmd_vel_with_its_spawned_drive_controller(tmp_path):
    # Example 2's shape: the drive controller exists only in the spawner's --param-file, its
    # ~/cmd_vel remapped to /cmd_vel; the robot stands on its wheels, free, from the start.
    drive = {'type': 'diff_drive_controller/DiffDriveController', 'cmd_vel_timeout': 0.0,
             **drive_parameters()}
    controllers = write_yaml(tmp_path, 'diffbot_controllers.yaml', yaml.safe_dump({
        JSB: {'ros__parameters': {'type': 'joint_state_broadcaster/JointStateBroadcaster'}},
        'diffbot_base_controller': {'ros__parameters': drive}}))
    with drop_in_node() as (harness, node):
        publish_description(harness, rover_urdf())
        sim = wait_built(harness, node)
        assert not sim.simulation.physics.fixed_base
        assert spawner_main(sim, [JSB, 'diffbot_base_controller', '--param-file', controllers,
                                  '--controller-ros-args', '-r ~/cmd_vel:=/cmd_vel']) == 0
        odometry = sim.collect(Odometry, '/diffbot_base_controller/odom')
        publisher = sim.probe.create_publisher(TwistStamped, '/cmd_vel', 10)
        assert sim.spin_until(lambda: publisher.get_subscription_count() > 0)
        forward = TwistStamped()
        forward.twist.linear.x = 0.2
        publisher.publish(forward)
        base = sim.simulation.physics.base_frame
        assert sim.spin_until(lambda: base().translation[0] > 0.3, BUILD_BUDGET_S), (
            'the base did not drive 0.3 m')
        publisher.publish(TwistStamped())
        assert sim.spin_until(lambda: odometry and abs(odometry[-1].twist.twist.linear.x) < 1e-3
                              and odometry[-1].pose.pose.position.x > 0.3, BUILD_BUDGET_S)
        sim.run_for(0.2)
        assert odometry[-1].pose.pose.position.x == pytest.approx(base().translation[0],
                                                                  rel=0.02)
