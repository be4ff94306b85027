"""The controller_manager node: what ros2_control's spawner and unspawner call, as upstream.

A test client plays jazzy's spawner.py step by step (list_controllers; the
controller's ``type`` and ``params_file`` through the node's parameter
services, built the way the spawner builds them; load_controller;
configure_controller; switch_controller STRICT) against sim_node started as
a ros2_control launch file starts gz_ros2_control: ``autostart_controllers``
false, nothing loaded.  Then a UR-style file's controllers are switched back
and forth, and a conflicting STRICT switch is refused.  A chain (a forward
group feeding a chainable controller) is spawned, listed and commanded.
"""

from __future__ import annotations

import importlib.util

import pytest
from builtin_interfaces.msg import Duration
from chaining_fixtures import CHAINABLE_TYPE, register_chainable
from node_harness import sim_node
from rclpy.parameter import Parameter
from ros2_control_fixtures import write, write_arm
from sensor_msgs.msg import JointState
from spawner_client import BEST_EFFORT, Spawner, srv
from std_msgs.msg import Float64MultiArray
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.ros import optional_interfaces
from pan_tilt_sim.ros.sim_node import SimNode
from pan_tilt_sim.share import package_share

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('controller_manager_msgs') is None,
    reason='controller_manager_msgs is not installed')

ARM = package_share() / 'urdf' / 'three_joint_arm.xacro'
ARM_CONTROLLERS = package_share() / 'config' / 'three_joint_arm_controllers.yaml'
ARM_JOINTS = ['shoulder_joint', 'extend_joint', 'wrist_joint']
JSB, JTC = 'joint_state_broadcaster', 'joint_trajectory_controller'
FORWARD_POSITION, FORWARD_VELOCITY = 'forward_position_controller', 'forward_velocity_controller'


@pytest.fixture
def spawner_mode():
    """The three-joint arm, started as a ros2_control launch file would: spawners wanted."""
    with sim_node(robot_description_file=str(ARM), controllers_file=str(ARM_CONTROLLERS),
                  autostart_controllers=False) as sim:
        yield sim, Spawner(sim)


def test_nothing_is_loaded_until_spawned_and_no_joint_states_flow(spawner_mode):
    sim, spawner = spawner_mode
    assert spawner.controllers() == {}
    sim.run_for(0.5)
    assert sim.states == []  # no broadcaster yet
    assert sim.node.count_subscribers('/arm_controller/joint_trajectory') == 0


def test_the_spawner_call_sequence_loads_configures_and_activates(spawner_mode):
    sim, spawner = spawner_mode
    assert spawner.spawn(JSB) == 0
    assert spawner.spawn('arm_controller') == 0
    listed = spawner.controllers()
    assert {name: c.state for name, c in listed.items()} == {
        JSB: 'active', 'arm_controller': 'active'}
    arm = listed['arm_controller']
    assert arm.type == 'joint_trajectory_controller/JointTrajectoryController'
    assert list(arm.claimed_interfaces) == [f'{j}/effort' for j in ARM_JOINTS]
    assert list(arm.required_state_interfaces) == [
        f'{j}/{i}' for j in ARM_JOINTS for i in ('position', 'velocity')]
    # Its own update_rate (the shipped file's 1000 Hz), not the controller_manager's 100 Hz.
    assert arm.update_rate == 1000 and listed[JSB].update_rate == 100
    # What it spawned works: joint states flow, the trajectory topic moves the arm.
    assert sim.spin_until(lambda: sim.states), 'no joint_states after spawning the broadcaster'
    sim.command('arm_controller', JointTrajectory(joint_names=ARM_JOINTS, points=[
        JointTrajectoryPoint(positions=[0.7, 0.1, 1.0], time_from_start=Duration(sec=1))]))
    sim.run_for(2.0)
    assert sim.position('shoulder_joint') == pytest.approx(0.7, abs=0.02)
    # The gripper was never spawned: its topic does not exist, its joint takes nothing.
    assert sim.node.count_subscribers('/gripper_controller/commands') == 0
    assert 'gripper_controller' not in spawner.controllers()


