"""A ros2_control launch file run with sim_node as its control node, and sim_node left waiting.

examples/launch/arm_ros2_control.launch.py is written in ros2_control_demos'
shape (pan_tilt_sim's ros2_control_node, unnamed, with the controllers YAML,
robot_state_publisher with the xacro output, spawners with ``--param-file``
and ``--controller-ros-args`` chained by OnProcessExit); a stand-in of the
launch API carries it out (test/support/launch_stand_in.py: sim_node and a stand-in
robot_state_publisher as processes, spawners in-process as jazzy's spawner calls).
test/data/gz_shaped/arm_sim_control.launch.py is a Gazebo launch in UR's shape
(its nodes made by an OpaqueFunction) with the spawn step swapped for sim_node.
With nobody publishing robot_description, the program says so once and waits idle.
"""

from __future__ import annotations

import importlib.util
import os
import selectors
import sys
import time

import launch_stand_in
import pytest
import sim_process
from builtin_interfaces.msg import Duration
from node_harness import PROBE_QUEUE, NodeHarness
from rcl_interfaces.srv import GetParameters
from sensor_msgs.msg import JointState
from spawner_client import Spawner
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('controller_manager_msgs') is None,
    reason='controller_manager_msgs is not installed')

LAUNCH_FILE = ('examples', 'launch', 'arm_ros2_control.launch.py')
GZ_SHAPED_LAUNCH_FILE = ('test', 'data', 'gz_shaped', 'arm_sim_control.launch.py')
ARM_JOINTS = ['shoulder_joint', 'extend_joint', 'wrist_joint']
TARGET = [0.5, 0.1, 0.3]
REACHED_RAD = 0.02
MOVE_BUDGET_S = 30.0
READ_BUDGET_S = 30.0
IDLE_WATCH_S = 2.0
# CPU seconds the waiting program may use while watched for IDLE_WATCH_S of wall time
# (a polling loop would use about all of it).
IDLE_CPU_S = 0.3
WAITING = 'Waiting for the robot description on'


def test_the_launch_file_swaps_only_the_control_node(repo_root, monkeypatch):
    actions = launch_stand_in.load(repo_root.joinpath(*LAUNCH_FILE), monkeypatch)
    nodes = [action for action in actions if isinstance(action, launch_stand_in.Node)]
    control = nodes[0]
    # ros2_control_node, unnamed as in ros2_control_demos: only its package differs.
    assert (control.kwargs['package'], control.kwargs['executable'],
            control.kwargs.get('name')) == ('pan_tilt_sim', 'ros2_control_node', None)
    assert [(node.kwargs['package'], node.kwargs['executable']) for node in nodes[1:]] == [
        ('robot_state_publisher', 'robot_state_publisher'), ('controller_manager', 'spawner')]


def test_the_launch_file_starts_the_simulation_spawns_and_the_arm_follows_its_command(
        repo_root, monkeypatch, tmp_path):
    actions = launch_stand_in.load(repo_root.joinpath(*LAUNCH_FILE), monkeypatch)
    launch = launch_stand_in.StandInLaunch(actions, tmp_path)
    harness = NodeHarness()
    states: list[JointState] = []
    harness.probe.create_subscription(JointState, '/joint_states', states.append, PROBE_QUEUE)
    try:
        launch.start_processes()
        assert launch.run_spawners(harness) == [0, 0]
        listed = {name: c.state for name, c in Spawner(harness).controllers().items()}
        assert listed == {'joint_state_broadcaster': 'active', 'arm_controller': 'active'}
        # --controller-ros-args "-r ~/joint_trajectory:=/arm/joint_trajectory"
        _assert_the_arm_follows(harness, states, '/arm/joint_trajectory')
    finally:
        harness.close()
        errors = launch.close()
    log = errors['ros2_control_node']
    assert log.count(WAITING) <= 1, log
    assert "Received robot description from topic '/robot_description'" in log


def _assert_the_arm_follows(harness: NodeHarness, states: list[JointState], topic: str) -> None:
    """Send TARGET as a JointTrajectory on ``topic``; wait until /joint_states is there."""
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


def test_a_gz_shaped_launch_built_in_an_opaque_function_spawns_and_the_arm_follows(
        repo_root, monkeypatch, tmp_path):
    actions = launch_stand_in.load(repo_root.joinpath(*GZ_SHAPED_LAUNCH_FILE), monkeypatch)
    launch = launch_stand_in.StandInLaunch(actions, tmp_path,
                                           {'with_gripper': 'false', 'scenery': 'false'})
    harness = NodeHarness()
    states: list[JointState] = []
    harness.probe.create_subscription(JointState, '/joint_states', states.append, PROBE_QUEUE)
    try:
        launch.start_processes()
        # No spawner for the gripper: its event handler's condition does not hold.
        assert launch.run_spawners(harness) == [0, 0]
        # Their types and the arm's effort interfaces come from the controllers file the
        # URDF's gazebo_ros2_control plugin names: the launch file gives sim_node no other.
        listed = {name: (c.state, c.type, sorted(c.claimed_interfaces))
                  for name, c in Spawner(harness).controllers().items()}
        assert listed == {
            'joint_state_broadcaster': ('active', 'joint_state_broadcaster/JointStateBroadcaster',
                                        []),
            'arm_controller': ('active', 'joint_trajectory_controller/JointTrajectoryController',
                               sorted(f'{joint}/effort' for joint in ARM_JOINTS))}
        # IfElseSubstitution's else_value, scenery:=false.
        world = harness.call(GetParameters, '/controller_manager/get_parameters',
                             GetParameters.Request(names=['world']))
        assert [value.string_value for value in world.values] == ['empty']
        _assert_the_arm_follows(harness, states, '/arm_controller/joint_trajectory')
    finally:
        harness.close()
        errors = launch.close()
    assert "Received robot description from topic '/robot_description'" in errors['sim_node']


