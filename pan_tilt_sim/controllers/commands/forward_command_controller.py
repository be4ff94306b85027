"""``forward_command_controller/ForwardCommandController``: one command per joint, as a group.

The controller drives the ``joints`` it names through one command
interface, ``interface_name``, and takes ``std_msgs/msg/Float64MultiArray``
commands on ``<controller>/commands``: element k is the command of the k-th
joint.  Each joint behaves exactly like the one-joint controller of its
interface (limits, ramp, actuator), which it is built from, with gains from
``gains: {<joint>: {p, i, d, i_clamp}}`` (see the design notes).

Design notes: docs/design/controllers.md#forward_command_controllerpy.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

from pan_tilt_sim.controllers.commands.joint_acceleration_controller import (
    JointAccelerationController,
)
from pan_tilt_sim.controllers.commands.joint_effort_controller import JointEffortController
from pan_tilt_sim.controllers.commands.joint_position_controller import JointPositionController
from pan_tilt_sim.controllers.commands.joint_velocity_controller import JointVelocityController
from pan_tilt_sim.controllers.framework.base import (
    MAX_COMMAND_MAGNITUDE,
    Actuator,
    CommandController,
    CommandKind,
    CommandResult,
    Controller,
    JointHandle,
    Reference,
    is_sane_number,
)
from pan_tilt_sim.controllers.framework.hardware_interfaces import DRIVABLE
from pan_tilt_sim.controllers.framework.multi_joint import JOINTS_FIELD, MultiJointController
from pan_tilt_sim.controllers.framework.parameter_spec import (
    REQUIRED,
    STRING,
    LoadedParameters,
    Param,
    not_empty,
)
from pan_tilt_sim.controllers.framework.shared_parameters import joint_gains
from pan_tilt_sim.controllers.framework.single_joint import PidJointController
from pan_tilt_sim.controllers.toolbox.gains import GAINS_FIELD, PID_FIELD, joint_gains_from_params
from pan_tilt_sim.controllers.toolbox.pid import Pid

INTERFACE_FIELD = 'interface_name'
# The one-joint controller each command interface stands for.
INTERFACE_CONTROLLERS: dict[str, type[CommandController]] = {
    'position': JointPositionController,
    'velocity': JointVelocityController,
    'effort': JointEffortController,
    'acceleration': JointAccelerationController,
}


class ForwardCommandController(MultiJointController):
    """One command per joint through ``interface_name``; a bad element rejects the whole command."""

    type_names = ('forward_command_controller/ForwardCommandController',)
    parameters = MultiJointController.parameters.extend(
        Param(INTERFACE_FIELD, STRING, REQUIRED, 'The command interface of every joint.',
              (not_empty(),), read_only=True, example='position'),
        *joint_gains())
    command_topic = 'commands'
    command_kind = CommandKind.FLOAT64_ARRAY
    # Set by the JointGroup*Controller types; otherwise ``interface_name`` says.
    fixed_interface: ClassVar[str | None] = None

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        interface: str = self.fixed_interface or self.params[INTERFACE_FIELD]
        self.interface_name = interface
        gains = joint_gains_from_params(self, self._joint_names)
        # Joints whose block declares ``interface`` though the simulator cannot drive it.
        self._undrivable: tuple[str, ...] = ()
        # No members for an interface the simulator cannot drive: configure() refuses it on a
        # joint (a chained reference may carry any interface its controller exports).
        member_type = INTERFACE_CONTROLLERS.get(interface)
        self._members = () if member_type is None else tuple(
            member_type(name, LoadedParameters({'joint': joint, PID_FIELD: gains.get(joint)}, []),
                        source)
            for joint in self._joint_names)
        for joint, member in zip(self._joint_names, self._members, strict=False):  # or none
            if isinstance(member, PidJointController):
                member.gains_origin = f'{name}.{GAINS_FIELD}.{joint}'

    @property
    def members(self) -> tuple[CommandController, ...]:
        """Per entry of ``joints``: its one-joint controller (PIDs may be tuned live).

        Once configured, an entry naming a reference interface has a
        :class:`ReferenceForwarder` instead.
        """
        return self._members

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return ``interface_name`` for every joint."""
        return {joint: (self.interface_name,) for joint in self._joint_names}

    def undrivable_interfaces(self) -> dict[str, str]:
        """Return ``interface_name`` for each joint it cannot drive though its block declares it."""
        return dict.fromkeys(self._undrivable, self.interface_name)

    def pids(self) -> dict[str, Pid]:
        """Return each joint's PID (none for the effort interface or the ideal actuator)."""
        return {joint: pid for member in self._members for joint, pid in member.pids().items()}

    def actuators(self) -> dict[str, Actuator]:
        """Return what drives each joint while this controller is active."""
        return {joint: actuator for member in self._members
                for joint, actuator in member.actuators().items()}

    def setpoints(self) -> dict[str, float]:
        """Return each joint's one-joint controller's setpoint."""
        return {joint: value for member in self._members
                for joint, value in member.setpoints().items()}

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind every entry to its joint or reference (named in errors as one of ``joints``).

        Refuses an ``interface_name`` the simulator cannot drive on a joint,
        naming the joint and the interface -- unless the joint's
        ``<ros2_control>`` entry declares it: then the controller configures
        with :meth:`undrivable_interfaces` naming the joint.
        """
        members: list[CommandController] = []
        undrivable: list[str] = []
        for index, entry in enumerate(self._joint_names):
            member = self._members[index] if self._members else None
            own = member.replaced if isinstance(member, ReferenceForwarder) else member
            target = self.command_target(joints, entry, self.interface_name, JOINTS_FIELD)
            if not isinstance(target, JointHandle):
                members.append(ReferenceForwarder(self.name, entry, self.interface_name, target,
                                                  own, self._source))
            elif own is None:
                if self.interface_name not in (target.declared_commands or ()):
                    raise self.error(INTERFACE_FIELD, f"joint '{entry}' interface "
                                     f"'{self.interface_name}': the simulator can drive "
                                     f'{DRIVABLE}')
                undrivable.append(entry)
            else:
                members.append(own)
        self._undrivable = tuple(undrivable)
        if undrivable:  # never activated (the manager refuses): nothing to drive or step
            members = []
        self._members = tuple(members)
        for member in members:
            member.configure(joints)

    def reset(self) -> None:
        """Every joint back to its one-joint controller's initial command."""
        for member in self._members:
            member.reset()

    def set_command(self, value: Sequence[float]) -> CommandResult:
        """Store one command per joint; reject the whole command if any element is bad."""
        members = self._members
        plural = '' if len(members) == 1 else 's'
        expected = (f'expected {len(members)} value{plural}, one per joint '
                    f"({', '.join(self._joint_names)})")
        if isinstance(value, str | bytes) or not hasattr(value, '__len__'):
            self._problem = f'ignored command {value!r}: {expected}'
            return CommandResult.REJECTED
        if len(value) != len(members):
            self._problem = f'ignored command with {len(value)} values: {expected}'
            return CommandResult.REJECTED
        for joint, element in zip(self._joint_names, value, strict=True):
            if not is_sane_number(element):
                self._problem = (f'ignored command {list(value)!r}: the value for '
                                 f"'{joint}' is not a finite number (within "
                                 f'+-{MAX_COMMAND_MAGNITUDE:g})')
                return CommandResult.REJECTED
        clamped = [joint for joint, member, element in zip(
            self._joint_names, members, value, strict=True)
            if member.set_command(element) is CommandResult.CLAMPED]
        if clamped:
            self._problem = (f'command {list(value)!r} is outside the limits of '
                             f"{', '.join(clamped)}; clamped")
            return CommandResult.CLAMPED
        return CommandResult.ACCEPTED

    def step_members(self) -> list[Controller]:
        """Return every joint's controller: the loop calls their updates directly."""
        return [inner for member in self._members for inner in member.step_members()]

    def update(self, time: float, period: float) -> None:
        """Update every joint's controller."""
        for member in self._members:
            member.update(time, period)


