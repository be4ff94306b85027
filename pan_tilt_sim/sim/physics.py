"""The physics layer: one PyBullet client, one robot, joints driven by effort or by a motor.

:class:`Physics` owns its own PyBullet client id (never the global default
client), so several simulations can live in one process.  The robot is
loaded with the URDF's inertia (links without ``<inertial>`` come massless,
see :mod:`pan_tilt_sim.model.inertials`); what PyBullet says while loading
goes to the log, one line per message.  What it builds is decided beforehand,
in a :mod:`~pan_tilt_sim.model.physics_plan`.

Design notes: docs/design/sim.md#physicspy.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import pathlib
import tempfile
import weakref
from collections.abc import Callable, Collection, Mapping, Sequence

import numpy

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.base_pose import ORIGIN, BasePose
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.model.physics_plan import BasePlacement, LinkSurface, PhysicsPlan, plan_physics
from pan_tilt_sim.model.physics_settings import DEFAULT_PHYSICS, PhysicsSettings
from pan_tilt_sim.model.robot import JointSpec
from pan_tilt_sim.model.surfaces import Surface
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.sim import compiled_step
from pan_tilt_sim.sim.bullet import (
    captured_native_output,
    message_lines,
    pybullet,
    quiet_native_output,
)
from pan_tilt_sim.sim.world import add_ground_plane

STANDARD_GRAVITY = 9.81  # m/s^2, along -z as in Gazebo's default world
URDF_FILE_NAME = 'robot.urdf'
# Index of the position, velocity and applied motor torque in one entry of
# pybullet.getJointStates.
STATE_POSITION = 0
STATE_VELOCITY = 1
STATE_MOTOR_TORQUE = 3
# Gear constraints of mimic joints: force bound high enough to be rigid, and
# the share of the position error corrected per step (1 would be all at once).
MIMIC_MAX_FORCE = 1e9
MIMIC_ERROR_REDUCTION = 0.8
BASE_LINK_INDEX = -1  # PyBullet's index of a body's base link
# A motor force "without limit" (N*m or N): PyBullet needs a finite number.
UNLIMITED_FORCE = 1e9
# How often the joints' effective inertias are recomputed for the damping
# (they change with the pose of an arm), in physics steps.
INERTIA_REFRESH_STEPS = 100
# PyBullet's explicit damping is kept where damping * time_step is at most this
# share of the joint's smallest effective inertia (it diverges at 2).
EXPLICIT_DAMPING_SHARE = 0.1
BALL_DOFS = 3  # a spherical joint's velocity columns
NO_MOTOR = 0.0  # force 0 removes a joint's motor row from PyBullet's solver
MOTOR_VELOCITY_GAIN = 1.0  # a velocity motor that reaches its target in one step if it can
# A free base's six degrees of freedom come first in PyBullet's mass matrix.
FREE_BASE_DOFS = 6
# Where a free base is held while its lowest point is measured: high above any ground (m).
MEASURING_HEIGHT = 100.0
# How far below that the closest-point query looks for the ground (m).
MEASURING_RANGE = 2.0 * MEASURING_HEIGHT
CLOSEST_DISTANCE = 8  # index of the distance in one of pybullet.getClosestPoints' points
CONTACT_LINK_A = 3  # index of body A's link in one of pybullet.getContactPoints' points
DYNAMICS_INERTIAL_POSITION = 3  # pybullet.getDynamicsInfo: the centre of mass in the link frame
DYNAMICS_INERTIAL_ORIENTATION = 4

LogFunction = Callable[[str], None]


def _disconnect(client: int, connections: list[compiled_step.Connection]) -> None:
    for connection in connections:  # before the client, which they point into, goes
        connection.close()
    with contextlib.suppress(pybullet.error):
        pybullet.disconnect(physicsClientId=client)


def _ignore(message: str) -> None:
    """Drop ``message`` (the default log function)."""


def free_ball_joints(body: int, client: int) -> list[int]:
    """Take the motor PyBullet puts on each ball joint of ``body``; return their indices.

    PyBullet holds a spherical joint at its start with a motor (as it does a
    revolute one); a ball joint turns freely, as SDF's and Gazebo's does.
    """
    found = []
    for index in range(pybullet.getNumJoints(body, physicsClientId=client)):
        if pybullet.getJointInfo(body, index, physicsClientId=client)[2] != (
                pybullet.JOINT_SPHERICAL):
            continue
        pybullet.setJointMotorControlMultiDof(
            body, index, pybullet.POSITION_CONTROL, targetPosition=[0.0, 0.0, 0.0, 1.0],
            targetVelocity=[0.0, 0.0, 0.0], positionGain=0.0, velocityGain=0.0,
            force=[0.0, 0.0, 0.0], physicsClientId=client)
        found.append(index)
    return found


def link_indices(body: int, client: int) -> dict[str, int]:
    """Return PyBullet's index of every link of ``body``, by URDF name (the base: -1)."""
    base = pybullet.getBodyInfo(body, physicsClientId=client)[0].decode('utf-8')
    links = {base: BASE_LINK_INDEX}
    for index in range(pybullet.getNumJoints(body, physicsClientId=client)):
        info = pybullet.getJointInfo(body, index, physicsClientId=client)
        links[info[12].decode('utf-8')] = index  # a joint's child link has its index
    return links


def apply_surface_friction(body: int, links: Mapping[str, int],
                           frictions: Mapping[str, Surface], client: int) -> None:
    """Give the links of ``body`` (indices by name) their friction (see the module)."""
    for name, friction in frictions.items():
        if name in links:  # a link merged away by a fixed joint has no body of its own
            pybullet.changeDynamics(body, links[name],
                                    lateralFriction=friction.friction,
                                    physicsClientId=client)