def test_spawning_with_a_param_file_sets_type_and_params_file(spawner_mode, tmp_path):
    sim, spawner = spawner_mode
    extra = write(tmp_path, 'extra.yaml', """\
        slow_arm:
          ros__parameters:
            type: joint_trajectory_controller/JointTrajectoryController
            joints: [shoulder_joint]
            command_interfaces: [effort]
            gains:
              shoulder_joint: {p: 50.0, i: 0.0, d: 5.0}
        """)
    # params_file as a STRING_ARRAY (spawner 4.21+) ...
    assert spawner.spawn('slow_arm', [extra]) == 0
    slow = sim.simulation.controller('slow_arm')
    assert slow.joint_names == ('shoulder_joint',)
    assert sim.node.get_parameter('slow_arm.gains.shoulder_joint.p').value == 50.0
    # ... and as one STRING (older spawners).
    client = spawner
    assert client.set_parameter('other_arm', 'params_file', str(extra).replace(
        'extra.yaml', 'extra.yaml'))
    assert client.set_parameter('other_arm', 'type',
                                'joint_trajectory_controller/JointTrajectoryController')
    assert not client.load('other_arm')  # the file has no section for other_arm: no joints
    assert 'other_arm' not in spawner.controllers()


def test_spawner_failures_are_ok_false(spawner_mode, capfd):
    sim, spawner = spawner_mode
    assert not spawner.load('no_such_controller')
    assert "The 'type' param was not defined for 'no_such_controller'" in capfd.readouterr().err
    assert spawner.set_parameter('vendor', 'type', 'acme_controllers/Magic')
    assert not spawner.load('vendor')
    assert "unknown controller type 'acme_controllers/Magic'" in capfd.readouterr().err
    assert not spawner.configure('arm_controller')  # not loaded
    assert spawner.spawn('arm_controller') == 0
    assert not spawner.load('arm_controller')  # already loaded
    # Spawning an active controller again fails at configure, as upstream: exit 1.
    assert spawner.spawn('arm_controller') == 1
    assert not spawner.set_parameter('arm_controller', 'type', 42)  # not a string


def test_the_unspawner_deactivates_and_unloads(spawner_mode):
    sim, spawner = spawner_mode
    assert spawner.spawn('gripper_controller') == 0
    assert sim.node.count_subscribers('/gripper_controller/commands') == 1
    assert not spawner.call('unload_controller', srv().UnloadController.Request(
        name='gripper_controller')).ok  # still active
    assert spawner.switch(deactivate=['gripper_controller']).ok
    assert spawner.controllers()['gripper_controller'].state == 'inactive'
    assert spawner.call('unload_controller', srv().UnloadController.Request(
        name='gripper_controller')).ok
    assert spawner.controllers() == {}
    assert sim.node.count_subscribers('/gripper_controller/commands') == 0
    # It can be spawned again afterwards.
    assert spawner.spawn('gripper_controller') == 0


def test_inactive_spawn_and_cleanup(spawner_mode):
    sim, spawner = spawner_mode
    assert spawner.load('gripper_controller')
    assert spawner.controllers()['gripper_controller'].state == 'unconfigured'
    assert spawner.controllers()['gripper_controller'].required_command_interfaces == []
    assert not spawner.switch(activate=['gripper_controller']).ok  # must be configured first
    assert spawner.configure('gripper_controller')  # `spawner --inactive`
    assert spawner.controllers()['gripper_controller'].state == 'inactive'
    assert spawner.call('cleanup_controller', srv().CleanupController.Request(
        name='gripper_controller')).ok
    assert spawner.controllers()['gripper_controller'].state == 'unconfigured'


def test_switching_works_while_the_physics_is_paused(spawner_mode):
    sim, spawner = spawner_mode
    sim.node.set_paused(True)
    frozen = sim.simulation.time
    assert spawner.spawn(JSB) == 0
    assert spawner.controllers()[JSB].state == 'active'
    assert sim.simulation.time == frozen


def test_switch_and_configure_answer_within_the_spawner_timeouts_at_real_time():
    with sim_node(robot_description_file=str(ARM), controllers_file=str(ARM_CONTROLLERS),
                  autostart_controllers=False, real_time_factor=1.0) as sim:
        assert Spawner(sim).spawn(JSB) == 0


