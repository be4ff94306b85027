"""simulation_interfaces for sim_node: the standard way to control a simulator from tests and tools.

Every answer fills ``result`` and says why in ``error_message``; a refused request changes
nothing.  The services act between batches of physics steps.  The simulator's own
services are here; the entity services (spawning among them) are in
:mod:`pan_tilt_sim.ros.entity_services`.

Design notes: docs/design/ros.md#simulation_servicespy.
"""

from __future__ import annotations

import importlib
import types
from collections.abc import Callable

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.service import Service

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model import naming
from pan_tilt_sim.ros import parameters as params
from pan_tilt_sim.ros import services as world_services
from pan_tilt_sim.ros.entity_services import Answers, EntityServices, Preparations
from pan_tilt_sim.ros.ros_interfaces import SERVICE_QOS
from pan_tilt_sim.ros.stepping import JobEnd, StepJob, StepRunner
from pan_tilt_sim.sim.entities import Entities

PACKAGE = 'simulation_interfaces'
NAMESPACE_PARAMETER = 'simulation_interfaces.namespace'
PRIVATE = '~'
DEFAULT_NAMESPACE = PRIVATE
SPAWN_FORMATS = ['urdf', 'sdf']
QUIT_GRACE_S = 0.1  # wall time between QUITTING's answer and the shutdown (DDS delivers it)
SCOPE_BITS = 0b111  # TIME | STATE | SPAWNED
# StepSimulation steps at most: a service call must answer within seconds (a few at
# most, whatever the robot costs per step), and a caller that dies mid-call cannot
# cancel it.  Longer runs are SimulateSteps goals, which report progress and cancel.
MAX_STEP_SIMULATION_STEPS = 100_000

AWAITING_SERVICES = ('step_simulation', 'spawn_entity', 'spawn_entities')
SERVICES = ('get_simulator_features', 'get_simulation_state', 'set_simulation_state',
            'step_simulation', 'reset_simulation', 'get_entities', 'get_entities_states',
            'get_entity_state', 'set_entity_state', 'get_entity_info', 'set_entity_info',
            'get_entity_bounds', 'spawn_entity', 'spawn_entities', 'delete_entity',
            'get_spawnables')
ACTION = 'simulate_steps'


def interfaces() -> types.SimpleNamespace | None:
    """Return simulation_interfaces' msg, srv and action modules, or None where not installed."""
    try:
        return types.SimpleNamespace(
            msg=importlib.import_module(f'{PACKAGE}.msg'),
            srv=importlib.import_module(f'{PACKAGE}.srv'),
            action=importlib.import_module(f'{PACKAGE}.action'))
    except ImportError:
        return None


def declare_namespace(node: Node) -> str:
    """Declare ``simulation_interfaces.namespace``; return it, checked."""
    namespace = params.declare(
        node, NAMESPACE_PARAMETER, params.STRING, DEFAULT_NAMESPACE,
        "Namespace of the simulation_interfaces services: '~' (default) = the node's own "
        "name (/sim_node/step_simulation), '' = the node's namespace (Isaac Sim's names: "
        '/step_simulation; replaces the Empty reset_simulation), or any namespace.')
    if namespace in (PRIVATE, ''):
        valid = True
    elif namespace.startswith(PRIVATE + naming.ROOT):  # '~/sim': under the node's name
        valid = naming.is_valid_namespace(namespace[len(PRIVATE):].rstrip(naming.ROOT))
    else:  # '~sim' is no name
        valid = not namespace.startswith(PRIVATE) and naming.is_valid_namespace(
            namespace.rstrip(naming.ROOT) or naming.ROOT)
    if not valid:
        raise ParameterError(
            f"parameter '{NAMESPACE_PARAMETER}': '{namespace}' is not '~', '' or a valid ROS "
            f'namespace ({naming.NAMESPACE_RULE})')
    return namespace


def create(node: Node, gazebo_services: list[Service]) -> SimulationServices | None:
    """Serve simulation_interfaces on ``node`` (a SimNode); None where it is not installed.

    The node says so in its one line about missing interface packages
    (:mod:`pan_tilt_sim.ros.optional_interfaces`).
    """
    namespace = declare_namespace(node)
    found = interfaces()
    if found is None:
        return None
    return SimulationServices(node, found, namespace, gazebo_services)


