"""The small base every controller stands on (after ros2_control's ControllerInterface).

A controller is pure Python: it is built from its YAML parameters, then
:meth:`Controller.configure` hands it the :class:`JointHandle` objects of
the joints it names, and :meth:`Controller.update` runs once per physics
step.  Handles carry the measured state (written by the simulation before
each update) and what the controller wants the physics to do with the joint
(read by the simulation after it).  At configure time the controller tells
each of its joints' handles which :class:`Actuator` drives it:

* :attr:`Drive.EFFORT` -- the physics applies ``handle.effort`` (N*m or N):
  an effort command, or a PID's output;
* :attr:`Drive.VELOCITY` -- the ideal actuator: a velocity motor moves the
  joint at ``handle.velocity_target`` with at most the joint's effort limit,
  and the simulation writes the effort it applied back into ``handle.effort``
  (an acceleration command is integrated into that target).

Controllers never touch PyBullet or rclpy.
"""

from __future__ import annotations

import abc
import dataclasses
import enum
import math
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

from pan_tilt_sim.controllers.actuator import TRACKING_GAIN
from pan_tilt_sim.controllers.pid import Pid, PidGains
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.robot import JointKind, JointSpec
from pan_tilt_sim.schedule import PeriodicSchedule

# The command interface a ros2_control controller package's controllers claim.
PACKAGE_INTERFACES = {'position_controllers': 'position', 'velocity_controllers': 'velocity',
                      'effort_controllers': 'effort'}
# Largest command magnitude taken on a side without a limit (rad, m, rad/s, N*m...):
# far beyond any real joint, small enough that PID arithmetic on it stays finite.
MAX_COMMAND_MAGNITUDE = 1e12


class Drive(enum.Enum):
    """How the physics moves a joint."""

    EFFORT = 'effort'  # apply handle.effort
    VELOCITY = 'velocity'  # velocity motor to handle.velocity_target, force <= effort limit


class ActuatorKind(enum.Enum):
    """What drives a joint, and through which :class:`Drive`."""

    PASSIVE = ('passive: no active controller', Drive.EFFORT)
    HOLD = ('held where it is until a spawned controller drives it', Drive.VELOCITY)
    MIMIC = ('mimic: follows its leader', Drive.EFFORT)
    EFFORT = ('effort command', Drive.EFFORT)
    POSITION_PID = ('position PID on effort', Drive.EFFORT)
    VELOCITY_PID = ('velocity PID on effort', Drive.EFFORT)
    IDEAL_POSITION = ('ideal position actuator', Drive.VELOCITY)
    IDEAL_VELOCITY = ('ideal velocity actuator', Drive.VELOCITY)
    IDEAL_ACCELERATION = ('acceleration command integrated into the ideal velocity actuator',
                          Drive.VELOCITY)

    @property
    def label(self) -> str:
        """How the start-up log names it."""
        return self.value[0]

    @property
    def drive(self) -> Drive:
        """What the physics applies for it."""
        return self.value[1]


@dataclasses.dataclass(frozen=True)
class Actuator:
    """What drives one joint, decided once at configure time, and why."""

    kind: ActuatorKind = ActuatorKind.PASSIVE
    controller: str = ''
    # For a PID: its live object and where its gains came from ('' = the defaults).
    pid: Pid | None = None
    gains_from: str = ''

    @property
    def drive(self) -> Drive:
        """What the physics applies for this joint."""
        return self.kind.drive

    def describe(self, spec: JointSpec) -> str:
        """One line for the start-up log: the actuator and the reason it was chosen."""
        owner = f' ({self.controller})' if self.controller else ''
        if self.pid is not None:
            gains = self.pid.gains
            source = (f'gains from {self.gains_from}' if self.gains_from else
                      f'no gains in the YAML: defaults for {self.controller}')
            return (f'{self.kind.label}{owner}, p {gains.p:g} i {gains.i:g} d {gains.d:g}: '
                    f'{source}')
        if self.drive is Drive.VELOCITY:
            force = 'N' if spec.kind is JointKind.PRISMATIC else 'N*m'
            limit = (f'at most {spec.effort_limit:g} {force}' if math.isfinite(spec.effort_limit)
                     else 'no effort limit in the URDF')
            if self.kind is ActuatorKind.HOLD:
                return (f'{self.kind.label}: a zero-velocity motor with {limit} '
                        "(gz_ros2_control's hold_joints)")
            if self.kind is ActuatorKind.IDEAL_ACCELERATION:
                return f'{self.kind.label}{owner}, a velocity motor with {limit}'
            return (f'{self.kind.label}{owner}, a velocity motor with {limit}: no PID gains '
                    'for it in the YAML')
        return f'{self.kind.label}{owner}'


