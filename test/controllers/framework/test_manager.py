"""ControllerManager: loaded and active controllers, as ros2_control's controller_manager.

A UR-style file declares three controllers on the same joints plus vendor
types; the manager loads what it can, activates what it is told, refuses
what ros2_control would refuse, and switches controllers atomically.
"""

from __future__ import annotations

import pytest
from robot_fixtures import JointDef, star_robot_urdf
from ros2_control_fixtures import UR_STYLE_YAML, write, write_arm

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.framework.manager import (
    ACTIVE,
    INACTIVE,
    UNCONFIGURED,
    ControllerManager,
)
from pan_tilt_sim.controllers.toolbox.actuator import ramp
from pan_tilt_sim.errors import ControllerConfigError, ControllerSwitchError
from pan_tilt_sim.model.controller_config import load_controllers_config
from pan_tilt_sim.model.description import load_description

ARGS = {'prefix': ''}
JTC = 'joint_trajectory_controller'
FORWARD_POSITION = 'forward_position_controller'
FORWARD_VELOCITY = 'forward_velocity_controller'
JSB = 'joint_state_broadcaster'
DT = 0.001


@pytest.fixture
def arm(tmp_path):
    """Return a function building a manager for the arm with a YAML (default: UR style)."""
    def build(yaml=UR_STYLE_YAML, active=None, args=ARGS):
        xacro = write_arm(tmp_path, yaml)
        description = load_description(xacro)
        handles = {joint.name: JointHandle(joint) for joint in description.actuated_joints}
        config = load_controllers_config(tmp_path / 'arm_controllers.yaml', args)
        return ControllerManager(config, handles, description.model, active=active), handles
    return build


def run(manager, steps=10):
    for step in range(steps):
        for update in manager.updates:
            update(step * DT, DT)


# --- start-up: which controllers, which active -------------------------------------------

def test_without_active_controllers_two_controllers_on_one_joint_is_an_error(arm):
    with pytest.raises(ControllerConfigError) as caught:
        arm()
    message = str(caught.value)
    assert "joint 'joint1' is claimed by both 'joint_trajectory_controller' and " \
           "'forward_velocity_controller'" in message
    assert "the parameter 'active_controllers'" in message


def test_the_active_ones_run_the_others_are_loaded_inactive_and_vendor_types_skipped(arm):
    manager, _ = arm(active=[JSB, JTC])
    assert [c.name for c in manager.active] == [JTC, JSB]  # command controllers update first
    assert {c.name for c in manager.controllers} == {JSB, JTC, FORWARD_POSITION,
                                                       FORWARD_VELOCITY}
    assert not manager.is_active(FORWARD_POSITION)
    assert [(s.name, s.type) for s in manager.skipped] == [
        ('io_and_status_controller', 'acme_controllers/GPIOController'),
        ('speed_scaling_state_broadcaster', 'acme_controllers/SpeedScalingStateBroadcaster'),
        ('scaled_joint_trajectory_controller',
         'acme_controllers/ScaledJointTrajectoryController')]
    assert all(s.reason == 'a controller type this simulator does not have'
               for s in manager.skipped)


def test_an_inactive_controller_runs_no_update(arm):
    # Without gains both drive their joints by the ideal actuator: a velocity target.
    manager, handles = arm(active=[JSB, JTC])
    manager.controller(FORWARD_POSITION).set_command([1.0, 1.0])
    run(manager)
    assert [handle.velocity_target for handle in handles.values()] == [0.0, 0.0]  # JTC holds
    manager.switch(activate=[FORWARD_POSITION], deactivate=[JTC])
    manager.controller(FORWARD_POSITION).set_command([1.0, 1.0])
    run(manager)
    assert all(handle.velocity_target > 0.0 for handle in handles.values())


def test_a_vendor_type_listed_as_active_is_an_error_listing_the_supported_types(arm):
    with pytest.raises(ControllerConfigError) as caught:
        arm(active=[JSB, 'scaled_joint_trajectory_controller'])
    message = str(caught.value)
    assert ("scaled_joint_trajectory_controller.type: unknown controller type "
            "'acme_controllers/ScaledJointTrajectoryController', and the parameter "
            "'active_controllers' lists it (supported: ") in message
    assert 'joint_trajectory_controller/JointTrajectoryController' in message


def test_an_active_name_the_file_does_not_have_is_an_error(arm):
    with pytest.raises(ControllerConfigError) as caught:
        arm(active=[JSB, 'arm_controller'])
    assert str(caught.value).startswith(
        "the parameter 'active_controllers': no controller 'arm_controller' in ")
    assert 'its controllers: joint_state_broadcaster, io_and_status_controller' in str(
        caught.value)