def service_name(namespace: str, leaf: str) -> str:
    """Return the name to create a service ``leaf`` under ``namespace`` with."""
    return f'{namespace.rstrip(naming.ROOT)}/{leaf}' if namespace else leaf


class SimulationServices:
    """simulation_interfaces' services and action on a SimNode (see the module's design notes).

    Two families answer them: :class:`SimulatorServices` (state, stepping,
    reset) and :class:`~pan_tilt_sim.ros.entity_services.EntityServices`.
    """

    def __init__(self, node: Node, interfaces: types.SimpleNamespace, namespace: str,
                 gazebo_services: list[Service]) -> None:
        self._node = node
        self._logger = node.get_logger()
        self._action_name = service_name(namespace, ACTION)
        self._closed = False
        self.simulator = SimulatorServices(node, interfaces, node.features.entities)
        self._drop_clashing(namespace, gazebo_services)
        # The awaiting callbacks (a step request waits for its steps, a spawn for its
        # preparation) get their own group: in the default one they would hold off the
        # steps they wait for.
        waiting = ReentrantCallbackGroup()
        self._preparations = Preparations(node, waiting)
        self.entities = EntityServices(interfaces, node.features.entities, node.simulation,
                                       self._logger, self._preparations)
        handlers = {**self.simulator.handlers(), **self.entities.handlers()}
        self.services = {
            leaf: node.create_service(
                kind, service_name(namespace, leaf), handler, qos_profile=SERVICE_QOS,
                callback_group=waiting if leaf in AWAITING_SERVICES else None)
            for leaf, (kind, handler) in handlers.items()}
        self.action_server = ActionServer(
            node, interfaces.action.SimulateSteps, self._action_name,
            execute_callback=self.simulator.simulate_steps,
            goal_callback=self.simulator.accept_goal,
            cancel_callback=self.simulator.cancel_goal, callback_group=waiting)

    @property
    def names(self) -> list[str]:
        """The services' and the action's full names."""
        return [self._node.resolve_service_name(service.srv_name)
                for service in self.services.values()] + [
            self._node.resolve_service_name(self._action_name)]

    def close(self) -> None:
        """Stop stepping (a job in progress fails) and serving the action (idempotent)."""
        if self._closed:
            return
        self._closed = True
        self.simulator.close()
        self._preparations.close()
        self.action_server.destroy()

    def _drop_clashing(self, namespace: str, gazebo_services: list[Service]) -> None:
        ours = self._node.resolve_service_name(service_name(namespace, 'reset_simulation'))
        for service in list(gazebo_services):
            if (service.srv_name == ours
                    or self._node.resolve_service_name(service.srv_name) == ours):
                self._node.destroy_service(service)
                gazebo_services.remove(service)
                self._logger.info(
                    f"{ours} is simulation_interfaces/srv/ResetSimulation ('{NAMESPACE_PARAMETER}'"
                    f" is '{namespace}'): gazebo_ros's std_srvs/srv/Empty "
                    f'{world_services.RESET_SIMULATION} is not offered')


