"""Gazebo launch files with only package names changed run on sim_node (several robots too).

Each fixture is written in an upstream shape with ``pan_tilt_sim`` where the Gazebo-side
package was (test/data/gz_shaped/, test/data/classic_shaped/); the launch stand-in
(test/launch_stand_in.py) follows their includes into pan_tilt_sim's gz_sim.launch.py and
gazebo.launch.py and starts the stand-ins (create, parameter_bridge, spawn_entity.py) as
processes, the spawners in-process once create or spawn_entity.py has exited.
"""

from __future__ import annotations

import importlib.util
import pathlib

import launch_stand_in
import pytest
from builtin_interfaces.msg import Duration
from geometry_msgs.msg import Twist, TwistStamped
from mobile_fixtures import (
    GZ_DIFF_DRIVE,
    WHEEL_RADIUS,
    WHEEL_SEPARATION,
    plugin_rover_urdf,
    rover_urdf,
)
from nav_msgs.msg import Odometry
from node_harness import PROBE_QUEUE, NodeHarness
from sensor_msgs.msg import JointState
from spawner_client import Spawner
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('controller_manager_msgs') is None
    or importlib.util.find_spec('simulation_interfaces') is None,
    reason='controller_manager_msgs or simulation_interfaces is not installed')

DATA = pathlib.Path(__file__).resolve().parents[1] / 'data'
GZ_ARM = DATA / 'gz_shaped' / 'arm_gz_spawn.launch.py'
GZ_ROVER = DATA / 'gz_shaped' / 'rover_gz_bridge.launch.py'
ROVER_BRIDGE = DATA / 'gz_shaped' / 'rover_bridge.yaml'
ROVER_WORLD = DATA / 'gz_shaped' / 'rover_world.launch.py'  # includes rover_spawn.launch.py
CLASSIC_ARM = DATA / 'classic_shaped' / 'arm_classic.launch.py'
GZ_TWO_ROVERS = DATA / 'gz_shaped' / 'two_rovers_namespaced.launch.py'
# Nav2's multi-robot top level: a GroupAction per robot including rover_in_namespace.launch.py.
GZ_TWO_ROVERS_GROUPED = DATA / 'gz_shaped' / 'two_rovers_grouped.launch.py'
TWO_ROVERS_BRIDGE = DATA / 'gz_shaped' / 'two_rovers_bridge.yaml'
# The rover's gz DiffDrive with its topics under the namespace its xacro is given.
NAMESPACED_DIFF_DRIVE = f'''
  <plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">
    <left_joint>left_wheel_joint</left_joint><right_joint>right_wheel_joint</right_joint>
    <wheel_separation>{WHEEL_SEPARATION}</wheel_separation>
    <wheel_radius>{WHEEL_RADIUS}</wheel_radius>
    <topic>/$(arg namespace)/cmd_vel</topic><odom_topic>/$(arg namespace)/odometry</odom_topic>
    <odom_publish_frequency>50</odom_publish_frequency>
  </plugin>'''
ARM_JOINTS = ['shoulder_joint', 'extend_joint', 'wrist_joint']
TARGET = [0.5, 0.1, 0.3]
REACHED_RAD = 0.02
MOVE_BUDGET_S = 30.0
EXIT_BUDGET_S = 60.0
DRIVE_SPEED = 0.3  # m/s


def _arm_follows(harness: NodeHarness, states: list[JointState], topic: str) -> None:
    publisher = harness.probe.create_publisher(JointTrajectory, topic, 10)
    assert harness.spin_until(lambda: publisher.get_subscription_count() > 0)
    publisher.publish(JointTrajectory(joint_names=ARM_JOINTS, points=[JointTrajectoryPoint(
        positions=TARGET, time_from_start=Duration(sec=1))]))

    def reached() -> bool:
        if not states:
            return False
        positions = dict(zip(states[-1].name, states[-1].position, strict=True))
        return all(abs(positions[joint] - target) < REACHED_RAD
                   for joint, target in zip(ARM_JOINTS, TARGET, strict=True))

    assert harness.spin_until(reached, MOVE_BUDGET_S), (
        f'the arm did not reach {TARGET}: last {states[-1] if states else None}')


