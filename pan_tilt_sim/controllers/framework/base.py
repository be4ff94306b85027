"""The small base every controller stands on (after ros2_control's ControllerInterface).

A controller is pure Python: built from its YAML parameters, then
:meth:`Controller.configure` hands it the :class:`JointHandle` objects of
its joints, and :meth:`Controller.update` runs on the controller's clock
(:mod:`pan_tilt_sim.controllers.framework.manager`).  Handles carry the
measured state (written by the simulation before each update) and what the
controller wants the physics to do with the joint (read after it).  At
configure time the controller tells each handle which :class:`Actuator`
drives it:

* :attr:`Drive.EFFORT` -- the physics applies ``handle.effort`` (N*m or N);
* :attr:`Drive.VELOCITY` -- the ideal actuator: a velocity motor moves the
  joint at ``handle.velocity_target`` with at most ``handle.force_limit``,
  and the effort it applied is written back into ``handle.effort``.

Design notes: docs/design/controllers.md#basepy.
"""

from __future__ import annotations

import abc
import dataclasses
import enum
import math
from collections.abc import Callable, Mapping, Sequence
from types import MappingProxyType
from typing import Any, ClassVar

from pan_tilt_sim.controllers.framework.hardware_interfaces import (
    NO_HARDWARE,
    CommandInterface,
    HardwareInterfaces,
    StateInterface,
)
from pan_tilt_sim.controllers.framework.parameter_spec import (
    LoadedParameters,
    ParameterSpec,
    load_parameters,
)
from pan_tilt_sim.controllers.framework.surface import CommandTopic, Endpoint
from pan_tilt_sim.controllers.toolbox.actuator import TRACKING_GAIN
from pan_tilt_sim.controllers.toolbox.pid import Pid, PidGains
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.robot import ControlJoint, JointKind, JointSpec
from pan_tilt_sim.schedule import PeriodicSchedule

# The command interface a ros2_control controller package's controllers claim.
PACKAGE_INTERFACES = {'position_controllers': 'position', 'velocity_controllers': 'velocity',
                      'effort_controllers': 'effort'}
# The state interfaces the physics measures for every joint; each is a JointHandle attribute.
MEASURED_STATES = ('position', 'velocity', 'effort')
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
    # For a velocity motor: whether the controller sets its force limit every step
    # (``JointHandle.force_limit``: a gripper's max_effort); else it is the effort limit.
    force_from_controller: bool = False
    # What limits the motor's force, when not the URDF's effort limit (a Gazebo plugin's torque).
    force_text: str = ''

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
            if self.force_text:
                return f'{self.kind.label}{owner}, a velocity motor with {self.force_text}'
            if self.force_from_controller:
                return (f'{self.kind.label}{owner}, a velocity motor with {limit}, or less as '
                        "the controller asks (a goal's max_effort)")
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

    ``control`` is the joint's entry in the URDF's ``<ros2_control>`` block, if
    it has one; :attr:`declared_commands` are its command interfaces (None for a
    joint outside every block). The joint's state interfaces
    (:attr:`state_interface_names`) are the :data:`MEASURED_STATES` -- the
    physics measures all three for every joint -- then the other
    ``<state_interface>`` entries the block declares for it
    (:attr:`other_states`). The physics measures none of those: each keeps the
    value it starts with (its ``initial_value``, else NaN), as a state interface
    of ros2_control's mock hardware does when nothing commands it.

    ``force_limit`` (N*m or N, may be inf) is the most the ideal actuator's
    motor may apply: the joint's effort limit, which the simulation restores
    whenever the actuators change; a controller whose actuator says
    ``force_from_controller`` sets it in its update, and the simulation
    reads it every step.
    """

    __slots__ = ('spec', 'position', 'velocity', 'effort', 'velocity_target',
                 'initial_position', 'plugin_gains', 'tracking_gain', 'actuator',
                 'other_states', 'force_limit', 'declared_commands')

    def __init__(self, spec: JointSpec, initial_position: float | None = None,
                 plugin_gains: PidGains | None = None,
                 tracking_gain: float = TRACKING_GAIN,
                 control: ControlJoint | None = None) -> None:
        self.spec = spec
        self.declared_commands: tuple[str, ...] | None = (
            None if control is None else control.command_interface_names)
        # Unmeasured state interfaces, in the block's order, and the value each holds
        # (read-only by contract; a plain dict so that handles can be copied).
        self.other_states: Mapping[str, float] = {
            interface.name: interface.initial_value
            for interface in (control.state_interfaces if control is not None else ())
            if interface.name not in MEASURED_STATES}
        self.initial_position = (spec.initial_position if initial_position is None
                                 else initial_position)
        self.plugin_gains = plugin_gains
        self.tracking_gain = tracking_gain
        self.actuator = idle_actuator(spec)
        self.position = self.initial_position
        self.velocity = 0.0
        self.effort = 0.0
        self.velocity_target = 0.0
        self.force_limit = spec.effort_limit

    @property
    def name(self) -> str:
        """The joint's URDF name."""
        return self.spec.name

    @property
    def drive(self) -> Drive:
        """How the physics moves the joint (see :class:`Drive`)."""
        return self.actuator.drive

    @property
    def state_interface_names(self) -> tuple[str, ...]:
        """The joint's state interfaces: the measured ones, then :attr:`other_states`."""
        return (*MEASURED_STATES, *self.other_states)

    def reset(self) -> None:
        """Return to the joint's initial state (at rest, no effort, its own effort limit)."""
        self.position = self.initial_position
        self.velocity = 0.0
        self.effort = 0.0
        self.velocity_target = 0.0
        self.force_limit = self.spec.effort_limit