# --- the ROS 1 examples' way: every controller active, and a UR-style file switched ---------------

@pytest.fixture
def ur_style(tmp_path):
    xacro = write_arm(tmp_path)
    with sim_node(robot_description_file=str(xacro), xacro_args=['prefix:=left_'],
                  controllers_args=['prefix:=left_'], active_controllers=[JSB, JTC]) as sim:
        yield sim, Spawner(sim)


def test_without_spawners_the_controllers_are_listed_as_they_run(ur_style):
    sim, spawner = ur_style
    states = {name: c.state for name, c in spawner.controllers().items()}
    assert states == {JSB: 'active', JTC: 'active', FORWARD_POSITION: 'inactive',
                      FORWARD_VELOCITY: 'inactive'}
    interfaces = spawner.call('list_hardware_interfaces')
    claimed = {i.name for i in interfaces.command_interfaces if i.is_claimed}
    assert claimed == {'left_joint1/position', 'left_joint2/position'}
    assert {i.name for i in interfaces.command_interfaces} == {
        'left_joint1/position', 'left_joint1/velocity', 'left_joint2/position'}
    assert all(i.data_type == 'double' and i.is_available for i in interfaces.state_interfaces)
    (component,) = spawner.call('list_hardware_components').component
    assert (component.name, component.type, component.state.label) == (
        'TwoLinkArm', 'system', 'active')
    types = spawner.call('list_controller_types')
    assert 'joint_trajectory_controller/JointTrajectoryController' in types.types
    chainable = {name for name, base in zip(types.types, types.base_classes, strict=True)
                 if base != 'controller_interface::ControllerInterface'}
    assert chainable == {'pid_controller/PidController',
                         'diff_drive_controller/DiffDriveController',
                         'ackermann_steering_controller/AckermannSteeringController',
                         'bicycle_steering_controller/BicycleSteeringController',
                         'tricycle_steering_controller/TricycleSteeringController',
                         'mecanum_drive_controller/MecanumDriveController',
                         'omni_wheel_drive_controller/OmniWheelDriveController'}


def test_switching_from_the_trajectory_controller_to_forward_position_and_back(ur_style):
    sim, spawner = ur_style
    response = spawner.switch(activate=[FORWARD_POSITION], deactivate=[JTC])
    assert response.ok, response.message
    states = spawner.controllers()
    assert (states[JTC].state, states[FORWARD_POSITION].state) == ('inactive', 'active')
    assert list(states[FORWARD_POSITION].claimed_interfaces) == [
        'left_joint1/position', 'left_joint2/position']
    sim.command(FORWARD_POSITION, Float64MultiArray(data=[0.5, -0.4]))
    sim.run_for(3.0)
    assert sim.position('left_joint1') == pytest.approx(0.5, abs=0.02)
    assert sim.position('left_joint2') == pytest.approx(-0.4, abs=0.02)
    # And back: the trajectory controller takes over where the joints are and holds them.
    response = spawner.switch(activate=[JTC], deactivate=[FORWARD_POSITION])
    assert response.ok, response.message
    assert sim.setpoints(JTC) == pytest.approx([0.5, -0.4], abs=0.02)
    sim.run_for(1.0)
    assert sim.position('left_joint1') == pytest.approx(0.5, abs=0.02)
    sim.command(JTC, JointTrajectory(joint_names=['left_joint1', 'left_joint2'], points=[
        JointTrajectoryPoint(positions=[-0.2, 0.3], time_from_start=Duration(sec=1))]))
    sim.run_for(2.5)
    assert sim.position('left_joint1') == pytest.approx(-0.2, abs=0.02)
    # The forward controller, inactive again, takes no command.
    sim.command(FORWARD_POSITION, Float64MultiArray(data=[1.0, 1.0]))
    sim.run_for(0.5)
    assert sim.position('left_joint1') == pytest.approx(-0.2, abs=0.02)