def _run_arm(monkeypatch, tmp_path, launch_file: pathlib.Path, spawn_step: str):
    """Run an arm launch file; return (spawner exits, spawn step's exit, outputs)."""
    launch = launch_stand_in.StandInLaunch(launch_stand_in.load(launch_file, monkeypatch),
                                           tmp_path)
    harness = NodeHarness()
    states: list[JointState] = []
    harness.probe.create_subscription(JointState, '/joint_states', states.append, PROBE_QUEUE)
    try:
        launch.start_processes()
        codes = launch.run_spawners(harness)
        spawned = launch.processes[spawn_step].returncode
        listed = {name: c.state for name, c in Spawner(harness).controllers().items()}
        assert listed == {'joint_state_broadcaster': 'active', 'arm_controller': 'active'}
        _arm_follows(harness, states, '/arm_controller/joint_trajectory')
        alive = {name: process.poll() is None for name, process in launch.processes.items()}
    finally:
        harness.close()
        outputs = launch.close()
    return codes, spawned, alive, outputs


def test_a_gz_launch_file_spawns_with_create_and_its_spawners_run_on_creates_exit(
        monkeypatch, tmp_path):
    codes, spawned, alive, outputs = _run_arm(monkeypatch, tmp_path, GZ_ARM, 'create')
    assert codes == [0, 0] and spawned == 0, outputs.get('create')
    # sim_node (gz_sim.launch.py's) and the bridge keep running; create has ended.
    assert alive == {'sim_node': True, 'create': False, 'parameter_bridge': True,
                     'robot_state_publisher': True}
    assert 'Entity creation successfull.' in outputs['create']
    assert 'No robot yet: waiting for one on' in outputs['sim_node']
    assert "simulating 'three_joint_arm'" in outputs['sim_node']
    assert 'parameter_bridge' in outputs and 'refused' not in outputs['parameter_bridge']


def test_a_classic_launch_file_spawns_with_spawn_entity_py(monkeypatch, tmp_path):
    codes, spawned, _alive, outputs = _run_arm(monkeypatch, tmp_path, CLASSIC_ARM,
                                               'spawn_entity.py')
    assert codes == [0, 0] and spawned == 0, outputs.get('spawn_entity.py')
    assert "simulating 'arm'" in outputs['sim_node']  # -entity names it


def test_a_bridge_config_gives_the_robots_gz_topics_their_ros_names_and_types(
        monkeypatch, tmp_path):
    urdf = tmp_path / 'rover.urdf'
    urdf.write_text(plugin_rover_urdf(GZ_DIFF_DRIVE))
    launch = launch_stand_in.StandInLaunch(
        launch_stand_in.load(GZ_ROVER, monkeypatch), tmp_path,
        {'description_file': str(urdf), 'bridge_config': str(ROVER_BRIDGE)})
    harness = NodeHarness()
    odometry: list[Odometry] = []
    harness.probe.create_subscription(Odometry, '/odom', odometry.append, PROBE_QUEUE)
    try:
        launch.start_processes()
        assert launch.wait_for_exit('create', EXIT_BUDGET_S) == 0, launch.output('create')
        assert harness.spin_until(lambda: odometry), (
            f'no /odom; the topics: {sorted(dict(harness.probe.get_topic_names_and_types()))}')
        names = dict(harness.probe.get_topic_names_and_types())
        command = harness.probe.create_publisher(TwistStamped, '/cmd_vel', 10)
        assert harness.spin_until(lambda: command.get_subscription_count() > 0), (
            'nobody reads /cmd_vel as TwistStamped')

        def driving() -> bool:
            message = TwistStamped()
            message.twist.linear.x = DRIVE_SPEED
            command.publish(message)
            return bool(odometry) and odometry[-1].twist.twist.linear.x > 0.8 * DRIVE_SPEED

        assert harness.spin_until(driving, MOVE_BUDGET_S), (
            f'the rover did not drive: {odometry[-1].twist.twist if odometry else None}')
        alive = launch.processes['parameter_bridge'].poll() is None
    finally:
        harness.close()
        outputs = launch.close()
    assert alive, outputs['parameter_bridge']
    assert 'to hand over its topics' in outputs['sim_node'] or (
        'bridged by' in outputs['parameter_bridge'])
    # The gz names are not on ROS: the bridge gave them others (unless sim_node had built the
    # robot before it discovered the bridge, and relays them).
    assert ('/model/rover/odometry' not in names and '/model/rover/cmd_vel' not in names) or (
        'existed before its bridge handed over' in outputs['sim_node']), outputs['sim_node']


def services_of(harness: NodeHarness, node: str) -> set[str]:
    """The services the graph shows for node ``/<node>`` (none while it is not seen yet)."""
    if (node, '/') not in harness.probe.get_node_names_and_namespaces():
        return set()
    return {name for name, _types in harness.probe.get_service_names_and_types_by_node(node, '/')}