class Reference:
    """One reference interface a chainable controller exports: ``<controller>/<reference>``.

    The preceding controller that claims it writes ``value`` in its update;
    the chainable controller reads it in its own, later in the same step.
    ``value`` is in the unit of the interface it stands for (rad for a
    ``.../position`` reference, say); NaN means nothing was written since
    the chainable controller last reset it.
    """

    __slots__ = ('name', 'value')

    def __init__(self, name: str) -> None:
        self.name = name
        self.value = math.nan


class CommandKind(enum.Enum):
    """What a command controller's topic carries (the node maps kinds to message types)."""

    FLOAT64 = 'std_msgs/msg/Float64'
    FLOAT64_ARRAY = 'std_msgs/msg/Float64MultiArray'
    JOINT_TRAJECTORY = 'trajectory_msgs/msg/JointTrajectory'
    MULTI_DOF_COMMAND = 'control_msgs/msg/MultiDOFCommand'
    TWIST_STAMPED = 'geometry_msgs/msg/TwistStamped'
    TWIST = 'geometry_msgs/msg/Twist'  # Gazebo's drive plugins: taken as an unstamped one


class CommandResult(enum.Enum):
    """What became of one command value."""

    ACCEPTED = 'accepted'
    CLAMPED = 'clamped'
    REJECTED = 'rejected'


