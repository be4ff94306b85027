"""ros_gz_bridge entries given to a world-only sim_node: its robot's gz topics move to ROS names.

The bridge stand-ins announce themselves on a hidden topic and then set sim_node's
``gz_bridge`` parameter; here the probe plays the bridge, so the order is the test's.
"""

from __future__ import annotations

import importlib.util
from types import SimpleNamespace

import pytest
from geometry_msgs.msg import TwistStamped
from mobile_fixtures import GZ_DIFF_DRIVE, plugin_rover_urdf
from nav_msgs.msg import Odometry
from node_harness import PROBE_QUEUE
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from stand_in_fixtures import BUILD_BUDGET_S, SERVICE, spawn, srv, world_only
from std_msgs.msg import Empty

from pan_tilt_sim.ros.bridged_topics import ANNOUNCE_TOPIC, PARAMETER, BridgedTopics

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('simulation_interfaces') is None,
    reason='simulation_interfaces is not installed')

HELD_S = 1.0
DRIVE_SPEED = 0.3  # m/s
ENTRIES = ['/model/rover/odometry|/odom|nav_msgs/msg/Odometry|gz.msgs.Odometry|GZ_TO_ROS',
           '/model/rover/cmd_vel|/cmd_vel|geometry_msgs/msg/TwistStamped|gz.msgs.Twist|'
           'ROS_TO_GZ']


def set_bridge(harness, values: list[str]):
    """Set sim_node's gz_bridge parameter from the probe; return the result."""
    client = AsyncParameterClient(harness.probe, '/sim_node')
    assert harness.spin_until(client.services_are_ready)
    future = client.set_parameters([Parameter(PARAMETER, Parameter.Type.STRING_ARRAY, values)])
    assert harness.spin_until(future.done)
    (result,) = future.result().results
    return result


def test_a_spawn_waits_for_an_announced_bridge_whose_entries_then_name_the_topics():
    with world_only() as (harness, node):
        harness.probe.create_publisher(Empty, ANNOUNCE_TOPIC, 1)  # a bridge is coming
        client = harness.probe.create_client(srv().SpawnEntity, SERVICE)
        assert harness.spin_until(client.service_is_ready)
        future = client.call_async(srv().SpawnEntity.Request(
            resource_string=plugin_rover_urdf(GZ_DIFF_DRIVE)))
        harness.spin_for(HELD_S)
        assert not future.done() and node.simulation is None  # held for the bridge
        assert set_bridge(harness, ['/probe', *ENTRIES]).successful
        assert harness.spin_until(future.done, BUILD_BUDGET_S)
        assert future.result().result.result == 1
        names = {name: types for name, types in harness.probe.get_topic_names_and_types()}
        assert '/model/rover/odometry' not in names and '/model/rover/cmd_vel' not in names
        assert harness.probe.get_publishers_info_by_topic('/odom')[0].node_name == 'sim_node'
        (reader,) = harness.probe.get_subscriptions_info_by_topic('/cmd_vel')
        assert reader.topic_type == 'geometry_msgs/msg/TwistStamped'


def test_entries_that_come_after_the_robot_copy_its_topics_to_and_from_their_ros_names():
    # The bridge's hand-over came late (its start, or sim_node's discovery of it, after the
    # spawn): the robot's topics exist under their gz names, and are relayed.
    with world_only() as (harness, node):
        assert spawn(harness, resource_string=plugin_rover_urdf(GZ_DIFF_DRIVE)).result.result == 1
        assert set_bridge(harness, ['/probe', *ENTRIES]).successful
        odometry: list[Odometry] = []
        harness.probe.create_subscription(Odometry, '/odom', odometry.append, PROBE_QUEUE)
        assert harness.spin_until(lambda: odometry), harness.probe.get_topic_names_and_types()
        command = harness.probe.create_publisher(TwistStamped, '/cmd_vel', 10)
        assert harness.spin_until(lambda: command.get_subscription_count() > 0), (
            'nobody reads /cmd_vel as TwistStamped')

        def driving() -> bool:
            message = TwistStamped()
            message.twist.linear.x = DRIVE_SPEED
            command.publish(message)
            return odometry[-1].twist.twist.linear.x > 0.5 * DRIVE_SPEED

        assert harness.spin_until(driving), odometry[-1].twist.twist
        assert sorted(node.bridged_topics.relays) == [('/model/rover/cmd_vel', '/cmd_vel'),
                                                      ('/model/rover/odometry', '/odom')]


def test_an_entry_that_would_retype_an_existing_topic_on_its_name_is_refused_others_taken():
    with world_only() as (harness, node):
        assert spawn(harness, resource_string=plugin_rover_urdf(GZ_DIFF_DRIVE)).result.result == 1
        refused = set_bridge(harness, [
            '/probe', '/model/rover/cmd_vel|/model/rover/cmd_vel|geometry_msgs/msg/TwistStamped|'
            'gz.msgs.Twist|ROS_TO_GZ'])
        assert not refused.successful
        assert "'/model/rover/cmd_vel' exists already" in refused.reason
        assert set_bridge(harness, [
            '/probe', '/model/rover/odometry|/model/rover/odometry|nav_msgs/msg/Odometry|'
            'gz.msgs.Odometry|GZ_TO_ROS', '/other|/other|std_msgs/msg/Float64|gz.msgs.Double|'
            'BIDIRECTIONAL']).successful
        bad = set_bridge(harness, ['/probe', '/x|/x|std_msgs/msg/Bool|gz.msgs.Double|GZ_TO_ROS'])
        assert not bad.successful and 'pairs with gz.msgs.Boolean' in bad.reason


class _Graph:
    """The node calls BridgedTopics makes, with the announcing endpoints given."""

    def __init__(self, announcers: list[tuple[str, str]]) -> None:
        self._announcers = announcers

    def declare_parameter(self, *_args) -> None:
        pass

    def add_on_set_parameters_callback(self, _callback) -> None:
        pass

    add_post_set_parameters_callback = add_on_set_parameters_callback

    def get_publishers_info_by_topic(self, topic: str) -> list:
        assert topic == ANNOUNCE_TOPIC
        return [SimpleNamespace(node_namespace=namespace, node_name=name)
                for namespace, name in self._announcers]


def test_a_bridge_not_yet_named_by_discovery_is_not_counted_as_another_bridge():
    # Right after discovery rmw names an endpoint's node '_NODE_NAME_UNKNOWN_'; the same
    # bridge then shows up twice, once by its name and once by the placeholder.
    bridges = BridgedTopics(_Graph([('/robot1', 'parameter_bridge'),
                                    ('_NODE_NAMESPACE_UNKNOWN_', '_NODE_NAME_UNKNOWN_')]))
    assert bridges.pending() == ['/robot1/parameter_bridge']
    assert bridges.known() == 1
