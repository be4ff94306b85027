"""simulation_interfaces, served by sim_node: each service called by a real rclpy client.

The node runs in-process at real_time_factor 0 beside the probe node (see
node_harness); the calls go over DDS like any other client's.  Entities,
spawning and resets have their own module (test_simulation_entities.py).
"""

from __future__ import annotations

import pytest
from node_harness import PROBE_QUEUE, sim_node, stamp_s
from rclpy.action import ActionClient, ActionServer
from rosgraph_msgs.msg import Clock
from sim_interfaces_client import (
    OK,
    SERVICES,
    Result,
    SimInterfaces,
    State,
    action,
    msg,
    srv,
)
from std_srvs.srv import Empty

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.ros import simulation_services
from pan_tilt_sim.ros.ros_interfaces import SERVICE_QOS

Features = msg.SimulatorFeatures
TIME_STEP = 0.002  # not the default, so that "steps x time_step" is checked
MAX_STEPS = simulation_services.MAX_STEP_SIMULATION_STEPS


@pytest.fixture
def paused():
    """A pan/tilt sim_node started paused (STOPPED), and its simulation_interfaces client."""
    with sim_node(paused=True, time_step=TIME_STEP) as sim:
        yield SimInterfaces(sim)


@pytest.fixture
def playing():
    """A pan/tilt sim_node started playing, and its simulation_interfaces client."""
    with sim_node(time_step=TIME_STEP) as sim:
        yield SimInterfaces(sim)


# --- names and features --------------------------------------------------------------------

def test_services_are_under_the_node_name_and_gazebo_ros_empty_reset_stays(paused):
    services = paused.sim.own_services()
    for leaf, (kind, _harmless) in SERVICES.items():
        assert services[f'/sim_node/{leaf}'] == f'simulation_interfaces/srv/{kind.__name__}'
    assert services['/reset_simulation'] == 'std_srvs/srv/Empty'
    # The action's send_goal, cancel_goal and get_result, as `ros2 action list` finds them.
    graph = paused.sim.services_once_seen('/sim_node/simulate_steps/_action/send_goal')
    assert graph['/sim_node/simulate_steps/_action/send_goal'] == [
        'simulation_interfaces/action/SimulateSteps_SendGoal']
    paused.sim.call(Empty, '/reset_simulation')  # still works as gazebo_ros's
    assert paused.state() == State.STATE_STOPPED


def test_an_empty_namespace_gives_isaac_names_and_replaces_the_empty_reset():
    with sim_node(**{'simulation_interfaces.namespace': '', 'paused': True}) as sim:
        services = sim.own_services()
        assert services['/reset_simulation'] == 'simulation_interfaces/srv/ResetSimulation'
        assert services['/step_simulation'] == 'simulation_interfaces/srv/StepSimulation'
        assert services['/reset_world'] == 'std_srvs/srv/Empty'
        client = SimInterfaces(sim, namespace='/')
        assert client.reset(msg_scope('SCOPE_ALL')).result == OK


def msg_scope(name: str) -> int:
    return getattr(srv.ResetSimulation.Request, name)


def test_features_are_what_is_implemented_and_nothing_else(paused):
    features = paused.call('get_simulator_features').features
    claimed = set(features.features)
    assert claimed == {
        Features.SPAWNING, Features.DELETING, Features.ENTITY_TAGS, Features.ENTITY_BOUNDS,
        Features.ENTITY_BOUNDS_BOX, Features.ENTITY_CATEGORIES,
        Features.SPAWNING_RESOURCE_STRING, Features.ENTITY_STATE_GETTING,
        Features.ENTITY_STATE_SETTING, Features.ENTITY_INFO_GETTING,
        Features.ENTITY_INFO_SETTING, Features.SPAWNABLES, Features.SIMULATION_RESET,
        Features.SIMULATION_RESET_TIME, Features.SIMULATION_RESET_STATE,
        Features.SIMULATION_RESET_SPAWNED, Features.SIMULATION_STATE_GETTING,
        Features.SIMULATION_STATE_SETTING, Features.SIMULATION_STATE_PAUSE,
        Features.STEP_SIMULATION_SINGLE, Features.STEP_SIMULATION_MULTIPLE,
        Features.STEP_SIMULATION_ACTION, Features.SPAWNING_ENTITIES}
    for missing in (Features.NAMED_POSES, Features.POSE_BOUNDS, Features.ENTITY_BOUNDS_CONVEX,
                    Features.WORLD_LOADING, Features.WORLD_RESOURCE_STRING,
                    Features.AVAILABLE_WORLDS):
        assert missing not in claimed
    assert list(features.spawn_formats) == ['urdf', 'sdf']
    assert f'{TIME_STEP} s' in features.custom_info


