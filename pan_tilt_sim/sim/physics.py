"""The physics layer: one PyBullet client, one robot, joints driven by torque.

:class:`Physics` owns its own PyBullet client id (never the global default
client), so several simulations can live in one process.  The robot is
loaded with a fixed base and the URDF's inertia; PyBullet's default velocity
motors are switched off, so every actuated joint moves only by the torque
the controllers ask for.  URDF ``damping`` is applied by PyBullet itself as
viscous torque; URDF ``friction`` is modelled as Coulomb friction by a
velocity motor held at zero speed whose force is capped at the friction
value, which also gives the static friction Gazebo users know.  A
``<mimic>`` joint is held at ``multiplier * leader + offset`` by a gear
constraint (see :mod:`pan_tilt_sim.model.mimic`).
"""

from __future__ import annotations

import contextlib
import pathlib
import tempfile
import weakref
from collections.abc import Callable, Sequence

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.model.mimic import follow_leaders, mimic_couplings
from pan_tilt_sim.model.robot import JointSpec
from pan_tilt_sim.sim.bullet import pybullet, quiet_native_output

STANDARD_GRAVITY = 9.81  # m/s^2, along -z as in Gazebo's default world
URDF_FILE_NAME = 'robot.urdf'
# Index of the position and velocity in one entry of pybullet.getJointStates.
STATE_POSITION = 0
STATE_VELOCITY = 1
# Gear constraints of mimic joints: force bound high enough to be rigid, and
# the share of the position error corrected per step (1 would be all at once).
MIMIC_MAX_FORCE = 1e9
MIMIC_ERROR_REDUCTION = 0.8
BASE_LINK_INDEX = -1  # PyBullet's index of a body's base link


def _disconnect(client: int) -> None:
    with contextlib.suppress(pybullet.error):
        pybullet.disconnect(physicsClientId=client)