def test_a_strict_switch_onto_claimed_joints_is_refused_and_changes_nothing(ur_style):
    sim, spawner = ur_style
    response = spawner.switch(activate=[FORWARD_POSITION])
    assert not response.ok
    assert "'joint_trajectory_controller' and 'forward_position_controller' would both " \
           "claim joint 'left_joint1'" in response.message
    states = spawner.controllers()
    assert (states[JTC].state, states[FORWARD_POSITION].state) == ('active', 'inactive')
    # Best effort does not make a conflict acceptable either (upstream checks interfaces always).
    assert not spawner.switch(activate=[FORWARD_POSITION], strictness=BEST_EFFORT).ok


def test_strict_refuses_what_best_effort_leaves_out(ur_style):
    sim, spawner = ur_style
    response = spawner.switch(activate=[JSB])  # already active
    assert not response.ok and 'already active' in response.message
    response = spawner.switch(deactivate=[JSB, 'no_such_controller'])
    assert not response.ok and "'no_such_controller'" in response.message
    assert spawner.controllers()[JSB].state == 'active'
    response = spawner.switch(deactivate=[JSB, 'no_such_controller'], strictness=BEST_EFFORT)
    assert response.ok and spawner.controllers()[JSB].state == 'inactive'
    response = spawner.switch(deactivate=[JSB], strictness=BEST_EFFORT)
    assert response.ok and response.message == (
        'After checking the controllers, no controllers need to be activated or deactivated.')
    # The URDF gives left_joint2 no velocity interface: refused whatever the strictness.
    response = spawner.switch(activate=[FORWARD_VELOCITY], deactivate=[JTC],
                              strictness=BEST_EFFORT)
    assert not response.ok and "'velocity' command interface of joint 'left_joint2'" in (
        response.message)


def test_a_namespaced_robot_has_its_controller_manager_in_its_namespace():
    with sim_node() as sim:  # the pan/tilt example, under /ex_urdf_pan_tilt
        spawner = Spawner(sim, '/ex_urdf_pan_tilt/controller_manager')
        states = {name: c.state for name, c in spawner.controllers().items()}
        assert states == {'joint_state_controller': 'active',
                          'joint1_position_controller': 'active',
                          'joint2_position_controller': 'active'}
        assert sim.node.controller_manager.get_fully_qualified_name() == (
            '/ex_urdf_pan_tilt/controller_manager')
        types = sim.node.controller_manager.get_parameter(
            'joint1_position_controller.type').value
        assert types == 'position_controllers/JointPositionController'  # from the YAML


def test_deactivating_a_trajectory_controller_aborts_its_goal(spawner_mode):
    if importlib.util.find_spec('control_msgs') is None:
        pytest.skip('control_msgs is not installed')
    from action_msgs.msg import GoalStatus
    from control_msgs.action import FollowJointTrajectory
    from rclpy.action import ActionClient

    sim, spawner = spawner_mode
    assert spawner.spawn('arm_controller') == 0
    client = ActionClient(sim.probe, FollowJointTrajectory, '/arm_controller/'
                          'follow_joint_trajectory')
    assert sim.spin_until(client.server_is_ready)
    goal = FollowJointTrajectory.Goal(trajectory=JointTrajectory(
        joint_names=ARM_JOINTS, points=[JointTrajectoryPoint(
            positions=[2.0, 0.2, 5.0], time_from_start=Duration(sec=20))]))
    sent = client.send_goal_async(goal)
    assert sim.spin_until(sent.done) and sent.result().accepted
    assert spawner.switch(deactivate=['arm_controller']).ok
    result = sent.result().get_result_async()
    assert sim.spin_until(result.done)
    assert result.result().status == GoalStatus.STATUS_ABORTED
    assert result.result().result.error_string == (
        'Current goal cancelled during deactivate transition.')


# --- start-up choices --------------------------------------------------------------------

def test_active_controllers_and_spawners_do_not_mix(context):
    with pytest.raises(ParameterError, match="'autostart_controllers' is false"):
        SimNode(context=context, parameter_overrides=[
            Parameter('autostart_controllers', value=False),
            Parameter('active_controllers', value=['joint_state_controller'])])


