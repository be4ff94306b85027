"""A simulation_interfaces client for node tests: real rclpy clients on the harness's probe.

Every service gets one client for the whole test.  Fast DDS may call a
service ready before the server has matched the client's response reader,
and then drops the first response (see node_harness.call); so each client is
first warmed up with a request the standard makes harmless (an empty
SpawnEntity is refused with NO_RESOURCE, StepSimulation of 0 steps does
nothing...), sent again until one is answered.  After that a request is
sent once and its answer awaited: non-idempotent calls (spawn, step) are
never repeated.

Where simulation_interfaces is not installed on purpose
(``PAN_TILT_SIM_INTERFACES=skip``), importing this module skips the test
module; otherwise a missing package fails it.
"""

from __future__ import annotations

import os
import time
from typing import Any

import pytest
from node_harness import RESEND_AFTER_S, SimUnderTest

try:
    from simulation_interfaces import action, msg, srv
except ImportError:
    if os.environ.get('PAN_TILT_SIM_INTERFACES') == 'skip':
        pytest.skip('PAN_TILT_SIM_INTERFACES=skip: simulation_interfaces is not built',
                    allow_module_level=True)
    raise
from geometry_msgs.msg import PoseStamped, Twist
from rclpy.action import ActionClient

NAMESPACE = '/sim_node'
BUDGET_S = 30.0
Result = msg.Result
State = msg.SimulationState
OK = Result.RESULT_OK

# Each service's type and a request that changes nothing (to warm the client up with).
SERVICES: dict[str, tuple[type, Any]] = {
    'get_simulator_features': (srv.GetSimulatorFeatures, None),
    'get_simulation_state': (srv.GetSimulationState, None),
    'set_simulation_state': (srv.SetSimulationState,
                             srv.SetSimulationState.Request(state=State(state=99))),
    'step_simulation': (srv.StepSimulation, srv.StepSimulation.Request(steps=0)),
    'reset_simulation': (srv.ResetSimulation, srv.ResetSimulation.Request(scope=8)),
    'get_entities': (srv.GetEntities, None),
    'get_entities_states': (srv.GetEntitiesStates, None),
    'get_entity_state': (srv.GetEntityState, None),
    'set_entity_state': (srv.SetEntityState, None),  # entity '' does not exist
    'get_entity_info': (srv.GetEntityInfo, None),
    'set_entity_info': (srv.SetEntityInfo, None),
    'get_entity_bounds': (srv.GetEntityBounds, None),
    'spawn_entity': (srv.SpawnEntity, None),  # no resource: NO_RESOURCE
    'spawn_entities': (srv.SpawnEntities, None),  # nothing to spawn
    'delete_entity': (srv.DeleteEntity, None),
    'get_spawnables': (srv.GetSpawnables, None),
}


def pose(x: float = 0.0, y: float = 0.0, z: float = 0.0,
         orientation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0),
         frame: str = '') -> PoseStamped:
    """Return a PoseStamped at (x, y, z) with ``orientation`` (x, y, z, w) in ``frame``."""
    stamped = PoseStamped()
    stamped.header.frame_id = frame
    stamped.pose.position.x, stamped.pose.position.y, stamped.pose.position.z = x, y, z
    (stamped.pose.orientation.x, stamped.pose.orientation.y, stamped.pose.orientation.z,
     stamped.pose.orientation.w) = orientation
    return stamped


def position(state) -> tuple[float, float, float]:
    """Return an EntityState's position as a tuple."""
    p = state.pose.position
    return (p.x, p.y, p.z)