def apply_link_surfaces(body: int, links: Mapping[str, int], surfaces: Sequence[LinkSurface],
                        client: int) -> None:
    """Give the links of ``body`` (indices by name) their friction and contact spring."""
    for surface in surfaces:
        if surface.link not in links:  # a link merged away by a fixed joint has no body
            continue
        if surface.spring is None:
            pybullet.changeDynamics(body, links[surface.link], lateralFriction=surface.friction,
                                    physicsClientId=client)
        else:
            stiffness, damping = surface.spring
            pybullet.changeDynamics(body, links[surface.link], lateralFriction=surface.friction,
                                    contactStiffness=stiffness, contactDamping=damping,
                                    physicsClientId=client)


def engine_parameters(settings: PhysicsSettings) -> dict[str, float | int]:
    """Return ``settings`` as ``pybullet.setPhysicsEngineParameter``'s keyword arguments."""
    return {'numSolverIterations': settings.solver_iterations, 'erp': settings.erp,
            'contactERP': settings.contact_erp, 'globalCFM': settings.cfm,
            'contactSlop': settings.contact_slop,
            'useSplitImpulse': int(settings.split_impulse)}


class Physics:
    """A PyBullet world holding one robot, its base welded to the world or free.

    Built from a :class:`~pan_tilt_sim.model.physics_plan.PhysicsPlan`, which
    decides everything about the model; the constructor makes one from
    ``description`` (:func:`~pan_tilt_sim.model.physics_plan.plan_physics`),
    :meth:`from_plan` takes one made already.
    ``initial_positions`` (one per actuated joint; default: each joint's
    :attr:`~pan_tilt_sim.model.robot.JointSpec.initial_position`) is where
    the joints start and where :meth:`reset_joints` without arguments puts
    them.  ``fixed_base`` welds the root link to the world; ``initial_pose``
    places the base (see the module's design notes).  ``warn`` receives
    PyBullet's load messages, one line each.

    With ``world`` (another robot's Physics) the robot is a guest in that
    robot's client: it owns its body, not the client, and its steps only
    apply its torques and motors -- the host's step advances the world, and
    :meth:`take_states` reads the guest's joints after it (and what its
    implicit damping rows felt).
    """

    def __init__(self, description: RobotDescription, time_step: float, *,
                 gui: bool = False, initial_positions: Sequence[float] | None = None,
                 warn: LogFunction = _ignore, fixed_base: bool = True,
                 initial_pose: BasePose = ORIGIN,
                 settings: PhysicsSettings = DEFAULT_PHYSICS,
                 world: Physics | None = None) -> None:
        self._build(plan_physics(description, fixed_base=fixed_base,
                                 initial_positions=initial_positions, initial_pose=initial_pose),
                    time_step, gui=gui, warn=warn, settings=settings, world=world)

    @classmethod
    def from_plan(cls, plan: PhysicsPlan, time_step: float, *, gui: bool = False,
                  warn: LogFunction = _ignore, settings: PhysicsSettings = DEFAULT_PHYSICS,
                  world: Physics | None = None) -> Physics:
        """Build the physics of ``plan`` (:func:`~pan_tilt_sim.model.physics_plan.plan_physics`)."""
        physics = cls.__new__(cls)
        physics._build(plan, time_step, gui=gui, warn=warn, settings=settings, world=world)
        return physics

    def _build(self, plan: PhysicsPlan, time_step: float, *, gui: bool, warn: LogFunction,
               settings: PhysicsSettings, world: Physics | None) -> None:
        """Build ``plan`` in PyBullet, in one pass: PyBullet calls only, no model decisions."""
        self._plan = plan
        self._time_step = time_step
        self._fixed_base = plan.fixed_base
        self._joints = plan.joints
        self._initial_positions = list(plan.initial_positions)
        self.velocity_cap = plan.velocity_cap
        self._workdir = tempfile.TemporaryDirectory(prefix='pan_tilt_sim_')
        self.is_guest = world is not None
        self._compiled: list[compiled_step.Connection] = []
        if world is not None:
            self._client = world.client_id
            self._disconnect = self._remove_body
            self._body = -1
            self._settings = world.settings
        else:
            mode = pybullet.GUI if gui else pybullet.DIRECT
            with quiet_native_output():
                self._client = pybullet.connect(mode)
            if self._client < 0:
                self._workdir.cleanup()
                raise DescriptionError('PyBullet: cannot connect a physics client')
            # Disconnects even if nobody calls close(): an owner abandoned half-built
            # (a signal during start-up) or left behind at interpreter exit.
            self._disconnect = weakref.finalize(self, _disconnect, self._client, self._compiled)
            # The world's solver settings are the first robot's: a guest leaves them.
            self.apply_settings(settings)
        # A guest's joint states after the last world step (see take_states).
        self._after_step: list = [()]
        try:
            self._body = self._load(plan, warn)
            connection = None if world is not None else compiled_step.connect(self._client)
            if connection is not None:
                self._compiled.append(connection)
        except BaseException:
            self.close()
            raise
        index_of, self._link_indices, self._dof_indices = self._joint_and_link_indices()
        self._indices = [index_of[joint.name] for joint in self._joints]
        self._remove_hidden_damping()
        self._balls = free_ball_joints(self._body, self._client)
        apply_link_surfaces(self._body, self._link_indices, plan.surfaces, self._client)
        self._couple_mimic_joints(index_of)
        self._drives = _Drives(self, [False] * len(self._joints), self._indices, plan.coupled)
        self.reset_joints()
        dynamics = pybullet.getDynamicsInfo(self._body, BASE_LINK_INDEX,
                                            physicsClientId=self._client)
        # PyBullet places a body by its base's centre of mass; the URDF frame is offset by this.
        self._base_inertial = Transform(tuple(dynamics[DYNAMICS_INERTIAL_POSITION]),
                                        tuple(dynamics[DYNAMICS_INERTIAL_ORIENTATION]))
        # A free robot stands on the ground from the start, every link touching it; the
        # ground's friction 1 leaves each link its own coefficient (PyBullet multiplies them).
        self.ground: int | None = None
        if plan.base.on_ground:
            self.ground = (world.ground if world is not None and world.ground is not None
                           else add_ground_plane(self._client, self._body, []))
        self._initial_base = self._place_base(plan.base)

    @property
    def plan(self) -> PhysicsPlan:
        """What this physics was built from."""
        return self._plan

    @property
    def fixed_base(self) -> bool:
        """Whether the root link is welded to the world (else the robot is free on the ground)."""
        return self._fixed_base

    @property
    def initial_base_frame(self) -> Transform:
        """Where the root link frame starts and where :meth:`reset_base` puts it (world frame)."""
        return self._initial_base

    def base_frame(self) -> Transform:
        """Return the root link frame's pose in the world now."""
        position, orientation = pybullet.getBasePositionAndOrientation(
            self._body, physicsClientId=self._client)
        return Transform(tuple(position), tuple(orientation)).then(
            _inverse(self._base_inertial))

    def base_velocity(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """Return the root link's centre-of-mass velocity (m/s) and angular velocity (rad/s).

        Both in world axes; zero for a welded base.
        """
        linear, angular = pybullet.getBaseVelocity(self._body, physicsClientId=self._client)
        return tuple(linear), tuple(angular)  # type: ignore[return-value]

    def set_base_velocity(self, linear: Sequence[float], angular: Sequence[float]) -> None:
        """Set the free base's velocity: ``linear`` (m/s) and ``angular`` (rad/s), world axes.

        What Gazebo's Model::SetLinearVel and SetAngularVel do for a model
        plugin (planar move); a welded base does not move.
        """
        if not self._fixed_base:
            pybullet.resetBaseVelocity(self._body, tuple(linear), tuple(angular),
                                       physicsClientId=self._client)

    def reset_base(self) -> None:
        """Put the base back where it started, at rest (a welded base only moves)."""
        self._set_base_frame(self._initial_base)

    def _set_base_frame(self, frame: Transform) -> None:
        com = frame.then(self._base_inertial)
        pybullet.resetBasePositionAndOrientation(self._body, com.translation, com.rotation,
                                                 physicsClientId=self._client)
        if not self._fixed_base:
            pybullet.resetBaseVelocity(self._body, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0),
                                       physicsClientId=self._client)

    def _place_base(self, placement: BasePlacement) -> Transform:
        """Put the base where ``placement`` says (a free one resting on the ground); return it."""
        frame = placement.frame
        if not placement.on_ground:
            if placement.as_loaded:
                return self.base_frame()
            self._set_base_frame(frame)
            return frame
        # Held high above the ground plane, the closest points between them give the
        # height of the robot's lowest collision point (meshes included).
        x, y, clearance = frame.translation
        lifted = Transform((x, y, MEASURING_HEIGHT), frame.rotation)
        self._set_base_frame(lifted)
        points = pybullet.getClosestPoints(self._body, self.ground, MEASURING_RANGE,
                                           physicsClientId=self._client)
        lowest = min((point[CLOSEST_DISTANCE] for point in points), default=MEASURING_HEIGHT)
        frame = Transform((x, y, MEASURING_HEIGHT - lowest + clearance), frame.rotation)
        self._set_base_frame(frame)
        return frame

    @property
    def client_id(self) -> int:
        """The PyBullet client id this object owns."""
        return self._client

    @property
    def body_id(self) -> int:
        """The PyBullet body id of the robot."""
        return self._body

    @property
    def time_step(self) -> float:
        """Seconds of simulated time per :meth:`step`."""
        return self._time_step

    @property
    def joints(self) -> tuple[JointSpec, ...]:
        """The actuated joints, in the order of every array this class takes or gives."""
        return self._joints

    @property
    def initial_positions(self) -> list[float]:
        """Where each joint starts (mimic joints where their leaders put them)."""
        return list(self._initial_positions)

    def joint_index(self, name: str) -> int:
        """PyBullet's index of the joint called ``name``."""
        return self._indices[[joint.name for joint in self._joints].index(name)]

    def link_index(self, name: str) -> int:
        """PyBullet's index of the link called ``name`` (-1: the base); KeyError if none."""
        return self._link_indices[name]

    def links_on_ground(self) -> tuple[str, ...]:
        """Return the robot's links touching the ground plane now, in link order (none: welded).

        From the contacts of the last step: what a free base stands or lies on.
        """
        if self.ground is None:
            return ()
        touching = {contact[CONTACT_LINK_A] for contact in pybullet.getContactPoints(
            bodyA=self._body, bodyB=self.ground, physicsClientId=self._client)}
        return tuple(name for name, index in sorted(self._link_indices.items(),
                                                    key=lambda item: item[1])
                     if index in touching)

    @property
    def compiled_step(self) -> bool:
        """Whether each step's PyBullet calls are made from C (:mod:`.compiled_step`)."""
        return bool(self._compiled)

    def effort_stepper(self, effort_indices: Sequence[int], motor_indices: Sequence[int] = ()
                       ) -> Callable[[Sequence[float]], Sequence]:
        """Return ``step(efforts)``: torques on the joints at ``effort_indices``, a step, states.

        The states are :meth:`read_states`'s.  The function is compiled
        where :attr:`compiled_step` says so, else three PyBullet calls; both
        send PyBullet the same commands.  The compiled one also has
        ``drive(efforts, targets, forces, gains)``: the velocity motors of the
        joints at ``motor_indices`` first (as ``setJointMotorControlArray``
        in ``VELOCITY_CONTROL``), then the same.
        """
        body, client, indices = self._body, self._client, self._indices
        if self.is_guest:
            torques, torque_control = pybullet.setJointMotorControlArray, pybullet.TORQUE_CONTROL
            guest_indices = list(effort_indices)
            zeros = [0.0] * len(guest_indices)
            after_step = self._after_step

            def guest_step(efforts: Sequence[float]) -> Sequence:
                if guest_indices:
                    torques(body, guest_indices, torque_control, zeros, zeros, efforts, zeros,
                            zeros, client)
                return after_step[0]
            return guest_step
        if self._compiled:
            def dofs(joints: Sequence[int]) -> list[int]:
                # uIndex, as setJointMotorControlArray takes it
                return [pybullet.getJointInfo(body, index, physicsClientId=client)[4]
                        for index in joints]
            return self._compiled[0].stepper(body, indices, dofs(effort_indices),
                                             dofs(motor_indices))
        set_motors, torque_mode = pybullet.setJointMotorControlArray, pybullet.TORQUE_CONTROL
        step_simulation, get_states = pybullet.stepSimulation, pybullet.getJointStates
        effort_indices = list(effort_indices)
        unused = [0.0] * len(effort_indices)

        def step(efforts: Sequence[float]) -> Sequence:
            if effort_indices:
                set_motors(body, effort_indices, torque_mode, unused, unused, efforts, unused,
                           unused, client)
            step_simulation(client)
            return get_states(body, indices, client)
        return step

    def law_runner(self) -> Callable[..., tuple] | None:
        """Return the compiled loop of controller laws for the present drives, or None.

        ``run(steps, dt, efforts, laws, states) -> (before_last, last)`` runs
        ``steps`` steps in C, each law being ``(effort slot, state slot,
        row)`` with the row of :mod:`pan_tilt_sim.controllers.toolbox.step_law`; see
        ``_compiled_step.c``.  None without the compiled step, or when a step
        sends PyBullet more than the efforts (velocity motors, implicit
        damping): those steps stay in Python.  Valid until the next
        :meth:`set_drives`.
        """
        return self._drives.run_laws

    def read_states(self) -> list:
        """``pybullet.getJointStates`` for the actuated joints: (position, velocity, ...)."""
        return pybullet.getJointStates(self._body, self._indices, self._client)

    def take_states(self) -> list:
        """Read a guest's joint states after the world stepped (its next step returns them)."""
        states = self._after_step[0] = pybullet.getJointStates(self._body, self._indices,
                                                               self._client)
        self._drives.settle(states)
        return states

    def _remove_body(self) -> None:
        """Take a guest's body out of the world it shares (its close; the world stays)."""
        if self._body >= 0:
            pybullet.removeBody(self._body, physicsClientId=self._client)
            self._body = -1

    def remove_robot(self) -> None:
        """Take the robot's body out of a world it hosts; the client and its bodies stay.

        The world goes on without it (its guests, the objects, the ground):
        afterwards the robot has no joints and no links, and only
        :meth:`bare_stepper` steps.  A guest leaves through :meth:`close`.
        """
        if self.is_guest or self._body < 0:
            return
        pybullet.removeBody(self._body, physicsClientId=self._client)
        self._body = -1
        self._joints = ()
        self._indices, self._balls, self._initial_positions = [], [], []
        self._link_indices, self._dof_indices = {}, {}

    @property
    def implicit_damping(self) -> tuple[str, ...]:
        """The effort-driven joints whose URDF damping is applied implicitly (see the module)."""
        drives = self._drives
        return tuple(self._joints[k].name for k in sorted(drives.implicit + drives.damped))

    def set_drives(self, velocity_driven: Sequence[bool]) -> None:
        """Say which joints a velocity motor drives (True) and which take efforts (False).

        Arrays given to :meth:`step` and the stepper follow this split: the
        efforts of the effort-driven joints and the velocity targets of the
        velocity-driven ones, each in joint order.
        """
        self._drives = _Drives(self, velocity_driven, self._indices, self._plan.coupled)

    def step(self, efforts: Sequence[float], targets: Sequence[float] = (),
             forces: Sequence[float] | None = None) -> list:
        """Apply ``efforts`` and velocity ``targets``, advance one time step, return the states.

        ``forces``: the most each velocity motor may apply (N*m or N, in the
        targets' order, each at most :data:`UNLIMITED_FORCE`); None keeps
        those of the previous step -- at first the joints' effort limits.
        """
        drives = self._drives
        if len(efforts) != len(drives.effort_slots) or len(targets) != len(
                drives.velocity_slots) or (forces is not None and len(forces) != len(targets)):
            raise ValueError(
                f'{len(efforts)} efforts, {len(targets)} targets and '
                f'{"no" if forces is None else len(forces)} forces for '
                f'{len(drives.effort_slots)} effort- and {len(drives.velocity_slots)} '
                'velocity-driven joints')
        return drives.step(efforts, targets, forces)

    def stepper(self) -> Callable[..., list]:
        """Return a function doing what :meth:`step` does, with every argument pre-bound.

        For hot loops: the function reads nothing from ``self``.  It stays
        valid until the next :meth:`set_drives`.
        """
        return self._drives.step

    def bare_stepper(self) -> Callable[[], None]:
        """Return ``stepSimulation`` bound to this client: a step that applies no efforts.

        For measuring PyBullet alone (the benchmark's raw figure).
        """
        step_simulation, client = pybullet.stepSimulation, self._client

        def step() -> None:
            step_simulation(client)
        return step

    def reset_joints(self, positions: Sequence[float] | None = None) -> None:
        """Put every actuated joint at ``positions`` (default: the initial ones), at rest.

        Mimic joints go where their leaders put them.
        """
        positions = self._initial_positions if positions is None else self._plan.with_mimics(
            positions)
        for index, position in zip(self._indices, positions, strict=True):
            pybullet.resetJointState(
                self._body, index, position, targetVelocity=0.0, physicsClientId=self._client)
        for index in self._balls:  # ball joints back to their mounting, at rest
            pybullet.resetJointStateMultiDof(self._body, index, [0.0, 0.0, 0.0, 1.0],
                                             [0.0, 0.0, 0.0], physicsClientId=self._client)
        self._drives.restart()

    def trial(self, steps: int) -> tuple[int, list] | None:
        """Step ``steps`` times with no effort applied, then put everything back as it was.

        Return the number of steps taken and the states (as :meth:`read_states`)
        at the first step that left a joint with a non-finite position or
        velocity; None if no step did.  The joints' motors stay as they are
        (URDF friction, no effort); PyBullet's saveState and restoreState put
        the world back, so what follows runs as if there had been no trial.
        """
        client, body, indices = self._client, self._body, self._indices
        saved = pybullet.saveState(physicsClientId=client)
        try:
            for count in range(1, steps + 1):
                pybullet.stepSimulation(physicsClientId=client)
                states = pybullet.getJointStates(body, indices, physicsClientId=client)
                if not all(math.isfinite(state[STATE_POSITION])
                           and math.isfinite(state[STATE_VELOCITY]) for state in states):
                    return count, list(states)
            return None
        finally:
            pybullet.restoreState(stateId=saved, physicsClientId=client)
            pybullet.removeState(saved, physicsClientId=client)

    def effective_inertias(self, positions: Sequence[float] | None = None) -> list[float]:
        """Return each joint's effective inertia at ``positions`` (default: as it is now).

        ``1 / (M^-1)_ii`` (kg m^2, or kg for a prismatic joint): what a force
        on joint i alone has to accelerate while the other joints move freely
        -- the inertia that explicit damping and PID gains must respect.
        """
        if positions is None:
            positions = [state[STATE_POSITION] for state in self.read_states()]
        dofs = [0.0] * self._dof_count
        for index, position in zip(self._indices, positions, strict=True):
            dofs[self._dof_indices[index]] = position
        matrix = numpy.array(pybullet.calculateMassMatrix(
            self._body, dofs, physicsClientId=self._client))
        try:
            diagonal = numpy.diag(numpy.linalg.inv(matrix))
            inertias = [1.0 / value if value > 0.0 else 0.0 for value in diagonal]
        except numpy.linalg.LinAlgError:  # a massless subtree: the locked diagonal at least
            inertias = list(numpy.diag(matrix))
        # A free base's rows come first: what a joint moves then includes the base's give.
        first = 0 if self._fixed_base else FREE_BASE_DOFS
        return [float(inertias[first + self._dof_indices[index]]) for index in self._indices]

    def smallest_inertias(self) -> list[float]:
        """Return each joint's smallest effective inertia over the plan's inertia poses.

        (:func:`~pan_tilt_sim.model.physics_plan.check_poses`.)
        """
        inertias = [self.effective_inertias(pose) for pose in self._plan.inertia_poses]
        return [min(values) for values in zip(*inertias, strict=True)]

    def gravity_torques(self, positions: Sequence[float] | None = None) -> list[float]:
        """Return the effort each joint needs to hold still against gravity at ``positions``.

        Zero for every joint of a free robot: PyBullet's inverse dynamics takes
        only a welded base, and on the ground the base itself is not held.
        """
        if not self._fixed_base:
            return [0.0] * len(self._indices)
        if positions is None:
            positions = [state[STATE_POSITION] for state in self.read_states()]
        dofs = [0.0] * self._dof_count
        for index, position in zip(self._indices, positions, strict=True):
            dofs[self._dof_indices[index]] = position
        zeros = [0.0] * len(dofs)
        try:
            torques = pybullet.calculateInverseDynamics(
                self._body, dofs, zeros, zeros, physicsClientId=self._client)
        except pybullet.error:
            return [0.0] * len(self._indices)
        return [torques[self._dof_indices[index]] for index in self._indices]

    @property
    def settings(self) -> PhysicsSettings:
        """The solver settings in force (see :mod:`pan_tilt_sim.model.physics_settings`)."""
        return self._settings

    def apply_settings(self, settings: PhysicsSettings) -> None:
        """Give PyBullet's constraint solver ``settings`` (checked already), from the next step."""
        pybullet.setPhysicsEngineParameter(**engine_parameters(settings),
                                           physicsClientId=self._client)
        self._settings = settings

    def close(self) -> None:
        """Disconnect the PyBullet client and remove temporary files (idempotent)."""
        if self._client >= 0:
            self._disconnect()
            self._client = -1
        self._workdir.cleanup()

    def __enter__(self) -> Physics:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def _load(self, plan: PhysicsPlan, warn: LogFunction) -> int:
        client = self._client
        pybullet.setGravity(0.0, 0.0, -STANDARD_GRAVITY, physicsClientId=client)
        pybullet.setTimeStep(self._time_step, physicsClientId=client)
        urdf_path = pathlib.Path(self._workdir.name) / URDF_FILE_NAME
        urdf_path.write_text(plan.urdf, encoding='utf-8')
        output: list[str] = []
        try:
            with captured_native_output(output):
                flags = pybullet.URDF_USE_INERTIA_FROM_FILE
                if plan.implicit_cylinders:
                    flags |= pybullet.URDF_USE_IMPLICIT_CYLINDER
                body = pybullet.loadURDF(
                    str(urdf_path), useFixedBase=plan.fixed_base, flags=flags,
                    physicsClientId=client)
        except pybullet.error as err:
            reasons = '; '.join(message_lines(''.join(output)))
            because = f' ({reasons})' if reasons else ''
            raise DescriptionError(
                f'{plan.source}: PyBullet cannot load the robot: {err}{because}') from None
        for line in message_lines(''.join(output)):
            warn(f'PyBullet, loading {plan.source.name}: {line}')
        return body

    def _joint_and_link_indices(self) -> tuple[dict[str, int], dict[str, int], dict[int, int]]:
        client = self._client
        base = pybullet.getBodyInfo(self._body, physicsClientId=client)[0].decode('utf-8')
        joints, links, dofs = {}, {base: BASE_LINK_INDEX}, {}
        self._dof_count = 0
        for index in range(pybullet.getNumJoints(self._body, physicsClientId=client)):
            info = pybullet.getJointInfo(self._body, index, physicsClientId=client)
            joints[info[1].decode('utf-8')] = index
            links[info[12].decode('utf-8')] = index  # a joint's child link has its index
            if info[3] >= 0:  # qIndex: the joint has a degree of freedom
                dofs[index] = self._dof_count
                # uIndex columns: a ball joint (SDF's, PyBullet's spherical) turns in three.
                self._dof_count += BALL_DOFS if info[2] == pybullet.JOINT_SPHERICAL else 1
        return joints, links, dofs

    def _remove_hidden_damping(self) -> None:
        client, body = self._client, self._body
        # PyBullet's per-body drag, and its explicit joint damping (applied
        # implicitly by _Drives instead); the speed cap raised.
        pybullet.changeDynamics(body, BASE_LINK_INDEX, linearDamping=0.0, angularDamping=0.0,
                                maxJointVelocity=self.velocity_cap, physicsClientId=client)
        for index in self._indices:
            pybullet.changeDynamics(body, index, jointDamping=0.0, physicsClientId=client)

    def _couple_mimic_joints(self, index_of: dict[str, int]) -> None:
        # A gear constraint keeps q_follower - multiplier * q_leader at offset.
        for coupling in self._plan.mimics:
            constraint = pybullet.createConstraint(
                self._body, index_of[coupling.follower], self._body, index_of[coupling.leader],
                pybullet.JOINT_GEAR, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0),
                physicsClientId=self._client)
            pybullet.changeConstraint(
                constraint, gearRatio=-coupling.multiplier, relativePositionTarget=coupling.offset,
                maxForce=MIMIC_MAX_FORCE, erp=MIMIC_ERROR_REDUCTION, physicsClientId=self._client)


