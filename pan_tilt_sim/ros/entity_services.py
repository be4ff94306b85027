"""simulation_interfaces' entity services: list, query, move, tag, spawn and delete entities.

:class:`~pan_tilt_sim.ros.simulation_services.SimulationServices` serves them
beside the simulator's own.  A spawn's object is read and tried in a thread of
its own (:class:`Preparations`) and loaded in the executor's turn.

Design notes: docs/design/ros.md#simulation_servicespy.
"""

from __future__ import annotations

import collections
import math
import pathlib
import queue
import re
import threading
import types
import xml.etree.ElementTree as ElementTree
from collections.abc import Callable, Iterable

from geometry_msgs.msg import Vector3
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.task import Future

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.resources import PACKAGE_SCHEME, resolve_resource
from pan_tilt_sim.model.transforms import Transform, rotate
from pan_tilt_sim.ros.ros_interfaces import stamp
from pan_tilt_sim.share import PACKAGE_NAME
from pan_tilt_sim.sim.engine import Simulation
from pan_tilt_sim.sim.entities import (
    Category,
    Entities,
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

WORLD_FRAME = 'world'
# GetSpawnables with no sources: the objects this package ships.
SPAWNABLES_FOLDER = pathlib.PurePosixPath('urdf', 'objects')
SPAWNABLE_SUFFIXES = ('.urdf', '.xacro')


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


class Answers:
    """What every simulation_interfaces answer fills: ``result``, and why in ``error_message``."""

    def __init__(self, interfaces: types.SimpleNamespace) -> None:
        self._msg, self._srv = interfaces.msg, interfaces.srv

    def _ok(self, response):
        response.result.result = self._msg.Result.RESULT_OK
        response.result.error_message = ''
        return response

    @staticmethod
    def _fail(response, code: int, message: str):
        response.result.result = code
        response.result.error_message = message
        return response


class EntityServices(Answers):
    """The entity services: what is in the world, where, what it is; spawning and deleting."""

    def __init__(self, interfaces: types.SimpleNamespace, entities: Entities,
                 simulation: Simulation, logger, preparations: Preparations) -> None:
        super().__init__(interfaces)
        self._entities = entities
        self._simulation = simulation  # its time stamps the states
        self._logger = logger
        self._preparations = preparations

    def handlers(self) -> dict[str, tuple[type, Callable]]:
        """Return each service's type and callback, by the service's last name."""
        srv = self._srv
        return {
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


# SpawnProblems without a code of their own in SpawnEntity: simulation_interfaces/msg/Result's.
_SPAWN_RESULTS = {'NOT_FOUND': 2, 'TOO_LARGE': 4}  # RESULT_NOT_FOUND, RESULT_OPERATION_FAILED
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