def test_without_controller_manager_msgs_there_is_no_controller_manager(monkeypatch, capfd):
    real = optional_interfaces.available
    monkeypatch.setattr(optional_interfaces, 'available',
                        lambda package: package != 'controller_manager_msgs' and real(package))
    with sim_node() as sim:
        assert sim.node.controller_manager is None
        assert sim.node.companion_nodes == []
    err = capfd.readouterr().err
    assert err.count("the controller_manager services (ros2_control's spawner) "
                     '(controller_manager_msgs)') == 1


def test_spawner_mode_needs_controller_manager_msgs(monkeypatch, context):
    real = optional_interfaces.available
    monkeypatch.setattr(optional_interfaces, 'available',
                        lambda package: package != 'controller_manager_msgs' and real(package))
    with pytest.raises(ParameterError, match='controller_manager_msgs is not installed'):
        SimNode(context=context, parameter_overrides=[
            Parameter('autostart_controllers', value=False)])


def test_a_late_joint_state_subscriber_gets_states_from_a_spawned_broadcaster(spawner_mode):
    sim, spawner = spawner_mode
    assert spawner.spawn(JSB) == 0
    late = sim.collect(JointState, '/joint_states')
    assert sim.spin_until(lambda: late), 'the spawned broadcaster publishes nothing'




# --- a chain of controllers --------------------------------------------------------------

CHAIN_FILE = """\
    pid:
      ros__parameters:
        type: test_controllers/ChainableTestController
        joints: [shoulder_joint]
    forward:
      ros__parameters:
        type: position_controllers/JointGroupPositionController
        joints: [pid/shoulder_joint]
    """


def shoulder(sim) -> float:
    return sim.simulation.joint_positions()['shoulder_joint']


@pytest.fixture
def chain(spawner_mode, tmp_path, monkeypatch):
    """``pid`` (the test's chainable type) and ``forward`` feeding it, spawned in that order."""
    sim, spawner = spawner_mode
    register_chainable(monkeypatch)
    params = write(tmp_path, 'chain.yaml', CHAIN_FILE)
    assert spawner.spawn('pid', [params]) == 0
    assert spawner.spawn('forward', [params]) == 0  # the following one first, as spawners do
    return sim, spawner


def test_a_spawned_chain_is_listed_with_its_references_and_connections(chain):
    sim, spawner = chain
    listed = spawner.controllers()
    pid, forward = listed['pid'], listed['forward']
    assert (pid.is_chainable, pid.is_chained) == (True, True)
    assert list(pid.reference_interfaces) == ['shoulder_joint/position']
    assert list(pid.chain_connections) == []
    assert (forward.is_chainable, forward.is_chained) == (False, False)
    assert list(forward.claimed_interfaces) == ['pid/shoulder_joint/position']
    assert [(c.name, list(c.reference_interfaces)) for c in forward.chain_connections] == [
        ('pid', ['shoulder_joint/position'])]
    types = spawner.call('list_controller_types')
    assert dict(zip(types.types, types.base_classes, strict=True))[CHAINABLE_TYPE] == (
        'controller_interface::ChainableControllerInterface')
    # pid cannot stop under the group; without the group it leaves chained mode.
    response = spawner.switch(deactivate=['pid'])
    assert not response.ok and response.message == (
        "Unable to deactivate controller with name 'pid' because preceding controller with "
        "name 'forward' is currently active and will not be deactivated.")
    assert spawner.switch(deactivate=['forward']).ok
    pid = spawner.controllers()['pid']
    assert (pid.state, pid.is_chained) == ('active', False)


def test_a_chained_controller_takes_its_reference_from_the_preceding_one_not_its_topic(chain):
    sim, spawner = chain
    sim.command('pid', Float64MultiArray(data=[-0.5]))
    sim.run_for(1.0)
    assert shoulder(sim) == pytest.approx(0.0, abs=0.01)
    sim.command('forward', Float64MultiArray(data=[0.5]))
    sim.run_for(2.0)
    assert shoulder(sim) == pytest.approx(0.5, abs=0.01)
    # Out of chained mode its own topic drives it again.
    assert spawner.switch(deactivate=['forward']).ok
    sim.command('pid', Float64MultiArray(data=[-0.3]))
    sim.run_for(2.0)
    assert shoulder(sim) == pytest.approx(-0.3, abs=0.01)
