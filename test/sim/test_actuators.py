"""Actuators like Gazebo's: a PID on effort when the YAML gives gains, else the ideal actuator.

The ideal actuator (no gains for a position or velocity interface) follows
the limited command within a few steps, holds against gravity, never pushes
harder than the URDF effort limit, and reports what it applied as the
joint's effort -- for a 5 g finger and a 20 kg arm alike.
"""

import math

import pytest
from robot_fixtures import (
    Log,
    arm_holding_torques,
    ros2_control_yaml,
    two_link_arm_urdf,
    write_text,
)

from pan_tilt_sim.controllers.broadcasters.joint_state_broadcaster import JointStateBroadcaster
from pan_tilt_sim.controllers.framework.base import ActuatorKind, Drive
from pan_tilt_sim.controllers.trajectory.trajectory import JointTrajectory, TrajectoryPoint
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.sim.engine import make_simulation

DT = 0.001
ARM_JOINTS = ['joint1', 'joint2']
POSITION_GROUP = ('position_controllers/JointGroupPositionController', {'joints': ARM_JOINTS})


def simulation(tmp_path, urdf, yaml, log=None, **options):
    robot = write_text(tmp_path, 'robot.urdf', urdf)
    controllers = write_text(tmp_path, 'controllers.yaml', yaml)
    return make_simulation(str(robot), str(controllers), DT, logger=log, **options)


def track(sim, joints, seconds):
    """Advance ``seconds``; return the largest |velocity| of each joint meanwhile."""
    fastest = dict.fromkeys(joints, 0.0)
    for _ in range(round(seconds / DT / 10)):
        sim.advance(10)
        for joint in joints:
            fastest[joint] = max(fastest[joint], abs(sim.joint_velocities()[joint]))
    return fastest


def test_a_gravity_loaded_arm_with_a_plain_ros2_control_yaml_reaches_30_degrees(tmp_path):
    target = math.radians(30.0)
    with simulation(tmp_path, two_link_arm_urdf(), ros2_control_yaml(
            {'arm': POSITION_GROUP})) as sim:
        assert [sim.handles[joint].drive for joint in ARM_JOINTS] == [Drive.VELOCITY] * 2
        sim.controller('arm').set_command([target, 0.0])
        fastest = track(sim, ARM_JOINTS, 2.0)
        positions = sim.joint_positions()
        assert positions['joint1'] == pytest.approx(target, abs=0.005)
        assert positions['joint2'] == pytest.approx(0.0, abs=0.005)
        assert fastest['joint1'] <= 2.0 * 1.001  # the URDF velocity limit
        # It holds there, reporting the torque gravity takes (what the motor applied).
        broadcaster = next(c for c in sim.controllers if isinstance(c, JointStateBroadcaster))
        samples = []
        broadcaster.set_sink(lambda time, names, q, v, efforts: samples.append(list(efforts)))
        sim.advance(1000)
        assert sim.joint_positions()['joint1'] == pytest.approx(target, abs=0.005)
        assert samples[-1] == pytest.approx(arm_holding_torques(target, 0.0), rel=1e-3)


def test_the_arm_cannot_push_harder_than_its_effort_limit(tmp_path):
    # Holding horizontal takes 12.3 N*m on joint1; the limit is 5: the arm sags.
    with simulation(tmp_path, two_link_arm_urdf(effort=5.0), ros2_control_yaml(
            {'arm': POSITION_GROUP})) as sim:
        sim.advance(500)
        assert sim.joint_positions()['joint1'] > 0.3
        assert abs(sim.handles['joint1'].effort) == pytest.approx(5.0)


def test_a_20_kg_arm_is_stable_and_reaches_its_targets(tmp_path):
    urdf = two_link_arm_urdf(masses=(12.0, 8.0), length=1.0, effort=1000.0, velocity=2.0)
    with simulation(tmp_path, urdf, ros2_control_yaml({'arm': POSITION_GROUP})) as sim:
        for target in ([0.5, -0.5], [-0.5, 1.0]):
            sim.controller('arm').set_command(target)
            fastest = track(sim, ARM_JOINTS, 3.0)
            positions = sim.joint_positions()
            assert [positions[joint] for joint in ARM_JOINTS] == pytest.approx(target, abs=0.005)
            assert max(fastest.values()) <= 2.0 * 1.001