@dataclasses.dataclass(frozen=True)
class DriveSplit:
    """The joints (slots in joint order, ascending) each drive kind takes.

    ``velocity``: a velocity motor (the ideal actuator); ``effort``: the
    rest, split by what their damping and friction need: ``explicit``
    (PyBullet's own damping), ``implicit`` (implicit damping, force-capped
    motor: with friction or a mimic coupling), ``damped`` (implicit damping
    alone, velocity-gain motor), ``frictional`` (friction, no or explicit
    damping) and ``plain`` (neither damping nor friction).
    """

    velocity: list[int]
    effort: list[int]
    explicit: list[int]
    implicit: list[int]
    damped: list[int]
    frictional: list[int]
    plain: list[int]


def split_drives(joints: Sequence[JointSpec], velocity_driven: Sequence[bool], time_step: float,
                 smallest_inertias: Callable[[], Sequence[float]],
                 coupled: Collection[str]) -> DriveSplit:
    """Sort the joints into drive kinds (:class:`DriveSplit`).

    ``smallest_inertias()`` (each joint's, over the checked poses) is called
    only if an effort joint has damping; ``coupled``: the names of the joints
    a mimic coupling joins.  Explicit damping is PyBullet's own, kept where it
    is far inside its stability bound.
    A velocity gain makes the motor a hard constraint that would override a
    mimic gear's forces, so coupled joints always take the force-capped form.
    """
    if len(velocity_driven) != len(joints):
        raise ValueError(f'{len(velocity_driven)} drives for {len(joints)} joints')
    velocity = [k for k, driven in enumerate(velocity_driven) if driven]
    effort = [k for k, driven in enumerate(velocity_driven) if not driven]
    with_damping = [k for k in effort if joints[k].damping > 0.0]
    smallest = smallest_inertias() if with_damping else []
    explicit = [k for k in with_damping
                if joints[k].damping * time_step <= EXPLICIT_DAMPING_SHARE * smallest[k]]
    damped = [k for k in with_damping if k not in explicit and joints[k].friction <= 0.0
              and joints[k].name not in coupled]
    implicit = [k for k in with_damping if k not in explicit and k not in damped]
    frictional = [k for k in effort
                  if joints[k].friction > 0.0 and (joints[k].damping <= 0.0 or k in explicit)]
    plain = [k for k in effort if joints[k].friction <= 0.0
             and (joints[k].damping <= 0.0 or k in explicit)]
    return DriveSplit(velocity, effort, explicit, implicit, damped, frictional, plain)


