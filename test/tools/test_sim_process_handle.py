"""The plugin's ``sim_process`` fixture: sim_node as a program, the same helpers over DDS."""

from __future__ import annotations

import importlib.util

import pytest
from std_msgs.msg import Float64

from pan_tilt_sim.tools.pytest_plugin import SimFactory
from pan_tilt_sim.tools.sim_process_handle import parameter_argument

PAN_COMMAND = '/ex_urdf_pan_tilt/joint1_position_controller/command'
ROVER = 'package://pan_tilt_sim/urdf/diff_drive_rover.urdf'
ARM = 'package://pan_tilt_sim/urdf/three_joint_arm.xacro'
ARM_CONTROLLERS = 'package://pan_tilt_sim/config/three_joint_arm_controllers.yaml'
ARM_JOINTS = ('shoulder_joint', 'extend_joint', 'wrist_joint')
BOX = ('<robot name="box"><link name="box"><inertial><mass value="1"/><inertia ixx="0.01" '
       'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>'
       '<box size="0.2 0.2 0.2"/></geometry></collision></link></robot>')


def test_parameters_are_written_as_ros_args_take_them():
    assert parameter_argument('paused', True) == 'paused:=true'
    assert parameter_argument('time_step', 0.002) == 'time_step:=0.002'
    assert parameter_argument('xacro_args', ['a:=1', 'b:=2']) == 'xacro_args:=[a:=1, b:=2]'
    assert parameter_argument('record', '') == "record:=''"


def test_it_needs_no_launch_pytest():
    """launch_pytest cannot be installed here: the fixture must stand without it."""
    assert importlib.util.find_spec('launch_pytest') is None


def test_a_command_moves_the_joint_in_sim_time_over_dds(sim_process):
    s = sim_process()
    assert s.time == 0.0
    s.publish(PAN_COMMAND, Float64(data=0.2))  # the pan turns at 0.1 rad/s at most
    s.run_until(lambda: s.joint_positions()['pan_joint'] > 0.15, timeout=5.0)
    assert 1.0 < s.time < 5.0
    before = s.time
    s.step(0.25)
    assert s.time == pytest.approx(before + 0.25, abs=1e-9)


def test_spawn_pose_and_reset_go_through_the_simulator_services(sim_process):
    s = sim_process()
    name = s.spawn(name='box', resource_string=BOX, position=(1.0, 0.0, 1.0))
    s.step(1.0)
    assert s.time == pytest.approx(1.0, abs=1e-9)
    assert s.entity_pose(name).position.z == pytest.approx(0.1, abs=0.01)
    s.reset()
    with pytest.raises(KeyError):
        s.entity_pose(name)


def test_closing_stops_the_program(request):
    factory = SimFactory(request, in_process=False)
    s = factory()
    factory.close()
    assert s.process.returncode is not None


def test_drive_over_dds_returns_the_true_pose_and_the_odometry(sim_process):
    s = sim_process(robot=ROVER)
    end = s.drive('cmd_vel', 0.3, 0.0, 1.5)
    assert s.time == pytest.approx(1.5, abs=0.011)
    assert 0.2 < end.pose.position.x < 0.5
    assert end.odometry.pose.pose.position.x == pytest.approx(end.pose.position.x, abs=0.05)


def test_follow_joint_trajectory_over_dds(sim_process):
    s = sim_process(robot=ARM, controllers=ARM_CONTROLLERS)
    result = s.follow_joint_trajectory('arm_controller', [(1.0, (0.6, 0.1, 1.0))])
    assert result.error_code == 0, result.error_string
    reached = s.joint_positions()
    assert [reached[j] for j in ARM_JOINTS] == pytest.approx((0.6, 0.1, 1.0), abs=0.03)
