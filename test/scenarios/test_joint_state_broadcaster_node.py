"""joint_state_broadcaster on sim_node: local topics per robot, and /dynamic_joint_states.

The fixture is shaped like ros2_control_demos' example 13 (several robots
under one controller_manager), written here from scratch: one URDF holding
a two-joint ``rrbot`` and a three-joint ``threedofbot`` whose
``<ros2_control>`` block also declares ``velocity`` and a custom
``pid_gain`` state interface; a controllers file with a global
joint_state_broadcaster, one broadcaster per robot with ``use_local_topics``
and ``joints`` x ``interfaces``, and a forward position controller for the
rrbot.
"""

from __future__ import annotations

import importlib.util
import math

import pytest
from node_harness import PROBE_QUEUE, sim_node
from robot_fixtures import JointDef, star_robot_urdf, write_text
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

RRBOT = ['rrbot_joint1', 'rrbot_joint2']
THREEDOFBOT = ['threedofbot_joint1', 'threedofbot_joint2', 'threedofbot_joint3']
JSB_TYPE = 'joint_state_broadcaster/JointStateBroadcaster'
# The global broadcaster's entry under controller_manager's ros__parameters.
GLOBAL_ENTRY = f"""
            joint_state_broadcaster:
              type: {JSB_TYPE}"""
RRBOT_JSB, THREEDOFBOT_JSB = 'rrbot_joint_state_broadcaster', 'threedofbot_joint_state_broadcaster'
PID_GAIN_START = 0.25  # threedofbot_joint1's pid_gain initial_value; the others have none
TARGET = [0.5, -0.25]  # rad, the rrbot's command
TOLERANCE = 0.02  # rad

needs_control_msgs = pytest.mark.skipif(importlib.util.find_spec('control_msgs') is None,
                                        reason='control_msgs is not installed')


def _control_joint(name: str, *custom: str, initial: float | None = None,
                   velocity: bool = False) -> str:
    start = '' if initial is None else f'<param name="initial_value">{initial}</param>'
    lines = [f'<joint name="{name}">', '<command_interface name="position"/>',
             '<state_interface name="position"/>']
    if velocity:
        lines.append('<state_interface name="velocity"/>')
    lines += [f'<state_interface name="{interface}">{start}</state_interface>'
              for interface in custom]
    return '\n'.join([*lines, '</joint>'])


def write_three_robots(folder, *, global_broadcaster: bool = True):
    """Write the fixture's URDF and controllers file; return both paths."""
    blocks = (
        '<ros2_control name="RRBotSystemPositionOnly" type="system">'
        '<hardware><plugin>demo/RRBotSystemPositionOnlyHardware</plugin></hardware>'
        + ''.join(_control_joint(joint) for joint in RRBOT) + '</ros2_control>'
        '<ros2_control name="FakeThreeDofBot" type="system">'
        '<hardware><plugin>mock_components/GenericSystem</plugin></hardware>'
        + _control_joint(THREEDOFBOT[0], 'pid_gain', initial=PID_GAIN_START, velocity=True)
        + ''.join(_control_joint(joint, 'pid_gain', velocity=True) for joint in THREEDOFBOT[1:])
        + '</ros2_control>')
    urdf = star_robot_urdf([JointDef(name) for name in RRBOT + THREEDOFBOT], 'three_robots')
    urdf_path = folder / 'three_robots.urdf'
    urdf_path.write_text(urdf.replace('</robot>', f'{blocks}</robot>'), encoding='utf-8')
    controllers = write_text(folder, 'three_robots_controllers.yaml', f"""
        controller_manager:
          ros__parameters:
            update_rate: 100{GLOBAL_ENTRY if global_broadcaster else ''}
            {RRBOT_JSB}:
              type: {JSB_TYPE}
            rrbot_position_controller:
              type: forward_command_controller/ForwardCommandController
            {THREEDOFBOT_JSB}:
              type: {JSB_TYPE}
        {RRBOT_JSB}:
          ros__parameters:
            use_local_topics: True
            joints: [{', '.join(RRBOT)}]
            interfaces: [position]
        rrbot_position_controller:
          ros__parameters:
            joints: [{', '.join(RRBOT)}]
            interface_name: position
        {THREEDOFBOT_JSB}:
          ros__parameters:
            use_local_topics: True
            joints: [{', '.join(THREEDOFBOT)}]
            interfaces: [position, pid_gain]
        """)
    return urdf_path, controllers


@pytest.fixture
def three_robots(tmp_path):
    urdf, controllers = write_three_robots(tmp_path)
    with sim_node(robot_description_file=str(urdf), controllers_file=str(controllers)) as sim:
        yield sim


def test_the_rrbot_broadcaster_publishes_only_its_two_joints_on_its_local_topic(three_robots):
    sim = three_robots
    topic = sim.node.topic(RRBOT_JSB, 'joint_states')
    local = sim.collect(JointState, topic, PROBE_QUEUE)
    sim.wait_for_subscribers(topic)
    sim.command('rrbot_position_controller', Float64MultiArray(data=TARGET))
    sim.run_for(1.0)
    assert local, f'nothing on {topic}'
    assert {tuple(message.name) for message in local} == {tuple(RRBOT)}
    last = local[-1]
    assert list(last.position) == pytest.approx(TARGET, abs=TOLERANCE)
    # Only position is selected: velocity and effort are NaN, as upstream leaves them.
    assert all(math.isnan(value) for value in (*last.velocity, *last.effort))
    # The global broadcaster still publishes every joint of both robots on joint_states.
    assert sim.states and list(sim.states[-1].name) == RRBOT + THREEDOFBOT
    assert sim.position('rrbot_joint1') == pytest.approx(TARGET[0], abs=TOLERANCE)


