"""simulation_interfaces for sim_node: the standard way to control a simulator from tests and tools.

Every answer fills ``result`` and says why in ``error_message``; a refused request changes
nothing.  The services act between batches of physics steps; a spawn's object is read and
tried in a thread of its own, and loaded in the executor's turn.

Design notes: docs/design/ros.md#simulation_servicespy.
"""

from __future__ import annotations

import collections
import importlib
import math
import pathlib
import queue
import re
import threading
import types
import xml.etree.ElementTree as ElementTree
from collections.abc import Callable, Iterable

from geometry_msgs.msg import Vector3
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.service import Service
from rclpy.task import Future

from pan_tilt_sim.errors import DescriptionError, ParameterError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.resources import PACKAGE_SCHEME, resolve_resource
from pan_tilt_sim.model.transforms import Transform, rotate
from pan_tilt_sim.ros import parameters as params
from pan_tilt_sim.ros import services as world_services
from pan_tilt_sim.ros.ros_interfaces import SERVICE_QOS, stamp
from pan_tilt_sim.ros.stepping import JobEnd, StepJob, StepRunner
from pan_tilt_sim.share import PACKAGE_NAME
from pan_tilt_sim.sim.entities import (
    Category,
    EntityInfo,
    EntityState,
    EntityStateError,
    NotDeletableError,
    PreparedObject,
    SpawnError,
    SpawnProblem,
    check_twist,
    checked_pose,
)

PACKAGE = 'simulation_interfaces'
NAMESPACE_PARAMETER = 'simulation_interfaces.namespace'
PRIVATE = '~'
DEFAULT_NAMESPACE = PRIVATE
WORLD_FRAME = 'world'
SPAWN_FORMATS = ['urdf', 'sdf']
QUIT_GRACE_S = 0.1  # wall time between QUITTING's answer and the shutdown (DDS delivers it)
# GetSpawnables with no sources: the objects this package ships.
SPAWNABLES_FOLDER = pathlib.PurePosixPath('urdf', 'objects')
SPAWNABLE_SUFFIXES = ('.urdf', '.xacro')
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