class ReferenceForwarder(CommandController):
    """The member of a group entry that names a reference interface: writes the command there.

    The command is any finite number within +-MAX_COMMAND_MAGNITUDE; every
    update writes the latest one to the reference.  Before the first command
    (after a reset) it writes nothing.  It has no step law, so a stepping
    loop runs it in Python, before the chainable controller that reads it.
    """

    def __init__(self, name: str, entry: str, interface: str, reference: Reference,
                 replaced: CommandController | None, source: str = '') -> None:
        super().__init__(name, {}, source)
        self.reference = reference
        # The joint member it stands in for, should the entry name a joint when configured again.
        self.replaced = replaced
        self._entry = entry
        self._interface = interface
        self._command: float | None = None

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The entry of ``joints`` (``<controller>/<dof>``); it claims no joint."""
        return (self._entry,)

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the claimed reference as ros2_control names it: ``<entry>/<interface>``."""
        return {self._entry: (self._interface,)}

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Nothing to bind: the reference was found when the group was configured."""
        self.reset()

    def reset(self) -> None:
        """Forget the command: write nothing until the next one."""
        self._command = None

    def set_command(self, value: float) -> CommandResult:
        """Store the command (NaN, Inf and huge values rejected; nothing to clamp to)."""
        if not is_sane_number(value):
            return CommandResult.REJECTED
        self._command = float(value)
        return CommandResult.ACCEPTED

    def setpoints(self) -> dict[str, float]:
        """Return the reference's present value (NaN until anything was written)."""
        return {self._entry: self.reference.value}

    def update(self, time: float, period: float) -> None:
        """Write the latest command to the reference."""
        if self._command is not None:
            self.reference.value = self._command
