"""The sensor arm's <ros2_control> sensors and gpio through sim_node (support/hardware_fixtures.py).

Its broadcasters publish what the simulation measures -- the payload's weight,
gravity on the IMU, the pose -- on their upstream topics, the gpio controller
echoes commands taken on ~/commands into ~/gpio_states, the controller_manager
lists the interfaces, and what the simulator cannot produce is in the log.
"""

import math

import pytest
from control_msgs.msg import DynamicInterfaceGroupValues, InterfaceValue
from controller_manager_msgs.srv import ListHardwareInterfaces
from geometry_msgs.msg import PoseStamped, WrenchStamped
from hardware_fixtures import (
    FT_HEIGHT,
    PAYLOAD_MASS,
    RANGE_HEIGHT,
    VACUUM_START,
    write_sensor_arm,
)
from node_harness import PROBE_QUEUE, sim_node, stamp_s
from sensor_msgs.msg import Imu, Range
from tf2_msgs.msg import TFMessage

from pan_tilt_sim.ros import controller_bindings, ros_interfaces
from pan_tilt_sim.ros.ros_interfaces import GROUP_VALUES
from pan_tilt_sim.sim.physics import STANDARD_GRAVITY

ONE_PERCENT = 0.01
PERIOD = 0.01  # s: the controller_manager's 100 Hz


@pytest.fixture
def arm(tmp_path):
    urdf, controllers = write_sensor_arm(tmp_path)
    with sim_node(robot_description_file=str(urdf), controllers_file=str(controllers),
                  world='ground') as sim:
        yield sim


def listen(sim, message_type, topic):
    received = sim.collect(message_type, topic, PROBE_QUEUE)
    sim.wait_for_subscribers(topic)
    return received


def test_the_wrench_shows_the_payloads_weight_in_the_broadcasters_frame(arm):
    wrenches = listen(arm, WrenchStamped, '/ft_broadcaster/wrench')
    arm.run_for(0.3)
    last = wrenches[-1]
    assert last.header.frame_id == 'ft_link'
    assert last.wrench.force.z == pytest.approx(-PAYLOAD_MASS * STANDARD_GRAVITY,
                                                rel=ONE_PERCENT)
    stamps = [stamp_s(message) for message in wrenches]
    assert all(abs(later - earlier - PERIOD) < 1e-6
               for earlier, later in zip(stamps, stamps[1:], strict=False))


def test_the_imu_at_rest_reads_gravity(arm):
    readings = listen(arm, Imu, '/imu_broadcaster/imu')
    arm.run_for(0.2)
    last = readings[-1]
    assert last.header.frame_id == 'imu_link'
    assert last.linear_acceleration.z == pytest.approx(STANDARD_GRAVITY, rel=ONE_PERCENT)
    assert (last.orientation.w, last.angular_velocity.y) == (pytest.approx(1.0),
                                                            pytest.approx(0.0, abs=1e-9))


def test_the_range_ray_meets_the_worlds_ground(arm):
    ranges = listen(arm, Range, '/range_broadcaster/range')
    arm.run_for(0.1)
    assert ranges[-1].header.frame_id == 'range_link'
    assert ranges[-1].range == pytest.approx(RANGE_HEIGHT, rel=1e-4)


def test_the_pose_and_its_transform_are_the_sensor_links(arm):
    poses = listen(arm, PoseStamped, '/pose_broadcaster/pose')
    transforms = listen(arm, TFMessage, '/tf')
    arm.run_for(0.2)
    assert poses[-1].header.frame_id == 'world'
    assert poses[-1].pose.position.z == pytest.approx(FT_HEIGHT, abs=1e-6)
    mine = [t for message in transforms for t in message.transforms
            if t.child_frame_id == 'tool_pose']
    assert mine and mine[-1].header.frame_id == 'world'
    assert mine[-1].transform.translation.z == pytest.approx(FT_HEIGHT, abs=1e-6)


