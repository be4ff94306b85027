"""A pid_controller chain on sim_node: a forward group feeds its references; physics moves it.

The robot is the test's own: one link turning about z (gravity loads it not)
whose ``<ros2_control>`` block gives ``joint1`` the effort command interface.
``pid`` (pid_controller/PidController, position and velocity references,
effort command) drives it; ``forward`` (a ForwardCommandController on
``pid/joint1``, position interface) commands ``pid``'s position reference.
Both start active, as the file declares them; list_controllers shows the
chain, and the joint reaches what the group commands.  Without the group,
``pid`` takes ``~/reference`` and reports ``~/controller_state``; its gains
are node parameters, and its ROS entities go at cleanup.
"""

from __future__ import annotations

import importlib.util

import pytest
from node_harness import sim_node
from ros2_control_fixtures import write
from spawner_client import Spawner, srv
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import SetBool

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('controller_manager_msgs') is None
    or importlib.util.find_spec('control_msgs') is None,
    reason='controller_manager_msgs or control_msgs is not installed')

TOLERANCE = 0.01  # rad, rad/s
P, D = 20.0, 2.0

URDF = """\
<?xml version="1.0"?>
<robot name="one_link">
  <link name="world"/>
  <link name="base">
    <inertial><mass value="5"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
  </link>
  <joint name="base_joint" type="fixed"><parent link="world"/><child link="base"/></joint>
  <link name="link1">
    <visual><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.04 0.04"/></geometry></visual>
    <inertial><origin xyz="0.2 0 0"/><mass value="1.0"/>
      <inertia ixx="0.0003" ixy="0" ixz="0" iyy="0.0135" iyz="0" izz="0.0135"/></inertial>
  </link>
  <joint name="joint1" type="revolute">
    <parent link="base"/><child link="link1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="1.5" effort="20" velocity="2"/>
    <dynamics damping="0.1"/>
  </joint>
  <ros2_control name="OneLink" type="system">
    <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>
    <joint name="joint1">
      <command_interface name="effort"/>
      <state_interface name="position"/>
      <state_interface name="velocity"/>
    </joint>
  </ros2_control>
</robot>
"""

CONTROLLERS = f"""\
controller_manager:
  ros__parameters:
    update_rate: 100
    pid:
      type: pid_controller/PidController
    forward:
      type: forward_command_controller/ForwardCommandController
pid:
  ros__parameters:
    dof_names: [joint1]
    command_interface: effort
    reference_and_state_interfaces: [position, velocity]
    gains:
      joint1: {{p: {P}, i: 0.0, d: {D}}}
forward:
  ros__parameters:
    joints: [pid/joint1]
    interface_name: position
"""


@pytest.fixture
def chained(tmp_path):
    """sim_node on the one-link robot with ``pid`` and ``forward`` active: a chain."""
    urdf = write(tmp_path, 'one_link.urdf', URDF)
    controllers = write(tmp_path, 'controllers.yaml', CONTROLLERS)
    with sim_node(robot_description_file=str(urdf), controllers_file=str(controllers)) as sim:
        yield sim, Spawner(sim)


def joint1(sim) -> tuple[float, float]:
    """Return joint1's position and velocity."""
    handle = sim.simulation.handles['joint1']
    return handle.position, handle.velocity


def multi_dof_command(values, values_dot=()):
    from control_msgs.msg import MultiDOFCommand

    return MultiDOFCommand(dof_names=['joint1'], values=list(values),
                           values_dot=list(values_dot))


def test_list_controllers_shows_the_chain(chained):
    _sim, spawner = chained
    listed = spawner.controllers()
    pid, forward = listed['pid'], listed['forward']
    assert (pid.state, pid.is_chainable, pid.is_chained) == ('active', True, True)
    assert list(pid.reference_interfaces) == ['joint1/position', 'joint1/velocity']
    assert list(pid.claimed_interfaces) == ['joint1/effort']
    assert list(pid.required_state_interfaces) == ['joint1/position', 'joint1/velocity']
    assert list(pid.chain_connections) == []
    assert (forward.state, forward.is_chainable, forward.is_chained) == (
        'active', False, False)
    assert list(forward.claimed_interfaces) == ['pid/joint1/position']
    assert [(c.name, list(c.reference_interfaces)) for c in forward.chain_connections] == [
        ('pid', ['joint1/position'])]
    types = spawner.call('list_controller_types')
    assert dict(zip(types.types, types.base_classes, strict=True))[
        'pid_controller/PidController'] == 'controller_interface::ChainableControllerInterface'