# --- state ---------------------------------------------------------------------------------

def test_started_paused_the_simulation_is_stopped_and_time_stands_still(paused):
    assert paused.state() == State.STATE_STOPPED
    paused.sim.spin_for(0.3)
    assert paused.sim.simulation.time == 0.0
    assert paused.sim.node.get_parameter('paused').value is True


def test_state_transitions_follow_the_standard(playing):
    sim = playing.sim
    assert playing.state() == State.STATE_PLAYING
    codes = srv.SetSimulationState.Response
    assert playing.set_state(State.STATE_PLAYING).result == codes.ALREADY_IN_TARGET_STATE

    assert playing.set_state(State.STATE_PAUSED).result == OK
    assert playing.state() == State.STATE_PAUSED
    assert sim.node.get_parameter('paused').value is True
    assert playing.set_state(State.STATE_PAUSED).result == codes.ALREADY_IN_TARGET_STATE

    assert sim.simulation.time > 0.0
    assert playing.set_state(State.STATE_STOPPED).result == OK  # reset and paused
    assert playing.state() == State.STATE_STOPPED
    assert sim.simulation.time == 0.0
    assert sim.simulation.joint_positions()['pan_joint'] == 0.0
    refused = playing.set_state(State.STATE_PAUSED)
    assert refused.result == codes.INCORRECT_TRANSITION
    assert 'step' in refused.error_message

    assert playing.step(10).result == OK  # stepped: paused, no longer stopped
    assert playing.state() == State.STATE_PAUSED
    assert playing.set_state(State.STATE_PLAYING).result == OK
    assert sim.node.get_parameter('paused').value is False
    assert sim.spin_until(lambda: sim.simulation.time > 10 * TIME_STEP + 0.1)
    assert playing.state() == State.STATE_PLAYING


def test_worlds_and_unknown_states_are_refused(playing):
    unsupported = playing.set_state(State.STATE_NO_WORLD)
    assert unsupported.result == Result.RESULT_FEATURE_UNSUPPORTED
    assert unsupported.error_message
    assert playing.set_state(State.STATE_LOADING_WORLD).result == (
        Result.RESULT_FEATURE_UNSUPPORTED)
    assert playing.set_state(77).result == (
        srv.SetSimulationState.Response.INCORRECT_TRANSITION)
    assert playing.state() == State.STATE_PLAYING


def test_the_paused_parameter_and_the_empty_services_are_the_same_switch(playing):
    playing.sim.call(Empty, '/pause_physics')
    assert playing.state() == State.STATE_PAUSED
    playing.sim.set_parameters(paused=False)
    assert playing.state() == State.STATE_PLAYING


def test_quitting_answers_then_shuts_the_context_down(paused):
    sim = paused.sim
    result = paused.set_state(State.STATE_QUITTING)
    assert result.result == OK
    assert sim.node.context.ok()  # the answer went out first
    try:
        assert sim.spin_until(lambda: not sim.node.context.ok(), budget_s=5.0)
    except Exception:  # noqa: BLE001 -- spinning a context that shut down mid-spin
        pass
    assert not sim.node.context.ok()


def test_forty_callers_at_once_are_all_answered(paused):
    # rclpy's default service QoS keeps 10 requests: a burst beyond that lost the oldest.
    sim = paused.sim
    callers = 40
    clients = [sim.probe.create_client(srv.GetSimulationState, paused.name('get_simulation_state'),
                                       qos_profile=SERVICE_QOS) for _ in range(callers)]
    assert sim.spin_until(lambda: all(client.service_is_ready() for client in clients))
    futures = [client.call_async(srv.GetSimulationState.Request()) for client in clients]
    assert sim.spin_until(lambda: all(future.done() for future in futures), budget_s=10.0), \
        f'{sum(not future.done() for future in futures)} of {callers} requests unanswered'
    assert {future.result().state.state for future in futures} == {State.STATE_STOPPED}
    for client in clients:
        sim.probe.destroy_client(client)