class Preparations:
    """Jobs run one at a time in a thread of their own; each one's outcome completes a Future.

    The outcome is handed back through a guard condition, so the Future is
    completed -- and whoever awaits it resumes -- in an executor callback, in
    its turn between two batches of physics steps.  The thread starts with
    the first job: a node that is never asked to spawn runs none.
    """

    def __init__(self, node: Node, callback_group: ReentrantCallbackGroup) -> None:
        self._jobs: queue.SimpleQueue = queue.SimpleQueue()
        self._finished: collections.deque = collections.deque()
        self._guard = node.create_guard_condition(self._deliver, callback_group=callback_group)
        self._thread = threading.Thread(target=self._run, name='spawn_preparation',
                                        daemon=True)
        self._starting = threading.Lock()

    def submit(self, job: Callable[[], object]) -> Future:
        """Queue ``job``; return the Future of its result (or of the exception it raised)."""
        future = Future()
        self._jobs.put((job, future))
        with self._starting:
            if self._thread.ident is None:
                self._thread.start()
        return future

    def close(self) -> None:
        """Stop after the job in progress (queued jobs are dropped; nobody awaits them)."""
        self._jobs.put(None)

    def _run(self) -> None:
        while (item := self._jobs.get()) is not None:
            job, future = item
            try:
                outcome = (job(), None)
            except Exception as error:  # handed to the caller, who answers with it
                outcome = (None, error)
            self._finished.append((future, outcome))
            try:
                self._guard.trigger()
            except Exception:  # the node is gone (rclpy's InvalidHandle): nobody waits
                return

    def _deliver(self) -> None:
        while self._finished:
            future, (result, error) = self._finished.popleft()
            if error is None:
                future.set_result(result)
            else:
                future.set_exception(error)


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
    """simulation_interfaces' services and action on a SimNode (see the module's design notes)."""

    def __init__(self, node: Node, interfaces: types.SimpleNamespace, namespace: str,
                 gazebo_services: list[Service]) -> None:
        self._node = node
        self._msg, srv, action = interfaces.msg, interfaces.srv, interfaces.action
        self._srv = srv
        self._action = action.SimulateSteps
        self._action_name = service_name(namespace, ACTION)
        self._simulation = node.simulation
        self._entities = node.features.entities
        self._logger = node.get_logger()
        self._runner = StepRunner(node, node.step, lambda: node.paused)
        self._stopped_at: int | None = node.steps_run if node.paused else None
        self._quit_timer = None
        self._quitting = False
        self._closed = False
        self._goal_jobs: dict[bytes, StepJob] = {}
        self._drop_clashing(namespace, gazebo_services)
        # The awaiting callbacks (a step request waits for its steps, a spawn for its
        # preparation) get their own group: in the default one they would hold off the
        # steps they wait for.
        waiting = ReentrantCallbackGroup()
        self._preparations = Preparations(node, waiting)
        handlers: dict[str, tuple[type, Callable]] = {
            'get_simulator_features': (srv.GetSimulatorFeatures, self._get_features),
            'get_simulation_state': (srv.GetSimulationState, self._get_state),
            'set_simulation_state': (srv.SetSimulationState, self._set_state),
            'step_simulation': (srv.StepSimulation, self._step_simulation),
            'reset_simulation': (srv.ResetSimulation, self._reset_simulation),
            'get_entities': (srv.GetEntities, self._get_entities),
            'get_entities_states': (srv.GetEntitiesStates, self._get_entities_states),
            'get_entity_state': (srv.GetEntityState, self._get_entity_state),
            'set_entity_state': (srv.SetEntityState, self._set_entity_state),
            'get_entity_info': (srv.GetEntityInfo, self._get_entity_info),
            'set_entity_info': (srv.SetEntityInfo, self._set_entity_info),
            'get_entity_bounds': (srv.GetEntityBounds, self._get_entity_bounds),
            'spawn_entity': (srv.SpawnEntity, self._spawn_entity),
            'spawn_entities': (srv.SpawnEntities, self._spawn_entities),
            'delete_entity': (srv.DeleteEntity, self._delete_entity),
            'get_spawnables': (srv.GetSpawnables, self._get_spawnables),
        }
        self.services = {
            leaf: node.create_service(
                kind, service_name(namespace, leaf), handler, qos_profile=SERVICE_QOS,
                callback_group=waiting if leaf in AWAITING_SERVICES else None)
            for leaf, (kind, handler) in handlers.items()}
        self.action_server = ActionServer(
            node, self._action, self._action_name,
            execute_callback=self._simulate_steps, goal_callback=self._accept_goal,
            cancel_callback=self._cancel_goal, callback_group=waiting)

    @property
    def names(self) -> list[str]:
        """The services' and the action's full names."""
        return [self._node.resolve_service_name(service.srv_name)
                for service in self.services.values()] + [
            self._node.resolve_service_name(self._action_name)]

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
        """Stop stepping (a job in progress fails) and serving the action (idempotent)."""
        if self._closed:
            return
        self._closed = True
        self._runner.close()
        self._preparations.close()
        if self._quit_timer is not None:
            self._quit_timer.cancel()
        self.action_server.destroy()

    # --- simulator --------------------------------------------------------------------------

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

    def _accept_goal(self, goal) -> GoalResponse:
        return GoalResponse.ACCEPT  # refusals come as results, with the reason (as O3DE)

    def _cancel_goal(self, goal_handle) -> CancelResponse:
        job = self._goal_jobs.get(bytes(goal_handle.goal_id.uuid))
        if job is not None:
            job.cancel_requested = True
        return CancelResponse.ACCEPT

    async def _simulate_steps(self, goal_handle):
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

    # --- entities ---------------------------------------------------------------------------

    def _get_entities(self, request, response):
        names = self._filtered(request.filters, response)
        if names is None:
            return response
        response.entities = names
        return self._ok(response)

    def _get_entities_states(self, request, response):
        names = self._filtered(request.filters, response)
        if names is None:
            return response
        response.entities = names
        response.states = [self._state_message(name) for name in names]
        return self._ok(response)

    def _get_entity_state(self, request, response):
        if not self._known(request.entity, response):
            return response
        response.state = self._state_message(request.entity)
        return self._ok(response)

    def _set_entity_state(self, request, response):
        if not self._known(request.entity, response):
            return response
        message = request.state
        invalid = self._srv.SetEntityState.Response.INVALID_POSE
        try:
            reference = self._entities.frame_pose(message.header.frame_id)
        except KeyError:
            return self._fail(response, invalid, f"unknown frame '{message.header.frame_id}' "
                              "(use '' or world, an entity's name, or a link of the robot)")
        twist = message.twist
        linear = (twist.linear.x, twist.linear.y, twist.linear.z)
        angular = (twist.angular.x, twist.angular.y, twist.angular.z)
        try:
            # Bounded and normalised in the request's own frame first, so that composing
            # with the reference frame cannot overflow (set_state checks the result).
            pose = checked_pose(_transform(message.pose),
                                lambda text: EntityStateError(text, invalid_pose=True))
            check_twist(linear, angular, lambda text: EntityStateError(
                f"'{request.entity}': {text}"))
            state = EntityState(reference.then(pose), rotate(reference.rotation, linear),
                                rotate(reference.rotation, angular))
            self._entities.set_state(request.entity, state)
        except EntityStateError as err:
            return self._fail(response, invalid if err.invalid_pose
                              else self._msg.Result.RESULT_OPERATION_FAILED, str(err))
        return self._ok(response)

    def _get_entity_info(self, request, response):
        if not self._known(request.entity, response):
            return response
        info = self._entities.get(request.entity).info
        response.info.category.category = _CATEGORY_CODES[info.category]
        response.info.description = info.description
        response.info.tags = list(info.tags)
        return self._ok(response)

    def _set_entity_info(self, request, response):
        if not self._known(request.entity, response):
            return response
        category = _CATEGORIES.get(request.info.category.category)
        if category is None:
            return self._fail(response, self._msg.Result.RESULT_OPERATION_FAILED,
                              f'unknown category {request.info.category.category}')
        self._entities.set_info(request.entity, EntityInfo(
            category, request.info.description, tuple(request.info.tags)))
        return self._ok(response)

    def _get_entity_bounds(self, request, response):
        if not self._known(request.entity, response):
            return response
        low, high = self._entities.bounds(request.entity)
        response.bounds.type = self._msg.Bounds.TYPE_BOX
        response.bounds.points = [_vector(Vector3(), low), _vector(Vector3(), high)]
        return self._ok(response)

    async def _spawn_entity(self, request, response):
        codes = self._srv.SpawnEntity.Response
        name = await self._spawn(request.name, request.allow_renaming, request.uri,
                                 request.resource_string, request.entity_namespace,
                                 request.initial_pose, response.result, codes)
        response.entity_name = name
        return response

    async def _spawn_entities(self, request, response):
        codes = self._msg.SpawnResult
        results = []
        for item in request.spawn_requests:
            result = self._msg.SpawnResult()
            result.entity_name = await self._spawn(
                item.name, item.allow_renaming, item.entity_resource.uri,
                item.entity_resource.resource_string, item.entity_namespace,
                item.initial_pose, result.result, codes)
            results.append(result)
        response.results = results
        failed = [f'{index}: {result.result.error_message}' for index, result in
                  enumerate(results) if result.result.result != self._msg.Result.RESULT_OK]
        if failed:
            response.result.result = self._srv.SpawnEntities.Response.ENTITIES_SPAWN_FAILED
            response.result.error_message = (
                f'{len(failed)} of {len(results)} failed (the others were spawned): '
                + '; '.join(failed))
        else:
            self._ok(response)
        return response

    async def _spawn(self, name: str, allow_renaming: bool, uri: str, resource_string: str,
                     namespace: str, initial_pose, result, codes) -> str:
        """Spawn one object: checked now, prepared off this thread, loaded in our turn."""
        entities = self._entities
        pose = _transform(initial_pose.pose)
        frame = initial_pose.header.frame_id
        try:
            entities.check_request(uri, resource_string, namespace, pose, frame)
            prepared: PreparedObject = await self._preparations.submit(
                lambda: entities.prepare(uri, resource_string))
            spawned = entities.add(prepared, name, pose=pose, frame=frame,
                                   allow_renaming=allow_renaming, namespace=namespace, uri=uri)
        except SpawnError as err:
            result.result = _SPAWN_RESULTS.get(err.problem.name) or getattr(
                codes, err.problem.name)
            result.error_message = str(err)
            if err.problem is SpawnProblem.TOO_LARGE:
                self._logger.warning(f'spawn refused: {err}', throttle_duration_sec=1.0)
            return ''
        position = entities.state(spawned).pose.translation
        self._logger.info(
            f"spawned '{spawned}' from {uri or 'a resource string'} at "
            f"({', '.join(f'{c:.3g}' for c in position)})")
        result.result = self._msg.Result.RESULT_OK
        return spawned

    def _delete_entity(self, request, response):
        if not self._known(request.entity, response):
            return response
        try:
            self._entities.delete(request.entity)
        except NotDeletableError as err:
            return self._fail(response, self._msg.Result.RESULT_OPERATION_FAILED, str(err))
        self._logger.info(f"deleted '{request.entity}'")
        return self._ok(response)

    def _get_spawnables(self, request, response):
        spawnables, unknown = [], []
        sources = list(request.sources) or [f'{PACKAGE_SCHEME}{PACKAGE_NAME}/{SPAWNABLES_FOLDER}']
        for source in sources:
            found = _spawnable_files(source)
            if found is None:
                unknown.append(source)
                continue
            for uri, description in found:
                spawnable = self._msg.Spawnable(uri=uri, description=description)
                spawnable.spawn_bounds.type = self._msg.Bounds.TYPE_EMPTY
                spawnables.append(spawnable)
        response.spawnables = spawnables
        self._ok(response)
        if unknown:
            response.result.error_message = (
                'not a folder (path, file:// or package:// URI): ' + ', '.join(unknown))
        return response

    # --- helpers ----------------------------------------------------------------------------

    def _filtered(self, filters, response) -> list[str] | None:
        """Return the entities that pass ``filters`` (all ANDed), or None after a failure."""
        result = self._msg.Result
        names = self._entities.names()
        if filters.filter:
            try:
                pattern = re.compile(filters.filter)
            except re.error as err:
                self._fail(response, result.RESULT_OPERATION_FAILED,
                           f"filter '{filters.filter}' is not a regular expression: {err}")
                return None
            names = [name for name in names if pattern.fullmatch(name)]
        if filters.categories:
            wanted = {category.category for category in filters.categories}
            names = [name for name in names
                     if _CATEGORY_CODES[self._entities.get(name).info.category] in wanted]
        tags = filters.tags
        if tags.tags:
            modes = self._msg.TagsFilter
            if tags.filter_mode not in (modes.FILTER_MODE_ANY, modes.FILTER_MODE_ALL):
                self._fail(response, result.RESULT_OPERATION_FAILED,
                           f'unknown tags filter_mode {tags.filter_mode}')
                return None
            match = any if tags.filter_mode == modes.FILTER_MODE_ANY else all
            names = [name for name in names
                     if match(tag in self._entities.get(name).info.tags for tag in tags.tags)]
        bounds = filters.bounds
        if bounds.type != self._msg.Bounds.TYPE_EMPTY:
            overlaps = self._bounds_test(bounds, response)
            if overlaps is None:
                return None
            names = [name for name in names if overlaps(*self._entities.world_bounds(name))]
        return names

    def _bounds_test(self, bounds, response) -> Callable | None:
        kinds, result = self._msg.Bounds, self._msg.Result
        points = [(p.x, p.y, p.z) for p in bounds.points]
        if bounds.type == kinds.TYPE_SPHERE and len(points) == 2 and points[1][0] >= 0.0:
            centre, radius = points[0], points[1][0]

            def in_sphere(low, high) -> bool:
                nearest = [min(max(c, lo), hi) for c, lo, hi in zip(centre, low, high,
                                                                      strict=True)]
                return math.dist(nearest, centre) <= radius
            return in_sphere
        if bounds.type == kinds.TYPE_BOX and len(points) == 2:
            box_low = [min(a, b) for a, b in zip(*points, strict=True)]
            box_high = [max(a, b) for a, b in zip(*points, strict=True)]

            def in_box(low, high) -> bool:
                return all(lo <= bh and hi >= bl for lo, hi, bl, bh in
                           zip(low, high, box_low, box_high, strict=True))
            return in_box
        if bounds.type == kinds.TYPE_CONVEX_HULL:
            self._fail(response, result.RESULT_FEATURE_UNSUPPORTED,
                       'bounds filter: TYPE_CONVEX_HULL is not supported (TYPE_BOX and '
                       'TYPE_SPHERE are)')
            return None
        self._fail(response, result.RESULT_OPERATION_FAILED,
                   f'bounds filter: type {bounds.type} with {len(points)} points is not a '
                   'sphere (centre, (radius, 0, 0)) or a box (two corners)')
        return None

    def _state_message(self, name: str):
        state = self._entities.state(name)
        message = self._msg.EntityState()
        message.header.frame_id = WORLD_FRAME
        stamp(self._simulation.time, message.header.stamp)
        pose = message.pose
        pose.position.x, pose.position.y, pose.position.z = state.pose.translation
        (pose.orientation.x, pose.orientation.y, pose.orientation.z,
         pose.orientation.w) = state.pose.rotation
        _vector(message.twist.linear, state.linear)
        _vector(message.twist.angular, state.angular)
        return message

    def _known(self, name: str, response) -> bool:
        if name in self._entities:
            return True
        self._fail(response, self._msg.Result.RESULT_NOT_FOUND,
                   f"no entity called '{name}' (get_entities lists them)")
        return False

    def _ok(self, response):
        response.result.result = self._msg.Result.RESULT_OK
        response.result.error_message = ''
        return response

    @staticmethod
    def _fail(response, code: int, message: str):
        response.result.result = code
        response.result.error_message = message
        return response