class Physics:
    """A PyBullet world holding one fixed-base robot."""

    def __init__(self, description: RobotDescription, time_step: float, *,
                 gui: bool = False) -> None:
        self._description = description
        self._time_step = time_step
        self._workdir = tempfile.TemporaryDirectory(prefix='pan_tilt_sim_')
        mode = pybullet.GUI if gui else pybullet.DIRECT
        with quiet_native_output():
            self._client = pybullet.connect(mode)
        if self._client < 0:
            self._workdir.cleanup()
            raise DescriptionError('PyBullet: cannot connect a physics client')
        # Disconnects even if nobody calls close(): an owner abandoned half-built
        # (a signal during start-up) or left behind at interpreter exit.
        self._disconnect = weakref.finalize(self, _disconnect, self._client)
        try:
            self._body = self._load(description)
        except BaseException:
            self.close()
            raise
        self._joints = description.actuated_joints
        index_of, self._link_indices = self._joint_and_link_indices()
        self._indices = [index_of[joint.name] for joint in self._joints]
        self._mimics = mimic_couplings(self._joints, description.source)
        self._configure_motors()
        self._couple_mimic_joints(index_of)
        self._step = self.stepper()
        self.reset_joints([joint.initial_position for joint in self._joints])

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

    def joint_index(self, name: str) -> int:
        """PyBullet's index of the joint called ``name``."""
        return self._indices[[joint.name for joint in self._joints].index(name)]

    def link_index(self, name: str) -> int:
        """PyBullet's index of the link called ``name`` (-1: the base); KeyError if none."""
        return self._link_indices[name]

    def read_states(self) -> list:
        """``pybullet.getJointStates`` for the actuated joints: (position, velocity, ...)."""
        return pybullet.getJointStates(self._body, self._indices, self._client)

    def step(self, efforts: Sequence[float]) -> list:
        """Apply ``efforts`` (N*m or N), advance one time step, return the new states."""
        return self._step(efforts)

    def stepper(self) -> Callable[[Sequence[float]], list]:
        """Return a function doing what :meth:`step` does, with every argument pre-bound.

        For hot loops: the function reads nothing from ``self``.  All PyBullet
        arguments are passed by position, because CPython decodes and hashes
        every keyword name of the C signature on each call with keywords
        (about 0.5 us of the ~1 us setJointMotorControlArray costs here).  In
        TORQUE_CONTROL PyBullet reads only the forces; the target and gain
        sequences in front of them just need the right length.
        """
        body, indices, client = self._body, self._indices, self._client
        torque = pybullet.TORQUE_CONTROL
        unused = [0.0] * len(indices)
        set_motors = pybullet.setJointMotorControlArray
        step_simulation = pybullet.stepSimulation
        get_states = pybullet.getJointStates

        def step(efforts: Sequence[float]) -> list:
            set_motors(body, indices, torque, unused, unused, efforts, unused, unused, client)
            step_simulation(client)
            return get_states(body, indices, client)
        return step

    def bare_stepper(self) -> Callable[[], None]:
        """Return ``stepSimulation`` bound to this client: a step that applies no efforts.

        For measuring PyBullet alone (the benchmark's raw figure).
        """
        step_simulation, client = pybullet.stepSimulation, self._client

        def step() -> None:
            step_simulation(client)
        return step

    def reset_joints(self, positions: Sequence[float]) -> None:
        """Put every actuated joint at ``positions`` (mimic joints by their leader), at rest."""
        if self._mimics:
            positions = follow_leaders(
                [joint.name for joint in self._joints], positions, self._mimics)
        for index, position in zip(self._indices, positions, strict=True):
            pybullet.resetJointState(
                self._body, index, position, targetVelocity=0.0, physicsClientId=self._client)

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

    def _load(self, description: RobotDescription) -> int:
        client = self._client
        pybullet.setGravity(0.0, 0.0, -STANDARD_GRAVITY, physicsClientId=client)
        pybullet.setTimeStep(self._time_step, physicsClientId=client)
        urdf_path = pathlib.Path(self._workdir.name) / URDF_FILE_NAME
        urdf_path.write_text(description.physics_urdf, encoding='utf-8')
        try:
            with quiet_native_output():
                return pybullet.loadURDF(
                    str(urdf_path), useFixedBase=True,
                    flags=pybullet.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
        except pybullet.error as err:
            raise DescriptionError(
                f'{description.source}: PyBullet cannot load the robot: {err}') from None

    def _joint_and_link_indices(self) -> tuple[dict[str, int], dict[str, int]]:
        client = self._client
        base = pybullet.getBodyInfo(self._body, physicsClientId=client)[0].decode('utf-8')
        joints, links = {}, {base: BASE_LINK_INDEX}
        for index in range(pybullet.getNumJoints(self._body, physicsClientId=client)):
            info = pybullet.getJointInfo(self._body, index, physicsClientId=client)
            joints[info[1].decode('utf-8')] = index
            links[info[12].decode('utf-8')] = index  # a joint's child link has its index
        return joints, links

    def _configure_motors(self) -> None:
        # Velocity motors at zero speed: force 0 switches PyBullet's default motors
        # off; a force equal to the URDF friction makes them Coulomb friction.
        pybullet.setJointMotorControlArray(
            self._body, self._indices, pybullet.VELOCITY_CONTROL,
            targetVelocities=[0.0] * len(self._indices),
            forces=[joint.friction for joint in self._joints],
            physicsClientId=self._client)

    def _couple_mimic_joints(self, index_of: dict[str, int]) -> None:
        # A gear constraint keeps q_follower - multiplier * q_leader at offset.
        for coupling in self._mimics:
            constraint = pybullet.createConstraint(
                self._body, index_of[coupling.follower], self._body, index_of[coupling.leader],
                pybullet.JOINT_GEAR, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0),
                physicsClientId=self._client)
            pybullet.changeConstraint(
                constraint, gearRatio=-coupling.multiplier, relativePositionTarget=coupling.offset,
                maxForce=MIMIC_MAX_FORCE, erp=MIMIC_ERROR_REDUCTION, physicsClientId=self._client)