def static_rows(joints: Sequence[JointSpec], split: DriveSplit) -> list[tuple[int, float]]:
    """Return the motor rows sent once, (slot, force): all at target speed 0.

    Friction-only joints hold with their friction; plain joints, and every
    velocity joint until its first step, have no motor (force 0).
    """
    return [(k, joints[k].friction) for k in split.frictional] + [
        (k, NO_MOTOR) for k in split.plain + split.velocity]


class ImplicitDamping:
    """Force-capped zero-speed motors: implicit damping with friction or a mimic coupling.

    Each step, the motor of an ``implicit`` joint may resist with at most
    ``f + d |v_end|``, ``v_end`` being the speed implicit Euler of ``J v' =
    tau + g - d v - f sgn(v)`` gives at the end of the step; the passive
    torque ``g`` (gravity, coupling) is read back from the step before.
    ``slots``: the joints; ``effort_slots``: where their efforts are in the
    efforts array; ``first_motor``: where their rows start in the motor arrays.
    """

    def __init__(self, joints: Sequence[JointSpec], slots: Sequence[int],
                 effort_slots: Sequence[int], first_motor: int) -> None:
        effort_of = {k: position for position, k in enumerate(effort_slots)}
        self.slots = list(slots)
        self._damping = [joints[k].damping for k in slots]
        # One row per joint, updated in place: [state slot, effort slot, motor slot, J / dt,
        # d dt / (J + d dt), f, g], g being the torque the joint felt last step besides
        # ours and the motor's.
        self._rows = [[k, effort_of[k], first_motor + number, 0.0, 0.0, joints[k].friction, 0.0]
                      for number, k in enumerate(slots)]

    def __bool__(self) -> bool:
        return bool(self._rows)

    @property
    def frictions(self) -> list[float]:
        """Each joint's Coulomb friction: its motor's force before the first step."""
        return [row[5] for row in self._rows]

    def refresh(self, inertias: Sequence[float], time_step: float) -> None:
        """Take the joints' effective inertias (``inertias[slot]``) for the next steps."""
        for row, damping in zip(self._rows, self._damping, strict=True):
            inertia = inertias[row[0]]
            row[3] = inertia / time_step
            row[4] = damping * time_step / (inertia + damping * time_step)

    def rest(self, gravity: Sequence[float]) -> None:
        """Start from rest: the passive torque is minus what holding against gravity takes."""
        for row in self._rows:
            row[6] = -gravity[row[0]]

    def resist(self, before: Sequence, efforts: Sequence[float], forces: list[float]) -> None:
        """Write each motor's force cap into ``forces``, from the states ``before`` the step."""
        for row in self._rows:
            slot, effort_slot, motor_slot, per_dt, gain, friction, passive = row
            drive = per_dt * before[slot][STATE_VELOCITY] + efforts[effort_slot] + passive
            excess = (drive if drive >= 0.0 else -drive) - friction
            forces[motor_slot] = friction + gain * excess if excess > 0.0 else friction

    def feel(self, before: Sequence, states: Sequence, efforts: Sequence[float]) -> None:
        """Read back the passive torque each joint felt from ``before`` to ``states``."""
        for row in self._rows:
            slot = row[0]
            state = states[slot]
            row[6] = (row[3] * (state[STATE_VELOCITY] - before[slot][STATE_VELOCITY])
                      - state[STATE_MOTOR_TORQUE] - efforts[row[1]])