def test_a_top_level_file_in_nav2_bringups_shape_brings_its_xacro_world_and_the_spawn_file(
        monkeypatch, tmp_path):
    # The world is written by `xacro -o` while gz_sim.launch.py starts; the robot comes
    # from an included spawn file (Nav2's spawn_tb3.launch.py shape: -string, -R -P -Y).
    from simulation_interfaces.srv import GetEntities

    urdf = tmp_path / 'rover.urdf'
    urdf.write_text(plugin_rover_urdf(GZ_DIFF_DRIVE))
    launch = launch_stand_in.StandInLaunch(
        launch_stand_in.load(ROVER_WORLD, monkeypatch), tmp_path,
        {'description_file': str(urdf)})
    harness = NodeHarness()
    odometry: list[Odometry] = []
    harness.probe.create_subscription(Odometry, '/odom', odometry.append, PROBE_QUEUE)
    world = pathlib.Path(launch.arguments['gz_args'].split()[-1])  # the file xacro writes
    try:
        launch.start_processes()
        assert world.is_file()
        assert launch.wait_for_exit('create', EXIT_BUDGET_S) == 0, launch.output('create')
        assert harness.spin_until(lambda: odometry), 'no /odom'
        entities = harness.call(GetEntities, '/gzserver/get_entities', GetEntities.Request())
        # Its gz systems alone run it: no controller manager, as in Gazebo (only
        # gz_ros2_control's plugin makes one).  /reset_simulation is made after it would be.
        assert harness.spin_until(lambda: '/reset_simulation' in services_of(harness, 'gzserver'))
        nodes = harness.probe.get_node_names_and_namespaces()
    finally:
        harness.close()
        outputs = launch.close()
    assert {'crate', 'rover'} <= set(entities.entities), (entities.entities,
                                                          outputs['sim_node'])
    assert not world.exists()  # its OnShutdown removed it, as nav2_bringup's does
    assert [node for node in nodes if node[0] == 'controller_manager'] == [], nodes


def namespaced_rover_xacro() -> str:
    """The plugin rover as a xacro taking ``namespace`` (Nav2's TB3 xacro takes it so)."""
    urdf = rover_urdf('rover', ros2_control=False,
                      extra=f'<gazebo>{NAMESPACED_DIFF_DRIVE}</gazebo>')
    return urdf.replace('<robot name="rover">', (
        '<robot name="rover" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:arg name="namespace" default="robot"/>'))


@pytest.mark.parametrize('launch_file', [GZ_TWO_ROVERS, GZ_TWO_ROVERS_GROUPED],
                         ids=['nodes_in_namespaces', 'grouped_includes'])
def test_two_robots_in_namespaces_share_one_world_each_driven_on_its_own_cmd_vel(
        monkeypatch, tmp_path, launch_file):
    xacro = tmp_path / 'rover.urdf.xacro'
    xacro.write_text(namespaced_rover_xacro())
    launch = launch_stand_in.StandInLaunch(
        launch_stand_in.load(launch_file, monkeypatch), tmp_path,
        {'description_file': str(xacro), 'bridge_config': str(TWO_ROVERS_BRIDGE)})
    harness = NodeHarness()
    odometry: dict[str, list[Odometry]] = {'robot1': [], 'robot2': []}
    for robot, received in odometry.items():
        harness.probe.create_subscription(Odometry, f'/{robot}/odom', received.append,
                                          PROBE_QUEUE)
    try:
        launch.start_processes()
        for create in ('create', 'create_2'):
            assert launch.wait_for_exit(create, EXIT_BUDGET_S) == 0, launch.output(create)
        assert harness.spin_until(lambda: all(odometry.values())), (
            f'no odometry from {[robot for robot, got in odometry.items() if not got]}; '
            f'the topics: {sorted(dict(harness.probe.get_topic_names_and_types()))}')
        command = harness.probe.create_publisher(Twist, '/robot2/cmd_vel', 10)
        assert harness.spin_until(lambda: command.get_subscription_count() > 0)

        def driving() -> bool:
            message = Twist()
            message.linear.x = DRIVE_SPEED
            command.publish(message)
            return odometry['robot2'][-1].pose.pose.position.x > 0.3

        assert harness.spin_until(driving, MOVE_BUDGET_S), (
            f"robot2 did not drive: {odometry['robot2'][-1].pose.pose.position}")
        assert abs(odometry['robot1'][-1].pose.pose.position.x) < 0.01
        # Each robot's robot_state_publisher in its namespace.
        publishers = {('robot_state_publisher', '/robot1'), ('robot_state_publisher', '/robot2')}
        assert harness.spin_until(
            lambda: publishers <= set(harness.probe.get_node_names_and_namespaces())), (
            harness.probe.get_node_names_and_namespaces())
    finally:
        harness.close()
        outputs = launch.close()
    assert "simulating 'robot2'" in outputs['sim_node']
    assert 'Traceback' not in outputs['sim_node']  # it ends cleanly with both robots
