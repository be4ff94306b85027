"""reset_simulation, reset_world, pause_physics, unpause_physics -- as gazebo_ros offers them.

The node runs in-process at real_time_factor 0 next to a probe node that
calls the services and commands the pan joint; every wait is a bounded spin.
"""

from __future__ import annotations

import pytest
from node_harness import PROBE_QUEUE, sim_node, stamp_s
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64
from std_srvs.srv import Empty

PAN = 'joint1_position_controller'
TILT_START = -1.570796
PAUSED_WALL_S = 0.3


@pytest.fixture
def world():
    with sim_node() as sim:
        yield sim


def _pan_position(world) -> float:
    return world.simulation.joint_positions()['pan_joint']


def test_reset_simulation_restores_joints_controllers_and_time_zero(world):
    clock = world.collect(Clock, '/clock', PROBE_QUEUE)
    world.wait_for_subscribers('/clock')
    world.command(PAN, Float64(data=1.0))
    world.run_for(2.0)
    pan = world.node.simulation.controller(PAN)
    assert _pan_position(world) > 0.1
    assert pan.pid.integral_term != 0.0

    # Paused, so that no tick runs between the reset and the checks.
    world.node.set_paused(True)
    world.call(Empty, '/reset_simulation')

    simulation = world.node.simulation
    assert simulation.time == 0.0
    assert _pan_position(world) == 0.0
    assert simulation.joint_positions()['tilt_joint'] == pytest.approx(TILT_START)
    assert simulation.joint_velocities() == {'pan_joint': 0.0, 'tilt_joint': 0.0}
    assert pan.setpoint == 0.0
    assert pan.pid.integral_term == 0.0
    # /clock says time went back: a message at 0 after the ones at 2 s.
    assert world.spin_until(lambda: any(stamp_s(m) == 0.0 for m in clock[1:]))
    # The old command is forgotten: the pan holds still at 0.
    world.node.set_paused(False)
    world.run_for(1.0)
    assert abs(_pan_position(world)) < 1e-3


def test_reset_world_restores_joints_but_keeps_time(world):
    world.command(PAN, Float64(data=1.0))
    world.run_for(2.0)
    world.node.set_paused(True)
    world.call(Empty, '/reset_world')
    assert world.node.simulation.time >= 2.0
    assert _pan_position(world) == 0.0
    assert world.node.simulation.controller(PAN).setpoint == 0.0


def test_pause_holds_sim_time_takes_commands_and_they_act_on_unpause(world):
    world.call(Empty, '/pause_physics')
    assert world.node.paused
    assert world.node.get_parameter('paused').value is True
    held = world.node.simulation.time
    world.command(PAN, Float64(data=1.0))
    world.spin_for(PAUSED_WALL_S)
    assert world.node.simulation.time == held
    assert _pan_position(world) == 0.0

    world.call(Empty, '/unpause_physics')
    assert not world.node.paused
    assert world.node.get_parameter('paused').value is False
    world.run_for(1.0)
    # The setpoint ramps at the pan's 0.1 rad/s from the moment of unpausing.
    ramp_s = world.node.simulation.time - held
    assert world.node.simulation.controller(PAN).setpoint == pytest.approx(0.1 * ramp_s,
                                                                          abs=1e-3)
    assert _pan_position(world) > 0.02


def test_the_paused_parameter_is_the_same_switch(world):
    world.node.set_parameters([Parameter('paused', value=True)])
    assert world.node.paused
    world.call(Empty, '/unpause_physics')
    assert world.node.get_parameter('paused').value is False
    world.node.set_paused(True)
    assert world.node.get_parameter('paused').value is True


def test_service_names_follow_the_node_namespace():
    with sim_node(node_namespace='/left') as sim:
        services = sim.own_services()
        assert {'/left/reset_simulation', '/left/reset_world', '/left/pause_physics',
                '/left/unpause_physics'} <= set(services)


def test_a_paused_value_of_the_wrong_type_is_refused_at_run_time(world):
    result, = world.node.set_parameters([Parameter('paused', value='yes')])
    assert not result.successful
    assert "'paused' must be a bool" in result.reason
    assert world.node.get_parameter('paused').value is False
    assert not world.node.paused


def test_resets_return_to_the_initial_positions_parameter():
    with sim_node(initial_positions=['pan_joint:=0.5', 'tilt_joint:=-2.0']) as world:
        simulation = world.node.simulation
        assert simulation.joint_positions() == pytest.approx(
            {'pan_joint': 0.5, 'tilt_joint': -2.0})
        world.command(PAN, Float64(data=1.0))
        world.run_for(2.0)  # 0.1 rad/s
        assert _pan_position(world) > 0.6
        world.node.set_paused(True)
        for service in ('/reset_world', '/reset_simulation'):
            world.call(Empty, service)
            assert simulation.joint_positions() == pytest.approx(
                {'pan_joint': 0.5, 'tilt_joint': -2.0})
            assert simulation.controller(PAN).setpoint == pytest.approx(0.5)