def test_each_local_broadcaster_has_its_own_topic_and_only_one_publishes_globally(
        three_robots):
    node = three_robots.node
    joint_states = sorted(publisher.topic_name for publisher in node.publishers
                          if publisher.msg_type is JointState)
    assert joint_states == sorted([node.topic('joint_states'),
                                   node.topic(RRBOT_JSB, 'joint_states'),
                                   node.topic(THREEDOFBOT_JSB, 'joint_states')])


@needs_control_msgs
def test_dynamic_joint_states_carry_the_declared_custom_interface(three_robots):
    from control_msgs.msg import DynamicJointState

    sim = three_robots
    topic = sim.node.topic(THREEDOFBOT_JSB, 'dynamic_joint_states')
    dynamic = sim.collect(DynamicJointState, topic, PROBE_QUEUE)
    sim.wait_for_subscribers(topic)
    sim.run_for(0.1)
    assert dynamic, f'nothing on {topic}'
    last = dynamic[-1]
    assert list(last.joint_names) == THREEDOFBOT
    assert [list(value.interface_names) for value in last.interface_values] == [
        ['position', 'pid_gain']] * 3
    gains = [value.values[1] for value in last.interface_values]
    # Nothing measures pid_gain: it holds its initial_value, else NaN.
    assert gains[0] == PID_GAIN_START and all(math.isnan(gain) for gain in gains[1:])


@needs_control_msgs
def test_the_global_dynamic_joint_states_list_every_interface_of_every_joint(three_robots):
    from control_msgs.msg import DynamicJointState

    sim = three_robots
    topic = sim.node.topic('dynamic_joint_states')
    dynamic = sim.collect(DynamicJointState, topic, PROBE_QUEUE)
    sim.wait_for_subscribers(topic)
    sim.command('rrbot_position_controller', Float64MultiArray(data=TARGET))
    sim.run_for(1.0)
    assert dynamic, f'nothing on {topic}'
    last = dynamic[-1]
    assert list(last.joint_names) == RRBOT + THREEDOFBOT
    interfaces = [list(value.interface_names) for value in last.interface_values]
    assert interfaces == [['position', 'velocity', 'effort']] * 2 + [
        ['position', 'velocity', 'effort', 'pid_gain']] * 3
    positions = [value.values[0] for value in last.interface_values[:2]]
    assert positions == pytest.approx(TARGET, abs=TOLERANCE)


@needs_control_msgs
def test_the_dynamic_message_is_sampled_only_while_someone_listens(three_robots):
    from control_msgs.msg import DynamicJointState

    sim = three_robots
    broadcaster = sim.simulation.controller(RRBOT_JSB)
    joint_states = sim.node.topic(RRBOT_JSB, 'joint_states')
    sim.collect(JointState, joint_states, PROBE_QUEUE)
    sim.wait_for_subscribers(joint_states)
    sim.command('rrbot_position_controller', Float64MultiArray(data=TARGET))
    sim.run_for(1.0)
    assert broadcaster.positions == pytest.approx(TARGET, abs=TOLERANCE)
    # Nobody subscribes to its dynamic topic: its values were never read since the start.
    assert [values[0] for values in broadcaster.dynamic_values] == [0.0, 0.0]
    dynamic_topic = sim.node.topic(RRBOT_JSB, 'dynamic_joint_states')
    dynamic = sim.collect(DynamicJointState, dynamic_topic, PROBE_QUEUE)
    sim.wait_for_subscribers(dynamic_topic)
    assert sim.spin_until(lambda: dynamic), f'nothing on {dynamic_topic}'
    assert [values[0] for values in broadcaster.dynamic_values] == pytest.approx(
        TARGET, abs=TOLERANCE)


@pytest.mark.skipif(importlib.util.find_spec('controller_manager_msgs') is None,
                    reason='controller_manager_msgs is not installed')
def test_list_controllers_shows_the_interfaces_each_broadcaster_reads(three_robots):
    from spawner_client import Spawner

    listed = Spawner(three_robots).controllers()
    required = {name: list(listed[name].required_state_interfaces)
                for name in ('joint_state_broadcaster', RRBOT_JSB, THREEDOFBOT_JSB)}
    rrbot = [f'{joint}/position' for joint in RRBOT]
    # What each reads that the hardware lists: the <ros2_control> blocks declare no effort.
    assert required == {
        'joint_state_broadcaster': rrbot + [f'{joint}/{interface}' for joint in THREEDOFBOT
                                            for interface in ('position', 'velocity', 'pid_gain')],
        RRBOT_JSB: rrbot,
        THREEDOFBOT_JSB: [f'{joint}/{interface}' for joint in THREEDOFBOT
                          for interface in ('position', 'pid_gain')]}


def test_with_only_local_broadcasters_start_up_warns_that_joint_states_stays_empty(
        tmp_path, capfd):
    urdf, controllers = write_three_robots(tmp_path, global_broadcaster=False)
    with sim_node(robot_description_file=str(urdf), controllers_file=str(controllers)) as sim:
        topic = sim.node.topic('joint_states')
    assert (f'no joint_state_broadcaster in {controllers} publishes on {topic} '
            f'(use_local_topics: {RRBOT_JSB}, {THREEDOFBOT_JSB}): nothing will be published on '
            f'{topic}') in capfd.readouterr().err
