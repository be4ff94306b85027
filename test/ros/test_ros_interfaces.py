"""ros_interfaces: command messages to the plain values controllers take."""

import math

import pytest
from builtin_interfaces.msg import Duration, Time
from control_msgs.msg import DynamicInterfaceGroupValues, InterfaceValue
from std_msgs.msg import Float64, Float64MultiArray
from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMessage
from trajectory_msgs.msg import JointTrajectoryPoint

from pan_tilt_sim.controllers import CommandKind
from pan_tilt_sim.controllers.trajectory.trajectory import JointTrajectory, TrajectoryPoint
from pan_tilt_sim.ros.ros_interfaces import (
    COMMAND_MESSAGES,
    GROUP_VALUES,
    joint_trajectory,
    optional_message,
    seconds,
)


def test_every_command_kind_and_the_gpio_commands_have_a_message_type():
    assert set(COMMAND_MESSAGES) == {kind.value for kind in CommandKind} | {GROUP_VALUES}
    for type_name, (message_type, _extract) in COMMAND_MESSAGES.items():
        if message_type is None:  # its interface package is optional, and not installed
            continue
        package, _, name = type_name.partition('/msg/')
        assert (message_type.__module__.split('.')[0], message_type.__name__) == (package, name)


def test_float64_arrays_become_lists_of_floats():
    _type, extract = COMMAND_MESSAGES[CommandKind.FLOAT64_ARRAY.value]
    value = extract(Float64MultiArray(data=[1.0, -2.5, math.nan]))
    assert isinstance(value, list)
    assert value[:2] == [1.0, -2.5] and math.isnan(value[2])


def test_float64_is_its_data():
    _type, extract = COMMAND_MESSAGES[CommandKind.FLOAT64.value]
    assert extract(Float64(data=1.57)) == 1.57


def test_seconds_of_time_and_duration():
    assert seconds(Time(sec=3, nanosec=250_000_000)) == 3.25
    assert seconds(Duration(sec=0, nanosec=1_000_000)) == 0.001


def trajectory_message(stamp=None):
    message = JointTrajectoryMessage(joint_names=['b', 'a'])
    if stamp is not None:
        message.header.stamp = stamp
    message.points = [
        JointTrajectoryPoint(positions=[0.1, 0.2], time_from_start=Duration(sec=1)),
        JointTrajectoryPoint(positions=[0.3, 0.4], velocities=[0.0, 0.5],
                             accelerations=[1.0, 1.0],
                             time_from_start=Duration(sec=2, nanosec=500_000_000)),
    ]
    return message


def test_joint_trajectory_becomes_a_plain_value_in_message_order():
    assert joint_trajectory(trajectory_message(Time(sec=4, nanosec=500_000_000))) == (
        JointTrajectory(
            joint_names=('b', 'a'),
            points=(TrajectoryPoint(1.0, (0.1, 0.2), ()),
                    TrajectoryPoint(2.5, (0.3, 0.4), (0.0, 0.5), (1.0, 1.0))),
            start_time=4.5))


def test_zero_stamp_means_start_now():
    assert joint_trajectory(trajectory_message()).start_time is None


def test_multi_dof_commands_become_names_values_and_values_dot():
    control_msgs = pytest.importorskip('control_msgs.msg', reason='control_msgs is not installed')
    message_type, extract = COMMAND_MESSAGES[CommandKind.MULTI_DOF_COMMAND.value]
    assert message_type is control_msgs.MultiDOFCommand
    value = extract(control_msgs.MultiDOFCommand(dof_names=['b', 'a'], values=[1.0, 2.5],
                                                 values_dot=[-0.5, 0.0]))
    assert value == (['b', 'a'], [1.0, 2.5], [-0.5, 0.0])


def test_gpio_group_values_become_plain_lists_of_groups_names_and_values():
    _type, extract = COMMAND_MESSAGES[GROUP_VALUES]
    message = DynamicInterfaceGroupValues(
        interface_groups=['flange_analog_IOs', 'flange_vacuum'],
        interface_values=[InterfaceValue(interface_names=['analog_output1'], values=[0.5]),
                          InterfaceValue(interface_names=['vacuum'], values=[1.0])])
    assert extract(message) == (['flange_analog_IOs', 'flange_vacuum'],
                                [(['analog_output1'], [0.5]), (['vacuum'], [1.0])])


def test_a_message_of_a_package_that_is_not_installed_is_none():
    assert optional_message(GROUP_VALUES) is DynamicInterfaceGroupValues
    assert optional_message('no_such_msgs/msg/Thing') is None
    assert optional_message('std_msgs/msg/NoSuchType') is None