# --- stepping ------------------------------------------------------------------------------

def test_step_simulation_runs_exactly_the_steps_asked_for_and_publishes_for_them(paused):
    sim = paused.sim
    clock = sim.collect(Clock, '/clock', PROBE_QUEUE)
    sim.wait_for_subscribers('/clock')
    sim.wait_for_subscribers(sim.node.topic('joint_states'))
    before = sim.simulation.steps
    assert paused.step(100).result == OK
    # The answer comes once the steps are done: nothing is left to run.
    assert sim.simulation.steps - before == 100
    assert sim.simulation.time == pytest.approx(100 * TIME_STEP, abs=1e-12)
    sim.drain()
    assert max(stamp_s(m) for m in clock) == pytest.approx(100 * TIME_STEP)
    # JointState at 50 Hz, each sampled as its step begins: 0 to 0.18 s for 0.2 s of steps.
    stamps = [stamp_s(m) for m in sim.states]
    assert stamps == pytest.approx([0.02 * k for k in range(10)])
    paused.sim.spin_for(0.2)
    assert sim.simulation.steps - before == 100  # and it stays paused
    assert paused.state() == State.STATE_PAUSED


def test_a_single_step_is_one_time_step(paused):
    assert paused.step(1).result == OK
    assert paused.sim.simulation.time == pytest.approx(TIME_STEP, abs=1e-12)


def test_stepping_while_playing_is_refused(playing):
    before = playing.sim.simulation.steps
    result = playing.step(MAX_STEPS)
    assert result.result == Result.RESULT_OPERATION_FAILED
    assert 'paused' in result.error_message
    # Not the steps asked for: the answer came at once (the pace runs on, a little).
    assert playing.sim.simulation.steps - before < MAX_STEPS


def test_many_steps_leave_the_executor_free_between_slices(paused):
    """A long step request does not hold the node: other services answer meanwhile."""
    sim = paused.sim
    client = paused._client('step_simulation')
    paused._client('get_simulation_state')
    future = client.call_async(srv.StepSimulation.Request(steps=MAX_STEPS))
    assert sim.spin_until(lambda: sim.simulation.steps > 0)
    state = paused.call('get_simulation_state')  # answered between slices
    assert not future.done()
    assert state.state.state == State.STATE_PAUSED
    second = paused.step(5)
    assert second.result == Result.RESULT_OPERATION_FAILED
    assert 'in progress' in second.error_message
    assert sim.spin_until(future.done, budget_s=60.0)
    assert future.result().result.result == OK
    assert sim.simulation.steps == MAX_STEPS


@pytest.mark.parametrize('steps', [MAX_STEPS + 1, 2 ** 63, 2 ** 64 - 1])
def test_step_simulation_beyond_its_bound_is_refused_at_once_pointing_to_the_action(paused,
                                                                                   steps):
    result = paused.step(steps)
    assert result.result == Result.RESULT_OPERATION_FAILED
    assert f'at most {MAX_STEPS} steps' in result.error_message
    assert 'simulate_steps' in result.error_message
    assert paused.sim.simulation.steps == 0
    assert paused.step(3).result == OK  # nothing left running
    assert paused.sim.simulation.steps == 3


def test_setting_playing_while_stepping_fails_the_request(paused):
    sim = paused.sim
    client = paused._client('step_simulation')
    paused._client('set_simulation_state')
    future = client.call_async(srv.StepSimulation.Request(steps=MAX_STEPS))
    assert sim.spin_until(lambda: sim.simulation.steps > 0)
    assert paused.set_state(State.STATE_PLAYING).result == OK
    assert sim.spin_until(future.done)
    result = future.result().result
    assert result.result == Result.RESULT_OPERATION_FAILED
    assert 'playing' in result.error_message


def _send_goal(client, sim, steps: int, feedback: list):
    future = client.action_client().send_goal_async(
        action.SimulateSteps.Goal(steps=steps),
        feedback_callback=lambda message: feedback.append(message.feedback))
    assert sim.spin_until(future.done), 'goal not answered'
    handle = future.result()
    assert handle.accepted
    return handle