class Controller(abc.ABC):
    """Base of every controller type; subclasses list their YAML ``type`` strings.

    ``parameters`` is the type's :class:`ParameterSpec`: the constructor
    checks ``params`` against it and keeps the checked values, defaults
    filled in, as :attr:`params`; keys the spec does not know are named in
    :attr:`config_warnings`.  Parameters already checked (a
    :class:`LoadedParameters`, as a group controller gives its members) are
    taken as they are.
    """

    type_names: ClassVar[tuple[str, ...]] = ()
    parameters: ClassVar[ParameterSpec] = ParameterSpec()
    # The YAML type this controller was created from (the registry sets it).
    type_name: str = ''
    # The YAML section the PID gains come from: 'pid' (ROS 1, one joint) or
    # 'gains' (ros2_controllers, per joint); the gain parameters follow it.
    gains_field: ClassVar[str] = 'gains'
    # Whether the type exports reference interfaces (ros2_control's ChainableControllerInterface).
    chainable: ClassVar[bool] = False
    # The namespace of the controller's node (its controller_manager's: the robot's), which
    # the ROS adapter sets before it asks for the surface; frame ids may depend on it.
    node_namespace: str = '/'
    # Whether the type drives a mobile base (its wheels move the robot over the ground): while
    # one will be active, sim_node's fixed_base:=auto frees the base (see model.base_pose).
    drives_base: ClassVar[bool] = False
    # Whether the type commands joints (a command controller, a gripper's action controller)
    # rather than only reading them (a broadcaster); those update first in every step.
    commands_joints: ClassVar[bool] = False
    # Whether the type keeps its update rate inside its own update, which then runs every
    # physics step (a steered base tracks its steering angles every step, its kinematics at
    # update_rate); the stepping loop gives it no clock of its own.
    own_clock: ClassVar[bool] = False
    # Chained mode, and the references offered before configure (see the methods below).
    _chained: bool = False
    _available_references: Mapping[str, Reference] = MappingProxyType({})
    # The robot's sensors and gpios, offered before configure (see set_hardware).
    _hardware: HardwareInterfaces = NO_HARDWARE

    def __init__(self, name: str, params: Mapping[str, Any] | LoadedParameters,
                 source: str = '') -> None:
        self.name = name
        self._source = source
        if not isinstance(params, LoadedParameters):
            params = load_parameters(type(self).parameters, params, name, source)
        self.params: dict[str, Any] = params.values
        self.config_warnings: list[str] = params.warnings
        # Events worth a warning while the controller runs (the node logs and clears them).
        self.notices: list[str] = []

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

    def actuation(self) -> Callable[[float], None] | None:
        """Return what the hardware does with this controller's held commands every physics step.

        Asked when the controller is active on a clock slower than the
        physics; the returned function is then called with the physics step
        (s) at every step, after the step's updates, as a hardware
        interface's ``write`` runs every step: an ideal position actuator
        ramps its setpoint toward the held command and turns it into a
        velocity target from the joint's present position
        (gz_ros2_control's ``position_proportional_gain`` per physics step).
        A controller that returns one may leave that part out of its update
        from then on.  None (the default): the held commands are all the
        physics needs.
        """
        return None

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the topics and actions this controller has while configured (none here)."""
        return ()

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
        :mod:`pan_tilt_sim.controllers.toolbox.step_law` returns its joint's handle
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

    def undrivable_interfaces(self) -> dict[str, str]:
        """Return, by joint, a claimed command interface the simulation cannot drive.

        Only ones the joint's ``<ros2_control>`` block declares (any other
        is refused at configure): such a controller configures, as upstream,
        but cannot be activated here.  None by default.
        """
        return {}

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the state interfaces this controller reads, by joint (none here)."""
        return {}

    # --- chaining: the following (chainable) side ------------------------------------------

    def reference_interfaces(self) -> Mapping[str, Reference]:
        """Return the reference interfaces this controller exports, by ``<name>/<reference>``.

        Only a :attr:`chainable` type exports any.  It creates them when it is
        built and keeps them as long as it lives (preceding controllers hold
        them from their configure on); it reads them in its update and
        resets their values when it is reset.
        """
        return MappingProxyType({})

    @property
    def is_chained(self) -> bool:
        """Whether an active controller writes this controller's references (chained mode).

        In chained mode the references come from the preceding controller,
        not from this controller's own command topic.
        """
        return self._chained

    def set_chained_mode(self, chained: bool) -> None:
        """Enter or leave chained mode (the manager calls it while the controller is stopped)."""
        self._chained = chained

    # --- chaining: the preceding side ---------------------------------------------------------

    def set_available_references(self, references: Mapping[str, Reference]) -> None:
        """Take the reference interfaces the loaded controllers export, by full name.

        The manager calls it before every :meth:`configure`; a controller that
        claims references finds them with :meth:`command_target`.
        """
        self._available_references = references

    def command_target(self, joints: Mapping[str, JointHandle], entry: str, interface: str,
                       field: str) -> JointHandle | Reference:
        """Return what ``entry`` of ``field`` commands through ``interface``.

        A joint of the robot: its handle (see :meth:`handle`).  Otherwise the
        reference interface ``<entry>/<interface>`` of a loaded chainable
        controller (``entry`` is ``<controller>/<dof>``, as ros2_control's
        chained controllers name it).  Neither: an error naming it and what
        exists.
        """
        if entry in joints or '/' not in entry:
            return self.handle(joints, entry, field)
        name = f'{entry}/{interface}'
        reference = self._available_references.get(name)
        if reference is not None:
            return reference
        owner = entry.partition('/')[0]
        theirs = [other for other in self._available_references if other.startswith(f'{owner}/')]
        if theirs:
            raise self.error(field, f"'{name}' is not a reference interface of controller "
                                    f"'{owner}' (its reference interfaces: {', '.join(theirs)})")
        raise self.error(
            field, f"'{entry}' is not a movable joint of the robot and '{name}' is not a "
            'reference interface of a loaded chainable controller (movable joints: '
            f"{', '.join(sorted(joints)) or 'none'}; reference interfaces: "
            f"{', '.join(self._available_references) or 'none'})")

    # --- sensors and gpios --------------------------------------------------------------------

    def set_hardware(self, hardware: HardwareInterfaces) -> None:
        """Take the robot's sensor and gpio interfaces (the manager calls it before configure)."""
        self._hardware = hardware

    def state_interface(self, name: str, field: str) -> StateInterface:
        """Look up the sensor or gpio state interface ``name`` (``<component>/<interface>``).

        The error names ``field`` and lists what exists (upstream's
        controller_manager refuses to activate a controller whose state
        interface is missing).
        """
        found = self._hardware.state_interfaces.get(name)
        if found is None:
            existing = ', '.join(self._hardware.state_interfaces) or 'none'
            raise self.error(field, f"'{name}' is not a state interface of the robot's "
                                    f'<ros2_control> sensors and gpios (they have: {existing})')
        return found

    def command_interface(self, name: str, field: str) -> CommandInterface:
        """Look up the gpio command interface ``name`` (``<component>/<interface>``)."""
        found = self._hardware.command_interfaces.get(name)
        if found is None:
            existing = ', '.join(self._hardware.command_interfaces) or 'none'
            raise self.error(field, f"'{name}' is not a command interface of the robot's "
                                    f'<ros2_control> gpios (they have: {existing})')
        return found

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

    def roller_wheels(self) -> dict[str, float]:
        """Return the wheel joints that carry free rollers, each with its rollers' angle (rad).

        The angle is between the wheel's rolling direction and the direction
        its rollers roll freely at the ground, turned towards the wheel's
        axis: pi / 2 for an omni wheel, +-pi / 4 for a mecanum wheel (see
        :mod:`pan_tilt_sim.sim.roller_wheels`).  Ordinary wheels: none here.
        """
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


class CommandController(Controller):
    """A controller that takes commands from a topic ``<controller>/<command_topic>``."""

    commands_joints = True
    command_topic: ClassVar[str] = 'command'
    command_kind: ClassVar[CommandKind] = CommandKind.FLOAT64

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the command topic ``~/<command_topic>``."""
        return (CommandTopic(f'~/{self.command_topic}', self.command_kind.value,
                             self.set_command, self.command_problem),)

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