class SimulatorServices(Answers):
    """The simulator's services: features, state, stepping (service and action), reset."""

    def __init__(self, node: Node, interfaces: types.SimpleNamespace,
                 entities: Entities) -> None:
        super().__init__(interfaces)
        self._node = node
        self._action = interfaces.action.SimulateSteps
        self._simulation = node.simulation
        self._entities = entities  # a reset restores them, or deletes the spawned ones
        self._logger = node.get_logger()
        self._runner = StepRunner(node, node.step, lambda: node.paused)
        self._stopped_at: int | None = node.steps_run if node.paused else None
        self._quit_timer = None
        self._quitting = False
        self._goal_jobs: dict[bytes, StepJob] = {}

    def handlers(self) -> dict[str, tuple[type, Callable]]:
        """Return each service's type and callback, by the service's last name."""
        srv = self._srv
        return {
            'get_simulator_features': (srv.GetSimulatorFeatures, self._get_features),
            'get_simulation_state': (srv.GetSimulationState, self._get_state),
            'set_simulation_state': (srv.SetSimulationState, self._set_state),
            'step_simulation': (srv.StepSimulation, self._step_simulation),
            'reset_simulation': (srv.ResetSimulation, self._reset_simulation),
        }

    def state(self) -> int:
        """Return the simulation state now (a SimulationState constant)."""
        states = self._msg.SimulationState
        if self._quitting:
            return states.STATE_QUITTING
        if not self._node.paused:
            return states.STATE_PLAYING
        if self._stopped_at == self._node.steps_run:
            return states.STATE_STOPPED
        return states.STATE_PAUSED

    def close(self) -> None:
        """Stop stepping (a job in progress fails) and the pending quit."""
        self._runner.close()
        if self._quit_timer is not None:
            self._quit_timer.cancel()

    def _get_features(self, request, response):
        features = self._msg.SimulatorFeatures
        response.features.features = [
            features.SPAWNING, features.DELETING, features.ENTITY_TAGS, features.ENTITY_BOUNDS,
            features.ENTITY_BOUNDS_BOX, features.ENTITY_CATEGORIES,
            features.SPAWNING_RESOURCE_STRING, features.ENTITY_STATE_GETTING,
            features.ENTITY_STATE_SETTING, features.ENTITY_INFO_GETTING,
            features.ENTITY_INFO_SETTING, features.SPAWNABLES, features.SIMULATION_RESET,
            features.SIMULATION_RESET_TIME, features.SIMULATION_RESET_STATE,
            features.SIMULATION_RESET_SPAWNED, features.SIMULATION_STATE_GETTING,
            features.SIMULATION_STATE_SETTING, features.SIMULATION_STATE_PAUSE,
            features.STEP_SIMULATION_SINGLE, features.STEP_SIMULATION_MULTIPLE,
            features.STEP_SIMULATION_ACTION, features.SPAWNING_ENTITIES]
        response.features.spawn_formats = list(SPAWN_FORMATS)
        response.features.custom_info = (
            f'pan_tilt_sim (PyBullet): one step = time_step = {self._simulation.time_step} s '
            'of sim time; entities: the robot, the scenery targets and URDF objects; '
            "frames: '' or world, an entity's name, or a link of the robot")
        return response

    def _get_state(self, request, response):
        response.state.state = self.state()
        return self._ok(response)

    def _set_state(self, request, response):
        states, codes = self._msg.SimulationState, self._srv.SetSimulationState.Response
        target, current = request.state.state, self.state()
        if target == states.STATE_QUITTING:
            self._quit()
            return self._ok(response)
        if target in (states.STATE_NO_WORLD, states.STATE_LOADING_WORLD):
            return self._fail(response, self._msg.Result.RESULT_FEATURE_UNSUPPORTED,
                              'worlds cannot be loaded or unloaded here (a world file is '
                              "given by the 'world' parameter at start)")
        if target not in (states.STATE_STOPPED, states.STATE_PLAYING, states.STATE_PAUSED):
            return self._fail(response, codes.INCORRECT_TRANSITION, f'unknown state {target}')
        if target == current:
            return self._fail(response, codes.ALREADY_IN_TARGET_STATE,
                              f'the simulation is {_STATE_NAMES[target]} already')
        if target == states.STATE_PAUSED and current == states.STATE_STOPPED:
            return self._fail(response, codes.INCORRECT_TRANSITION,
                              'a stopped simulation cannot be paused: step it '
                              '(step_simulation) or set it PLAYING')
        if target == states.STATE_STOPPED:
            self._runner.fail('the simulation was stopped')
            self._node.set_paused(True)
            self._reset(time=True, state=True, spawned=True, full=True)
        else:
            self._node.set_paused(target == states.STATE_PAUSED)
        return self._ok(response)

    def _quit(self) -> None:
        if self._quitting:
            return
        self._quitting = True
        self._runner.fail('the simulator is quitting')
        self._node.set_paused(True)
        self._logger.info('QUITTING (set_simulation_state): shutting down')
        self._quit_timer = self._node.create_timer(QUIT_GRACE_S, self._shut_down)

    def _shut_down(self) -> None:
        self._quit_timer.cancel()
        self._node.context.try_shutdown()

    async def _step_simulation(self, request, response):
        if request.steps > MAX_STEP_SIMULATION_STEPS:
            return self._fail(
                response, self._msg.Result.RESULT_OPERATION_FAILED,
                f'steps {request.steps}: a step_simulation request runs at most '
                f'{MAX_STEP_SIMULATION_STEPS} steps (it cannot be cancelled); run more with '
                'the simulate_steps action, which reports progress and can be cancelled')
        problem = self._cannot_step()
        if problem:
            return self._fail(response, self._msg.Result.RESULT_OPERATION_FAILED, problem)
        job = StepJob(request.steps)
        self._runner.start(job)
        how = await job.future
        if how is JobEnd.DONE:
            return self._ok(response)
        return self._fail(response, self._msg.Result.RESULT_OPERATION_FAILED,
                          f'stopped after {job.completed} of {job.total} steps: {job.reason}')

    def _cannot_step(self) -> str:
        if not self._node.paused:
            return ('the simulation must be paused to step it (it is playing): set_simulation_'
                    'state PAUSED, pause_physics, or start with -p paused:=true')
        job = self._runner.job
        if job is not None:
            return (f'another step request is in progress ({job.completed} of {job.total} '
                    'steps done)')
        return ''

    def accept_goal(self, goal) -> GoalResponse:
        """Accept every SimulateSteps goal."""
        return GoalResponse.ACCEPT  # refusals come as results, with the reason (as O3DE)

    def cancel_goal(self, goal_handle) -> CancelResponse:
        """Ask the goal's job to stop after the slice in progress."""
        job = self._goal_jobs.get(bytes(goal_handle.goal_id.uuid))
        if job is not None:
            job.cancel_requested = True
        return CancelResponse.ACCEPT

    async def simulate_steps(self, goal_handle):
        """Run a SimulateSteps goal: its steps in slices, with feedback; cancelable."""
        action = self._action
        result = action.Result()
        problem = self._cannot_step()
        if problem:
            result.result.result = self._msg.Result.RESULT_OPERATION_FAILED
            result.result.error_message = problem
            goal_handle.abort()
            return result

        def feedback(job: StepJob) -> None:
            goal_handle.publish_feedback(action.Feedback(
                completed_steps=job.completed, remaining_steps=job.remaining))

        job = StepJob(goal_handle.request.steps, feedback)
        key = bytes(goal_handle.goal_id.uuid)
        self._goal_jobs[key] = job
        if goal_handle.is_cancel_requested:
            job.cancel_requested = True
        try:
            self._runner.start(job)
            how = await job.future
        finally:
            del self._goal_jobs[key]
        if how is JobEnd.FAILED:
            result.result.result = self._msg.Result.RESULT_OPERATION_FAILED
            result.result.error_message = (
                f'stopped after {job.completed} of {job.total} steps: {job.reason}')
            goal_handle.abort()
            return result
        result.result.result = self._msg.Result.RESULT_OK
        if how is JobEnd.CANCELED:
            result.result.error_message = f'canceled after {job.completed} of {job.total} steps'
            goal_handle.canceled()
        else:
            goal_handle.succeed()
        return result

    def _reset_simulation(self, request, response):
        scopes = self._srv.ResetSimulation.Request
        scope = request.scope
        if scope in (scopes.SCOPE_DEFAULT, scopes.SCOPE_ALL):
            self._reset(time=True, state=True, spawned=True, full=True)
            return self._ok(response)
        if scope & ~SCOPE_BITS:
            return self._fail(response, self._msg.Result.RESULT_FEATURE_UNSUPPORTED,
                              f'scope {scope}: only TIME (1), STATE (2), SPAWNED (4), their '
                              'sums, DEFAULT (0) and ALL (255)')
        self._reset(time=bool(scope & scopes.SCOPE_TIME), state=bool(scope & scopes.SCOPE_STATE),
                    spawned=bool(scope & scopes.SCOPE_SPAWNED))
        return self._ok(response)

    def _reset(self, *, time: bool, state: bool, spawned: bool, full: bool = False) -> None:
        if full:
            self._entities.restore()
        elif spawned:
            deleted = self._entities.delete_spawned()
            if deleted:
                self._logger.info(f"reset: deleted {', '.join(deleted)}")
        if time or state:
            self._node.reset(reset_time=time, reset_state=state)
        if time and state and self._node.paused:
            self._stopped_at = self._node.steps_run


_STATE_NAMES = {0: 'STOPPED', 1: 'PLAYING', 2: 'PAUSED', 3: 'QUITTING'}
