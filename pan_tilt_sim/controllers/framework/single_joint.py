"""The shared part of the one-joint command controllers.

:class:`SingleJointController` names its joint with the ``joint`` parameter
and binds that joint's handle at configure time.  :class:`PidJointController`
drives its joint by a PID on effort when gains are given for it -- its
``pid`` section, else ``gazebo_ros_control/pid_gains/<joint>`` -- and
otherwise by the ideal actuator (:mod:`pan_tilt_sim.controllers.toolbox.actuator`);
on the effort interface (the ``effort_controllers/`` types) it always uses a
PID, with the subclass's default gains when none are given.  The PID's
integral term is bounded by the joint's effort limit unless the YAML gives a
clamp.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from pan_tilt_sim.controllers.framework.base import (
    PACKAGE_INTERFACES,
    Actuator,
    ActuatorKind,
    CommandController,
    JointHandle,
)
from pan_tilt_sim.controllers.framework.parameter_spec import ParameterSpec
from pan_tilt_sim.controllers.framework.shared_parameters import JOINT, pid_gains
from pan_tilt_sim.controllers.toolbox.gains import PID_FIELD, choose_gains, gains_from_params
from pan_tilt_sim.controllers.toolbox.pid import Pid, PidGains

EFFORT_INTERFACE = 'effort'


class SingleJointController(CommandController):
    """A command controller driving the one joint its ``joint`` parameter names."""

    gains_field = PID_FIELD
    parameters = ParameterSpec([JOINT])
    # The interface claimed unless the type's package says (effort_controllers/...).
    default_interface: ClassVar[str] = 'position'

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._joint_name: str = self.params['joint']
        self._handle: JointHandle | None = None

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The one joint this controller drives."""
        return (self._joint_name,)

    @property
    def interface(self) -> str:
        """The command interface: the type's package's, else the controller's own."""
        package = self.type_name.partition('/')[0]
        return PACKAGE_INTERFACES.get(package, self.default_interface)

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the one joint's interface (see :attr:`interface`)."""
        return {self._joint_name: (self.interface,)}

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the joint's handle (and what :meth:`bind` derives from it), then reset."""
        handle = self.handle(joints, self._joint_name, 'joint')
        self._handle = handle
        self.bind(handle)
        self.reset()

    def bind(self, handle: JointHandle) -> None:  # noqa: B027 -- optional hook
        """Take what the controller needs from the joint's handle (limits, say)."""

    def setpoints(self) -> dict[str, float]:
        """Return the joint's present command (see :meth:`CommandController.setpoints`)."""
        return {self._joint_name: self._command}


class PidJointController(SingleJointController):
    """A one-joint controller: a PID on effort when it has gains, else the ideal actuator."""

    parameters = SingleJointController.parameters.extend(*pid_gains(PID_FIELD))
    default_gains: ClassVar[PidGains]
    pid_kind: ClassVar[ActuatorKind]
    ideal_kind: ClassVar[ActuatorKind]

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._own_gains = gains_from_params(self, None)
        self._pid: Pid | None = None
        self._actuator = Actuator()
        # Where the own gains are written (a group controller names its ``gains.<joint>``).
        self.gains_origin = f'{name}.{PID_FIELD}'

    @property
    def pid(self) -> Pid | None:
        """The PID (its gains may be changed live); None when the ideal actuator drives."""
        return self._pid

    @property
    def ideal(self) -> bool:
        """Whether the ideal actuator drives the joint (no PID gains for it)."""
        return self._pid is None

    def pids(self) -> dict[str, Pid]:
        """Return the one joint's PID, if it has one."""
        return {} if self._pid is None else {self._joint_name: self._pid}

    def actuators(self) -> dict[str, Actuator]:
        """Return what drives the joint while this controller is active."""
        return {self._joint_name: self._actuator}

    def bind(self, handle: JointHandle) -> None:
        """Choose PID or ideal actuator; a PID's integral is bounded by the effort limit."""
        self._effort_limit = handle.spec.effort_limit
        self._tracking_gain = handle.tracking_gain
        default = self.default_gains if self.interface == EFFORT_INTERFACE else None
        gains, source = choose_gains(self._own_gains, self.gains_origin, handle, default)
        if gains is None:
            self._pid = None
            self._actuator = Actuator(self.ideal_kind, self.name)
        else:
            self._pid = Pid(gains.with_default_clamp(self._effort_limit))
            self._actuator = Actuator(self.pid_kind, self.name, self._pid, source)
