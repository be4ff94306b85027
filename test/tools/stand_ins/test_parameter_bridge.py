"""ros_gz_bridge's parameter_bridge stand-in as a program: its entries reach sim_node.

The simulation runs in-process (a world-only SimNode, spun while the program runs);
parameter_bridge runs as ``python -m pan_tilt_sim.tools.stand_ins parameter_bridge``.
"""

from __future__ import annotations

import importlib.util
import signal

import pytest
from mobile_fixtures import GZ_DIFF_DRIVE, plugin_rover_urdf
from nav_msgs.msg import Odometry
from node_harness import PROBE_QUEUE
from stand_in_fixtures import finish, spawn, start, world_only

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('simulation_interfaces') is None,
    reason='simulation_interfaces is not installed')

BUDGET_S = 60.0


def run(*arguments: str):
    """Start parameter_bridge with ``arguments``."""
    return start('parameter_bridge', *arguments)


def test_a_type_pair_that_makes_no_sense_exits_2_with_one_line_naming_it():
    code, output = finish(None, run('/scan@sensor_msgs/msg/LaserScan[gz.msgs.Image'))
    assert code == 2 and output.strip() == (
        "parameter_bridge: argument '/scan@sensor_msgs/msg/LaserScan[gz.msgs.Image': "
        "'sensor_msgs/msg/LaserScan' pairs with gz.msgs.LaserScan, not 'gz.msgs.Image'")


def test_a_bad_config_file_entry_exits_2_naming_the_file_and_entry(tmp_path):
    config = tmp_path / 'bridge.yaml'
    config.write_text('- topic_name: odom\n  ros_type_name: nav_msgs/msg/Odometry\n'
                      '  gz_type_name: gz.msgs.Odometry\n  direction: SIDEWAYS\n')
    code, output = finish(None, run('--ros-args', '-p', f'config_file:={config}'))
    assert code == 2 and output.strip() == (
        f"parameter_bridge: {config}: entry 0: invalid direction 'SIDEWAYS' "
        '(BIDIRECTIONAL, GZ_TO_ROS, ROS_TO_GZ)')


def test_its_entries_rename_the_robots_topics_and_it_stays_until_stopped():
    with world_only() as (harness, node):
        # A relative name: the ROS name is in the bridge's namespace, the gz one is not.
        process = run('model/rover/odometry@nav_msgs/msg/Odometry[gz.msgs.Odometry',
                        '--ros-args', '-r', '__ns:=/robot1')
        try:
            assert harness.spin_until(
                lambda: node.bridged_topics.pending() == [] and node.bridged_topics._sources,
                BUDGET_S), 'the bridge never handed over'
            assert process.poll() is None  # a bridge runs until stopped
            response = spawn(harness, resource_string=plugin_rover_urdf(GZ_DIFF_DRIVE))
            assert response.result.result == 1
            def renamed() -> bool:
                names = dict(harness.probe.get_topic_names_and_types())
                return ('/robot1/model/rover/odometry' in names
                        and '/model/rover/odometry' not in names)

            assert harness.spin_until(renamed), harness.probe.get_topic_names_and_types()
        finally:
            process.send_signal(signal.SIGINT)
            code, output = finish(harness, process)
        assert code == 0, output


