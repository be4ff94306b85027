"""The shared part of the one-joint command controllers.

:class:`SingleJointController` names its joint with the ``joint`` parameter
and binds that joint's handle at configure time; :class:`PidJointController`
adds a PID whose gains come from the ``pid`` section (or the subclass's
defaults) and whose integral term is bounded by the joint's effort limit
unless the YAML gives a clamp.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from pan_tilt_sim.controllers.base import PACKAGE_INTERFACES, CommandController, JointHandle
from pan_tilt_sim.controllers.gains import PID_FIELD, gains_from_params
from pan_tilt_sim.controllers.pid import Pid, PidGains


class SingleJointController(CommandController):
    """A command controller driving the one joint its ``joint`` parameter names."""

    gains_field = PID_FIELD
    # The interface claimed unless the type's package says (effort_controllers/...).
    default_interface: ClassVar[str] = 'position'

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._joint_name = self.required_joint()
        self._handle: JointHandle | None = None

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The one joint this controller drives."""
        return (self._joint_name,)

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the one joint's interface: the type's package's, else the controller's own."""
        package = self.type_name.partition('/')[0]
        return {self._joint_name: (PACKAGE_INTERFACES.get(package, self.default_interface),)}

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
    """A one-joint controller whose effort comes from a PID."""

    default_gains: ClassVar[PidGains]

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._gains = gains_from_params(self, self.default_gains)

    @property
    def pid(self) -> Pid:
        """The PID (its gains may be changed live)."""
        return self._pid

    def pids(self) -> dict[str, Pid]:
        """Return the one joint's PID."""
        return {self._joint_name: self._pid}

    def bind(self, handle: JointHandle) -> None:
        """Build the PID, its integral bounded by the effort limit unless clamped in the YAML."""
        self._effort_limit = handle.spec.effort_limit
        self._pid = Pid(self._gains.with_default_clamp(self._effort_limit))