def test_simulate_steps_reports_progress_and_ends_with_every_step_run(paused):
    sim = paused.sim
    feedback: list = []
    handle = _send_goal(paused, sim, 50_000, feedback)
    result = handle.get_result_async()
    assert sim.spin_until(result.done, budget_s=60.0)
    assert result.result().status == 4  # GoalStatus.STATUS_SUCCEEDED
    assert result.result().result.result.result == OK
    assert sim.simulation.steps == 50_000
    assert sim.simulation.time == pytest.approx(50_000 * TIME_STEP)
    assert sim.spin_until(lambda: feedback and feedback[-1].remaining_steps == 0)
    assert len(feedback) >= 2
    completed = [f.completed_steps for f in feedback]
    assert completed == sorted(completed)
    assert all(f.completed_steps + f.remaining_steps == 50_000 for f in feedback)
    assert paused.state() == State.STATE_PAUSED


def test_simulate_steps_cancelled_stops_and_stays_paused(paused):
    sim = paused.sim
    feedback: list = []
    handle = _send_goal(paused, sim, 50_000_000, feedback)
    assert sim.spin_until(lambda: len(feedback) >= 2)
    cancel = handle.cancel_goal_async()
    assert sim.spin_until(cancel.done)
    assert len(cancel.result().goals_canceling) == 1
    result = handle.get_result_async()
    assert sim.spin_until(result.done)
    assert result.result().status == 5  # GoalStatus.STATUS_CANCELED
    assert result.result().result.result.result == OK
    assert 'canceled after' in result.result().result.result.error_message
    stopped_at = sim.simulation.steps
    assert 0 < stopped_at < 50_000_000
    sim.spin_for(0.2)
    assert sim.simulation.steps == stopped_at  # paused: time stands still
    assert paused.state() == State.STATE_PAUSED


def test_simulate_steps_while_playing_is_aborted_with_the_reason(playing):
    sim = playing.sim
    handle = _send_goal(playing, sim, 100, [])
    result = handle.get_result_async()
    assert sim.spin_until(result.done)
    assert result.result().status == 6  # GoalStatus.STATUS_ABORTED
    assert result.result().result.result.result == Result.RESULT_OPERATION_FAILED
    assert 'paused' in result.result().result.result.error_message


def test_a_closed_harness_leaves_no_action_client_holding_its_probe():
    # rclpy's destroy_node spares action clients, whose handles keep the node and
    # its DDS participant alive until garbage collection: the next test's nodes
    # would meet its endpoints, and each such test would leave native threads behind.
    with sim_node(paused=True) as sim:
        SimInterfaces(sim).action_client()
        probe = sim.probe
        assert [w for w in probe.waitables if isinstance(w, ActionClient)]
    assert not [w for w in probe.waitables if isinstance(w, ActionClient)]


# --- without the package -------------------------------------------------------------------

def test_without_simulation_interfaces_the_node_runs_and_says_so_once(capfd, monkeypatch):
    monkeypatch.setattr(simulation_services, 'interfaces', lambda: None)
    with sim_node() as sim:
        sim.run_until_sim_time(0.2)
        assert sim.node.simulation_interfaces is None
        services = sim.own_services()
        assert not [leaf for leaf in SERVICES if f'/sim_node/{leaf}' in services]
        assert not [w for w in sim.node.waitables if isinstance(w, ActionServer)]  # no action
        assert services['/reset_simulation'] == 'std_srvs/srv/Empty'
    err = capfd.readouterr().err
    assert err.count('off, for want of their interface packages:') == 1
    assert err.count('the simulator services (get_simulator_features, step_simulation, '
                     'spawn_entity, ...) (simulation_interfaces)') == 1


@pytest.mark.parametrize('namespace, name', [
    ('~/control', '/sim_node/control/get_simulator_features'),
    ('/', '/get_simulator_features'),
    ('/sim/', '/sim/get_simulator_features'),
    ('sim', '/sim/get_simulator_features'),
])
def test_the_namespace_parameter_moves_the_services(namespace, name):
    with sim_node(**{'simulation_interfaces.namespace': namespace}) as sim:
        assert name in sim.node.simulation_interfaces.names
        assert name in sim.own_services()


@pytest.mark.parametrize('namespace', ['~sim', '9sim', 'a b', '/a//b'])
def test_a_bad_namespace_ends_start_up_naming_the_parameter(namespace):
    with pytest.raises(ParameterError, match="'simulation_interfaces.namespace'"):
        with sim_node(**{'simulation_interfaces.namespace': namespace}):
            pass
