"""sim_node as the robot behind topic_based_ros2_control: JointState in, JointState out.

The plugin's cycle is played by the probe in lockstep with the physics: read
the latest state, publish a command, let 10 ms of sim time pass (a
StepSimulation of 10 steps) -- a controller_manager at 100 Hz.
"""

from __future__ import annotations

import pytest
from node_harness import PROBE_QUEUE, sim_node, stamp_s
from sensor_msgs.msg import JointState
from sim_interfaces_client import OK, SimInterfaces
from topic_based_fixtures import topic_based_urdf_file

from pan_tilt_sim.errors import ParameterError

NS = '/ex_urdf_pan_tilt'
CYCLE_STEPS = 10  # 10 ms at the default 1 ms step: a 100 Hz controller_manager
ISAAC_COMMANDS, ISAAC_STATES = '/isaac_joint_commands', '/isaac_joint_states'


class PluginSide:
    """What topic_based_ros2_control does: publishes commands, reads the latest state."""

    def __init__(self, sim, commands_topic: str, states_topic: str) -> None:
        self.sim = sim
        self.states = sim.collect(JointState, states_topic, PROBE_QUEUE)
        self.publisher = sim.probe.create_publisher(JointState, commands_topic, 1)
        assert sim.spin_until(lambda: self.publisher.get_subscription_count() > 0)
        sim.wait_for_subscribers(states_topic)

    def send(self, names, **arrays) -> None:
        """Publish one command; return once the node took it."""
        hardware = self.sim.node.topic_hardware
        before = hardware.commands_received
        self.publisher.publish(JointState(name=list(names), **arrays))
        assert self.sim.spin_until(lambda: hardware.commands_received > before)


def test_a_100_hz_position_stream_moves_the_joint_and_states_come_back_in_sim_time(tmp_path):
    """Mixed interfaces, packed as the plugin packs them, on the URDF's (Isaac's) topics."""
    urdf = topic_based_urdf_file(tmp_path, {'a': ['position'], 'b': ['velocity'],
                                            'c': ['effort']}, commands=ISAAC_COMMANDS,
                                 states=ISAAC_STATES)
    with sim_node(robot_description_file=str(urdf), paused=True) as sim:
        client = SimInterfaces(sim)
        plugin = PluginSide(sim, ISAAC_COMMANDS, ISAAC_STATES)
        for cycle in range(150):  # 1.5 s: a position ramp to 1 rad over the first second
            target = min(1.0, 0.01 * cycle)
            plugin.send(['a', 'b', 'c'], position=[target], velocity=[0.5], effort=[0.0])
            assert client.step(CYCLE_STEPS).result == OK
        sim.drain()
        positions = sim.simulation.joint_positions()
        assert positions['a'] == pytest.approx(1.0, abs=1e-3)
        assert positions['b'] == pytest.approx(0.5 * 1.5, abs=0.01)
        states = plugin.states
        assert len(states) == 150  # 100 Hz of sim time, 0 to 1.49 s
        assert [stamp_s(m) for m in states] == pytest.approx([0.01 * k for k in range(150)])
        last = states[-1]
        assert list(last.name) == ['a', 'b', 'c']
        assert len(last.position) == len(last.velocity) == len(last.effort) == 3
        assert last.position[0] == pytest.approx(1.0, abs=1e-3)
        assert last.velocity[1] == pytest.approx(0.5, abs=1e-3)
        # The ideal actuators: the position follows the ramp of 100 Hz steps a few
        # cycles behind (the setpoint's acceleration limit), at its 1 rad/s.
        mid = next(m for m in states if abs(stamp_s(m) - 0.5) < 1e-6)
        assert 0.49 - 0.06 < mid.position[0] < 0.49
        assert mid.velocity[0] == pytest.approx(1.0, abs=0.05)
        actuators = {name: handle.actuator.kind.label
                     for name, handle in sim.simulation.handles.items()}
        assert actuators == {'a': 'ideal position actuator', 'b': 'ideal velocity actuator',
                             'c': 'effort command'}


def test_partial_messages_by_name_on_the_plugins_default_topics():
    with sim_node(**{'topic_based.enabled': True, 'paused': True}) as sim:
        client = SimInterfaces(sim)
        plugin = PluginSide(sim, '/robot_joint_commands', '/robot_joint_states')
        plugin.send(['pan_joint'], position=[0.3])
        assert client.step(5000).result == OK  # the pan/tilt example's pan ramps at 0.1 rad/s
        positions = sim.simulation.joint_positions()
        assert positions['pan_joint'] == pytest.approx(0.3, abs=1e-3)
        assert positions['tilt_joint'] == pytest.approx(-1.5708, abs=1e-3)  # held
        plugin.send(['tilt_joint', 'pan_joint'], position=[-2.0, 0.3])
        assert client.step(6000).result == OK
        assert sim.simulation.joint_positions()['tilt_joint'] == pytest.approx(-2.0, abs=1e-3)


def test_the_yaml_controllers_do_not_run_in_topic_mode():
    with sim_node(**{'topic_based.enabled': True}) as sim:
        sim.run_until_sim_time(0.1)
        published, subscribed = sim.own_topics()
        assert published['/robot_joint_states'] == 'sensor_msgs/msg/JointState'
        assert subscribed['/robot_joint_commands'] == 'sensor_msgs/msg/JointState'
        assert f'{NS}/joint_states' not in published
        assert not [topic for topic in subscribed if 'controller' in topic]


def test_bad_commands_are_ignored_with_the_reason(capfd):
    with sim_node(**{'topic_based.enabled': True, 'paused': True}) as sim:
        client = SimInterfaces(sim)
        plugin = PluginSide(sim, '/robot_joint_commands', '/robot_joint_states')
        plugin.send(['pan_joint'], velocity=[1.0])
        plugin.send(['pan_joint', 'tilt_joint'], position=[1.0, 2.0, 3.0])
        assert client.step(1000).result == OK
        assert sim.simulation.joint_positions()['pan_joint'] == pytest.approx(0.0, abs=1e-3)
    err = capfd.readouterr().err
    assert "'pan_joint' takes position commands; its velocity ignored" in err


def test_gains_give_a_pid_tunable_live(tmp_path):
    urdf = topic_based_urdf_file(tmp_path, {'a': ['position']})
    with sim_node(robot_description_file=str(urdf),
                  **{'topic_based.pid_gains.a.p': 40.0, 'topic_based.pid_gains.a.d': 2.0}) as sim:
        member = sim.node.topic_hardware._members['a']
        assert (member.pid.gains.p, member.pid.gains.d) == (40.0, 2.0)
        assert sim.node.get_parameter('topic_based_position.gains.a.p').value == 40.0


@pytest.mark.parametrize('overrides, message', [
    ({'topic_based.joints': ['nope']}, "'topic_based.joints': 'nope' is not a movable joint"),
    ({'topic_based.command_interface': 'torque'}, "'topic_based.command_interface' must be"),
    ({'topic_based.publish_rate': 0.0}, "'topic_based.publish_rate' must be > 0"),
])
def test_bad_settings_end_start_up_naming_the_parameter(overrides, message):
    with pytest.raises(ParameterError, match=message):
        with sim_node(**{'topic_based.enabled': True, **overrides}):
            pass
