"""A robot's own ros2_control setup starts unchanged, given only what its launch file would give.

The fixture robot (test/support/ros2_control_fixtures.py) is shaped like Universal
Robots' and ros2_control_demos' setups: a xacro with a ``prefix`` argument, a
``<ros2_control>`` block, a gz_ros2_control plugin naming its controllers
file, and a controllers file with three controllers on the same joints,
vendor types and ``$(var prefix)`` joint names.  sim_node gets the xacro,
``xacro_args``, ``controllers_args`` and ``active_controllers`` -- nothing
else -- and its active joint_trajectory_controller moves the arm.
"""

from __future__ import annotations

import pytest
from builtin_interfaces.msg import Duration
from node_harness import sim_node
from rclpy.parameter import Parameter
from ros2_control_fixtures import ARM_XACRO, HEAD_YAML, UR_STYLE_YAML, write, write_arm
from std_msgs.msg import Float64, Float64MultiArray
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from pan_tilt_sim.errors import ConfigurationError, ControllerConfigError
from pan_tilt_sim.ros.sim_node import SimNode

TARGET = {'left_joint1': 0.8, 'left_joint2': -0.6}
TOLERANCE = 0.02  # rad
ACTIVE = ['joint_state_broadcaster', 'joint_trajectory_controller']


@pytest.fixture
def arm_xacro(tmp_path):
    return write_arm(tmp_path)


def ur_style_parameters(xacro, **overrides):
    """Return what a UR-style launch file would give: the xacro and three lists."""
    return {'robot_description_file': str(xacro), 'xacro_args': ['prefix:=left_'],
            'controllers_args': ['prefix:=left_'], 'active_controllers': ACTIVE, **overrides}


def test_the_active_trajectory_controller_moves_the_arm(arm_xacro):
    with sim_node(**ur_style_parameters(arm_xacro)) as sim:
        assert sim.spin_until(lambda: sim.states), 'no joint_states'
        assert set(sim.states[-1].name) == set(TARGET)
        sim.command('joint_trajectory_controller', JointTrajectory(
            joint_names=list(TARGET),
            points=[JointTrajectoryPoint(positions=list(TARGET.values()),
                                         time_from_start=Duration(sec=1))]))

        def arrived():
            return sim.states and all(abs(sim.position(joint) - target) < TOLERANCE
                                      for joint, target in TARGET.items())
        assert sim.spin_until(arrived), f'the arm stopped at {sim.states[-1].position}'


def test_an_inactive_controller_takes_no_command(arm_xacro):
    with sim_node(**ur_style_parameters(arm_xacro)) as sim:
        simulation = sim.simulation
        forward = simulation.controller('forward_position_controller')
        before = forward.setpoints()
        sim.command('forward_position_controller', Float64MultiArray(data=[1.0, 1.0]))
        sim.run_for(0.5)
        assert forward.setpoints() == before
        assert all(abs(position) < TOLERANCE
                   for position in simulation.joint_positions().values())


def test_vendor_controllers_are_not_loaded_and_the_others_wait_inactive(arm_xacro):
    with sim_node(**ur_style_parameters(arm_xacro)) as sim:
        manager = sim.simulation.manager
        assert [c.name for c in manager.active] == [
            'joint_trajectory_controller', 'joint_state_broadcaster']
        assert {c.name for c in manager.controllers} - {c.name for c in manager.active} == {
            'forward_velocity_controller', 'forward_position_controller'}
        assert {s.name for s in manager.skipped} == {
            'io_and_status_controller', 'speed_scaling_state_broadcaster',
            'scaled_joint_trajectory_controller'}
        # Loaded controllers keep their command topics, as ros2_control's configured ones do.
        sim.wait_for_subscribers('/forward_position_controller/commands')


def test_a_ros1_file_with_one_controller_drives_its_joint(tmp_path, arm_xacro):
    head = write(tmp_path, 'head.yaml', HEAD_YAML)
    with sim_node(robot_description_file=str(arm_xacro), controllers_file=str(head)) as sim:
        sim.command('head', Float64(data=0.5))
        assert sim.spin_until(
            lambda: abs(sim.simulation.joint_positions()['joint1'] - 0.5) < TOLERANCE)
        assert sim.states == []  # no broadcaster in the file: nothing on joint_states


def test_the_pan_tilt_model_still_gets_its_own_controllers(repo_root):
    with sim_node(robot_description_file=str(repo_root / 'urdf' / 'pan_tilt.xacro')) as sim:
        assert sim.node.topic('joint_states') == '/ex_urdf_pan_tilt/joint_states'
        assert {c.name for c in sim.simulation.manager.active} == {
            'joint_state_controller', 'joint1_position_controller', 'joint2_position_controller'}