def test_two_active_controllers_on_one_joint_is_an_error_naming_both(arm):
    with pytest.raises(ControllerConfigError) as caught:
        arm(active=[JTC, FORWARD_POSITION])
    assert str(caught.value) == (
        "the parameter 'active_controllers': 'joint_trajectory_controller' and "
        "'forward_position_controller' both claim joint 'joint1'; only one active controller "
        'can command a joint')


VENDOR_ONLY = """
    controller_manager:
      ros__parameters:
        joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
        speed_scaling: {type: acme_controllers/SpeedScalingStateBroadcaster}
        arm_controller: {type: acme_controllers/RobotController}
    arm_controller:
      ros__parameters: {joints: [joint1, joint2]}
    """


def test_when_every_controller_that_commands_joints_is_unknown_start_up_stops(arm):
    with pytest.raises(ControllerConfigError) as caught:
        arm(VENDOR_ONLY)
    assert ("arm_controller.type: unknown controller type 'acme_controllers/RobotController', "
            'and no other controller in the file commands a joint (supported: ') in str(
                caught.value)


def test_a_vendor_controller_beside_a_known_one_is_skipped_when_all_are_active(arm):
    manager, _ = arm("""
        controller_manager:
          ros__parameters:
            joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
            group: {type: position_controllers/JointGroupPositionController}
            arm_controller: {type: acme_controllers/RobotController}
        group:
          ros__parameters: {joints: [joint1]}
        """)
    assert [c.name for c in manager.active] == ['group', JSB]
    assert [s.name for s in manager.skipped] == ['arm_controller']


def test_a_gripper_action_controller_commands_joints_it_is_known_and_updates_first(arm):
    manager, _ = arm("""
        controller_manager:
          ros__parameters:
            joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
            gripper: {type: position_controllers/GripperActionController}
            arm_controller: {type: acme_controllers/RobotController}
        gripper:
          ros__parameters: {joint: joint2}
        """)
    assert [c.name for c in manager.active] == ['gripper', JSB]
    assert [s.name for s in manager.skipped] == ['arm_controller']


def test_an_inactive_controller_that_cannot_load_is_skipped_with_its_reason(arm):
    broken = UR_STYLE_YAML.replace('    interface_name: velocity\n',
                                   '    interface_name: velocity\n    joints: [elbow]\n')
    manager, _ = arm(broken, active=[JSB, JTC])
    (velocity,) = [s for s in manager.skipped if s.name == FORWARD_VELOCITY]
    assert velocity.reason.startswith('cannot be loaded: ')
    assert "joint 'elbow' is not a movable joint of the robot" in velocity.reason
    with pytest.raises(ControllerConfigError, match="joint 'elbow' is not a movable joint"):
        arm(broken, active=[JSB, FORWARD_VELOCITY])


# --- the URDF's <ros2_control> interfaces ------------------------------------------------

def test_an_effort_controller_on_a_position_only_joint_is_refused(arm):
    effort = UR_STYLE_YAML.replace('velocity_controllers/JointGroupVelocityController',
                                   'effort_controllers/JointGroupEffortController')
    with pytest.raises(ControllerConfigError) as caught:
        arm(effort, active=[FORWARD_VELOCITY])
    assert str(caught.value).endswith(
        ": forward_velocity_controller (effort_controllers/JointGroupEffortController) claims "
        "the 'effort' command interface of joint 'joint1', which the URDF's <ros2_control> "
        'block does not give it (its command interfaces: position, velocity)')


def test_joints_outside_every_ros2_control_block_take_any_interface(tmp_path):
    from pan_tilt_sim.share import package_share

    description = load_description(package_share() / 'urdf' / 'pan_tilt.xacro')
    handles = {joint.name: JointHandle(joint) for joint in description.actuated_joints}
    path = write(tmp_path, 'e.yaml',
                 'e: {type: effort_controllers/JointEffortController, joint: pan_joint}\n')
    manager = ControllerManager(load_controllers_config(path), handles, description.model)
    assert [c.name for c in manager.active] == ['e']


# --- switching at run time ---------------------------------------------------------------

def test_switching_hands_the_joints_over_and_the_new_controller_holds_them(arm):
    manager, handles = arm(active=[JSB, JTC])
    handles['joint1'].position, handles['joint2'].position = 0.3, -0.2
    manager.switch(activate=[FORWARD_POSITION], deactivate=[JTC])
    assert [c.name for c in manager.active] == [FORWARD_POSITION, JSB]
    assert manager.controller(FORWARD_POSITION).setpoints() == {'joint1': 0.3, 'joint2': -0.2}