def test_example_13s_inactive_spawner_of_a_pid_gain_controller_exits_0(monkeypatch, tmp_path):
    from ros2_control_fixtures import (
        PID_GAIN_CONTROLLER,
        THREE_DOF_YAML,
        three_dof_launch,
        three_dof_urdf,
        write,
    )

    # ros2_control_demos example 13's shape: the pid_gain controller is spawned --inactive
    # through controller_manager.launch_utils, as its launch file does.
    urdf = write(tmp_path, 'threedofbot.urdf', three_dof_urdf())
    controllers = write(tmp_path, 'three_robots_controllers.yaml', THREE_DOF_YAML)
    launch_file = write(tmp_path, 'three_robots.launch.py', three_dof_launch(urdf, controllers))
    launch = launch_stand_in.StandInLaunch(launch_stand_in.load(launch_file, monkeypatch),
                                           tmp_path)
    harness = NodeHarness()
    try:
        launch.start_processes()
        assert launch.run_spawners(harness) == [0, 0]
        listed = {name: c.state for name, c in Spawner(harness).controllers().items()}
        assert listed == {'joint_state_broadcaster': 'active',
                          'threedofbot_joint_state_broadcaster': 'inactive',
                          'threedofbot_position_controller': 'inactive',
                          PID_GAIN_CONTROLLER: 'inactive'}
    finally:
        harness.close()
        errors = launch.close()
    assert 'unknown parameter' not in errors['sim_node']  # real_time_factor, given under /**


def _cpu_seconds(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` so far (Linux /proc)."""
    fields = open(f'/proc/{pid}/stat').read().rpartition(')')[2].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def _read(process, seen: list[str], until: str | None, budget_s: float) -> None:
    """Append stderr lines to ``seen`` until one holds ``until`` (None: for ``budget_s``)."""
    deadline = time.monotonic() + budget_s
    with selectors.DefaultSelector() as selector:
        selector.register(process.stderr, selectors.EVENT_READ)
        while until is None or not any(until in line for line in seen):
            remaining = deadline - time.monotonic()
            if remaining <= 0 or process.poll() is not None:
                return
            if selector.select(remaining):
                seen.append(process.stderr.readline())


@pytest.mark.skipif(not sys.platform.startswith('linux'), reason='reads /proc')
def test_with_no_robot_description_it_says_so_once_and_waits_idle():
    process = sim_process.start('-r', '__node:=controller_manager')
    seen: list[str] = []
    try:
        _read(process, seen, WAITING, READ_BUDGET_S)
        assert any(WAITING in line for line in seen), seen
        before = _cpu_seconds(process.pid)
        more: list[str] = []
        _read(process, more, None, IDLE_WATCH_S)
        used = _cpu_seconds(process.pid) - before
        assert process.poll() is None  # still waiting
    finally:
        ended, rest = sim_process.stop(process, 10.0)
    assert ended and process.returncode == 0, rest
    assert more == [], more  # nothing more to say while waiting
    assert used < IDLE_CPU_S, f'{used:.2f} s of CPU in {IDLE_WATCH_S} s of waiting'
    (line,) = [line for line in seen if WAITING in line]
    assert line.startswith('[INFO]') and "'/robot_description'" in line


def test_the_real_launch_api_reads_the_launch_file_where_installed(repo_root):
    try:
        from launch import LaunchDescription  # noqa: I001 (launch/ reads as first-party)
        from launch_ros.actions import Node
    except ImportError:  # from the source tree, its launch/ folder imports as an empty package
        pytest.skip('the ROS 2 launch and launch_ros packages are not installed')
    spec = importlib.util.spec_from_file_location('arm_launch', repo_root.joinpath(*LAUNCH_FILE))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    description = module.generate_launch_description()
    assert isinstance(description, LaunchDescription)
    nodes = [entity for entity in description.entities if isinstance(entity, Node)]
    assert (nodes[0].node_package, nodes[0].node_executable) == ('pan_tilt_sim', 'sim_node')


def test_a_description_it_cannot_simulate_ends_the_program_with_one_error_line():
    from robot_state_publisher_stand_in import RobotStatePublisherStandIn

    process = sim_process.start('-r', '__node:=controller_manager')
    harness = NodeHarness()
    try:
        seen: list[str] = []
        _read(process, seen, WAITING, READ_BUDGET_S)
        harness.add(RobotStatePublisherStandIn('<robot name="x"><link name="a"/></robot>',
                                               context=harness.context))
        assert harness.spin_until(lambda: process.poll() is not None, READ_BUDGET_S), (
            'sim_node kept running on a robot it cannot simulate')
        _stdout, rest = process.communicate(timeout=READ_BUDGET_S)
    finally:
        harness.close()
        if process.poll() is None:
            sim_process.stop(process, 10.0)
    assert process.returncode == 2
    errors = [line for line in rest.splitlines() if not line.startswith('[')]
    assert errors == ['sim_node: error: /robot_description: the robot has no movable joints '
                      'to control'], rest
