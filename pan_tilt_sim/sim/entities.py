"""The things in the world, by name: the robot, the scenery's targets, spawned objects. No ROS.

:class:`Entities` keeps one record per entity of one simulation and does
what ``simulation_interfaces`` asks of them, in the simulation's own PyBullet
client (see the design notes).

Design notes: docs/design/sim.md#entitiespy.
"""

from __future__ import annotations

import dataclasses
import enum
import itertools
import math
import pathlib
import re
import tempfile
from collections.abc import Callable, Sequence

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.model.entity_resource import (
    DEFAULT_LIMITS,
    EntityLimits,
    EntityResourceError,
    ResourceProblem,
    is_static,
    read_entity_resource,
)
from pan_tilt_sim.model.transforms import IDENTITY_ROTATION, ZERO_VECTOR, Transform, Vector
from pan_tilt_sim.model.world_file import World, WorldFileError
from pan_tilt_sim.plugins.registry import create_plugins
from pan_tilt_sim.sim.bullet import pybullet, quiet_native_output
from pan_tilt_sim.sim.physics import (
    BASE_LINK_INDEX,
    Physics,
    apply_surface_friction,
    free_ball_joints,
    link_indices,
)
from pan_tilt_sim.sim.stability import ObjectTrials
from pan_tilt_sim.sim.world import add_ground_plane, grounded_links

WORLD_FRAMES = ('', 'world')  # frame ids that mean the world frame
WORLD_ORIGIN = Transform()
DEFAULT_NAME = 'entity'  # base of a generated name when neither request nor URDF gives one
# An entity name: printable, no white space (it is matched by regular expressions and
# typed on command lines).
_NAME = re.compile(r'[^\s]+')
NORM_TOLERANCE = 1e-6  # a quaternion this close to length 0 is no rotation
# What an entity's state may be (set_entity_state, spawn, world files).  Beyond these
# PyBullet's integration leaves the range of floats within a few steps, and the pose
# would turn NaN for good.  They are far beyond any robot scene: 1,000 km from the
# world origin, 10 km/s, 10,000 rad/s.
MAX_POSITION_M = 1e6  # each coordinate of a position, in the world
MAX_LINEAR_SPEED = 1e4  # m/s, length of the linear velocity
MAX_ANGULAR_SPEED = 1e4  # rad/s, length of the angular velocity
DYNAMICS_MASS = 0  # index of the mass in pybullet.getDynamicsInfo
DYNAMICS_INERTIAL_POSITION = 3
DYNAMICS_INERTIAL_ORIENTATION = 4
LINK_FRAME_POSITION = 4  # pybullet.getLinkState: the URDF link frame
LINK_FRAME_ORIENTATION = 5
STATE_POSITION = 0
ZERO_TWIST = (ZERO_VECTOR, ZERO_VECTOR)


class Category(enum.Enum):
    """What an entity is (simulation_interfaces' EntityCategory)."""

    OBJECT = 'object'
    ROBOT = 'robot'
    HUMAN = 'human'
    DYNAMIC_OBJECT = 'dynamic object'
    STATIC_OBJECT = 'static object'


class Origin(enum.Enum):
    """Where an entity came from, which decides what a reset does to it."""

    ROBOT = 'robot'  # never deleted
    SCENERY = 'scenery'  # the targets: never deleted
    WORLD_FILE = 'world file'  # deletable; a full reset brings it back
    SPAWNED = 'spawned'  # deletable; reset with SCOPE_SPAWNED removes it


class SpawnProblem(enum.Enum):
    """Why a spawn was refused (each is one of SpawnEntity's result codes)."""

    NAME_NOT_UNIQUE = 'name not unique'
    NAME_INVALID = 'name invalid'
    UNSUPPORTED_FORMAT = 'unsupported format'
    NO_RESOURCE = 'no resource'
    NAMESPACE_INVALID = 'namespace invalid'
    RESOURCE_PARSE_ERROR = 'resource parse error'
    MISSING_ASSETS = 'missing assets'
    UNSUPPORTED_ASSETS = 'unsupported assets'
    INVALID_POSE = 'invalid pose'
    NOT_FOUND = 'not found'
    TOO_LARGE = 'too large'