def test_a_conflicting_switch_is_refused_and_changes_nothing(arm):
    manager, _ = arm(active=[JSB, JTC])
    with pytest.raises(ControllerSwitchError,
                       match="'joint_trajectory_controller' and 'forward_position_controller' "
                             "would both claim joint 'joint1'"):
        manager.switch(activate=[FORWARD_POSITION])
    assert [c.name for c in manager.active] == [JTC, JSB]


def test_a_switch_to_an_interface_the_joint_lacks_is_refused(arm):
    manager, _ = arm(active=[JSB, JTC])
    with pytest.raises(ControllerSwitchError, match="'velocity' command interface of joint "
                                                    "'joint2'"):
        manager.switch(activate=[FORWARD_VELOCITY], deactivate=[JTC])
    assert manager.is_active(JTC) and not manager.is_active(FORWARD_VELOCITY)


def test_switching_an_unknown_or_skipped_controller_is_refused(arm):
    manager, _ = arm(active=[JSB, JTC])
    with pytest.raises(ControllerSwitchError, match="could not activate controller with name "
                                                    "'scaled_joint_trajectory_controller' because "
                                                    'no controller with this name exists'):
        manager.switch(activate=['scaled_joint_trajectory_controller'], deactivate=[JTC])


def test_a_deactivated_controller_holds_nothing_its_joints_keep_the_last_command(arm):
    manager, handles = arm(active=[JSB, FORWARD_POSITION])
    manager.controller(FORWARD_POSITION).set_command([1.0, -1.0])
    run(manager)
    last = [(handle.effort, handle.velocity_target) for handle in handles.values()]
    assert last[0][1] > 0.0 > last[1][1]
    manager.switch(deactivate=[FORWARD_POSITION])
    handles['joint1'].position = 0.5  # the joint moves; nobody recomputes its command
    run(manager)
    assert [(handle.effort, handle.velocity_target) for handle in handles.values()] == last
    assert [c.name for c in manager.active] == [JSB]


# --- the lifecycle, as controller_manager's services drive it ----------------------------

@pytest.fixture
def idle(tmp_path):
    """A manager that loaded nothing (autostart off: spawners will), and the arm's handles."""
    xacro = write_arm(tmp_path)
    description = load_description(xacro)
    handles = {joint.name: JointHandle(joint) for joint in description.actuated_joints}
    config = load_controllers_config(tmp_path / 'arm_controllers.yaml', ARGS)
    return ControllerManager(config, handles, description.model, autostart=False), handles


def load(manager, name):
    spec = manager.declared[name]
    return manager.load(name, spec.type, spec.params)


def test_without_autostart_nothing_is_loaded_and_the_file_is_only_declared(idle):
    manager, _ = idle
    assert manager.controllers == [] and manager.updates == []
    assert set(manager.declared) >= {JSB, JTC, FORWARD_POSITION, 'io_and_status_controller'}
    assert manager.skipped == ()


def test_load_configure_activate_then_deactivate_cleanup_unload(idle):
    manager, handles = idle
    load(manager, JTC)
    assert manager.state(JTC) == UNCONFIGURED and manager.configured == []
    manager.configure(JTC)
    assert manager.state(JTC) == INACTIVE and manager.updates == []
    assert manager.switch(activate=[JTC]) == []
    assert manager.state(JTC) == ACTIVE and len(manager.updates) == 1
    with pytest.raises(ControllerConfigError, match="can not be configured from 'active'"):
        manager.configure(JTC)
    with pytest.raises(ControllerConfigError, match='because it is still active'):
        manager.unload(JTC)
    with pytest.raises(ControllerConfigError, match="can not be cleaned-up from 'active'"):
        manager.cleanup(JTC)
    manager.switch(deactivate=[JTC])
    manager.cleanup(JTC)
    assert manager.state(JTC) == UNCONFIGURED
    manager.unload(JTC)
    assert not manager.is_loaded(JTC) and manager.controllers == []


def test_load_refuses_a_second_controller_of_a_name_and_types_it_lacks(idle):
    manager, _ = idle
    load(manager, JSB)
    with pytest.raises(ControllerConfigError, match=f"a controller named '{JSB}' was already"):
        load(manager, JSB)
    with pytest.raises(ControllerConfigError, match="unknown controller type 'acme_controllers"):
        load(manager, 'io_and_status_controller')
    with pytest.raises(ControllerConfigError, match="could not configure controller with name "
                                                    "'nothing' because no controller"):
        manager.configure('nothing')


