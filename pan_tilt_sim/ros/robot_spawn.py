"""A world without a robot yet: the first SpawnEntity request brings THE robot.

With ``robot_from_spawn`` true (what the ros_gz_sim and gazebo_ros stand-ins start
sim_node with) sim_node loads its world and waits, serving simulation_interfaces'
``SpawnEntity`` where the simulation services will be (``~/spawn_entity``).  The
first request's description becomes the robot, as if sim_node had been started
with it: its plugins, its controller manager (``<ros2_control>`` with a
gz_ros2_control plugin), its sensors, at the request's pose and namespace.  The
answer follows once it is built, so ``create`` exits when the robot is in.  The
service stays: a later request whose description is a robot (plugins, sensors or
``<ros2_control>``) adds one more robot to the world (``build_more``) -- one that comes
while the first is being built waits for it -- and any other goes to the simulation
services' SpawnEntity (objects), whose server of that name it replaces.  A robot is
built once the bridge stand-ins that announced themselves have handed over their
entries (:mod:`.bridged_topics`), at most :data:`BRIDGE_WAIT_S` later; in a world
whose robots came with bridges, a later robot first waits for a bridge of its own
(:meth:`RobotSpawnService._new_bridge`).
docs/launch-files.md is the reference.
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
import time
from collections.abc import Callable, Iterable

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.task import Future

from pan_tilt_sim.errors import ConfigurationError, ParameterError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.base_pose import BasePose
from pan_tilt_sim.model.description import (
    RobotDescription,
    description_from_text,
    load_description,
)
from pan_tilt_sim.model.resources import resolve_resource
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.ros import parameters as params
from pan_tilt_sim.ros.ros_interfaces import SERVICE_QOS
from pan_tilt_sim.ros.simulation_services import interfaces

PARAMETER = 'robot_from_spawn'
SERVICE = '~/spawn_entity'  # where simulation_services' default namespace puts it
WORLD_FRAMES = ('', 'world')
# Wall seconds a spawn waits for announced bridges to hand over (their start-up is ~1 s).
BRIDGE_WAIT_S = 10.0
BRIDGE_POLL_S = 0.1
# Wall seconds a later robot in a bridged world waits for a bridge of its own to appear
# (Nav2's multi-robot launch starts one per robot, with its create, in its namespace),
# unless a bridge's entries name its topics already.
NEW_BRIDGE_WAIT_S = 3.0


@dataclasses.dataclass(frozen=True)
class Spawn:
    """What a spawn request asks of the robot besides its description."""

    name: str
    pose: BasePose
    namespace: str  # '' = the description's own (its plugins')


def declare(node: Node) -> bool:
    """Declare ``robot_from_spawn``; return whether the robot comes from a spawn request."""
    return params.declare(
        node, PARAMETER, params.BOOL, False,
        'true: start with the world only; the first simulation_interfaces SpawnEntity '
        "request on '~/spawn_entity' (ros_gz_sim's create, gazebo_ros's spawn_entity.py) "
        "brings the robot, with its plugins and controller manager.")


def unit_quaternion(x: float, y: float, z: float, w: float) -> tuple[float, float, float, float]:
    """Return the quaternion normalised; ValueError if it is zero or not finite."""
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    if not math.isfinite(norm) or norm < 1e-9:
        raise ValueError('the orientation is not a rotation (zero or non-finite quaternion)')
    return x / norm, y / norm, z / norm, w / norm


def roll_pitch_yaw(x: float, y: float, z: float, w: float) -> tuple[float, float, float]:
    """Return (roll, pitch, yaw) of a quaternion (rad, fixed axes x, y, z: gz's pose angles)."""
    x, y, z, w = unit_quaternion(x, y, z, w)
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


def free_name(wanted: str, taken: Iterable[str], allow_renaming: bool) -> str | None:
    """Return ``wanted``, or with ``allow_renaming`` the first free ``wanted_N``; None if taken."""
    taken = set(taken)
    if wanted not in taken:
        return wanted
    if not allow_renaming:
        return None
    number = 1
    while f'{wanted}_{number}' in taken:
        number += 1
    return f'{wanted}_{number}'


def renamed(description: RobotDescription, name: str) -> RobotDescription:
    """Return ``description`` with the robot called ``name``."""
    if name == description.name:
        return description
    return dataclasses.replace(description, model=dataclasses.replace(description.model,
                                                                      name=name))


class RobotSpawnService:
    """Serves SpawnEntity until the robot is in; ``build(description, spawn)`` builds it.

    ``taken`` are the world's entity names (a robot may not take one, unless
    renamed).  A request refused (no resource, bad description, taken name,
    bad pose) leaves sim_node waiting; one whose robot cannot be built ends
    sim_node with that error after the answer, as a bad description file does.
    """

    def __init__(self, node: Node, build: Callable[[RobotDescription, Spawn], None],
                 taken: Iterable[str] = (),
                 build_more: Callable[[RobotDescription, Spawn], None] | None = None,
                 names: Callable[[], Iterable[str]] | None = None,
                 is_robot: Callable[[RobotDescription], bool] | None = None,
                 frame_pose: Callable[[str], Transform] | None = None,
                 own_topics: Callable[[RobotDescription, str], Iterable[str]] | None = None,
                 ) -> None:
        found = interfaces()
        if found is None:
            raise ParameterError(
                f"parameter '{PARAMETER}' is true, but simulation_interfaces is not installed: "
                'nothing could spawn the robot (scripts/build_interfaces.sh builds it)')
        self._node, self._build, self._taken = node, build, tuple(taken)
        # Once the first robot is in: more robots (build_more), the world's names (names).
        self._build_more, self._names, self._is_robot = build_more, names, is_robot
        # A frame's pose in the world (KeyError: none such), for a later robot's initial_pose.
        self._frame_pose = frame_pose
        # A later robot's topics before bridges rename them, from its description and the
        # request's namespace: what its own bridge's entries name.
        self._own_topics = own_topics
        self._srv = found.srv.SpawnEntity
        self._result = found.msg.Result
        self._built = False
        self._busy = False  # a request is waiting for the bridges
        self._bridges_seen = 0  # bridges known when the last robot was built
        self.awaiting_bridge = False  # a later robot's request waits for its bridge to appear
        self._failure: ConfigurationError | None = None
        self._objects: Callable | None = None  # the simulation services' handler, once built
        # Reentrant: an object's spawn awaits its preparation, which other callbacks finish.
        self.service = node.create_service(self._srv, SERVICE, self._spawn,
                                           qos_profile=SERVICE_QOS,
                                           callback_group=ReentrantCallbackGroup())
        node.get_logger().info(
            f"No robot yet: waiting for one on '{node.resolve_service_name(SERVICE)}' "
            "(ros_gz_sim's create, "
            "gazebo_ros's spawn_entity.py, or a SpawnEntity request); the simulation starts "
            'with it')

    async def _spawn(self, request, response):
        while self._busy:  # the first robot is being built: this request follows it
            await self._pause(BRIDGE_POLL_S)
        more = self._more_robot(request) if self._built and self._failure is None else None
        if more is not None:
            # Its bridge (in its namespace) may have started with its create: wait for it too.
            await self._new_bridge(request, more)
            await self._bridges_handed_over()
            return self._spawn_robot(request, response, more=True)
        if self._objects is not None:
            return await self._objects(request, response)
        if self._built or self._busy:  # being built, or it failed (sim_node is ending)
            return self._refuse(response, self._result.RESULT_OPERATION_FAILED,
                                'the robot is in or being loaded: spawn objects through the '
                                'simulation services')
        self._busy = True
        try:
            await self._bridges_handed_over()
            return self._spawn_robot(request, response)
        finally:
            self._busy = False

    async def _new_bridge(self, request, description: RobotDescription) -> None:
        """In a world whose robots came with bridges, give a later robot's bridge a moment.

        Ends once a bridge not seen when the last robot was built appears, or a handed-over
        entry names one of the robot's topics (its bridge came first, or one bridge serves
        every robot); else after NEW_BRIDGE_WAIT_S (a bridge after that gets relays).
        """
        bridges = getattr(self._node, 'bridged_topics', None)
        if bridges is None or not self._bridges_seen:
            return
        topics = self._topics_of(request, description)
        deadline = time.monotonic() + NEW_BRIDGE_WAIT_S
        self.awaiting_bridge = True
        try:
            while (bridges.known() <= self._bridges_seen and not bridges.names_any(topics)
                   and time.monotonic() < deadline):
                await self._pause(BRIDGE_POLL_S)
        finally:
            self.awaiting_bridge = False

    def _topics_of(self, request, description: RobotDescription) -> set[str]:
        """Return the topics the robot of ``request`` will have (none known: empty)."""
        if self._own_topics is None or self._names is None:
            return set()
        name = free_name(request.name or description.name, self._names(),
                         request.allow_renaming) or description.name
        return set(self._own_topics(renamed(description, name),
                                    naming.normalize(request.entity_namespace)))

    async def _bridges_handed_over(self) -> None:
        """Wait (at most BRIDGE_WAIT_S) for the bridges in the graph to give their entries."""
        bridges = getattr(self._node, 'bridged_topics', None)
        if bridges is None:
            return
        deadline = time.monotonic() + BRIDGE_WAIT_S
        pending = bridges.pending()
        if pending:
            self._node.get_logger().info(
                f"waiting for {', '.join(pending)} to hand over its topics before the robot "
                'is built')
        while pending and time.monotonic() < deadline:
            await self._pause(BRIDGE_POLL_S)
            pending = bridges.pending()
        if pending:
            self._node.get_logger().warning(
                f"{', '.join(pending)} did not hand over its topics within {BRIDGE_WAIT_S:g} s: "
                'the robot is built without them')
        self._bridges_seen = bridges.known()

    def _pause(self, seconds: float) -> Future:
        """Return a Future done after ``seconds`` of wall time (a one-shot timer completes it)."""
        future = Future()

        def done() -> None:
            self._node.destroy_timer(timer)
            future.set_result(None)

        timer = self._node.create_timer(seconds, done)
        return future

    def _more_robot(self, request) -> RobotDescription | None:
        """Return the robot a request after the first one brings (None: it is an object)."""
        if self._build_more is None or self._is_robot is None:
            return None
        try:
            description = self._description(request)
        except ConfigurationError:
            return None  # the objects' SpawnEntity says what is wrong with it
        return description if self._is_robot(description) else None

    def _spawn_robot(self, request, response, *, more: bool = False):
        codes = self._srv.Response
        if not request.uri and not request.resource_string:
            return self._refuse(response, codes.NO_RESOURCE,
                                'neither uri nor resource_string is set')
        if request.entity_namespace and not naming.is_valid_namespace(
                naming.normalize(request.entity_namespace)):
            return self._refuse(response, codes.NAMESPACE_INVALID,
                                f"entity_namespace '{request.entity_namespace}' is not a valid "
                                f'ROS namespace ({naming.NAMESPACE_RULE})')
        pose = request.initial_pose
        frame = pose.header.frame_id
        if frame not in WORLD_FRAMES and (not more or self._frame_pose is None):
            return self._refuse(response, codes.INVALID_POSE,
                                f"initial_pose frame '{frame}': the first robot is placed in "
                                "'' or 'world' only (the world's entities are built with it)")
        position, orientation = pose.pose.position, pose.pose.orientation
        try:
            roll, pitch, yaw = roll_pitch_yaw(orientation.x, orientation.y, orientation.z,
                                              orientation.w)
        except ValueError as err:
            return self._refuse(response, codes.INVALID_POSE, f'initial_pose: {err}')
        xyz = (position.x, position.y, position.z)
        if not all(math.isfinite(value) for value in xyz):
            return self._refuse(response, codes.INVALID_POSE,
                                'initial_pose: the position is not finite')
        if frame not in WORLD_FRAMES:  # relative to an entity, or a link of the first robot
            try:
                reference = self._frame_pose(frame)
            except KeyError:
                return self._refuse(response, codes.INVALID_POSE,
                                    f"initial_pose frame '{frame}': no such frame (use '' or "
                                    "'world', an entity's name, or a link of the first robot)")
            placed = reference.then(Transform(xyz, unit_quaternion(
                orientation.x, orientation.y, orientation.z, orientation.w)))
            xyz = placed.translation
            roll, pitch, yaw = roll_pitch_yaw(*placed.rotation)
        try:
            description = self._description(request)
        except ConfigurationError as err:
            code = (self._result.RESULT_NOT_FOUND if 'no such file' in str(err)
                    or 'unknown package' in str(err) else codes.RESOURCE_PARSE_ERROR)
            return self._refuse(response, code, str(err))
        taken = self._names() if more else self._taken
        name = free_name(request.name or description.name, taken, request.allow_renaming)
        if name is None:
            return self._refuse(response, codes.NAME_NOT_UNIQUE,
                                f"entity named '{request.name or description.name}' already "
                                'exists (allow_renaming is false)')
        spawn = Spawn(name, BasePose(*xyz, yaw, roll, pitch),
                      naming.normalize(request.entity_namespace))
        if more:
            try:
                self._build_more(renamed(description, name), spawn)
            except ConfigurationError as err:  # the robots in the world run on
                return self._refuse(response, self._result.RESULT_OPERATION_FAILED, str(err))
            response.result.result = self._result.RESULT_OK
            response.entity_name = name
            return response
        self._built = True
        try:
            self._build(renamed(description, name), spawn)
        except ConfigurationError as err:
            # As for a description file: sim_node ends with this line, after the answer.
            self._failure = err
            self._once(self._fail)
            return self._refuse(response, self._result.RESULT_OPERATION_FAILED, str(err))
        self._take_over()
        response.result.result = self._result.RESULT_OK
        response.entity_name = name
        return response

    def _description(self, request) -> RobotDescription:
        if request.uri:
            return load_description(resolve_resource(request.uri, pathlib.Path.cwd()))
        return description_from_text(request.resource_string, '<SpawnEntity resource_string>')

    def _refuse(self, response, code: int, message: str):
        self._node.get_logger().error(f'SpawnEntity refused: {message}')
        response.result.result = code
        response.result.error_message = message
        return response

    def _once(self, action: Callable[[], None]) -> None:
        """Run ``action`` once, in the executor's next turn (after this answer is sent)."""
        def run() -> None:
            self._node.destroy_timer(timer)
            action()

        timer = self._node.create_timer(0.0, run)

    def _take_over(self) -> None:
        """Serve the simulation services' SpawnEntity in place of their own server."""
        simulation = getattr(self._node, 'simulation_interfaces', None)
        theirs = None if simulation is None else simulation.services.get('spawn_entity')
        if theirs is None:
            return
        if (self._node.resolve_service_name(theirs.srv_name)
                != self._node.resolve_service_name(self.service.srv_name)):
            return  # elsewhere (simulation_interfaces.namespace): both stay
        self._objects = theirs.callback
        self._node.destroy_service(theirs)
        simulation.services['spawn_entity'] = self.service

    def _fail(self) -> None:
        raise self._failure
