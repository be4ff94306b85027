"""sim_node with robots other than the pan/tilt: the my_robot example, the three-joint arm.

In-process like test_sim_node.py (node and probe on one executor,
real_time_factor 0, bounded spins), except the start-up error test, which
needs the exit code and so runs sim_node in its own process.
"""

import contextlib
import os
import pathlib
import subprocess

import mesh_fixtures as mf
import pytest
import sim_process
from builtin_interfaces.msg import Duration
from node_harness import sim_node, stamp_s
from robot_fixtures import JointDef, write_star_robot, write_text
from std_msgs.msg import Float64, Float64MultiArray
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from pan_tilt_sim.ros.ros_interfaces import stamp
from pan_tilt_sim.ros.runner import EXIT_CONFIGURATION_ERROR

STARTUP_BUDGET_S = 30.0


@pytest.fixture
def start_node():
    """Start sim_nodes with the given parameters; all are stopped after the test."""
    with contextlib.ExitStack() as running:
        yield lambda **parameters: running.enter_context(sim_node(**parameters))


# --- the my_robot example: my_robot_pkg from an ament prefix, with generated meshes ---------

@pytest.fixture
def my_robot_package(tmp_path, monkeypatch, original_examples):
    """Install my_robot_pkg (URDF, meshes, its controllers YAML) into a temporary ament prefix."""
    prefix = mf.make_my_robot_package(tmp_path, original_examples / 'my_robot.urdf')
    mf.write_file(prefix / 'share' / mf.MY_ROBOT_PACKAGE / 'config' / 'joint_controllers.yaml',
                  (original_examples / 'joint_controllers.yaml').read_bytes())
    monkeypatch.setenv('AMENT_PREFIX_PATH', os.pathsep.join(
        [str(prefix), os.environ.get('AMENT_PREFIX_PATH', '')]))
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path / 'cache'))
    from ament_index_python.packages import get_package_share_directory
    return pathlib.Path(get_package_share_directory(mf.MY_ROBOT_PACKAGE))


def test_my_robot_example_arm_joint_reaches_its_command_under_the_plugin_namespace(my_robot_package,
                                                                      start_node):
    robot = start_node(
        robot_description_file=str(my_robot_package / mf.MY_ROBOT_URDF_RELPATH),
        controllers_file=str(my_robot_package / 'config' / 'joint_controllers.yaml'))
    assert robot.node.robot_namespace == '/my_robot'
    topics = robot.topics_once_seen('/my_robot/arm_controller/command', '/my_robot/joint_states')
    assert topics['/my_robot/arm_controller/command'] == ['std_msgs/msg/Float64']
    assert topics['/my_robot/joint_states'] == ['sensor_msgs/msg/JointState']
    robot.command('arm_controller', Float64(data=1.57))
    robot.run_for(4.0)  # 1.57 rad at the URDF's 1 rad/s, then settling
    assert robot.position('arm_joint') == pytest.approx(1.57, abs=0.01)
    assert list(robot.states[-1].name) == ['arm_joint']


def test_my_robot_missing_mesh_ends_start_up_with_code_2_naming_the_uri(my_robot_package, tmp_path):
    missing = my_robot_package / mf.MY_ROBOT_MESHES['arm_collision']
    missing.unlink()
    result = subprocess.run(
        sim_process.command(
            '-p', f'robot_description_file:={my_robot_package / mf.MY_ROBOT_URDF_RELPATH}',
            '-p', f"controllers_file:={my_robot_package / 'config' / 'joint_controllers.yaml'}"),
        capture_output=True, text=True, env=sim_process.environment(),
        timeout=STARTUP_BUDGET_S)
    assert result.returncode == EXIT_CONFIGURATION_ERROR
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert 'package://my_robot_pkg/meshes/collision/arm.stl' in lines[0]
    assert str(missing) in lines[0]


# --- the three-joint arm, ros2_control style -----------------------------------------------

@pytest.fixture
def arm(repo_root, start_node):
    return start_node(
        robot_description_file=str(repo_root / 'urdf' / 'three_joint_arm.xacro'),
        controllers_file=str(repo_root / 'config' / 'three_joint_arm_controllers.yaml'))