class GainDamping:
    """Zero-speed motors with velocity gain ``d dt / (J + d dt)``: implicit damping alone.

    Sent again whenever the effective inertias are refreshed; unbounded force.
    """

    def __init__(self, joints: Sequence[JointSpec], slots: Sequence[int]) -> None:
        self.slots = list(slots)
        self._damping = [joints[k].damping for k in slots]

    def __bool__(self) -> bool:
        return bool(self.slots)

    def gains(self, inertias: Sequence[float], time_step: float) -> list[float]:
        """Return each joint's velocity gain for the effective ``inertias[slot]``."""
        return [damping * time_step / (inertias[k] + damping * time_step)
                for k, damping in zip(self.slots, self._damping, strict=True)]


class MotorRows:
    """The velocity motor rows sent every step: the velocity joints', then implicit damping's.

    ``targets`` and ``forces`` are updated in place; a velocity joint's force
    starts at its effort limit (at most :data:`UNLIMITED_FORCE`), an
    implicit-damping joint's at its friction.
    """

    def __init__(self, joints: Sequence[JointSpec], velocity: Sequence[int],
                 implicit: ImplicitDamping, indices: Sequence[int]) -> None:
        self.velocity_count = len(velocity)
        self.indices = [indices[k] for k in list(velocity) + implicit.slots]
        count = len(self.indices)
        self.targets = [0.0] * count
        self.forces = [min(joints[k].effort_limit, UNLIMITED_FORCE) for k in velocity] + (
            implicit.frictions)
        self.zeros = [0.0] * count
        self.gains = [MOTOR_VELOCITY_GAIN] * count

    def __bool__(self) -> bool:
        return bool(self.indices)

    def command(self, targets: Sequence[float], forces: Sequence[float] | None) -> None:
        """Take the velocity joints' ``targets`` and force caps (None: keep the last ones)."""
        count = self.velocity_count
        if count:
            self.targets[:count] = targets
            if forces is not None:
                self.forces[:count] = forces