_RESOURCE_PROBLEMS = {
    ResourceProblem.NOT_FOUND: SpawnProblem.NOT_FOUND,
    ResourceProblem.UNSUPPORTED_FORMAT: SpawnProblem.UNSUPPORTED_FORMAT,
    ResourceProblem.PARSE_ERROR: SpawnProblem.RESOURCE_PARSE_ERROR,
    ResourceProblem.MISSING_ASSETS: SpawnProblem.MISSING_ASSETS,
    ResourceProblem.UNSUPPORTED_ASSETS: SpawnProblem.UNSUPPORTED_ASSETS,
    ResourceProblem.TOO_LARGE: SpawnProblem.TOO_LARGE,
}


class SpawnError(Exception):
    """A spawn request was refused; nothing in the simulation changed."""

    def __init__(self, problem: SpawnProblem, message: str) -> None:
        super().__init__(message)
        self.problem = problem


class EntityStateError(Exception):
    """A state cannot be given to an entity (a twist to a static one, a bad pose)."""

    def __init__(self, message: str, *, invalid_pose: bool = False) -> None:
        super().__init__(message)
        self.invalid_pose = invalid_pose


class NotDeletableError(Exception):
    """The robot and the scenery cannot be deleted."""


@dataclasses.dataclass
class EntityInfo:
    """What GetEntityInfo tells (and SetEntityInfo may change)."""

    category: Category
    description: str = ''
    tags: tuple[str, ...] = ()


@dataclasses.dataclass
class Entity:
    """One named body in the world."""

    name: str
    body: int
    origin: Origin
    static: bool
    info: EntityInfo
    initial_pose: Transform
    namespace: str = ''
    # The centre of mass in the root link frame (PyBullet's base frame is the CoM).
    inertial: Transform = Transform()
    initial_joints: tuple[float, ...] = ()
    initial_info: EntityInfo = None  # type: ignore[assignment]  # a copy of info by default
    # An object's description (None for the robot and the scenery) and its joints in
    # PyBullet's order: what a view of the world draws.
    description: RobotDescription | None = None
    joint_names: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.initial_info is None:
            self.initial_info = dataclasses.replace(self.info)


@dataclasses.dataclass(frozen=True)
class PreparedObject:
    """An object read, checked and tried (:meth:`Entities.prepare`), ready to load."""

    resource: RobotDescription
    path: pathlib.Path  # PyBullet's copy of its URDF, removed once loaded


@dataclasses.dataclass(frozen=True)
class EntityState:
    """Where an entity is and how it moves, in the world frame."""

    pose: Transform
    linear: Vector = ZERO_VECTOR
    angular: Vector = ZERO_VECTOR