def test_the_joint_reaches_what_the_preceding_group_commands_not_pids_own_topic(chained):
    sim, _spawner = chained
    sim.command('forward', Float64MultiArray(data=[0.6]))
    sim.run_for(3.0)
    position, velocity = joint1(sim)
    assert position == pytest.approx(0.6, abs=TOLERANCE)
    assert velocity == pytest.approx(0.0, abs=TOLERANCE)
    sim.command('pid', multi_dof_command([-0.4]))  # chained: ignored
    sim.run_for(1.0)
    assert joint1(sim)[0] == pytest.approx(0.6, abs=TOLERANCE)


def test_without_the_group_pid_takes_its_topic_and_reports_its_state(chained):
    from control_msgs.msg import MultiDOFStateStamped

    sim, spawner = chained
    assert spawner.switch(deactivate=['forward']).ok
    assert not spawner.controllers()['pid'].is_chained
    states = sim.collect(MultiDOFStateStamped, '/pid/controller_state')
    sim.command('pid', multi_dof_command([-0.4], [0.0]))
    sim.run_for(3.0)
    assert joint1(sim)[0] == pytest.approx(-0.4, abs=TOLERANCE)
    assert states, 'nothing on /pid/controller_state'
    (last,) = states[-1].dof_states
    assert last.name == 'joint1' and last.reference == -0.4
    assert last.feedback == pytest.approx(-0.4, abs=TOLERANCE)
    assert last.output == pytest.approx(P * last.error + D * last.error_dot)
    response = sim.call(SetBool, '/pid/set_feedforward_control', SetBool.Request(data=True))
    assert response.success and sim.simulation.controller('pid').feedforward


def test_its_gains_are_node_parameters_tuned_live(chained):
    sim, _spawner = chained
    assert sim.node.get_parameter('pid.gains.joint1.p').value == P
    assert sim.node.get_parameter('pid.gains.joint1.d').value == D
    (result,) = sim.set_parameters(**{'pid.gains.joint1.p': 35.0})
    assert result.successful
    assert sim.simulation.controller('pid').pids()['joint1'].gains.p == 35.0


def test_cleanup_removes_its_topics_service_and_parameters(chained):
    sim, spawner = chained
    assert spawner.switch(deactivate=['forward', 'pid']).ok
    assert spawner.call('cleanup_controller', srv().CleanupController.Request(name='pid')).ok
    publishers, subscriptions = sim.own_topics()
    assert '/pid/reference' not in subscriptions
    assert '/pid/controller_state' not in publishers
    assert '/pid/set_feedforward_control' not in sim.own_services()
    assert not sim.node.has_parameter('pid.gains.joint1.p')
    assert spawner.configure('pid')
    assert '/pid/reference' in sim.own_topics()[1]
    assert sim.own_services()['/pid/set_feedforward_control'] == 'std_srvs/srv/SetBool'


@pytest.fixture
def chained_on_external_state(tmp_path):
    """The chain, with ``pid`` reading its state from ``~/measured_state``."""
    urdf = write(tmp_path, 'one_link.urdf', URDF)
    controllers = write(tmp_path, 'controllers.yaml', CONTROLLERS.replace(
        '    command_interface: effort\n',
        '    command_interface: effort\n    use_external_measured_states: true\n'))
    with sim_node(robot_description_file=str(urdf), controllers_file=str(controllers)) as sim:
        yield sim


def test_in_chained_mode_the_measured_state_topic_is_still_read(chained_on_external_state):
    sim = chained_on_external_state
    assert sim.simulation.controller('pid').is_chained
    sim.command('forward', Float64MultiArray(data=[0.5]))
    sim.run_for(0.5)
    assert joint1(sim)[0] == 0.0  # no measured state yet: no command
    publisher = sim.probe.create_publisher(type(multi_dof_command([0.0])),
                                           '/pid/measured_state', 10)
    sim.wait_for_subscribers('/pid/measured_state')
    counts = sim.node.commands_received
    before = counts['pid']
    publisher.publish(multi_dof_command([0.0], [0.0]))  # held at 0: the error stays 0.5
    assert sim.spin_until(lambda: counts['pid'] > before), 'pid never took the measured state'
    sim.run_for(0.5)
    assert joint1(sim)[0] > 0.1