def idle_actuator(spec: JointSpec, *, hold: bool = False) -> Actuator:
    """Return what drives a joint no active controller claims: nothing, or its mimic leader.

    ``hold``: a zero-velocity motor capped at the effort limit instead of nothing
    (gz_ros2_control's ``hold_joints``, for joints that wait for a spawner).
    """
    if spec.mimic is not None:
        return Actuator(ActuatorKind.MIMIC)
    return Actuator(ActuatorKind.HOLD if hold else ActuatorKind.PASSIVE)


class JointHandle:
    """State and command of one joint, shared by simulation and controllers.

    ``initial_position`` is where the joint starts and resets to;
    ``plugin_gains`` are the joint's ``gazebo_ros_control/pid_gains`` (None
    if the YAML gives none), which a position or velocity controller without
    gains of its own uses, as gazebo_ros_control does; ``tracking_gain`` is
    the share of its position error an ideal position actuator closes per
    step (gz_ros2_control's ``position_proportional_gain``).  ``actuator``
    is what drives the joint now: the simulation sets it from the active
    controllers (:meth:`Controller.actuators`).
    """

    __slots__ = ('spec', 'position', 'velocity', 'effort', 'velocity_target',
                 'initial_position', 'plugin_gains', 'tracking_gain', 'actuator')

    def __init__(self, spec: JointSpec, initial_position: float | None = None,
                 plugin_gains: PidGains | None = None,
                 tracking_gain: float = TRACKING_GAIN) -> None:
        self.spec = spec
        self.initial_position = (spec.initial_position if initial_position is None
                                 else initial_position)
        self.plugin_gains = plugin_gains
        self.tracking_gain = tracking_gain
        self.actuator = idle_actuator(spec)
        self.position = self.initial_position
        self.velocity = 0.0
        self.effort = 0.0
        self.velocity_target = 0.0

    @property
    def name(self) -> str:
        """The joint's URDF name."""
        return self.spec.name

    @property
    def drive(self) -> Drive:
        """How the physics moves the joint (see :class:`Drive`)."""
        return self.actuator.drive

    def reset(self) -> None:
        """Return to the joint's initial state (at rest, no effort)."""
        self.position = self.initial_position
        self.velocity = 0.0
        self.effort = 0.0
        self.velocity_target = 0.0


class CommandKind(enum.Enum):
    """What a command controller's topic carries (the node maps kinds to message types)."""

    FLOAT64 = 'std_msgs/msg/Float64'
    FLOAT64_ARRAY = 'std_msgs/msg/Float64MultiArray'
    JOINT_TRAJECTORY = 'trajectory_msgs/msg/JointTrajectory'


class CommandResult(enum.Enum):
    """What became of one command value."""

    ACCEPTED = 'accepted'
    CLAMPED = 'clamped'
    REJECTED = 'rejected'