class Entities:
    """The named bodies of one simulation (see the module's design notes)."""

    def __init__(self, physics: Physics, robot_name: str, *, targets: dict[str, int] | None = None,
                 ground: bool = True, limits: EntityLimits = DEFAULT_LIMITS) -> None:
        self._physics = physics
        self.limits = limits
        self._trials = ObjectTrials(physics.time_step)
        self._client = physics.client_id
        self._robot = physics.body_id
        self._ground_wanted = ground
        self._ground: int | None = None
        # Taken now, in the robot's initial pose (see world.add_ground_plane); a free
        # robot stands on the ground with every link.
        self._grounded = (grounded_links(self._client, self._robot) if physics.fixed_base
                          else [])
        self._workdir = tempfile.TemporaryDirectory(prefix='pan_tilt_sim_entities_')
        self._files = itertools.count(1)
        self._entities: dict[str, Entity] = {}
        self._world_file: dict[str, _WorldFileObject] = {}
        # Robots spawned after the first: what deleting each takes away besides its body.
        self._robot_removers: dict[str, Callable[[str], None]] = {}
        robot = self._record(robot_name, self._robot, Origin.ROBOT, static=physics.fixed_base,
                             info=EntityInfo(Category.ROBOT, 'the simulated robot'))
        self._entities[robot.name] = robot
        self._robot_name = robot.name
        if physics.ground is not None:  # a free robot's: the physics made it
            self._ground = physics.ground
        for name, body in (targets or {}).items():
            colour = name.rpartition('_')[2]
            self._entities[name] = self._record(
                name, body, Origin.SCENERY, static=True,
                info=EntityInfo(Category.STATIC_OBJECT, f'a {colour} target cube (scenery)'))

    # --- looking --------------------------------------------------------------------------

    @property
    def robot_name(self) -> str:
        """The first robot's entity name (its URDF ``<robot name>``), deleted or not.

        Once DeleteEntity took it away the name names no entity (``name in entities``
        is False); it never names another one.
        """
        return self._robot_name

    @property
    def has_ground(self) -> bool:
        """Whether the ground plane is a collision body yet."""
        return self._ground is not None

    def names(self) -> list[str]:
        """Every entity's name: the robot first, then the scenery, then objects in spawn order."""
        return list(self._entities)

    def __contains__(self, name: str) -> bool:
        return name in self._entities

    def get(self, name: str) -> Entity:
        """Return the entity called ``name``; KeyError if there is none."""
        return self._entities[name]

    def state(self, name: str) -> EntityState:
        """Return the pose of the entity's root link frame and its twist, in the world frame."""
        entity = self._entities[name]
        client = self._client
        com_position, com_orientation = pybullet.getBasePositionAndOrientation(
            entity.body, physicsClientId=client)
        pose = _pose_of_link(Transform(tuple(com_position), tuple(com_orientation)),
                             entity.inertial)
        if entity.static:
            return EntityState(pose)
        linear, angular = pybullet.getBaseVelocity(entity.body, physicsClientId=client)
        # The root link frame's origin moves with v_com + w x (p_link - p_com).
        offset = _minus(pose.translation, com_position)
        return EntityState(pose, _plus(linear, _cross(angular, offset)), tuple(angular))

    def joint_positions(self, name: str) -> dict[str, float]:
        """Return the position of every joint of an object, by name (none for the robot)."""
        entity = self._entities[name]
        if not entity.joint_names:
            return {}
        states = pybullet.getJointStates(entity.body, list(range(len(entity.joint_names))),
                                         physicsClientId=self._client)
        return {joint: state[STATE_POSITION]
                for joint, state in zip(entity.joint_names, states, strict=True)}

    def world_bounds(self, name: str) -> tuple[Vector, Vector]:
        """Return the world-axis-aligned box around every link of the entity (min, max)."""
        entity = self._entities[name]
        client = self._client
        links = range(BASE_LINK_INDEX, pybullet.getNumJoints(entity.body, physicsClientId=client))
        boxes = [pybullet.getAABB(entity.body, link, physicsClientId=client) for link in links]
        low = tuple(min(box[0][axis] for box in boxes) for axis in range(3))
        high = tuple(max(box[1][axis] for box in boxes) for axis in range(3))
        return low, high  # type: ignore[return-value]

    def bounds(self, name: str) -> tuple[Vector, Vector]:
        """Return a box around the entity in its own (root link) frame: opposite corners.

        The world box's corners, taken into the entity's frame: exact when the
        entity is not rotated, otherwise a box that holds it.
        """
        low, high = self.world_bounds(name)
        inverse = _inverse(self.state(name).pose)
        corners = [inverse.apply((x, y, z)) for x in (low[0], high[0])
                   for y in (low[1], high[1]) for z in (low[2], high[2])]
        return (tuple(min(c[axis] for c in corners) for axis in range(3)),  # type: ignore
                tuple(max(c[axis] for c in corners) for axis in range(3)))

    def frame_pose(self, frame: str) -> Transform:
        """Return the pose of a frame in the world: '' or world, an entity, or a robot link."""
        if frame in WORLD_FRAMES:
            return Transform()
        if frame in self._entities:
            return self.state(frame).pose
        try:
            link = self._physics.link_index(frame)
        except KeyError:
            raise KeyError(frame) from None
        if link == BASE_LINK_INDEX:
            return self.state(self.robot_name).pose
        state = pybullet.getLinkState(self._robot, link, computeForwardKinematics=True,
                                      physicsClientId=self._client)
        return Transform(tuple(state[LINK_FRAME_POSITION]), tuple(state[LINK_FRAME_ORIENTATION]))

    # --- changing -------------------------------------------------------------------------

    def set_state(self, name: str, state: EntityState) -> None:
        """Put the entity at ``state`` at once (pose and twist; a static one only moves).

        The pose is bounded and its quaternion normalised (:func:`checked_pose`),
        the twist bounded (:func:`check_twist`); else :class:`EntityStateError`
        and nothing changes.
        """
        entity = self._entities[name]
        pose = checked_pose(state.pose, lambda text: EntityStateError(text, invalid_pose=True))
        check_twist(state.linear, state.angular,
                    lambda text: EntityStateError(f"'{name}': {text}"))
        velocities = (*state.linear, *state.angular)
        if entity.static and any(velocities):
            raise EntityStateError(
                f"'{name}' is static ({entity.origin.value}): it can be moved, but not given "
                'a velocity')
        com = pose.then(entity.inertial)
        client = self._client
        pybullet.resetBasePositionAndOrientation(entity.body, com.translation, com.rotation,
                                                 physicsClientId=client)
        if not entity.static:
            offset = _minus(com.translation, pose.translation)
            linear = _plus(state.linear, _cross(state.angular, offset))
            pybullet.resetBaseVelocity(entity.body, linear, state.angular,
                                       physicsClientId=client)

    def set_info(self, name: str, info: EntityInfo) -> None:
        """Replace what GetEntityInfo tells about the entity."""
        self._entities[name].info = dataclasses.replace(info, tags=tuple(info.tags))

    def spawn(self, name: str = '', *, uri: str = '', resource_string: str = '',
              base_dir: pathlib.Path | None = None, pose: Transform = WORLD_ORIGIN,
              frame: str = '', allow_renaming: bool = False, namespace: str = '',
              description: str = '', tags: Sequence[str] = (),
              origin: Origin = Origin.SPAWNED) -> str:
        """Load a URDF object into the world; return its (possibly generated) name.

        Raises :class:`SpawnError` -- and changes nothing -- when the request
        cannot be honoured.  ``pose`` is given in ``frame`` ('' or ``world``,
        an entity's name, or a link of the robot).  :meth:`check_request`,
        :meth:`prepare` and :meth:`add` in one.
        """
        self.check_request(uri, resource_string, namespace, pose, frame)
        prepared = self.prepare(uri, resource_string, base_dir)
        return self.add(prepared, name, pose=pose, frame=frame, allow_renaming=allow_renaming,
                        namespace=namespace, description=description, tags=tags, origin=origin,
                        uri=uri)

    def check_request(self, uri: str, resource_string: str, namespace: str, pose: Transform,
                      frame: str) -> None:
        """Refuse (:class:`SpawnError`) a request naming nothing, or a bad namespace or pose."""
        if not uri and not resource_string:
            raise SpawnError(SpawnProblem.NO_RESOURCE, 'give a uri or a resource_string')
        if namespace and not naming.is_valid_namespace(namespace):
            raise SpawnError(SpawnProblem.NAMESPACE_INVALID,
                             f"'{namespace}' is not a valid ROS namespace "
                             f'({naming.NAMESPACE_RULE})')
        checked_pose(pose, lambda text: SpawnError(SpawnProblem.INVALID_POSE, text))
        self._reference(frame)

    def prepare(self, uri: str = '', resource_string: str = '',
                base_dir: pathlib.Path | None = None) -> PreparedObject:
        """Read, check (within :attr:`limits`) and try an object; :class:`SpawnError` if it fails.

        Touches neither the simulation's PyBullet client nor the records: any
        thread may call it, one call at a time.
        """
        try:
            resource = read_entity_resource(uri, resource_string, base_dir=base_dir,
                                            limits=self.limits)
        except EntityResourceError as err:
            raise SpawnError(_RESOURCE_PROBLEMS[err.problem], str(err)) from None
        try:  # a malformed plugin element refuses the object as it ends the robot's start-up
            create_plugins(resource.model)
        except DescriptionError as err:
            raise SpawnError(SpawnProblem.RESOURCE_PARSE_ERROR, str(err)) from None
        path = pathlib.Path(self._workdir.name, f'{next(self._files)}.urdf')
        path.write_text(resource.physics_urdf, encoding='utf-8')
        try:
            problem = self._trials.run(path, is_static(resource), resource.model)
        except BaseException:
            path.unlink(missing_ok=True)
            raise
        if problem:
            path.unlink(missing_ok=True)
            raise SpawnError(SpawnProblem.RESOURCE_PARSE_ERROR, f'{resource.source}: {problem}')
        return PreparedObject(resource, path)

    def add(self, prepared: PreparedObject, name: str = '', *, pose: Transform = WORLD_ORIGIN,
            frame: str = '', allow_renaming: bool = False, namespace: str = '',
            description: str = '', tags: Sequence[str] = (), origin: Origin = Origin.SPAWNED,
            uri: str = '') -> str:
        """Load a prepared object into the world (between two steps); return its name.

        The name and the pose are checked now, against the world as it is now;
        :class:`SpawnError` (nothing changed) if they cannot be honoured.
        ``uri`` only words the description.
        """
        resource = prepared.resource
        try:
            name = self._free_name(name or resource.name, allow_renaming)
            pose = checked_pose(pose, lambda text: SpawnError(SpawnProblem.INVALID_POSE, text))
            placed = checked_pose(self._reference(frame).then(pose),
                                  lambda text: SpawnError(SpawnProblem.INVALID_POSE, text))
            entity = self._load(resource, name, placed, origin, prepared.path)
        finally:
            prepared.path.unlink(missing_ok=True)
        entity.namespace = namespace
        entity.info.description = description or (
            f"'{resource.model.name}' from {uri}" if uri else
            f"'{resource.model.name}' from a resource string")
        entity.info.tags = tuple(tags)
        entity.initial_info = dataclasses.replace(entity.info)
        if origin is Origin.WORLD_FILE:
            self._world_file[name] = _WorldFileObject(resource, entity.initial_pose,
                                                      dataclasses.replace(entity.info))
        self._entities[name] = entity
        self._ensure_ground()
        return name

    def _reference(self, frame: str) -> Transform:
        try:
            return self.frame_pose(frame)
        except KeyError:
            raise SpawnError(SpawnProblem.INVALID_POSE,
                             f"unknown frame '{frame}' (use '' or 'world', an entity's name, or "
                             'a link of the robot)') from None

    def add_robot(self, name: str, physics: Physics, *, remove: Callable[[str], None]) -> None:
        """Record one more robot (its own ``physics``, a guest in this world) as an entity.

        Deleting it calls ``remove(name)``, which takes its body out of the world
        (with its plugins, controllers and topics).
        """
        self._entities[name] = self._record(
            name, physics.body_id, Origin.ROBOT, static=physics.fixed_base,
            info=EntityInfo(Category.ROBOT, 'a spawned robot'))
        self._robot_removers[name] = remove

    def let_delete(self, name: str, remove: Callable[[str], None]) -> None:
        """Let DeleteEntity take the first robot ``name`` away, through ``remove(name)``.

        ``remove`` takes its body out of the world (with its plugins, controllers
        and topics); the world stays.  Without this the first robot stays.
        """
        self._robot_removers[name] = remove

    def delete(self, name: str) -> None:
        """Remove a spawned (or world file) object or a spawned robot.

        KeyError if unknown; NotDeletableError for the scenery, and for the
        first robot unless :meth:`let_delete` allowed it.
        """
        entity = self._entities[name]
        remover = self._robot_removers.pop(name, None)
        if remover is not None:
            del self._entities[name]
            remover(name)
            if entity.body == self._robot:  # the first robot: its links are no frames now
                self._robot, self._grounded = -1, []
            return
        if entity.origin is Origin.ROBOT:
            raise NotDeletableError(
                f"'{name}' is the robot sim_node was started with (robot_description_file or "
                'the robot_description topic): it stays while sim_node runs; robots and '
                'objects spawned into the world can be deleted')
        if entity.origin is Origin.SCENERY:
            raise NotDeletableError(f"'{name}' is scenery: only spawned objects can be deleted")
        pybullet.removeBody(entity.body, physicsClientId=self._client)
        del self._entities[name]

    def delete_spawned(self) -> list[str]:
        """Remove every object spawned at run time (world-file objects stay); return their names."""
        names = [name for name, entity in self._entities.items()
                 if entity.origin is Origin.SPAWNED]
        for name in names:
            self.delete(name)
        return names

    def reset_state(self) -> None:
        """Put every entity back where it started (pose, joints), at rest."""
        for entity in self._entities.values():  # the robot's joints: the engine's business
            self._place(entity, entity.initial_pose)
            for index, position in enumerate(entity.initial_joints):
                pybullet.resetJointState(entity.body, index, position, targetVelocity=0.0,
                                         physicsClientId=self._client)

    def restore(self) -> None:
        """As if restarted: spawned objects gone, world-file objects back, all at their start."""
        self.delete_spawned()
        for entity in self._entities.values():
            entity.info = dataclasses.replace(entity.initial_info)
        for name, source in self._world_file.items():
            if name not in self._entities:
                entity = self._load(source.description, name, source.pose, Origin.WORLD_FILE)
                entity.info = dataclasses.replace(source.info)
                entity.initial_info = dataclasses.replace(source.info)
                self._entities[name] = entity
        self.reset_state()

    def close(self) -> None:
        """Remove the temporary files and the trial client (the bodies go with the simulation's)."""
        self._trials.close()
        self._workdir.cleanup()

    # --- inside ---------------------------------------------------------------------------

    def _check_name(self, name: str, allow_renaming: bool) -> None:
        if not _NAME.fullmatch(name) and not allow_renaming:
            raise SpawnError(SpawnProblem.NAME_INVALID,
                             f"'{name}' is not a valid entity name (no white space)")
        if name in self._entities and not allow_renaming:
            raise SpawnError(SpawnProblem.NAME_NOT_UNIQUE,
                             f"an entity called '{name}' exists (allow_renaming gives a new one)")

    def _free_name(self, wanted: str, allow_renaming: bool) -> str:
        if wanted and _NAME.fullmatch(wanted) and wanted not in self._entities:
            return wanted
        if not allow_renaming:
            if not wanted:
                raise SpawnError(SpawnProblem.NAME_INVALID,
                                 'no name given and the URDF has none (allow_renaming makes one)')
            self._check_name(wanted, allow_renaming)
        base = '_'.join(wanted.split()) or DEFAULT_NAME  # white space made underscores
        if base not in self._entities:
            return base
        number = 1
        while f'{base}_{number}' in self._entities:
            number += 1
        return f'{base}_{number}'

    def _load(self, resource: RobotDescription, name: str, pose: Transform,
              origin: Origin, path: pathlib.Path | None = None) -> Entity:
        """Load a checked and tried object (its URDF file at ``path``, else written now)."""
        if path is None:
            path = pathlib.Path(self._workdir.name, f'{next(self._files)}.urdf')
            path.write_text(resource.physics_urdf, encoding='utf-8')
        fixed = is_static(resource)
        client = self._client
        try:
            with quiet_native_output():
                body = pybullet.loadURDF(
                    str(path), pose.translation, pose.rotation, useFixedBase=fixed,
                    flags=pybullet.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
        except pybullet.error as err:
            raise SpawnError(SpawnProblem.RESOURCE_PARSE_ERROR,
                             f'{resource.source}: PyBullet cannot load it: {err}') from None
        finally:
            path.unlink(missing_ok=True)
        # No drag that neither the URDF nor Gazebo has (PyBullet's default 0.04), as
        # for the robot (sim/physics.py).
        pybullet.changeDynamics(body, BASE_LINK_INDEX, linearDamping=0.0, angularDamping=0.0,
                                physicsClientId=client)
        links = link_indices(body, client)
        for index in links.values():
            # Static friction holds a contact where it is (PyBullet's friction anchor):
            # without it an object held between fingers creeps down, step after step.
            pybullet.changeDynamics(body, index, frictionAnchor=1, physicsClientId=client)
        apply_surface_friction(body, links, resource.model.link_frictions, client)
        joints = pybullet.getNumJoints(body, physicsClientId=client)
        names = [pybullet.getJointInfo(body, index, physicsClientId=client)[1].decode()
                 for index in range(joints)]
        balls = free_ball_joints(body, client)
        single = [index for index in range(joints) if index not in balls]
        if single:
            friction = {joint.name: joint.friction for joint in resource.joints}
            pybullet.setJointMotorControlArray(
                body, single, pybullet.VELOCITY_CONTROL,
                targetVelocities=[0.0] * len(single),
                forces=[friction.get(names[index], 0.0) for index in single],
                physicsClientId=client)
        static = fixed or pybullet.getDynamicsInfo(
            body, BASE_LINK_INDEX, physicsClientId=client)[DYNAMICS_MASS] == 0.0
        category = Category.STATIC_OBJECT if static else Category.DYNAMIC_OBJECT
        entity = self._record(name, body, origin, static=static, info=EntityInfo(category))
        entity.description = resource
        entity.joint_names = tuple(names)
        return entity

    def _record(self, name: str, body: int, origin: Origin, *, static: bool,
                info: EntityInfo) -> Entity:
        client = self._client
        dynamics = pybullet.getDynamicsInfo(body, BASE_LINK_INDEX, physicsClientId=client)
        rotation = tuple(dynamics[DYNAMICS_INERTIAL_ORIENTATION])
        if abs(sum(q * q for q in rotation) - 1.0) > NORM_TOLERANCE:
            # A maximal-coordinates body (the targets) reports no inertial frame
            # (a zero quaternion, or memory garbage): its base frame is its own.
            inertial = Transform()
        else:
            inertial = Transform(tuple(dynamics[DYNAMICS_INERTIAL_POSITION]), rotation)
        joints = pybullet.getNumJoints(body, physicsClientId=client)
        initial_joints = tuple(state[STATE_POSITION] for state in pybullet.getJointStates(
            body, list(range(joints)), physicsClientId=client)) if joints else ()
        com_position, com_orientation = pybullet.getBasePositionAndOrientation(
            body, physicsClientId=client)
        pose = _pose_of_link(Transform(tuple(com_position), tuple(com_orientation)), inertial)
        return Entity(name, body, origin, static, info, pose, inertial=inertial,
                      initial_joints=initial_joints if origin is not Origin.ROBOT else ())

    def _place(self, entity: Entity, pose: Transform) -> None:
        com = pose.then(entity.inertial)
        pybullet.resetBasePositionAndOrientation(entity.body, com.translation, com.rotation,
                                                 physicsClientId=self._client)
        if not entity.static:
            pybullet.resetBaseVelocity(entity.body, ZERO_VECTOR, ZERO_VECTOR,
                                       physicsClientId=self._client)

    def _ensure_ground(self) -> None:
        if self._ground_wanted and self._ground is None:
            self._ground = add_ground_plane(self._client, self._robot, self._grounded)


@dataclasses.dataclass(frozen=True)
class _WorldFileObject:
    """A world-file object as a full reset spawns it again."""

    description: RobotDescription
    pose: Transform
    info: EntityInfo


def spawn_world_objects(entities: Entities, world: World) -> list[str]:
    """Spawn the objects a world file lists; return their names.

    A problem ends start-up: :class:`~pan_tilt_sim.model.world_file.WorldFileError`
    naming the file, the entry and what is wrong.
    """
    names = []
    for index, spec in enumerate(world.entities):
        try:
            names.append(entities.spawn(
                spec.name, uri=spec.uri, resource_string=spec.resource_string,
                base_dir=world.base_dir, pose=Transform(spec.position, spec.orientation),
                description=spec.description, tags=spec.tags, origin=Origin.WORLD_FILE))
        except SpawnError as err:
            label = f" ('{spec.name}')" if spec.name else ''
            raise WorldFileError(f'{world.source}: entities[{index}]{label}: {err}') from None
    return names


def checked_pose(pose: Transform, error: Callable[[str], Exception]) -> Transform:
    """Return ``pose`` with its quaternion normalised, or raise ``error(text)`` saying why not.

    A pose must be finite numbers, each coordinate within ±:data:`MAX_POSITION_M`,
    and its quaternion of length >= :data:`NORM_TOLERANCE` (any finite length
    above it is normalised, 1e300 included: the length is computed without
    overflow).
    """
    values = (*pose.translation, *pose.rotation)
    if not all(math.isfinite(v) for v in values):
        raise error('the pose must be finite numbers')
    if any(abs(v) > MAX_POSITION_M for v in pose.translation):
        raise error(f'the position must lie within ±{MAX_POSITION_M:g} m of the world origin '
                    f'on each axis, got {tuple(pose.translation)}')
    norm = math.hypot(*pose.rotation)
    if norm < NORM_TOLERANCE:
        raise error('the orientation is a quaternion of length 0')
    return Transform(tuple(pose.translation),  # type: ignore[arg-type]
                     tuple(q / norm for q in pose.rotation))  # type: ignore[arg-type]


def check_twist(linear: Sequence[float], angular: Sequence[float],
                error: Callable[[str], Exception]) -> None:
    """Raise ``error(text)`` unless both velocities are finite and within their bounds.

    Linear: length <= :data:`MAX_LINEAR_SPEED` m/s; angular: length <=
    :data:`MAX_ANGULAR_SPEED` rad/s.
    """
    if not all(math.isfinite(v) for v in (*linear, *angular)):
        raise error('the twist must be finite numbers')
    for what, vector, bound, unit in (('linear', linear, MAX_LINEAR_SPEED, 'm/s'),
                                      ('angular', angular, MAX_ANGULAR_SPEED, 'rad/s')):
        if math.hypot(*vector) > bound:
            raise error(f'the {what} velocity must be at most {bound:g} {unit} long, got '
                        f'{tuple(vector)}')


def _inverse(pose: Transform) -> Transform:
    x, y, z, w = pose.rotation
    conjugate = (-x, -y, -z, w)
    rotated = Transform((0.0, 0.0, 0.0), conjugate).apply(pose.translation)
    return Transform((-rotated[0], -rotated[1], -rotated[2]), conjugate)


def _pose_of_link(com: Transform, inertial: Transform) -> Transform:
    """Return the root link frame from PyBullet's base (centre of mass) frame."""
    if inertial.translation == ZERO_VECTOR and inertial.rotation == IDENTITY_ROTATION:
        return com
    return com.then(_inverse(inertial))


def _plus(a: Sequence[float], b: Sequence[float]) -> Vector:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _minus(a: Sequence[float], b: Sequence[float]) -> Vector:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _cross(a: Sequence[float], b: Sequence[float]) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