def test_configuring_an_inactive_controller_again_starts_it_afresh(idle):
    manager, handles = idle
    load(manager, FORWARD_POSITION)
    first = manager.configure(FORWARD_POSITION)
    handles['joint1'].position = 0.7
    again = manager.configure(FORWARD_POSITION)
    assert again is first and manager.state(FORWARD_POSITION) == INACTIVE
    assert again.setpoints()['joint1'] == 0.7


def test_an_unconfigured_controller_cannot_be_activated(idle):
    manager, _ = idle
    load(manager, JTC)
    with pytest.raises(ControllerSwitchError, match='is unconfigured'):
        manager.switch(activate=[JTC])


def test_best_effort_leaves_out_what_strict_refuses(arm):
    manager, _ = arm(active=[JSB, JTC])
    with pytest.raises(ControllerSwitchError, match=f"'{JSB}' since it is already active"):
        manager.switch(activate=[JSB])
    with pytest.raises(ControllerSwitchError, match=f"'{FORWARD_POSITION}' since it is not "
                                                    'active'):
        manager.switch(deactivate=[FORWARD_POSITION, JSB])
    assert manager.is_active(JSB)
    dropped = manager.switch(deactivate=[FORWARD_POSITION, JSB, 'nothing'], strict=False)
    assert not manager.is_active(JSB)
    assert len(dropped) == 2 and "'nothing'" in dropped[0] and 'not active' in dropped[1]
    with pytest.raises(ControllerSwitchError, match="'nothing' because no controller"):
        manager.switch(activate=['nothing'], strict=False)  # the list names nothing loaded



def test_planning_a_switch_says_what_it_would_do_and_changes_nothing(arm):
    manager, _ = arm(active=[JSB, JTC])
    calls = []
    manager.add_switch_listener(lambda: calls.append('switched'))
    plan = manager.plan_switch(activate=[FORWARD_POSITION, FORWARD_POSITION],
                               deactivate=[JTC, 'nothing'], strict=False)
    assert plan.activate == (FORWARD_POSITION,) and plan.deactivate == (JTC,)
    assert plan.active == {FORWARD_POSITION, JSB}
    assert len(plan.dropped) == 1 and "'nothing'" in plan.dropped[0]
    assert [c.name for c in manager.active] == [JTC, JSB] and not calls
    assert manager.state(FORWARD_POSITION) == INACTIVE
    with pytest.raises(ControllerSwitchError, match="would both claim joint 'joint1'"):
        manager.plan_switch(activate=[FORWARD_POSITION])
    assert manager.switch(activate=[FORWARD_POSITION], deactivate=[JTC, 'nothing'],
                          strict=False) == list(plan.dropped)
    assert {c.name for c in manager.active} == plan.active and calls == ['switched']

def test_a_deactivated_trajectory_controller_ends_its_goal(arm):
    from pan_tilt_sim.controllers.trajectory.trajectory import JointTrajectory, TrajectoryPoint
    from pan_tilt_sim.controllers.trajectory.trajectory_goal import GoalStatus

    manager, _ = arm(active=[JSB, JTC])
    jtc = manager.controller(JTC)
    goal = jtc.start_goal(JointTrajectory(('joint1', 'joint2'), (
        TrajectoryPoint(1.0, (0.5, 0.5)),)), jtc.default_tolerances)
    manager.switch(activate=[FORWARD_POSITION], deactivate=[JTC])
    assert goal.status is GoalStatus.ABORTED


# --- what the <ros2_control> block's hardware accepts (example 3's shape) -------------------

DEMO_PLUGIN = 'ros2_control_demo_example_3/RRBotSystemMultiInterfaceHardware'
MOCK_PLUGIN = 'mock_components/GenericSystem'
GAZEBO_PLUGIN = 'gz_ros2_control/GazeboSimSystem'
MODES = ('position', 'velocity', 'acceleration')


def forward(joints, interface):
    names = ', '.join(joints)
    return ('    type: forward_command_controller/ForwardCommandController\n'
            f'    joints: [{names}]\n    interface_name: {interface}\n')


