"""A controller on an interface the robot declares but the simulation cannot drive.

ros2_control_demos' example 13 in small (test/support/ros2_control_fixtures.py): its
ThreeDofBot's mock hardware declares a ``pid_gain`` command interface on each
joint, and a ForwardCommandController claims it.  Upstream loads and
configures that controller and refuses to activate it; so does sim_node,
with one line naming the joint and the interface, while the rest runs.  An
interface the ``<ros2_control>`` block does not declare is malformed input:
start-up ends with one line.
"""

from __future__ import annotations

import importlib.util

import pytest
from drop_in_fixtures import drop_in_node
from node_harness import SimUnderTest, sim_node
from robot_state_publisher_stand_in import RobotStatePublisherStandIn
from ros2_control_fixtures import (
    PID_GAIN_CONTROLLER,
    THREE_DOF_ACTIVE,
    THREE_DOF_YAML,
    three_dof_urdf,
    write,
)
from spawner_client import STRICT, Spawner
from std_msgs.msg import Float64MultiArray

from pan_tilt_sim.errors import ControllerConfigError

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec('controller_manager_msgs') is None,
    reason='controller_manager_msgs is not installed')

REFUSAL = (f"Unable to activate controller '{PID_GAIN_CONTROLLER}' since the command interface "
           "'threedofbot_joint1/pid_gain' is not available: the simulation can drive position, "
           'velocity, effort and acceleration')
BUILD_BUDGET_S = 20.0


def standalone(tmp_path, urdf: str | None = None) -> dict:
    return {'robot_description_file': str(write(tmp_path, 'threedofbot.urdf',
                                                urdf or three_dof_urdf())),
            'controllers_file': str(write(tmp_path, 'three_robots_controllers.yaml',
                                          THREE_DOF_YAML))}


def test_standalone_the_others_are_active_and_it_stays_inactive_with_one_line(tmp_path, capfd):
    with sim_node(**standalone(tmp_path)) as sim:
        manager = sim.simulation.manager
        assert {c.name for c in manager.active} == set(THREE_DOF_ACTIVE)
        assert manager.state(PID_GAIN_CONTROLLER) == 'inactive'
        # The rest runs: the position group moves its joints.
        sim.command('threedofbot_position_controller', Float64MultiArray(data=[0.3, -0.2, 0.1]))
        sim.run_until_sim_time(1.0)
        positions = sim.simulation.joint_positions()
        assert positions['threedofbot_joint1'] == pytest.approx(0.3, abs=0.01)
    lines = [line for line in capfd.readouterr().err.splitlines() if PID_GAIN_CONTROLLER in line]
    assert len(lines) == 1, lines
    assert lines[0].startswith('[WARN]') and lines[0].endswith(REFUSAL)


def test_an_interface_the_block_does_not_declare_ends_start_up_with_one_line(tmp_path):
    urdf = three_dof_urdf(pid_gain_joints=('threedofbot_joint1', 'threedofbot_joint2'))
    with pytest.raises(ControllerConfigError) as raised:
        with sim_node(**standalone(tmp_path, urdf)):
            pass
    assert str(raised.value).endswith(
        f"{PID_GAIN_CONTROLLER}.interface_name: joint 'threedofbot_joint3' interface "
        "'pid_gain': the simulator can drive position, velocity, effort and acceleration")
    assert '\n' not in str(raised.value)


def test_its_inactive_spawner_succeeds_and_activating_it_is_refused_with_the_line(tmp_path):
    controllers = write(tmp_path, 'three_robots_controllers.yaml', THREE_DOF_YAML)
    with drop_in_node('--params-file', str(controllers)) as (harness, node):
        harness.add(RobotStatePublisherStandIn(three_dof_urdf(), context=harness.context))
        assert harness.spin_until(lambda: node.simulation is not None, BUILD_BUDGET_S)
        spawner = Spawner(SimUnderTest(harness, node))
        assert spawner.spawn(PID_GAIN_CONTROLLER, [controllers], inactive=True) == 0
        assert spawner.controllers()[PID_GAIN_CONTROLLER].state == 'inactive'
        response = spawner.switch(activate=[PID_GAIN_CONTROLLER], strictness=STRICT)
        assert not response.ok and response.message == REFUSAL
        assert spawner.spawn(PID_GAIN_CONTROLLER, [controllers]) == 1  # a spawner activating it
        assert spawner.controllers()[PID_GAIN_CONTROLLER].state == 'inactive'