class Controller(abc.ABC):
    """Base of every controller type; subclasses list their YAML ``type`` strings."""

    type_names: ClassVar[tuple[str, ...]] = ()
    # The YAML type this controller was created from (the registry sets it).
    type_name: str = ''
    # The YAML section the PID gains come from: 'pid' (ROS 1, one joint) or
    # 'gains' (ros2_controllers, per joint); the gain parameters follow it.
    gains_field: ClassVar[str] = 'gains'

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        self.name = name
        self.params = params
        self._source = source

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The joints this controller claims (commands them exclusively)."""
        return ()

    @abc.abstractmethod
    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Take the handles of the joints this controller uses."""

    @abc.abstractmethod
    def update(self, time: float, period: float) -> None:
        """Run one control step at sim ``time`` (s), ``period`` s after the previous one."""

    def step_members(self) -> list[Controller]:
        """Return the controllers whose ``update`` the stepping loop calls every step, in order.

        By default the controller itself; a controller made of others
        returns theirs, so the loop calls them directly; a controller on a
        :meth:`schedule` returns none.
        """
        return [] if self.schedule() is not None else [self]

    def step_law(self) -> tuple[JointHandle, list[float]] | None:
        """Return this step's update as data a compiled loop can run, or None (Python only).

        A controller whose per-step :meth:`update` is one of the laws of
        :mod:`pan_tilt_sim.controllers.step_law` returns its joint's handle
        and the law's row; after the compiled steps the loop hands the row
        back to :meth:`absorb_step_law`.
        """
        return None

    def absorb_step_law(self, row: Sequence[float]) -> None:
        """Take back the state a compiled loop left in the row :meth:`step_law` gave."""
        raise NotImplementedError(f'{type(self).__name__} has no step law')

    def schedule(self) -> PeriodicSchedule | None:
        """Return the schedule :meth:`update` runs on, if not every step.

        The stepping loop then calls ``update`` only when the schedule says a
        sample is due (it advances the schedule itself).
        """
        return None

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the command interfaces this controller claims, by joint (ros2_control's claim).

        ``position``, ``velocity``, ``effort``, ``acceleration``: a joint whose
        ``<ros2_control>`` block lacks one of them cannot be driven by this
        controller, and the block's hardware may refuse some combinations
        (:mod:`pan_tilt_sim.model.command_modes`).
        """
        return {}

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the state interfaces this controller reads, by joint (none here)."""
        return {}

    def reset(self) -> None:  # noqa: B027 -- stateless controllers need no reset
        """Forget commands and internal state, as after a fresh start."""

    def deactivate(self) -> None:  # noqa: B027 -- most controllers have nothing to end
        """End what the controller was doing for someone (its updates stop after this)."""

    def pids(self) -> dict[str, Pid]:
        """Return the PIDs of this controller by joint (gains may change live); none here."""
        return {}

    def actuators(self) -> dict[str, Actuator]:
        """Return what drives each of this controller's joints while it is active; none here."""
        return {}

    def error(self, field: str, problem: str) -> ControllerConfigError:
        """Return an error naming this controller's field in the controllers file."""
        where = f'{self._source}: ' if self._source else ''
        return ControllerConfigError(f'{where}{self.name}.{field}: {problem}')

    def handle(self, joints: Mapping[str, JointHandle], joint: str, field: str, *,
               commanded: bool = True) -> JointHandle:
        """Look up ``joint``; the error lists the joints that exist.

        A ``<mimic>`` joint follows its leader, so it cannot be ``commanded``.
        """
        try:
            handle = joints[joint]
        except KeyError:
            existing = ', '.join(sorted(joints)) or 'none'
            raise self.error(
                field, f"joint '{joint}' is not a movable joint of the robot "
                f'(movable joints: {existing})') from None
        mimic = handle.spec.mimic
        if commanded and mimic is not None:
            raise self.error(
                field, f"joint '{joint}' mimics '{mimic.joint}': it follows that joint "
                'and cannot be commanded')
        return handle

    def required_joint(self) -> str:
        """Return the ``joint`` parameter, which must be a non-empty string."""
        joint = self.params.get('joint')
        if joint is None or joint == '':
            raise self.error('joint', 'missing: name the joint this controller drives')
        if not isinstance(joint, str):
            raise self.error('joint', f'{joint!r} is not a joint name (expected one string)')
        return joint

    def joint_list(self, field: str = 'joints', *, required: bool = True) -> tuple[str, ...]:
        """Return the ``joints`` parameter: distinct joint names (may be empty if not required)."""
        joints = self.params.get(field)
        if joints is None and not required:
            return ()
        if not isinstance(joints, list | tuple) or not all(
                isinstance(joint, str) and joint for joint in joints):
            raise self.error(field, f'{joints!r} must be a list of joint names')
        if required and not joints:
            raise self.error(field, 'empty: name the joints this controller drives')
        repeated = sorted({joint for joint in joints if joints.count(joint) > 1})
        if repeated:
            raise self.error(field, f"joint '{repeated[0]}' is named more than once")
        return tuple(joints)


class CommandController(Controller):
    """A controller that takes commands from a topic ``<controller>/<command_topic>``."""

    command_topic: ClassVar[str] = 'command'
    command_kind: ClassVar[CommandKind] = CommandKind.FLOAT64

    @abc.abstractmethod
    def set_command(self, value: Any) -> CommandResult:
        """Store the latest command (called from subscriptions; must be cheap)."""

    @abc.abstractmethod
    def setpoints(self) -> dict[str, float]:
        """Return what each joint is driven toward now, by joint, in its interface's unit.

        For a position loop the rate-limited setpoint, for a velocity or
        effort command the (clamped) command, for a trajectory the desired
        position sampled at the present sim time.
        """

    def command_problem(self, value: Any, result: CommandResult) -> str:
        """Describe what was wrong with ``value``, which ``set_command`` rejected or clamped."""
        if result is CommandResult.REJECTED:
            return (f'ignored command {value!r}: not a finite number within '
                    f'+-{MAX_COMMAND_MAGNITUDE:g}')
        return f"command {value!r} is outside the joint's limits; clamped"


def clamp(value: float, lower: float, upper: float) -> float:
    """Limit ``value`` to [lower, upper]."""
    return lower if value < lower else upper if value > upper else value


def is_sane_number(value: Any) -> bool:
    """Whether ``value`` is a finite number within +-MAX_COMMAND_MAGNITUDE."""
    return isinstance(value, int | float) and math.isfinite(value) and (
        abs(value) <= MAX_COMMAND_MAGNITUDE)


def bounded_command(value: float, lower: float, upper: float) -> tuple[float, CommandResult]:
    """Check a scalar command: non-finite or huge is rejected, out-of-range is clamped.

    A command beyond +-MAX_COMMAND_MAGNITUDE (1e308, say) is rejected, not
    clamped: no joint means it, it is a broken sender, and on a side without
    a limit gains times such an error would overflow.
    """
    if not is_sane_number(value):
        return value, CommandResult.REJECTED
    if value < lower or value > upper:
        return clamp(value, lower, upper), CommandResult.CLAMPED
    return value, CommandResult.ACCEPTED