# Controllers on both joints in each mode, one on each joint alone, and a trajectory
# controller commanding position and velocity.
MULTI_INTERFACE_YAML = (
    'controller_manager:\n  ros__parameters:\n    joint_state_broadcaster:\n'
    '      type: joint_state_broadcaster/JointStateBroadcaster\n'
    + ''.join(f'forward_{mode}_controller:\n  ros__parameters:\n'
              + forward(('joint1', 'joint2'), mode) for mode in MODES)
    + 'position_joint1:\n  ros__parameters:\n' + forward(('joint1',), 'position')
    + 'position_joint2:\n  ros__parameters:\n' + forward(('joint2',), 'position')
    + 'velocity_joint2:\n  ros__parameters:\n' + forward(('joint2',), 'velocity')
    + 'pid_gain_controller:\n  ros__parameters:\n' + forward(('joint1', 'joint2'), 'pid_gain')
    + 'trajectory_controller:\n  ros__parameters:\n'
    '    type: joint_trajectory_controller/JointTrajectoryController\n'
    '    joints: [joint1, joint2]\n    command_interfaces: [position, velocity]\n')


@pytest.fixture
def rrbot(tmp_path):
    """Return a function building a manager for a two-joint robot under ``plugin``."""
    def build(plugin, active, params=''):
        entries = ''.join(
            f'<joint name="{joint}">'
            + ''.join(f'<command_interface name="{interface}"/>'
                      for interface in (*MODES, 'pid_gain'))
            + '<state_interface name="position"/><state_interface name="velocity"/></joint>'
            for joint in ('joint1', 'joint2'))
        block = (f'<ros2_control name="MultiInterfaceBot" type="system"><hardware>'
                 f'<plugin>{plugin}</plugin>{params}</hardware>{entries}</ros2_control>')
        urdf = star_robot_urdf([JointDef('joint1'), JointDef('joint2')], 'rrbot').replace(
            '</robot>', f'{block}</robot>')
        description = load_description(write(tmp_path, 'rrbot.urdf', urdf))
        handles = {joint.name: JointHandle(joint, control=description.model.control_joint(
            joint.name)) for joint in description.actuated_joints}
        config = load_controllers_config(write(tmp_path, 'rrbot.yaml', MULTI_INTERFACE_YAML))
        return ControllerManager(config, handles, description.model, active=active)
    return build


REJECTED = 'Could not switch controllers since prepare command mode switch was rejected: '
DEMO_COMPONENT = f"component 'MultiInterfaceBot' ({DEMO_PLUGIN}) did not accept command "


def test_the_demo_hardware_refuses_at_start_up_a_mode_on_one_of_its_joints(rrbot):
    with pytest.raises(ControllerConfigError) as caught:
        rrbot(DEMO_PLUGIN, active=[JSB, 'position_joint1'])
    assert str(caught.value) == (
        f"the parameter 'active_controllers': {REJECTED}{DEMO_COMPONENT}interfaces combination "
        '(start: joint1/position; stop: none): all joints (joint1, joint2) must be given new '
        'command mode at the same time')


def test_the_demo_hardware_refuses_a_switch_to_a_mode_on_one_of_its_joints(rrbot):
    manager = rrbot(DEMO_PLUGIN, active=[JSB, 'forward_velocity_controller'])
    with pytest.raises(ControllerSwitchError) as caught:
        manager.switch(activate=['position_joint1'], deactivate=['forward_velocity_controller'])
    assert str(caught.value) == (
        f'{REJECTED}{DEMO_COMPONENT}interfaces combination (start: joint1/position; stop: '
        'joint1/velocity, joint2/velocity): all joints (joint1, joint2) must be given new '
        'command mode at the same time')
    assert manager.is_active('forward_velocity_controller')
    assert not manager.is_active('position_joint1')


def test_the_demo_hardware_refuses_position_on_one_joint_with_velocity_on_the_other(rrbot):
    manager = rrbot(DEMO_PLUGIN, active=[JSB])
    with pytest.raises(ControllerSwitchError, match=r'all joints must have the same command '
                                                    r'mode \(joint1/position, joint2/velocity\)'):
        manager.switch(activate=['position_joint1', 'velocity_joint2'])
    assert [c.name for c in manager.active] == [JSB]


def test_the_demo_hardware_refuses_to_stop_its_mode_without_starting_another(rrbot):
    manager = rrbot(DEMO_PLUGIN, active=[JSB, 'forward_velocity_controller'])
    with pytest.raises(ControllerSwitchError, match=r'\(start: none; stop: joint1/velocity, '
                                                    r'joint2/velocity\): all joints'):
        manager.switch(deactivate=['forward_velocity_controller'])
    assert manager.is_active('forward_velocity_controller')