FINGER = """<?xml version="1.0"?>
<robot name="finger"><link name="palm"/>
  <link name="finger"><inertial><mass value="0.005"/>
    <inertia ixx="1e-7" iyy="1e-7" izz="1e-7" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="finger_joint" type="prismatic"><parent link="palm"/><child link="finger"/>
    <axis xyz="0 0 1"/><limit lower="0" upper="0.04" effort="20" velocity="0.1"/>
    <dynamics damping="1.0" friction="0.5"/></joint>
</robot>
"""


def test_a_5_gram_finger_reaches_its_command_within_its_velocity_limit(tmp_path):
    yaml = ros2_control_yaml({'gripper': (
        'forward_command_controller/ForwardCommandController',
        {'joints': ['finger_joint'], 'interface_name': 'position'})})
    with simulation(tmp_path, FINGER, yaml) as sim:
        sim.controller('gripper').set_command([0.03])
        fastest = track(sim, ['finger_joint'], 1.0)
        assert sim.joint_positions()['finger_joint'] == pytest.approx(0.03, abs=0.0005)
        assert fastest['finger_joint'] <= 0.1 * 1.001
        # Vertical: it holds its own 5 g against gravity (0.049 N), not more.
        assert sim.handles['finger_joint'].effort == pytest.approx(0.005 * 9.81, rel=1e-3)


WHEELS = """<?xml version="1.0"?>
<robot name="cart"><link name="base"/>
  <link name="wheel"><inertial><mass value="0.3"/>
    <inertia ixx="3.4e-5" iyy="3.4e-5" izz="3.4e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="wheel_joint" type="continuous"><parent link="base"/><child link="wheel"/>
    <axis xyz="0 0 1"/><limit effort="100" velocity="1.0"/><dynamics damping="0.2"/></joint>
</robot>
"""


@pytest.mark.parametrize('command, expected', [(0.5, 0.5), (-3.0, -1.0)])
def test_a_velocity_interface_turns_a_light_wheel_at_the_clamped_command(tmp_path, command,
                                                                         expected):
    # DiffBot's wheel: PyBullet's explicit damping 0.2 on 3.4e-5 kg m^2 ran away to the cap.
    yaml = ros2_control_yaml({'wheels': (
        'velocity_controllers/JointGroupVelocityController', {'joints': ['wheel_joint']})})
    with simulation(tmp_path, WHEELS, yaml) as sim:
        sim.controller('wheels').set_command([command])
        sim.advance(200)
        assert sim.joint_velocities()['wheel_joint'] == pytest.approx(expected, abs=1e-9)
        assert sim.handles['wheel_joint'].effort == pytest.approx(0.0, abs=1e-6)  # no damping


def test_a_trajectory_controller_without_gains_follows_the_trajectory_under_gravity(tmp_path):
    yaml = ros2_control_yaml({'arm': (
        'joint_trajectory_controller/JointTrajectoryController',
        {'joints': ARM_JOINTS, 'command_interfaces': '[position]',
         'state_interfaces': '[position, velocity]'})})
    points = (TrajectoryPoint(1.0, (0.5, -0.5)), TrajectoryPoint(2.0, (-0.3, 0.8)))
    with simulation(tmp_path, two_link_arm_urdf(), yaml) as sim:
        sim.controller('arm').set_command(JointTrajectory(tuple(ARM_JOINTS), points))
        errors = []
        for point in points:
            sim.advance(round(point.time_from_start / DT) - sim.steps)
            positions = sim.joint_positions()
            errors += [positions[joint] - target
                       for joint, target in zip(ARM_JOINTS, point.positions, strict=True)]
    assert max(map(abs, errors)) < 0.01


def test_a_trajectory_faster_than_the_velocity_limit_is_followed_at_the_limit(tmp_path):
    # 1.2 rad in 0.3 s asks 4 rad/s of joints whose URDF limit is 2 rad/s: without gains the
    # trajectory controller's ideal actuator holds them to 2 rad/s, and they arrive late.
    yaml = ros2_control_yaml({'arm': (
        'joint_trajectory_controller/JointTrajectoryController',
        {'joints': ARM_JOINTS, 'command_interfaces': '[position]'})})
    points = (TrajectoryPoint(0.3, (1.2, -1.2)),)
    with simulation(tmp_path, two_link_arm_urdf(velocity=2.0), yaml) as sim:
        sim.controller('arm').set_command(JointTrajectory(tuple(ARM_JOINTS), points))
        fastest = track(sim, ARM_JOINTS, 1.5)
        positions = sim.joint_positions()
    assert max(fastest.values()) <= 2.0 * 1.001
    assert min(fastest.values()) >= 2.0 * 0.99  # they did move at the limit
    assert [positions[joint] for joint in ARM_JOINTS] == pytest.approx([1.2, -1.2], abs=0.005)


