"""Loaded and active controllers, as ros2_control's controller_manager keeps them.

ros2_control loads the controllers a launch file's spawners name, configures
them and activates them; a controllers file may declare more (Universal
Robots' declares a trajectory controller and two forward command
controllers on the same six joints), and only one controller may claim a
joint's command interface at a time.  :class:`ControllerManager` does the
same with the controllers of one :class:`ControllersConfig`:

* ``active`` unset: every controller is active (the seeds' way), and two
  controllers claiming one joint is an error naming both and the parameter
  that chooses between them.
* ``active`` given: those are active; every other controller of a type the
  simulator has is loaded and configured but inactive -- it runs no update
  and takes no command.  One that cannot be loaded (a joint the robot lacks,
  say) is skipped with its reason, as ros2_control never loads what no
  spawner names.
* A type the simulator does not have (a vendor controller) is skipped with
  its reason when it is not active.  Listed as active, or -- with ``active``
  unset -- when no controller of the file that commands joints is of a known
  type, it ends start-up, listing the supported types.
* A controller may claim only command interfaces that the URDF's
  ``<ros2_control>`` block gives its joints (joints outside every block are
  not checked).

:meth:`ControllerManager.switch` activates and deactivates controllers at run
time, atomically, under the same rules.  An activated controller starts from
the joints' present state (a position loop holds where the joint is); a
deactivated one holds nothing: its joints keep the last command applied to
them (the last effort), as a ros2_control command interface keeps its last
value when its controller stops writing it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Mapping, Sequence

from pan_tilt_sim.controllers.base import CommandController, Controller, JointHandle
from pan_tilt_sim.controllers.registry import (
    create_controller,
    is_command_type,
    is_known_type,
    supported_types,
)
from pan_tilt_sim.errors import ControllerConfigError, ControllerSwitchError
from pan_tilt_sim.model.controller_config import ControllersConfig
from pan_tilt_sim.model.robot import RobotModel

ACTIVE_CONTROLLERS = 'active_controllers'


@dataclasses.dataclass(frozen=True)
class SkippedController:
    """A controller of the file that is not loaded, and why."""

    name: str
    type: str
    reason: str


class ControllerManager:
    """The controllers of one file: loaded, configured, and which of them are active."""

    def __init__(self, config: ControllersConfig, handles: Mapping[str, JointHandle],
                 model: RobotModel | None = None, *, active: Sequence[str] | None = None,
                 active_name: str = f"the parameter '{ACTIVE_CONTROLLERS}'") -> None:
        self._source = config.label
        self._model = model
        specs = config.controllers
        names = [spec.name for spec in specs]
        wanted = None if active is None else list(dict.fromkeys(active))
        for name in wanted or ():
            if name not in names:
                raise ControllerConfigError(
                    f"{active_name}: no controller '{name}' in {self._source} "
                    f"(its controllers: {', '.join(names)})")
        unknown = [spec for spec in specs if not is_known_type(spec.type)]
        for spec in unknown:
            if wanted is not None and spec.name in wanted:
                raise ControllerConfigError(
                    f"{self._source}: {spec.name}.type: unknown controller type '{spec.type}', "
                    f"and {active_name} lists it (supported: {', '.join(supported_types())})")
        if wanted is None:
            drivers = [spec for spec in specs if is_command_type(spec.type)]
            if drivers and all(spec in unknown for spec in drivers):
                raise ControllerConfigError(
                    f"{self._source}: {drivers[0].name}.type: unknown controller type "
                    f"'{drivers[0].type}', and no other controller in the file commands a "
                    f"joint (supported: {', '.join(supported_types())})")
        skipped = [SkippedController(spec.name, str(spec.type),
                                     'a controller type this simulator does not have')
                   for spec in unknown]
        unmovable = {joint.name: joint.kind for joint in (model.joints if model else ())
                     if not joint.kind.is_actuated}
        loaded = []
        for spec in specs:
            if spec in unknown:
                continue
            try:
                controller = create_controller(spec.name, spec.type, spec.params, self._source)
                for joint in controller.joint_names:
                    if joint in unmovable:
                        raise ControllerConfigError(
                            f"{self._source}: {spec.name}: joint '{joint}' is a "
                            f'{unmovable[joint].value} joint; a controller can only drive '
                            'revolute, continuous and prismatic joints')
                controller.configure(handles)
            except ControllerConfigError as err:
                if wanted is None or spec.name in wanted:
                    raise
                skipped.append(SkippedController(spec.name, str(spec.type),
                                                 f'cannot be loaded: {err}'))
                continue
            loaded.append(controller)
        # Command controllers first: broadcasters then sample this step's efforts.
        loaded.sort(key=lambda controller: not isinstance(controller, CommandController))
        self._controllers = loaded
        self._by_name = {controller.name: controller for controller in loaded}
        self.skipped: tuple[SkippedController, ...] = tuple(skipped)
        self._switch_listeners: list[Callable[[], None]] = []
        active_names = set(self._by_name) if wanted is None else set(wanted)
        problem = self._problem(active_names)
        if problem is not None:
            joint, first, second, interface = problem
            if interface is not None:
                raise ControllerConfigError(self._interface_problem(first, joint, interface))
            if wanted is None:
                raise ControllerConfigError(
                    f"{self._source}: joint '{joint}' is claimed by both '{first}' and "
                    f"'{second}': ros2_control loads both but activates only the ones a spawner "
                    f'names; list those in {active_name}')
            raise ControllerConfigError(
                f"{active_name}: '{first}' and '{second}' both claim joint '{joint}'; "
                'only one active controller can command a joint')
        self._set_active(active_names)

    @property
    def controllers(self) -> list[Controller]:
        """Every loaded controller, active or not (command controllers first)."""
        return list(self._controllers)

    @property
    def active(self) -> list[Controller]:
        """The active controllers, in update order (command controllers first)."""
        return list(self._active)

    @property
    def updates(self) -> list[Callable[[float, float], None]]:
        """The update methods of the active controllers, in order (for the stepping loop)."""
        return self._updates

    def controller(self, name: str) -> Controller:
        """Return the loaded controller called ``name``; KeyError if there is none."""
        return self._by_name[name]

    def is_active(self, name: str) -> bool:
        """Whether the loaded controller ``name`` is active."""
        return name in self._active_names

    def switch(self, activate: Iterable[str] = (), deactivate: Iterable[str] = ()) -> None:
        """Deactivate, then activate, controllers: all or nothing.

        Raises :class:`ControllerSwitchError` (and changes nothing) when a name
        is not a loaded controller, or when afterwards a joint would be
        claimed by two active controllers or lack an interface one claims.
        Activated controllers start from the joints' present state;
        deactivated ones leave their joints with the last command applied.
        """
        activate, deactivate = list(activate), list(deactivate)
        for name in (*activate, *deactivate):
            if name not in self._by_name:
                raise ControllerSwitchError(
                    f"no loaded controller '{name}' (loaded: {', '.join(self._by_name)})")
        names = (self._active_names - set(deactivate)) | set(activate)
        problem = self._problem(names)
        if problem is not None:
            joint, first, second, interface = problem
            if interface is not None:
                raise ControllerSwitchError(self._interface_problem(first, joint, interface))
            raise ControllerSwitchError(
                f"'{first}' and '{second}' would both claim joint '{joint}'; "
                'only one active controller can command a joint')
        started = names - self._active_names
        self._set_active(names)
        for controller in self._active:
            if controller.name in started:
                controller.reset()
        for listener in self._switch_listeners:
            listener()

    def add_switch_listener(self, listener: Callable[[], None]) -> None:
        """Call ``listener()`` after every switch (the simulation re-drives the joints)."""
        self._switch_listeners.append(listener)

    def _set_active(self, names: set[str]) -> None:
        self._active_names = frozenset(names)
        self._active = [c for c in self._controllers if c.name in self._active_names]
        self._updates = [controller.update for controller in self._active]

    def _problem(self, names: set[str]) -> tuple[str, str, str | None, str | None] | None:
        """Return what is wrong with ``names`` as the active set, or None.

        (joint, controller, other controller, None) for a joint claimed twice,
        (joint, controller, None, interface) for an interface the joint lacks.
        """
        owners: dict[str, str] = {}
        for controller in self._controllers:
            if controller.name not in names:
                continue
            for joint in controller.joint_names:
                if joint in owners:
                    return joint, owners[joint], controller.name, None
                owners[joint] = controller.name
            for joint, interfaces in controller.command_interfaces().items():
                for interface in interfaces:
                    if interface not in self._interfaces_of(joint, interface):
                        return joint, controller.name, None, interface
        return None

    def _interfaces_of(self, joint: str, interface: str) -> tuple[str, ...]:
        """Return the joint's command interfaces in the URDF (outside every block: any)."""
        control = self._model.control_joint(joint) if self._model is not None else None
        return (interface,) if control is None else control.command_interface_names

    def _interface_problem(self, name: str, joint: str, interface: str) -> str:
        controller = self._by_name[name]
        has = ', '.join(self._interfaces_of(joint, interface)) or 'none'
        return (f"{self._source}: {name} ({controller.type_name}) claims the '{interface}' "
                f"command interface of joint '{joint}', which the URDF's <ros2_control> block "
                f'does not give it (its command interfaces: {has})')