def test_the_demo_hardware_takes_one_mode_on_both_joints_and_hands_it_over(rrbot):
    manager = rrbot(DEMO_PLUGIN, active=[JSB, 'forward_velocity_controller'])
    manager.switch(activate=['forward_position_controller'],
                   deactivate=['forward_velocity_controller'])
    manager.switch(activate=['forward_acceleration_controller'],
                   deactivate=['forward_position_controller'])
    manager.switch(activate=['position_joint1', 'position_joint2'],
                   deactivate=['forward_acceleration_controller'])
    assert {c.name for c in manager.active} == {JSB, 'position_joint1', 'position_joint2'}
    assert rrbot(DEMO_PLUGIN, active=[JSB, 'position_joint1', 'position_joint2']).is_active(
        'position_joint2')


def test_the_demo_hardware_refuses_two_modes_on_a_joint(rrbot):
    with pytest.raises(ControllerConfigError, match='must be given new command mode'):
        rrbot(DEMO_PLUGIN, active=['trajectory_controller'])


def test_mock_hardware_with_dynamics_refuses_two_command_interfaces_on_one_joint(rrbot):
    dynamics = '<param name="calculate_dynamics">true</param>'
    with pytest.raises(ControllerConfigError) as caught:
        rrbot(MOCK_PLUGIN, active=['trajectory_controller'], params=dynamics)
    assert str(caught.value).endswith(
        "(start: joint1/position, joint1/velocity, joint2/position, joint2/velocity; stop: "
        "none): Got multiple (2) starting interfaces for joint 'joint1' - this is not "
        'supported!')
    manager = rrbot(MOCK_PLUGIN, active=[JSB], params=dynamics)
    with pytest.raises(ControllerSwitchError, match=f'^{REJECTED}.*Got multiple'):
        manager.switch(activate=['trajectory_controller'])
    manager.switch(activate=['position_joint1', 'velocity_joint2'])  # one mode per joint


@pytest.mark.parametrize(('plugin', 'params'), [
    (GAZEBO_PLUGIN, ''),
    (MOCK_PLUGIN, ''),
])
def test_gazebo_and_mock_hardware_take_position_and_velocity_on_one_joint(rrbot, plugin, params):
    manager = rrbot(plugin, active=[JSB, 'trajectory_controller'], params=params)
    assert manager.is_active('trajectory_controller')
    manager.switch(activate=['position_joint1', 'velocity_joint2'],
                   deactivate=['trajectory_controller'])
    manager.switch(deactivate=['position_joint1'])
    assert [c.name for c in manager.active] == ['velocity_joint2', JSB]


PID_GAIN_REFUSAL = (
    "Unable to activate controller 'pid_gain_controller' since the command interface "
    "'joint1/pid_gain' is not available: the simulation can drive position, velocity, effort "
    'and acceleration')


def test_a_declared_interface_the_simulator_cannot_drive_configures_but_is_not_activated(
        rrbot):
    manager = rrbot(GAZEBO_PLUGIN, active=[JSB, 'forward_acceleration_controller'])
    assert manager.skipped == ()
    assert manager.state('pid_gain_controller') == INACTIVE
    assert manager.refused == {}  # not asked for: nothing to say at start-up
    assert manager.activation_refusal('pid_gain_controller') == PID_GAIN_REFUSAL
    with pytest.raises(ControllerSwitchError) as caught:
        manager.switch(activate=['pid_gain_controller'],
                       deactivate=['forward_acceleration_controller'])
    assert str(caught.value) == PID_GAIN_REFUSAL
    assert manager.is_active('forward_acceleration_controller')
    # BEST_EFFORT leaves it out with the same line; the rest of the switch happens.
    dropped = manager.switch(activate=['pid_gain_controller', 'position_joint1',
                                       'position_joint2'],
                             deactivate=['forward_acceleration_controller'], strict=False)
    assert dropped == [PID_GAIN_REFUSAL]
    assert {c.name for c in manager.active} == {JSB, 'position_joint1', 'position_joint2'}


def test_listed_as_active_a_controller_the_simulator_cannot_drive_ends_start_up(rrbot):
    with pytest.raises(ControllerConfigError) as caught:
        rrbot(GAZEBO_PLUGIN, active=[JSB, 'pid_gain_controller'])
    assert str(caught.value) == f"the parameter 'active_controllers': {PID_GAIN_REFUSAL}"


