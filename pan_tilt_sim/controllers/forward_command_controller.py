"""``forward_command_controller/ForwardCommandController``: one command per joint, as a group.

The controller drives the ``joints`` it names through one command
interface, ``interface_name``, and takes ``std_msgs/msg/Float64MultiArray``
commands on ``<controller>/commands``: element k is the command of the k-th
joint.  Each joint behaves exactly like the one-joint controller of its
interface (limits, ramp, actuator), which it is built from, with gains from
``gains: {<joint>: {p, i, d, i_clamp}}``:

* position and velocity: a joint with gains (there, or in
  ``gazebo_ros_control/pid_gains``) is driven by a PID on effort; one
  without by the ideal actuator (see :mod:`~pan_tilt_sim.controllers.actuator`),
  as Gazebo does.  A PID is stable while (for the position loop)
  ``d * time_step / 2 + p * time_step^2 / 4`` stays below the joint's
  effective inertia -- at the default 1 ms step and the seed's p 100, d 10,
  inertias above 0.005 kg m^2 (or 5 g on a prismatic joint); the simulation
  warns at start-up about any joint that is too light for its gains.
* effort: the command is the effort;
* acceleration: the command is integrated into the velocity target of the
  ideal velocity actuator, as ros2_control's mock hardware integrates it
  (:mod:`~pan_tilt_sim.controllers.joint_acceleration_controller`).

ros2_control lets a ``<ros2_control>`` block name any command interface, so
any ``interface_name`` is taken when the file is read; configuring the
controller refuses, naming the joint, one the simulator cannot drive
(``pid_gain``, say).  Whether the joint's block gives it the interface, and
whether the block's hardware accepts it beside the others, is the
:mod:`~pan_tilt_sim.controllers.manager`'s question when the controller is
activated.

A command of the wrong length, or with a NaN or infinite element, is
rejected whole and nothing changes.  The ``JointGroup*Controller`` types
are this controller with the interface fixed.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

from pan_tilt_sim.controllers.base import (
    MAX_COMMAND_MAGNITUDE,
    Actuator,
    CommandController,
    CommandKind,
    CommandResult,
    Controller,
    JointHandle,
    is_sane_number,
)
from pan_tilt_sim.controllers.gains import GAINS_FIELD, PID_FIELD, joint_gains_from_params
from pan_tilt_sim.controllers.joint_acceleration_controller import JointAccelerationController
from pan_tilt_sim.controllers.joint_effort_controller import JointEffortController
from pan_tilt_sim.controllers.joint_position_controller import JointPositionController
from pan_tilt_sim.controllers.joint_velocity_controller import JointVelocityController
from pan_tilt_sim.controllers.multi_joint import JOINTS_FIELD, MultiJointController
from pan_tilt_sim.controllers.pid import Pid
from pan_tilt_sim.controllers.single_joint import PidJointController

INTERFACE_FIELD = 'interface_name'
# The one-joint controller each command interface stands for.
INTERFACE_CONTROLLERS: dict[str, type[CommandController]] = {
    'position': JointPositionController,
    'velocity': JointVelocityController,
    'effort': JointEffortController,
    'acceleration': JointAccelerationController,
}
DRIVABLE = 'position, velocity, effort and acceleration'


class ForwardCommandController(MultiJointController):
    """A group of joints, commanded together through one interface."""

    type_names = ('forward_command_controller/ForwardCommandController',)
    command_topic = 'commands'
    command_kind = CommandKind.FLOAT64_ARRAY
    # Set by the JointGroup*Controller types; otherwise ``interface_name`` says.
    fixed_interface: ClassVar[str | None] = None

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        interface = self.fixed_interface or params.get(INTERFACE_FIELD)
        if not isinstance(interface, str) or not interface:
            raise self.error(INTERFACE_FIELD, f'{interface!r} must name the command interface '
                             f'to drive (the simulator can drive {DRIVABLE})')
        self.interface_name = interface
        gains = joint_gains_from_params(self, self._joint_names)
        # No members for an interface the simulator cannot drive: configure() refuses it.
        member_type = INTERFACE_CONTROLLERS.get(interface)
        self._members = () if member_type is None else tuple(
            member_type(name, {'joint': joint, PID_FIELD: gains.get(joint)}, source)
            for joint in self._joint_names)
        for joint, member in zip(self._joint_names, self._members, strict=False):  # or none
            if isinstance(member, PidJointController):
                member.gains_origin = f'{name}.{GAINS_FIELD}.{joint}'

    @property
    def members(self) -> tuple[CommandController, ...]:
        """The one-joint controller of each joint (their PIDs may be tuned live)."""
        return self._members

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return ``interface_name`` for every joint."""
        return {joint: (self.interface_name,) for joint in self._joint_names}

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
        """Bind every joint (named in errors as an entry of ``joints``).

        Refuses an ``interface_name`` the simulator cannot drive, naming the
        first joint and the interface.
        """
        for joint in self._joint_names:
            self.handle(joints, joint, JOINTS_FIELD)
        if self.interface_name not in INTERFACE_CONTROLLERS:
            raise self.error(INTERFACE_FIELD, f"joint '{self._joint_names[0]}' interface "
                             f"'{self.interface_name}': the simulator can drive {DRIVABLE}")
        for member in self._members:
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