# SpawnProblems without a code of their own in SpawnEntity: simulation_interfaces/msg/Result's.
_SPAWN_RESULTS = {'NOT_FOUND': 2, 'TOO_LARGE': 4}  # RESULT_NOT_FOUND, RESULT_OPERATION_FAILED
_STATE_NAMES = {0: 'STOPPED', 1: 'PLAYING', 2: 'PAUSED', 3: 'QUITTING'}
# simulation_interfaces/msg/EntityCategory values.
_CATEGORY_CODES = {Category.OBJECT: 0, Category.ROBOT: 1, Category.HUMAN: 2,
                   Category.DYNAMIC_OBJECT: 4, Category.STATIC_OBJECT: 5}
_CATEGORIES = {code: category for category, code in _CATEGORY_CODES.items()}


def _transform(pose) -> Transform:
    return Transform((pose.position.x, pose.position.y, pose.position.z),
                     (pose.orientation.x, pose.orientation.y, pose.orientation.z,
                      pose.orientation.w))


def _vector(message, values: Iterable[float]):
    message.x, message.y, message.z = values
    return message


def _spawnable_files(source: str) -> list[tuple[str, str]] | None:
    """Return (uri, description) of the URDF and xacro files in a folder; None if no folder."""
    try:
        folder = resolve_resource(source, pathlib.Path.cwd())
    except DescriptionError:  # an unknown package or scheme
        return None
    if not folder.is_dir():
        return None
    found = []
    for path in sorted(folder.iterdir()):
        if path.suffix.lower() not in SPAWNABLE_SUFFIXES or not path.is_file():
            continue
        if source.startswith(PACKAGE_SCHEME):
            uri = f"{source.rstrip('/')}/{path.name}"
        else:
            uri = path.as_uri()
        found.append((uri, _describe_file(path)))
    return found


def _describe_file(path: pathlib.Path) -> str:
    """Return a URDF's first XML comment inside <robot>, else its robot name."""
    try:
        parser = ElementTree.XMLParser(target=ElementTree.TreeBuilder(insert_comments=True))
        root = ElementTree.fromstring(path.read_text(encoding='utf-8'), parser=parser)
    except (OSError, UnicodeDecodeError, ElementTree.ParseError):
        return path.name
    for element in root.iter():
        if element.tag is ElementTree.Comment and (element.text or '').strip():
            return ' '.join(element.text.split())
    return f"'{root.get('name', path.stem)}' ({path.name})"