class SimInterfaces:
    """simulation_interfaces calls to a SimNode under test, from the probe node."""

    def __init__(self, sim: SimUnderTest, namespace: str = NAMESPACE) -> None:
        self.sim = sim
        self.namespace = namespace.rstrip('/')
        self._clients: dict[str, Any] = {}
        self._action_client: ActionClient | None = None

    def name(self, leaf: str) -> str:
        """Return the full name of service ``leaf``."""
        return f'{self.namespace}/{leaf}'

    def call(self, leaf: str, request: Any = None, budget_s: float = BUDGET_S) -> Any:
        """Call service ``leaf`` once (its client warmed up); return the response."""
        kind, _harmless = SERVICES[leaf]
        client = self._client(leaf)
        future = client.call_async(kind.Request() if request is None else request)
        assert self.sim.spin_until(future.done, budget_s), f'{leaf} did not answer'
        response = future.result()
        assert response is not None, f'{leaf} failed: {future.exception()!r}'
        return response

    # --- the common calls -------------------------------------------------------------------

    def state(self) -> int:
        """Return the simulation state."""
        response = self.call('get_simulation_state')
        assert response.result.result == OK, response.result.error_message
        return response.state.state

    def set_state(self, state: int) -> Any:
        """Ask for a simulation state; return the Result."""
        return self.call('set_simulation_state',
                         srv.SetSimulationState.Request(state=State(state=state))).result

    def step(self, steps: int) -> Any:
        """Step ``steps`` steps; return the Result."""
        return self.call('step_simulation', srv.StepSimulation.Request(steps=steps)).result

    def reset(self, scope: int) -> Any:
        """Reset with ``scope``; return the Result."""
        return self.call('reset_simulation', srv.ResetSimulation.Request(scope=scope)).result

    def spawn(self, name: str = '', *, uri: str = '', resource_string: str = '',
              at: PoseStamped | None = None, allow_renaming: bool = False,
              namespace: str = '') -> Any:
        """Spawn; return the response (result and entity_name)."""
        return self.call('spawn_entity', srv.SpawnEntity.Request(
            name=name, uri=uri, resource_string=resource_string,
            initial_pose=at or pose(), allow_renaming=allow_renaming,
            entity_namespace=namespace))

    def spawn_async(self, name: str = '', *, resource_string: str = '',
                    at: PoseStamped | None = None) -> Any:
        """Send a spawn request (its client warmed up); return its future, not waiting."""
        return self._client('spawn_entity').call_async(srv.SpawnEntity.Request(
            name=name, resource_string=resource_string, initial_pose=at or pose()))

    def entities(self, **filters: Any) -> list[str]:
        """Return the entity names GetEntities gives for ``filters`` (EntityFilters fields)."""
        response = self.call('get_entities', srv.GetEntities.Request(
            filters=msg.EntityFilters(**filters)))
        assert response.result.result == OK, response.result.error_message
        return list(response.entities)

    def entity_state(self, entity: str) -> Any:
        """Return the EntityState of ``entity`` (the call must succeed)."""
        response = self.call('get_entity_state', srv.GetEntityState.Request(entity=entity))
        assert response.result.result == OK, response.result.error_message
        return response.state

    def set_entity_state(self, entity: str, at: PoseStamped,
                         twist: Twist | None = None) -> Any:
        """Set an entity's pose (and twist); return the Result."""
        state = msg.EntityState(header=at.header, pose=at.pose, twist=twist or Twist())
        return self.call('set_entity_state',
                         srv.SetEntityState.Request(entity=entity, state=state)).result

    def delete(self, entity: str) -> Any:
        """Delete an entity; return the Result."""
        return self.call('delete_entity', srv.DeleteEntity.Request(entity=entity)).result

    # --- the action -------------------------------------------------------------------------

    def action_client(self) -> ActionClient:
        """Return the SimulateSteps client, its server found and a 0-step goal answered."""
        if self._action_client is None:
            client = ActionClient(self.sim.probe, action.SimulateSteps,
                                  self.name('simulate_steps'))
            assert self.sim.spin_until(client.server_is_ready), 'no simulate_steps server'
            deadline = time.monotonic() + BUDGET_S
            while True:  # warm up: a 0-step goal changes nothing
                future = client.send_goal_async(action.SimulateSteps.Goal(steps=0))
                if self.sim.spin_until(future.done, RESEND_AFTER_S):
                    handle = future.result()
                    result = handle.get_result_async()
                    assert self.sim.spin_until(result.done), '0-step goal never ended'
                    break
                assert time.monotonic() < deadline, 'simulate_steps never answered a goal'
            self._action_client = client
        return self._action_client

    def _client(self, leaf: str):
        client = self._clients.get(leaf)
        if client is not None:
            return client
        kind, harmless = SERVICES[leaf]
        client = self.sim.probe.create_client(kind, self.name(leaf))
        assert self.sim.spin_until(client.service_is_ready), f'no service {self.name(leaf)}'
        deadline = time.monotonic() + BUDGET_S
        while True:
            future = client.call_async(kind.Request() if harmless is None else harmless)
            if self.sim.spin_until(future.done, RESEND_AFTER_S):
                break
            client.remove_pending_request(future)
            assert time.monotonic() < deadline, f'{leaf} never answered'
        self._clients[leaf] = client
        return client