def test_arm_topics_are_at_the_root_with_ros2_control_names(arm):
    topics = arm.topics_once_seen('/joint_states', '/arm_controller/joint_trajectory',
                                  '/gripper_controller/commands')
    assert topics['/joint_states'] == ['sensor_msgs/msg/JointState']
    assert topics['/arm_controller/joint_trajectory'] == [
        'trajectory_msgs/msg/JointTrajectory']
    assert topics['/gripper_controller/commands'] == ['std_msgs/msg/Float64MultiArray']


def test_arm_joint_states_come_at_the_controller_manager_update_rate(arm):
    arm.run_for(1.05)
    first_second = [stamp_s(m) for m in arm.states if stamp_s(m) < 1.0 - 1e-9]
    assert len(first_second) == 100
    assert list(arm.states[0].name) == ['shoulder_joint', 'extend_joint', 'wrist_joint',
                                        'left_finger_joint', 'right_finger_joint']


def test_arm_follows_a_three_point_trajectory_sent_on_its_topic(arm):
    waypoints = [(1.0, {'wrist_joint': 1.0, 'shoulder_joint': 0.5, 'extend_joint': 0.05}),
                 (2.0, {'wrist_joint': 3.0, 'shoulder_joint': 1.0, 'extend_joint': 0.15}),
                 (3.0, {'wrist_joint': 7.0, 'shoulder_joint': -0.5, 'extend_joint': 0.1})]
    names = list(waypoints[0][1])
    start = round(arm.node.simulation.time + 0.5, 2)  # a stamp on the 10 ms state grid
    message = JointTrajectory(joint_names=names)
    stamp(start, message.header.stamp)
    message.points = [JointTrajectoryPoint(
        positions=[targets[joint] for joint in names],
        time_from_start=Duration(sec=int(when), nanosec=round(when % 1 * 1e9)))
        for when, targets in waypoints]
    arm.command('arm_controller', message)
    arm.run_for(start + 3.5 - arm.node.simulation.time)
    for when, targets in waypoints:
        state = arm.state_at(start + when)
        for joint, target in targets.items():
            assert arm.position(joint, state) == pytest.approx(target, abs=0.02), (when, joint)


def test_gripper_moves_both_fingers_the_mimic_one_by_its_leader(arm):
    arm.command('gripper_controller', Float64MultiArray(data=[0.03]))
    arm.run_for(1.0)
    assert arm.position('left_finger_joint') == pytest.approx(0.03, abs=0.001)
    assert arm.position('right_finger_joint') == pytest.approx(-0.03, abs=0.001)


# --- every group controller type, through its topic ----------------------------------------

GROUPS = [
    ('position_controllers/JointGroupPositionController', '', [0.5, -0.1]),
    ('velocity_controllers/JointGroupVelocityController', '', [0.5, -0.1]),
    ('effort_controllers/JointGroupEffortController', '', [0.5, -0.1]),
    ('forward_command_controller/ForwardCommandController', 'interface_name: position',
     [0.5, -0.1]),
]


@pytest.mark.parametrize(('type_name', 'extra', 'command'), GROUPS,
                         ids=[type_name.split('/')[1] for type_name, _, _ in GROUPS])
def test_group_controller_moves_its_joints_through_its_commands_topic(
        tmp_path, start_node, type_name, extra, command):
    robot_file = write_star_robot(tmp_path, [JointDef('pan', 'revolute', -1.5, 1.5),
                                             JointDef('slide', 'prismatic', -0.3, 0.3)])
    controllers = write_text(tmp_path, 'group.yaml', f"""
        controller_manager:
          ros__parameters:
            joint_state_broadcaster:
              type: joint_state_broadcaster/JointStateBroadcaster
            group:
              type: {type_name}
        group:
          ros__parameters:
            joints: [pan, slide]
            {extra}
        """)
    robot = start_node(robot_namespace='star', robot_description_file=str(robot_file),
                       controllers_file=str(controllers))
    topics = robot.topics_once_seen('/star/group/commands', '/star/joint_states')
    assert topics['/star/group/commands'] == ['std_msgs/msg/Float64MultiArray']
    assert topics['/star/joint_states'] == ['sensor_msgs/msg/JointState']
    robot.command('group', Float64MultiArray(data=[1.0, 1.0, 1.0]))
    robot.run_for(0.2)
    assert [robot.position('pan'), robot.position('slide')] == [0.0, 0.0]
    robot.command('group', Float64MultiArray(data=command))
    robot.run_for(1.0)
    for joint, value in zip(('pan', 'slide'), command, strict=True):
        moved = robot.position(joint)
        assert moved * value > 0.0 and abs(moved) > 0.02, (joint, moved)