def example_13_manager(tmp_path, pid_gain_joints=('joint1', 'joint2')):
    """Example 13's shape with every controller active: a broadcaster, position and pid_gain."""
    entries = ''.join(
        f'<joint name="{joint}"><command_interface name="position"/>'
        + ('<command_interface name="pid_gain"/>' if joint in pid_gain_joints else '')
        + '<state_interface name="position"/></joint>' for joint in ('joint1', 'joint2'))
    block = ('<ros2_control name="FakeThreeDofBot" type="system"><hardware><plugin>'
             f'{MOCK_PLUGIN}</plugin></hardware>{entries}</ros2_control>')
    urdf = star_robot_urdf([JointDef('joint1'), JointDef('joint2')], 'bot').replace(
        '</robot>', f'{block}</robot>')
    description = load_description(write(tmp_path, 'bot.urdf', urdf))
    handles = {joint.name: JointHandle(joint, control=description.model.control_joint(
        joint.name)) for joint in description.actuated_joints}
    config = load_controllers_config(write(tmp_path, 'bot.yaml', (
        'controller_manager:\n  ros__parameters:\n    joint_state_broadcaster:\n'
        '      type: joint_state_broadcaster/JointStateBroadcaster\n'
        'position_controller:\n  ros__parameters:\n' + forward(('joint1', 'joint2'), 'position')
        + 'pid_gain_controller:\n  ros__parameters:\n'
        + forward(('joint1', 'joint2'), 'pid_gain'))))
    return ControllerManager(config, handles, description.model)


def test_with_every_controller_active_it_stays_inactive_with_its_line_and_the_rest_run(
        tmp_path):
    manager = example_13_manager(tmp_path)
    assert {c.name for c in manager.active} == {JSB, 'position_controller'}
    assert manager.state('pid_gain_controller') == INACTIVE
    assert manager.refused == {'pid_gain_controller': PID_GAIN_REFUSAL}


def test_an_interface_the_block_does_not_declare_is_refused_at_configure(tmp_path):
    with pytest.raises(ControllerConfigError) as caught:
        example_13_manager(tmp_path, pid_gain_joints=('joint1',))
    assert str(caught.value).endswith(
        ": pid_gain_controller.interface_name: joint 'joint2' interface 'pid_gain': the "
        'simulator can drive position, velocity, effort and acceleration')


# --- gpio command interfaces ---------------------------------------------------------------

def gpio_manager(tmp_path):
    from pan_tilt_sim.controllers.framework.hardware_interfaces import (
        CommandInterface,
        GpioHandle,
        HardwareInterfaces,
        StateInterface,
    )
    from pan_tilt_sim.model.controller_config import ControllersConfig, ControllerSpec

    state = StateInterface('io/vacuum', 1.0)
    io = GpioHandle('io', [CommandInterface('io/vacuum', state)], [state])
    spec = {'type': 'gpio_controllers/GpioCommandController', 'gpios': ['io'],
            'command_interfaces': {'io': {'interfaces': ['vacuum']}}}
    # The second controller is named like the gpio: a controller's name is no gpio's.
    config = ControllersConfig((ControllerSpec('gripper', spec['type'], spec),
                                ControllerSpec('io', spec['type'], spec)),
                               tmp_path / 'c.yaml')
    return ControllerManager(config, {}, active=['gripper'],
                             hardware=HardwareInterfaces([], [io]))


def test_two_active_controllers_on_one_gpio_command_interface_is_refused(tmp_path):
    manager = gpio_manager(tmp_path)
    assert manager.chain_connections('gripper') == {}  # a gpio is no chained controller
    with pytest.raises(ControllerSwitchError, match=r"'gripper' and 'io' would both claim "
                                                    r"the command interface 'io/vacuum'"):
        manager.switch(['io'])
    manager.switch(['io'], ['gripper'])
    assert [c.name for c in manager.active] == ['io']


# --- each controller's clock, as ros2_control runs it ------------------------------------

def star_manager(tmp_path, controllers: str, *, time_step: float | None = DT):
    """Return a manager of a two-joint star robot with ``controllers`` (YAML text)."""
    urdf = tmp_path / 'star.urdf'
    urdf.write_text(star_robot_urdf([JointDef('a'), JointDef('b')]), encoding='utf-8')
    description = load_description(urdf)
    handles = {joint.name: JointHandle(joint) for joint in description.actuated_joints}
    path = write(tmp_path, 'controllers.yaml', controllers)
    return ControllerManager(load_controllers_config(path), handles, description.model,
                             time_step=time_step)


def ros2_style(manager_rate: float, own_rate: str = '', *, position: bool = True,
               tricycle: bool = False) -> str:
    """A ros2_control style file: a broadcaster, and a position and/or a tricycle controller."""
    declared = ['jsb: {type: joint_state_broadcaster/JointStateBroadcaster}']
    sections = []
    if position:
        declared.append('pos: {type: position_controllers/JointPositionController}')
        sections.append(f'pos:\n  ros__parameters: {{joint: a, {own_rate}}}')
    if tricycle:
        declared.append('steer: {type: tricycle_controller/TricycleController}')
        sections.append('steer:\n  ros__parameters: {traction_joint_name: b, '
                        'steering_joint_name: a, wheelbase: 1.0, wheel_radius: 0.1}')
    lines = '\n'.join(f'    {entry}' for entry in declared)
    return (f'controller_manager:\n  ros__parameters:\n    update_rate: {manager_rate}\n'
            f'{lines}\n' + '\n'.join(sections) + '\n')


