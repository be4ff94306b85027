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
* The block's hardware may refuse a combination of command interfaces --
  two on one joint, different command modes on its joints -- as its
  ``prepare_command_mode_switch`` does; which hardware refuses what, and
  why the simulator follows it, is in :mod:`pan_tilt_sim.model.command_modes`.
  The start-up active set is asked as one switch that starts all of them
  (as one spawner activating them as a group).

:meth:`ControllerManager.switch` activates and deactivates controllers at run
time, atomically, under the same rules.  An activated controller starts from
the joints' present state (a position loop holds where the joint is); a
deactivated one holds nothing: its joints keep the last command applied to
them (the last effort), as a ros2_control command interface keeps its last
value when its controller stops writing it.

Each loaded controller has ros2_control's lifecycle state
(:data:`UNCONFIGURED`, :data:`INACTIVE`, :data:`ACTIVE`): :meth:`load`,
:meth:`configure`, :meth:`cleanup`, :meth:`unload` and :meth:`switch`
follow controller_manager's rules, so that its services can be served from
here.  With ``autostart`` false nothing is loaded at start-up -- as with
gz_ros2_control, whose controller_manager waits for spawners -- and the
file's controllers are only :attr:`ControllerManager.declared`, for
:meth:`load` to take their type and parameters from.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.base import CommandController, Controller, JointHandle
from pan_tilt_sim.controllers.registry import (
    create_controller,
    is_command_type,
    is_known_type,
    supported_types,
)
from pan_tilt_sim.errors import ControllerConfigError, ControllerSwitchError
from pan_tilt_sim.model.command_modes import (
    SWITCH_REJECTED,
    Claim,
    mode_switch_refusal,
    system_claims,
)
from pan_tilt_sim.model.controller_config import ControllersConfig, ControllerSpec
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.schedule import PeriodicSchedule