# --- what start-up refuses, in one line ---------------------------------------------------

def _start(context, **parameters) -> str:
    parameters.setdefault('real_time_factor', 0.0)
    with pytest.raises(ConfigurationError) as raised:
        node = SimNode(context=context, parameter_overrides=[
            Parameter(name, value=value) for name, value in parameters.items()])
        node.destroy_node()
    message = str(raised.value)
    assert '\n' not in message
    return message


def test_without_active_controllers_the_conflict_names_both_and_the_parameter(
        context, arm_xacro):
    message = _start(context, **ur_style_parameters(arm_xacro, active_controllers=[]))
    assert "joint 'left_joint1' is claimed by both 'joint_trajectory_controller' and " \
           "'forward_velocity_controller'" in message
    assert "list those in the parameter 'active_controllers'" in message


def test_an_unset_var_names_it_and_controllers_args(context, arm_xacro):
    message = _start(context, **ur_style_parameters(arm_xacro, controllers_args=[]))
    assert message.endswith(
        "arm_controllers.yaml:33: $(var prefix) is not set: give it in the parameter "
        "'controllers_args' as 'prefix:=<value>' (a launch file would fill it from its "
        'arguments)')


def test_a_malformed_controllers_arg_names_the_parameter(context, arm_xacro):
    message = _start(context, **ur_style_parameters(arm_xacro, controllers_args=['prefix']))
    assert message == "parameter 'controllers_args': 'prefix' is not of the form name:=value"


def test_a_vendor_type_listed_as_active_stops_start_up(context, arm_xacro):
    message = _start(context, **ur_style_parameters(
        arm_xacro, active_controllers=['scaled_joint_trajectory_controller']))
    assert "unknown controller type 'acme_controllers/ScaledJointTrajectoryController', " \
           "and the parameter 'active_controllers' lists it (supported: " in message


def test_an_effort_controller_on_a_position_only_joint_stops_start_up(context, tmp_path):
    xacro = write_arm(tmp_path, UR_STYLE_YAML.replace(
        'position_controllers/JointGroupPositionController',
        'effort_controllers/JointGroupEffortController'))
    message = _start(context, **ur_style_parameters(
        xacro, active_controllers=['forward_position_controller']))
    assert message.endswith(
        "forward_position_controller (effort_controllers/JointGroupEffortController) claims the "
        "'effort' command interface of joint 'left_joint1', which the URDF's <ros2_control> "
        'block does not give it (its command interfaces: position, velocity)')


def test_a_user_urdf_that_names_no_controllers_file_is_told_so(context, tmp_path):
    bare = write(tmp_path, 'bare.urdf.xacro', ARM_XACRO.replace(
        '<parameters>$(arg controllers)</parameters>', ''))
    message = _start(context, robot_description_file=str(bare))
    assert message == (
        f"{bare}: no controllers file: the parameter 'controllers_file' is not set and the "
        'URDF names none (no gz_ros2_control, ign_ros2_control or gazebo_ros2_control plugin '
        "with <parameters>); give the controller YAML with the parameter 'controllers_file'")
    assert 'pan_joint' not in message


def test_a_controllers_file_the_plugin_names_but_that_is_missing_is_named(context, tmp_path):
    xacro = write(tmp_path, 'arm.urdf.xacro', ARM_XACRO)
    message = _start(context, robot_description_file=str(xacro))
    assert message == (
        f"{xacro}: the gz_ros2_control-system plugin's <parameters> names 'arm_controllers.yaml' "
        f"(resolved to {tmp_path / 'arm_controllers.yaml'}): no such file")


def test_listing_a_controller_the_file_lacks_is_an_error(context, arm_xacro):
    message = _start(context, **ur_style_parameters(
        arm_xacro, active_controllers=['joint_state_broadcaster', 'arm_controller']))
    assert message.startswith(
        "the parameter 'active_controllers': no controller 'arm_controller' in ")


def test_a_bad_position_proportional_gain_stops_start_up(context, tmp_path):
    xacro = write_arm(tmp_path)
    xacro.write_text(ARM_XACRO.replace('>0.5</param>', '>-1</param>'))
    with pytest.raises(ConfigurationError, match="'-1' must be a number > 0"):
        SimNode(context=context, parameter_overrides=[
            Parameter('robot_description_file', value=str(xacro))])


def test_controllers_errors_are_controller_config_errors(context, arm_xacro):
    with pytest.raises(ControllerConfigError):
        SimNode(context=context, parameter_overrides=[
            Parameter('robot_description_file', value=str(arm_xacro)),
            Parameter('xacro_args', value=['prefix:=left_']),
            Parameter('controllers_args', value=['prefix:=left_'])])