class _Drives:
    """The per-step work for one split of the joints into effort- and velocity-driven.

    Composes the drive kinds (:func:`split_drives`): PyBullet's explicit
    damping and the :func:`static_rows` are sent once here; the
    :class:`MotorRows` (velocity motors and :class:`ImplicitDamping`) every
    step; the :class:`GainDamping` rows when the inertias are refreshed.
    ``indices``: PyBullet's index of each joint; ``coupled``: the names of the
    joints a mimic coupling joins.
    """

    def __init__(self, physics: Physics, velocity_driven: Sequence[bool],
                 indices: Sequence[int], coupled: Collection[str]) -> None:
        joints = physics.joints
        self._physics = physics
        body, client, dt = physics.body_id, physics.client_id, physics.time_step
        self._body, self._client, self._dt = body, client, dt
        split = split_drives(joints, velocity_driven, dt, physics.smallest_inertias, coupled)
        self.velocity_slots, self.effort_slots = split.velocity, split.effort
        self.explicit, self.implicit, self.damped = split.explicit, split.implicit, split.damped
        for k, joint in enumerate(joints):
            pybullet.changeDynamics(body, indices[k], jointDamping=joint.damping
                                    if k in split.explicit else 0.0, physicsClientId=client)
        static = static_rows(joints, split)
        if static:
            count = len(static)
            pybullet.setJointMotorControlArray(
                body, [indices[k] for k, _ in static], pybullet.VELOCITY_CONTROL,
                [0.0] * count, [0.0] * count, [force for _, force in static], [0.0] * count,
                [MOTOR_VELOCITY_GAIN] * count, client)
        self._implicit = ImplicitDamping(joints, split.implicit, split.effort,
                                         len(split.velocity))
        self._gain = GainDamping(joints, split.damped)
        self._gain_indices = [indices[k] for k in split.damped]
        self._motors = MotorRows(joints, split.velocity, self._implicit, indices)
        # Torques, one step, the states: compiled where the package was built with it;
        # there, the velocity motors go from C in the same call (``drive``).
        self._effort_step = effort_step = physics.effort_stepper(
            [indices[k] for k in split.effort], self._motors.indices)
        self._drive_motors = getattr(effort_step, 'drive', None)
        self._countdown = 0
        self._states = physics.read_states()
        self._felt = [0.0] * len(split.effort)  # a guest's last efforts, until settle()
        # Many steps of controller laws in C: only where a step is nothing but the efforts.
        self.run_laws = None
        if not self._motors and not self._gain:
            self.run_laws = getattr(effort_step, 'run_laws', None)

            def step(efforts: Sequence[float], targets: Sequence[float] = (),
                     forces: Sequence[float] | None = None) -> Sequence:
                return effort_step(efforts)
            self.step = step
        else:
            self.step = self._motor_step
        self.restart()

    def _motor_step(self, efforts: Sequence[float], targets: Sequence[float] = (),
                    forces: Sequence[float] | None = None) -> Sequence:
        """Step with motor rows: the velocity targets, the implicit damping, then the efforts."""
        self._countdown -= 1
        if self._countdown < 0:
            self._refresh()
        before, motors, implicit = self._states, self._motors, self._implicit
        if motors:
            motors.command(targets, forces)
            implicit.resist(before, efforts, motors.forces)
            if self._drive_motors is not None:
                states = self._drive_motors(efforts, motors.targets, motors.forces,
                                            motors.gains)
            else:
                pybullet.setJointMotorControlArray(
                    self._body, motors.indices, pybullet.VELOCITY_CONTROL, motors.zeros,
                    motors.targets, motors.forces, motors.zeros, motors.gains, self._client)
                states = self._effort_step(efforts)
        else:
            states = self._effort_step(efforts)
        if self._physics.is_guest:  # the host's step comes next: settle() reads it back
            self._felt[:] = efforts
            return states
        implicit.feel(before, states, efforts)
        self._states = states
        return states

    def settle(self, states: Sequence) -> None:
        """Read back what a guest's joints felt in the world step that gave ``states``."""
        if self._implicit:
            self._implicit.feel(self._states, states, self._felt)
        self._states = states

    def restart(self) -> None:
        """Start over from the joints' present state (after a reset, or at the start)."""
        self._states = self._physics.read_states()
        if self._physics.is_guest:
            self._physics._after_step[0] = self._states
        self._countdown = 0
        if self._implicit:
            self._implicit.rest(self._physics.gravity_torques())

    def _refresh(self) -> None:
        """Recompute the effective inertias the implicit damping uses."""
        self._countdown = INERTIA_REFRESH_STEPS - 1
        if not self._implicit and not self._gain:
            return
        dt = self._dt
        inertias = self._physics.effective_inertias()
        self._implicit.refresh(inertias, dt)
        if self._gain:
            gains = self._gain.gains(inertias, dt)
            count = len(gains)
            pybullet.setJointMotorControlArray(
                self._body, self._gain_indices, pybullet.VELOCITY_CONTROL,
                [0.0] * count, [0.0] * count, [UNLIMITED_FORCE] * count, [0.0] * count, gains,
                self._client)


def health_problem(name: str, state: Sequence[float], cap: float) -> str:
    """Describe what is wrong with a joint's ``state`` ('' if nothing)."""
    position, velocity = state[STATE_POSITION], state[STATE_VELOCITY]
    if not (math.isfinite(position) and math.isfinite(velocity)):
        return (f"joint '{name}' has a non-finite state (position {position}, velocity "
                f'{velocity}): the simulation is unstable')
    return (f"joint '{name}' moves at {velocity:.6g}, PyBullet's speed cap ({cap:g}): it is "
            'unstable (gains too high for its inertia?)')


def _inverse(transform: Transform) -> Transform:
    """Return the transform that undoes ``transform``."""
    x, y, z, w = transform.rotation
    conjugate = (-x, -y, -z, w)
    moved = Transform((0.0, 0.0, 0.0), conjugate).apply(transform.translation)
    return Transform((-moved[0], -moved[1], -moved[2]), conjugate)