def test_a_gpio_command_is_echoed_into_its_state(arm):
    states = listen(arm, DynamicInterfaceGroupValues, '/gpio_controller/gpio_states')
    arm.run_for(0.05)
    first = states[-1]
    assert list(first.interface_groups) == ['tool_io']
    (entry,) = first.interface_values
    assert list(entry.interface_names) == ['vacuum', 'pressure']
    assert entry.values[0] == VACUUM_START and math.isnan(entry.values[1])
    arm.command('gpio_controller', DynamicInterfaceGroupValues(
        interface_groups=['tool_io'],
        interface_values=[InterfaceValue(interface_names=['vacuum'], values=[0.0])]))
    arm.run_for(0.05)
    assert states[-1].interface_values[0].values[0] == 0.0


def test_the_controller_manager_lists_the_sensor_and_gpio_interfaces(arm):
    response = arm.call(ListHardwareInterfaces, '/controller_manager/list_hardware_interfaces')
    commands = {item.name: item.is_claimed for item in response.command_interfaces}
    states = {item.name for item in response.state_interfaces}
    assert commands['tool_io/vacuum'] is True  # claimed by the active gpio controller
    assert {'ft_sensor/force.z', 'imu_sensor/linear_acceleration.z', 'range_sensor/range',
            'thermometer/temperature', 'tool_io/pressure'} <= states


def test_what_the_simulator_cannot_produce_is_in_the_node_log_once(tmp_path, capfd):
    urdf, controllers = write_sensor_arm(tmp_path)
    with sim_node(robot_description_file=str(urdf), controllers_file=str(controllers)) as sim:
        sim.run_until_sim_time(0.05)
    warnings = [line for line in capfd.readouterr().err.splitlines()
                if line.startswith('[WARN]')]
    assert len([line for line in warnings if "sensor 'thermometer'" in line]) == 1
    assert len([line for line in warnings if "gpio 'tool_io'" in line]) == 1


def test_a_broadcaster_cleaned_up_stops_watching_its_sensor(arm):
    source = next(sensor for sensor in arm.simulation.hardware.sensors
                  if sensor.control.name == 'ft_sensor')
    listen(arm, WrenchStamped, '/ft_broadcaster/wrench')
    arm.run_for(0.05)
    assert source.feedback_on
    arm.node.set_paused(True)
    arm.node.controllers.switch([], ['ft_broadcaster'], strict=True)
    arm.node.controllers.cleanup('ft_broadcaster')
    assert not source.feedback_on  # PyBullet's joint feedback costs every step


def test_without_control_msgs_the_gpio_controller_runs_without_topics_and_says_so(
        tmp_path, capfd, monkeypatch):
    monkeypatch.delitem(controller_bindings.STATE_SINKS, GROUP_VALUES)
    monkeypatch.delitem(ros_interfaces.COMMAND_MESSAGES, GROUP_VALUES)
    urdf, controllers = write_sensor_arm(tmp_path)
    with sim_node(robot_description_file=str(urdf), controllers_file=str(controllers)) as sim:
        publishers, subscriptions = sim.own_topics()
        assert sim.simulation.manager.is_active('gpio_controller')
    assert not [topic for topic in [*publishers, *subscriptions] if 'gpio_controller' in topic]
    lines = [line for line in capfd.readouterr().err.splitlines() if 'gpio_controller: no topic'
             in line]
    assert len(lines) == 2 and 'control_msgs is not installed' in lines[0]
    assert all(line.startswith('[WARN]') for line in lines)


def test_a_broadcasters_absolute_topic_stays_absolute_in_a_robot_namespace(tmp_path):
    urdf, controllers = write_sensor_arm(tmp_path)
    with sim_node(robot_description_file=str(urdf), controllers_file=str(controllers),
                  robot_namespace='left') as sim:
        publishers, _subscriptions = sim.own_topics()
    assert publishers['/left/pose_broadcaster/pose'] == 'geometry_msgs/msg/PoseStamped'
    assert '/tf' in publishers and '/left/tf' not in publishers