def test_lazy_is_taken_without_a_warning_and_a_subscriber_gets_the_messages(tmp_path):
    # ros_gz_bridge's lazy saves the bridge's copying; sim_node copies nothing, so a ROS
    # subscriber sees what it sees without lazy, and nothing is warned about.
    from nav_msgs.msg import Odometry

    config = tmp_path / 'bridge.yaml'
    config.write_text('- ros_topic_name: rover_odom\n  gz_topic_name: /model/rover/odometry\n'
                      '  ros_type_name: nav_msgs/msg/Odometry\n  gz_type_name: gz.msgs.Odometry\n'
                      '  direction: GZ_TO_ROS\n  lazy: true\n')
    with world_only() as (harness, node):
        process = run('/clock@rosgraph_msgs/msg/Clock[gz.msgs.Clock', '--ros-args',
                      '-p', 'lazy:=true', '-p', f'config_file:={config}')
        try:
            assert harness.spin_until(
                lambda: node.bridged_topics.pending() == [] and node.bridged_topics._sources,
                BUDGET_S), 'the bridge never handed over'
            odometry: list = []
            harness.probe.create_subscription(Odometry, '/rover_odom', odometry.append, 10)
            response = spawn(harness, resource_string=plugin_rover_urdf(GZ_DIFF_DRIVE))
            assert response.result.result == 1
            assert harness.spin_until(lambda: len(odometry) >= 3, BUDGET_S), 'no odometry'
        finally:
            process.send_signal(signal.SIGINT)
            code, output = finish(harness, process)
        assert code == 0, output
        assert output.count('(Lazy 1)') == 2 and 'not honoured' not in output, output


def test_a_bridge_started_after_the_robot_is_in_has_its_topic_copied_to_the_ros_name():
    with world_only() as (harness, node):
        assert spawn(harness, resource_string=plugin_rover_urdf(GZ_DIFF_DRIVE)).result.result == 1
        process = run('model/rover/odometry@nav_msgs/msg/Odometry[gz.msgs.Odometry',
                      '--ros-args', '-r', '__ns:=/robot1')
        odometry: list[Odometry] = []
        harness.probe.create_subscription(Odometry, '/robot1/model/rover/odometry',
                                          odometry.append, PROBE_QUEUE)
        try:
            assert harness.spin_until(lambda: odometry, BUDGET_S), (
                harness.probe.get_topic_names_and_types())
            assert process.poll() is None  # not refused: it runs until stopped
        finally:
            process.send_signal(signal.SIGINT)
            code, output = finish(harness, process)
        assert code == 0, output


def test_image_bridge_hands_its_image_topics_over_and_without_topics_prints_its_usage():
    code, output = finish(None, start('image_bridge'))
    assert code == 255 and 'image_bridge <topic> <topic>' in output
    with world_only() as (harness, node):
        process = start('image_bridge', '/camera/image_raw')
        try:
            assert harness.spin_until(lambda: '/ros_gz_image' in node.bridged_topics._sources,
                                      BUDGET_S), 'image_bridge never handed over'
            assert process.poll() is None
        finally:
            process.send_signal(signal.SIGINT)
            code, output = finish(harness, process)
        assert code == 0, output


def test_image_bridge_names_a_qos_it_does_not_apply_in_one_warning():
    with world_only() as (harness, node):
        process = start('image_bridge', '/camera/image_raw', '--ros-args', '-p',
                        'qos:=sensor_data')
        try:
            assert harness.spin_until(lambda: '/ros_gz_image' in node.bridged_topics._sources,
                                      BUDGET_S), 'image_bridge never handed over'
        finally:
            process.send_signal(signal.SIGINT)
            code, output = finish(harness, process)
        assert code == 0, output
        assert output.count("qos 'sensor_data' is not honoured") == 1, output


def test_ros_names_are_the_bridge_nodes_and_gz_names_absolute_unless_expanded():
    from node_harness import NodeHarness
    from rclpy.node import Node

    from pan_tilt_sim.model.gz_bridge import GZ_TO_ROS, BridgeEntry
    from pan_tilt_sim.tools.stand_ins.bridging import absolute

    harness = NodeHarness()
    try:
        node = Node('ros_gz_bridge', namespace='/robot1', context=harness.context)
        entry = BridgeEntry('odom', 'odom', 'nav_msgs/msg/Odometry', 'gz.msgs.Odometry',
                            GZ_TO_ROS)
        plain, expanded = absolute(node, entry, False), absolute(node, entry, True)
        assert (plain.ros_topic, plain.gz_topic) == ('/robot1/odom', '/odom')
        assert (expanded.ros_topic, expanded.gz_topic) == ('/robot1/odom', '/robot1/odom')
        node.destroy_node()
    finally:
        harness.close()