def test_each_controller_updates_at_the_managers_rate_or_its_own(tmp_path):
    manager = star_manager(tmp_path, ros2_style(100))
    assert manager.update_rate_of('pos') == 100.0
    assert manager.clock_of(manager.controller('pos')) == (10, 10 * DT)
    assert manager.step_clocks == [(10, 10 * DT)]
    manager = star_manager(tmp_path, ros2_style(100, 'update_rate: 500'))
    assert manager.update_rate_of('pos') == 500.0
    assert manager.step_clocks == [(2, 2 * DT)]
    assert manager.clock_notes == []


def test_a_ros1_files_controllers_update_at_every_physics_step(tmp_path):
    manager = star_manager(tmp_path, """
        pos: {type: position_controllers/JointPositionController, joint: a}
        """)
    assert manager.update_rate_of('pos') is None
    assert manager.step_clocks == [(1, DT)]
    assert manager.actuations == []  # the update itself tracks, every step


def test_a_rate_whose_period_is_no_whole_number_of_steps_is_said_in_one_line(tmp_path):
    manager = star_manager(tmp_path, ros2_style(300))
    assert manager.step_clocks == [(4, 4 * DT)]
    # The broadcaster keeps its own schedule: it is not named.
    assert manager.clock_notes == [
        'update_rate 300 Hz of pos is not a whole number of physics steps (0.001 s): updates '
        'every 4 steps, 250 Hz (period 0.004 s), at the first step where 1 / update_rate has '
        'passed since the last update, as gz_ros2_control runs it']
    faster = star_manager(tmp_path, ros2_style(100, 'update_rate: 2500'))
    assert faster.step_clocks == [(1, DT)]
    assert faster.clock_notes[0].startswith(
        'update_rate 2500 Hz of pos is not a whole number of physics steps (0.001 s): updates '
        'every 1 step, 1000 Hz (period 0.001 s)')


def test_a_controller_keeping_its_own_rate_is_called_every_step(tmp_path):
    manager = star_manager(tmp_path, ros2_style(300, position=False, tricycle=True))
    assert manager.update_rate_of('steer') == 300.0
    assert [member.name for member in manager.step_members] == ['steer']
    assert manager.step_clocks == [(1, DT)] and manager.clock_notes == []


def test_an_ideal_actuator_on_a_slower_clock_ramps_and_tracks_every_step(tmp_path):
    manager = star_manager(tmp_path, ros2_style(100))
    (actuate,) = manager.actuations
    controller = manager.controller('pos')
    handle = controller._handle
    controller.set_command(0.5)
    manager.updates[0](0.0, 0.01)  # takes the command; the hardware moves toward it
    assert controller.setpoint == 0.0 and handle.velocity_target == 0.0
    handle.position = -0.001
    actuate(DT)  # one physics step of the ramp, then the target from the joint's position
    setpoint, rate = ramp(0.0, 0.0, 0.5, DT, 2.0)
    assert (controller.setpoint, controller._rate) == (setpoint, rate)
    assert handle.velocity_target == rate + handle.tracking_gain / DT * (setpoint + 0.001)


def test_without_a_time_step_every_controller_updates_every_call(tmp_path):
    manager = star_manager(tmp_path, ros2_style(100),
                           time_step=None)
    assert manager.step_clocks == [(1, 0.0)] and manager.actuations == []


@pytest.mark.parametrize(('rate', 'problem'), [
    ("'fast'", "'fast' is not a number of Hz"),
    ('true', 'True is not a number of Hz'),
    ('-5', '-5 must be a rate > 0 Hz whose period 1 / rate is finite'),
    ('5.0e-324', '5e-324 must be a rate > 0 Hz whose period 1 / rate is finite'),
])
def test_a_controllers_own_update_rate_that_is_no_rate_is_refused_naming_it(tmp_path, rate,
                                                                             problem):
    # JointPositionController does not list update_rate among its parameters: the
    # manager checks it for every type.
    with pytest.raises(ControllerConfigError) as caught:
        star_manager(tmp_path, ros2_style(100, f'update_rate: {rate}'))
    assert str(caught.value).endswith(f'controllers.yaml: pos.update_rate: {problem}')