def test_gazebo_ros_control_pid_gains_put_a_pid_on_a_position_controller(tmp_path):
    yaml = """
        arm:
          joint1_controller: {type: position_controllers/JointPositionController, joint: joint1}
          joint2_controller: {type: position_controllers/JointPositionController, joint: joint2}
          gazebo_ros_control:
            pid_gains:
              joint1: {p: 2000.0, i: 100.0, d: 40.0, i_clamp: 50.0}
        """
    log = Log()
    with simulation(tmp_path, two_link_arm_urdf(), yaml, log) as sim:
        assert sim.handles['joint1'].actuator.kind is ActuatorKind.POSITION_PID
        assert sim.handles['joint2'].actuator.kind is ActuatorKind.IDEAL_POSITION
        assert sim.controller('joint1_controller').pid.gains.p == 2000.0
    assert ("joint 'joint1': position PID on effort (joint1_controller), p 2000 i 100 d 40: "
            'gains from gazebo_ros_control.pid_gains.joint1') in log.infos
    assert ("joint 'joint2': ideal position actuator (joint2_controller), a velocity motor with "
            'at most 100 N*m: no PID gains for it in the YAML') in log.infos


def test_pid_gains_for_a_joint_the_robot_lacks_are_refused(tmp_path):
    yaml = """
        c: {type: position_controllers/JointPositionController, joint: joint1}
        gazebo_ros_control: {pid_gains: {elbow: {p: 1.0}}}
        """
    with pytest.raises(ControllerConfigError, match=r"gazebo_ros_control\.pid_gains\.elbow: "
                                                    "'elbow' is not a movable joint"):
        simulation(tmp_path, two_link_arm_urdf(), yaml)


def test_effort_controllers_keep_their_pid_with_default_gains(tmp_path):
    yaml = """
        c: {type: effort_controllers/JointPositionController, joint: joint1}
        """
    log = Log()
    with simulation(tmp_path, two_link_arm_urdf(), yaml, log) as sim:
        assert sim.handles['joint1'].actuator.kind is ActuatorKind.POSITION_PID
    assert ("joint 'joint1': position PID on effort (c), p 100 i 0.01 d 10: no gains in the "
            'YAML: defaults for c') in log.infos
    assert "joint 'joint2': passive: no active controller" in log.infos


def test_the_pan_tilt_pan_still_settles_within_15_mrad_never_faster_than_its_limit(repo_root):
    with make_simulation(str(repo_root / 'urdf' / 'pan_tilt.xacro'),
                         str(repo_root / 'config' / 'pan_tilt_control.yaml'), DT) as sim:
        assert sim.handles['pan_joint'].actuator.kind is ActuatorKind.POSITION_PID
        sim.controller('joint1_position_controller').set_command(1.0)
        fastest = track(sim, ['pan_joint'], 12.0)
        assert sim.joint_positions()['pan_joint'] == pytest.approx(1.0, abs=0.015)
        assert fastest['pan_joint'] <= 0.1 + 1e-4


def test_switching_controllers_switches_the_actuators(tmp_path):
    gains = '{joint1: {p: 3000.0, i: 500.0, d: 60.0}, joint2: {p: 1000.0, i: 200.0, d: 20.0}}'
    yaml = ros2_control_yaml({
        'arm': ('joint_trajectory_controller/JointTrajectoryController',
                {'joints': ARM_JOINTS, 'command_interfaces': '[position]'}),
        # At the physics rate: the gains are tuned for a 1 ms loop.
        'pid_arm': ('position_controllers/JointGroupPositionController',
                    {'joints': ARM_JOINTS, 'gains': gains, 'update_rate': 1000})})
    with simulation(tmp_path, two_link_arm_urdf(), yaml,
                    active_controllers=['joint_state_broadcaster', 'arm']) as sim:
        assert sim.handles['joint1'].drive is Drive.VELOCITY
        sim.advance(500)
        sim.manager.switch(activate=['pid_arm'], deactivate=['arm'])
        assert [sim.handles[joint].actuator.kind for joint in ARM_JOINTS] == [
            ActuatorKind.POSITION_PID] * 2
        sim.controller('pid_arm').set_command([0.3, -0.3])
        sim.advance(3000)
        positions = sim.joint_positions()
        assert [positions[joint] for joint in ARM_JOINTS] == pytest.approx([0.3, -0.3], abs=0.02)
        sim.manager.switch(activate=['arm'], deactivate=['pid_arm'])
        assert sim.handles['joint1'].drive is Drive.VELOCITY
        held = sim.joint_positions()
        sim.advance(1000)  # an activated controller starts from where the joints are
        assert sim.joint_positions() == pytest.approx(held, abs=0.005)
        sim.manager.switch(deactivate=['arm'])
        assert [sim.handles[joint].actuator.kind for joint in ARM_JOINTS] == [
            ActuatorKind.PASSIVE] * 2