ACTIVE_CONTROLLERS = 'active_controllers'
# ros2_control's lifecycle labels (controller_manager_msgs/ControllerState.state).
UNCONFIGURED = 'unconfigured'
INACTIVE = 'inactive'
ACTIVE = 'active'


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
                 active_name: str = f"the parameter '{ACTIVE_CONTROLLERS}'",
                 autostart: bool = True) -> None:
        self._source = config.label
        self._model = model
        self._handles = handles
        # The file's controllers by name: what load() takes a type and parameters from.
        self.declared: dict[str, ControllerSpec] = {spec.name: spec
                                                    for spec in config.controllers}
        self.update_rate = config.update_rate
        self._unmovable = {joint.name: joint.kind for joint in (model.joints if model else ())
                           if not joint.kind.is_actuated}
        self._controllers: list[Controller] = []
        self._by_name: dict[str, Controller] = {}
        self._states: dict[str, str] = {}
        self._switch_listeners: list[Callable[[], None]] = []
        self._set_active(set())
        self.skipped: tuple[SkippedController, ...] = ()
        if autostart:
            self._start(config.controllers, active, active_name)

    def _start(self, specs: Sequence[ControllerSpec], active: Sequence[str] | None,
               active_name: str) -> None:
        """Load and configure the file's controllers; activate ``active`` (None: all)."""
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
        for spec in specs:
            if spec in unknown:
                continue
            try:
                controller = self._create(spec.name, spec.type, spec.params, self._source)
                controller.configure(self._handles)
            except ControllerConfigError as err:
                if wanted is None or spec.name in wanted:
                    raise
                skipped.append(SkippedController(spec.name, str(spec.type),
                                                 f'cannot be loaded: {err}'))
                continue
            self._add(controller, INACTIVE)
        self.skipped = tuple(skipped)
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
        refusal = self._hardware_refusal([name for name in self._by_name if name in active_names],
                                         [])
        if refusal is not None:
            where = self._source if wanted is None else active_name
            raise ControllerConfigError(f'{where}: {refusal}')
        self._set_active(active_names)

    @property
    def controllers(self) -> list[Controller]:
        """Every loaded controller, in any state (command controllers first)."""
        return list(self._controllers)

    @property
    def configured(self) -> list[Controller]:
        """The loaded controllers that are configured: inactive or active."""
        return [c for c in self._controllers if self._states[c.name] != UNCONFIGURED]

    @property
    def active(self) -> list[Controller]:
        """The active controllers, in update order (command controllers first)."""
        return list(self._active)

    @property
    def updates(self) -> list[Callable[[float, float], None]]:
        """What the stepping loop calls every step for the active controllers, in order."""
        return self._updates

    @property
    def step_members(self) -> list[Controller]:
        """The controllers whose updates :attr:`updates` are, in the same order."""
        return self._step_members

    @property
    def scheduled_updates(self) -> list[tuple[PeriodicSchedule, Callable[[float, float], None]]]:
        """The active controllers on a schedule, each with its update (called when due).

        They run after :attr:`updates` each step (they are the broadcasters,
        which sample what the command controllers just computed).
        """
        return self._scheduled

    def controller(self, name: str) -> Controller:
        """Return the loaded controller called ``name``; KeyError if there is none."""
        return self._by_name[name]

    def is_active(self, name: str) -> bool:
        """Whether the loaded controller ``name`` is active."""
        return name in self._active_names

    def is_loaded(self, name: str) -> bool:
        """Whether a controller called ``name`` is loaded (in any state)."""
        return name in self._by_name

    def state(self, name: str) -> str:
        """Return the lifecycle state of the loaded controller ``name``; KeyError if none."""
        return self._states[name]

    # --- lifecycle, as controller_manager's services -------------------------------------

    def load(self, name: str, type_name: Any, params: Mapping[str, Any],
             source: str = '') -> Controller:
        """Create controller ``name`` of ``type_name`` from ``params``: it is unconfigured.

        Raises :class:`ControllerConfigError` for a name already loaded, a type
        the simulator does not have, or parameters the type refuses.
        """
        if name in self._by_name:
            raise ControllerConfigError(f"a controller named '{name}' was already loaded")
        controller = self._create(name, type_name, params, source or self._source)
        self._add(controller, UNCONFIGURED)
        return controller

    def configure(self, name: str) -> Controller:
        """Bind an unconfigured or inactive controller to its joints: it becomes inactive.

        An inactive one is cleaned up first and configured afresh.  Raises
        :class:`ControllerConfigError` for an unknown or an active controller,
        or a joint the robot lacks (the controller is then unconfigured).
        """
        controller = self._loaded(name, 'configure')
        if self._states[name] == ACTIVE:
            raise ControllerConfigError(
                f"controller '{name}' can not be configured from '{ACTIVE}' state")
        self._states[name] = UNCONFIGURED
        controller.configure(self._handles)
        self._states[name] = INACTIVE
        return controller

    def cleanup(self, name: str) -> Controller:
        """Return an inactive controller to unconfigured (an unconfigured one stays so)."""
        controller = self._loaded(name, 'cleanup')
        if self._states[name] == ACTIVE:
            raise ControllerConfigError(
                f"controller '{name}' can not be cleaned-up from '{ACTIVE}' state")
        self._states[name] = UNCONFIGURED
        return controller

    def unload(self, name: str) -> Controller:
        """Remove a controller that is not active."""
        controller = self._loaded(name, 'unload')
        if self._states[name] == ACTIVE:
            raise ControllerConfigError(
                f"could not unload controller with name '{name}' because it is still active")
        self._controllers.remove(controller)
        del self._by_name[name], self._states[name]
        return controller

    def switch(self, activate: Iterable[str] = (), deactivate: Iterable[str] = (), *,
               strict: bool = True) -> list[str]:
        """Deactivate, then activate, controllers: all or nothing.

        As controller_manager's switch_controller: every name must be a loaded
        controller, every one to activate inactive (or active and being
        deactivated in the same call), every one to deactivate active.
        ``strict`` (STRICT): any of these problems refuses the whole switch;
        otherwise (BEST_EFFORT) the controllers concerned are left out -- one
        line each in the returned list -- and only a list naming no loaded
        controller at all is refused.  Either way the switch is refused when
        afterwards a joint would be claimed by two active controllers or lack
        an interface one claims, or when a ``<ros2_control>`` block's hardware
        refuses the interfaces it starts and stops
        (:mod:`~pan_tilt_sim.model.command_modes`).  Refusals raise
        :class:`ControllerSwitchError` and change nothing.  Activated
        controllers start from the joints' present state; deactivated ones
        leave their joints with the last command applied.
        """
        activate, deactivate = list(dict.fromkeys(activate)), list(dict.fromkeys(deactivate))
        dropped: list[str] = []

        def refuse(problem: str) -> None:
            if strict:
                raise ControllerSwitchError(problem)
            dropped.append(problem)

        for action, names in (('deactivate', deactivate), ('activate', activate)):
            unknown = [name for name in names if name not in self._by_name]
            for name in unknown:
                problem = (f"could not {action} controller with name '{name}' because no "
                           'controller with this name exists (loaded: '
                           f"{', '.join(self._by_name) or 'none'})")
                if len(unknown) == len(names):
                    raise ControllerSwitchError(problem)
                refuse(problem)
            names[:] = [name for name in names if name in self._by_name]
        for name in list(deactivate):
            if self._states[name] != ACTIVE:
                deactivate.remove(name)
                refuse(f"could not deactivate controller '{name}' since it is not active")
        for name in list(activate):
            state = self._states[name]
            if state == ACTIVE and name not in deactivate:
                activate.remove(name)
                refuse(f"could not activate controller '{name}' since it is already active")
            elif state == UNCONFIGURED:
                activate.remove(name)
                refuse(f"could not activate controller '{name}': it is unconfigured and must "
                       "be configured (to 'inactive') first")
        names = (self._active_names - set(deactivate)) | set(activate)
        problem = self._problem(names)
        if problem is not None:
            joint, first, second, interface = problem
            if interface is not None:
                raise ControllerSwitchError(self._interface_problem(first, joint, interface))
            raise ControllerSwitchError(
                f"'{first}' and '{second}' would both claim joint '{joint}'; "
                'only one active controller can command a joint')
        refusal = self._hardware_refusal(activate, deactivate)
        if refusal is not None:
            raise ControllerSwitchError(refusal)
        stopped = [self._by_name[name] for name in deactivate]
        started = set(activate)
        self._set_active(names)
        for controller in stopped:
            controller.deactivate()
        for controller in self._active:
            if controller.name in started:
                controller.reset()
        for listener in self._switch_listeners:
            listener()
        return dropped

    def add_switch_listener(self, listener: Callable[[], None]) -> None:
        """Call ``listener()`` after every switch (the simulation re-drives the joints)."""
        self._switch_listeners.append(listener)

    def _set_active(self, names: set[str]) -> None:
        self._active_names = frozenset(names)
        for name, state in self._states.items():
            if name in names:
                self._states[name] = ACTIVE
            elif state == ACTIVE:
                self._states[name] = INACTIVE
        self._active = [c for c in self._controllers if c.name in self._active_names]
        self._step_members = [member for controller in self._active
                              for member in controller.step_members()]
        self._updates = [member.update for member in self._step_members]
        self._scheduled = [(schedule, controller.update) for controller in self._active
                           if (schedule := controller.schedule()) is not None]

    def _loaded(self, name: str, action: str) -> Controller:
        try:
            return self._by_name[name]
        except KeyError:
            raise ControllerConfigError(
                f"could not {action} controller with name '{name}' because no controller "
                'with this name exists') from None

    def _create(self, name: str, type_name: Any, params: Mapping[str, Any],
                source: str) -> Controller:
        controller = create_controller(name, type_name, params, source)
        for joint in controller.joint_names:
            if joint in self._unmovable:
                raise ControllerConfigError(
                    f"{source}: {name}: joint '{joint}' is a "
                    f'{self._unmovable[joint].value} joint; a controller can only drive '
                    'revolute, continuous and prismatic joints')
        return controller

    def _add(self, controller: Controller, state: str) -> None:
        self._controllers.append(controller)
        # Command controllers first: broadcasters then sample this step's efforts.
        self._controllers.sort(key=lambda c: not isinstance(c, CommandController))
        self._by_name[controller.name] = controller
        self._states[controller.name] = state

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

    def _hardware_refusal(self, activate: Sequence[str], deactivate: Sequence[str]) -> str | None:
        """Return why a ``<ros2_control>`` block's hardware refuses this switch, or None.

        As controller_manager, the interfaces of the controllers to activate
        are started and those of the controllers to deactivate stopped (both
        for a controller restarted), and every block is asked about its own.
        """
        if self._model is None:
            return None
        start, stop = self._claims(activate), self._claims(deactivate)
        in_use = self._claims(self._active_names)
        for system in self._model.ros2_control:
            own = system_claims(system)
            refusal = mode_switch_refusal(
                system, [claim for claim in start if claim in own],
                [claim for claim in stop if claim in own], own.intersection(in_use))
            if refusal is not None:
                return f'{SWITCH_REJECTED}: {refusal}'
        return None

    def _claims(self, names: Iterable[str]) -> list[Claim]:
        """Return the command interfaces the controllers ``names`` claim, in their order."""
        return [(joint, interface) for name in names
                for joint, interfaces in self._by_name[name].command_interfaces().items()
                for interface in interfaces]

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