def test_waiting_for_spawners_undriven_joints_hold_and_once_driven_are_passive(tmp_path):
    # gz_ros2_control holds joints no controller commands (hold_joints): before its spawners
    # run, a gravity-loaded arm stays where it starts.  A controller switched off later holds
    # nothing: its joints keep the last effort applied (here the motor's holding torque).
    log = Log()
    with simulation(tmp_path, two_link_arm_urdf(), ros2_control_yaml({'arm': POSITION_GROUP}),
                    log=log, autostart_controllers=False) as sim:
        assert [sim.handles[j].actuator.kind for j in ARM_JOINTS] == [ActuatorKind.HOLD] * 2
        assert any("joint 'joint1': held where it is until a spawned controller drives it"
                   in line for line in log.infos)
        sim.advance(1000)
        assert sim.joint_positions()['joint1'] == pytest.approx(0.0, abs=0.002)
        assert sim.handles['joint1'].effort == pytest.approx(
            arm_holding_torques(0.0, 0.0)[0], rel=0.05)
        spec = sim.manager.declared['arm']
        sim.manager.load('arm', spec.type, spec.params)
        sim.manager.configure('arm')
        sim.manager.switch(activate=['arm'])
        sim.controller('arm').set_command([0.3, 0.0])
        sim.advance(1000)
        assert sim.joint_positions()['joint1'] == pytest.approx(0.3, abs=0.005)
        last = sim.handles['joint1'].effort
        sim.manager.switch(deactivate=['arm'])
        assert sim.handles['joint1'].actuator.kind is ActuatorKind.PASSIVE
        sim.advance(10)
        assert sim.handles['joint1'].effort == last  # the last effort, not a hold
        sim.reset()
        assert sim.handles['joint1'].actuator.kind is ActuatorKind.HOLD  # as at start
        sim.advance(500)
        assert sim.joint_positions()['joint1'] == pytest.approx(0.0, abs=0.002)


def test_waiting_for_spawners_only_joints_with_command_interfaces_are_held(tmp_path):
    # gz_ros2_control holds only the joints its <ros2_control> block gives a command
    # interface (is_actuated); a joint outside the block (an unlisted wheel) stays free.
    block = ('<ros2_control name="arm" type="system"><hardware>'
             '<plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>'
             '<joint name="joint1"><command_interface name="position"/>'
             '<state_interface name="position"/></joint></ros2_control>\n</robot>')
    urdf = two_link_arm_urdf().replace('</robot>', block)
    one_joint = ('position_controllers/JointGroupPositionController', {'joints': ['joint1']})
    with simulation(tmp_path, urdf, ros2_control_yaml({'arm': one_joint}),
                    autostart_controllers=False) as sim:
        assert sim.handles['joint1'].actuator.kind is ActuatorKind.HOLD
        assert sim.handles['joint2'].actuator.kind is ActuatorKind.PASSIVE
        sim.advance(500)
        positions = sim.joint_positions()
        assert positions['joint1'] == pytest.approx(0.0, abs=0.002)
        assert positions['joint2'] > 0.3  # gravity swings it down


def test_started_the_pan_tilt_examples_way_an_undriven_joint_is_passive_and_falls(tmp_path):
    with simulation(tmp_path, two_link_arm_urdf(), ros2_control_yaml({'arm': POSITION_GROUP}),
                    active_controllers=[]) as sim:
        assert sim.handles['joint1'].actuator.kind is ActuatorKind.PASSIVE
        sim.advance(500)
        assert sim.joint_positions()['joint1'] > 0.3
