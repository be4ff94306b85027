"""Loaded and active controllers, as ros2_control's controller_manager keeps them (no ROS).

ros/controller_manager.py is the ROS node that serves this bookkeeping.

ros2_control loads the controllers a launch file's spawners name, configures
them and activates them; a controllers file may declare more (Universal
Robots' declares a trajectory controller and two forward command
controllers on the same six joints), and only one controller may claim a
joint's command interface at a time.  :class:`ControllerManager` does the
same with the controllers of one :class:`ControllersConfig`: which are active,
which interfaces each may claim, the lifecycle states (:data:`UNCONFIGURED`,
:data:`INACTIVE`, :data:`ACTIVE`), atomic switches and chaining follow
controller_manager's rules (see the design notes).

Design notes: docs/design/controllers.md#managerpy.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.framework.base import Controller, JointHandle, Reference
from pan_tilt_sim.controllers.framework.hardware_interfaces import (
    DRIVABLE,
    NO_HARDWARE,
    HardwareInterfaces,
)
from pan_tilt_sim.controllers.framework.registry import (
    create_controller,
    is_command_type,
    is_known_type,
    supported_types,
)
from pan_tilt_sim.errors import ControllerConfigError, ControllerSwitchError
from pan_tilt_sim.model import ros1_diff_drive
from pan_tilt_sim.model.command_modes import (
    SWITCH_REJECTED,
    Claim,
    mode_switch_refusal,
    system_claims,
)
from pan_tilt_sim.model.controller_config import (
    UPDATE_RATE_FIELD,
    ControllersConfig,
    ControllerSpec,
)
from pan_tilt_sim.model.rates import rate_problem
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.schedule import DUE_EPSILON, PeriodicSchedule, steps_per_update

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


@dataclasses.dataclass(frozen=True)
class SwitchPlan:
    """A switch :meth:`ControllerManager.plan_switch` accepted, ready to be carried out."""

    activate: tuple[str, ...]
    deactivate: tuple[str, ...]
    # The active set afterwards.
    active: frozenset[str]
    # BEST_EFFORT: one line per controller left out, and why.
    dropped: tuple[str, ...]


@dataclasses.dataclass(frozen=True)
class _StartPlan:
    """What start-up loads and activates, decided from the file before anything is loaded."""

    specs: tuple[ControllerSpec, ...]
    # The names to activate, in order; None: every controller loaded.
    wanted: tuple[str, ...] | None
    # The controllers of types the simulator does not have (skipped).
    unknown: tuple[ControllerSpec, ...]
    # How the list of names to activate is called in messages.
    active_name: str

    def leaves_out(self, name: str) -> bool:
        """Whether start-up may go on without the controller ``name`` (it names others)."""
        return self.wanted is not None and name not in self.wanted


@dataclasses.dataclass(frozen=True)
class _StartActivation:
    """The start-up active set, and the controllers left inactive because they are refused."""

    active: frozenset[str]
    refused: dict[str, str]


class _Refusals:
    """A switch's refusals: STRICT raises the first; BEST_EFFORT collects them all."""

    def __init__(self, strict: bool) -> None:
        self.strict = strict
        self.dropped: list[str] = []

    def __call__(self, problem: str) -> None:
        if self.strict:
            raise ControllerSwitchError(problem)
        self.dropped.append(problem)


class ControllerManager:
    """The controllers of one file: loaded, configured, and which of them are active."""

    def __init__(self, config: ControllersConfig, handles: Mapping[str, JointHandle],
                 model: RobotModel | None = None, *, active: Sequence[str] | None = None,
                 active_name: str = f"the parameter '{ACTIVE_CONTROLLERS}'",
                 autostart: bool = True,
                 hardware: HardwareInterfaces = NO_HARDWARE,
                 time_step: float | None = None) -> None:
        self._source = config.label
        # The physics step (s) the controllers' clocks count in; None: every controller
        # updates at every step (a manager driven by hand, without physics).
        self._time_step = time_step
        # Each loaded controller's update_rate (Hz) as its parameters give it; None: none
        # given (a ROS 1 file), every physics step.
        self._rates: dict[str, float | None] = {}
        # One line each: a rate whose period is not a whole number of physics steps, and
        # what the controllers on it do instead (the start-up log says them).
        self.clock_notes: list[str] = []
        self._model = model
        self._handles = handles
        # The robot's <ros2_control> sensors and gpios, offered to every controller.
        self.hardware = hardware
        # The file's controllers by name: what load() takes a type and parameters from.
        self.declared: dict[str, ControllerSpec] = {spec.name: spec
                                                    for spec in config.controllers}
        self.update_rate = config.update_rate
        self._unmovable = {joint.name: joint.kind for joint in (model.joints if model else ())
                           if not joint.kind.is_actuated}
        self._controllers: list[Controller] = []
        self._by_name: dict[str, Controller] = {}
        self._states: dict[str, str] = {}
        # Per configured controller, the references it was configured against, by full name.
        self._bound: dict[str, dict[str, Reference]] = {}
        self._switch_listeners: list[Callable[[], None]] = []
        self._set_active(set())
        self.skipped: tuple[SkippedController, ...] = ()
        # Start-up: configured controllers left inactive because activating them is refused,
        # by name, with the one line that says why (see activation_refusal).
        self.refused: dict[str, str] = {}
        if autostart:
            self._start(config.controllers, active, active_name)

    def _start(self, specs: Sequence[ControllerSpec], active: Sequence[str] | None,
               active_name: str) -> None:
        """Load and configure the file's controllers; activate ``active`` (None: all).

        Validate the file, load what it declares, validate the active set, apply it.
        """
        plan = self._plan_start(specs, active, active_name)
        self._load_start(plan)
        activation = self._plan_start_activation(plan)
        self.refused = activation.refused
        self._change_active(set(activation.active), set())
        self.clock_notes = self._clock_notes(self.configured)

    def _plan_start(self, specs: Sequence[ControllerSpec], active: Sequence[str] | None,
                    active_name: str) -> _StartPlan:
        """Return what start-up loads and activates; refuse a file that cannot start.

        Pure: checks the names ``active`` lists and the file's unknown types.
        """
        names = [spec.name for spec in specs]
        wanted = None if active is None else tuple(dict.fromkeys(active))
        for name in wanted or ():
            if name not in names:
                raise ControllerConfigError(
                    f"{active_name}: no controller '{name}' in {self._source} "
                    f"(its controllers: {', '.join(names)})")
        unknown = tuple(spec for spec in specs if not is_known_type(spec.type))
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
        return _StartPlan(tuple(specs), wanted, unknown, active_name)

    def _load_start(self, plan: _StartPlan) -> None:
        """Load, then configure, the plan's controllers of known types; set :attr:`skipped`.

        A controller that fails ends start-up when the plan activates it;
        otherwise it is skipped, with the reason.
        """
        failures: dict[str, str] = {}

        def fail(spec: ControllerSpec, err: ControllerConfigError) -> None:
            if not plan.leaves_out(spec.name):
                raise err
            failures[spec.name] = f'cannot be loaded: {err}'

        # All loaded before any is configured: a preceding controller needs the
        # references of the ones it feeds, wherever the file declares them.
        loaded: list[tuple[ControllerSpec, Controller]] = []
        for spec in plan.specs:
            if spec in plan.unknown:
                continue
            try:
                controller = self._create(spec.name, spec.type, spec.params, self._source)
            except ControllerConfigError as err:
                fail(spec, err)
                continue
            self._add(controller, UNCONFIGURED)
            loaded.append((spec, controller))
        for spec, controller in loaded:
            try:
                self._configure(controller)
            except ControllerConfigError as err:
                self.unload(controller.name)
                fail(spec, err)
        self.skipped = tuple(
            [SkippedController(spec.name, str(spec.type),
                               'a controller type this simulator does not have')
             for spec in plan.unknown]
            + [SkippedController(spec.name, str(spec.type), failures[spec.name])
               for spec in plan.specs if spec.name in failures])

    def _plan_start_activation(self, plan: _StartPlan) -> _StartActivation:
        """Return the start-up active set of the loaded controllers; refuse one that cannot run.

        Pure: a controller the plan activates by default whose activation is
        refused stays inactive (in the result's ``refused``).
        """
        wanted, active_name = plan.wanted, plan.active_name
        active_names = set(self._by_name) if wanted is None else set(wanted)
        refused = {name: refusal for name in self._by_name if name in active_names
                   and (refusal := self.activation_refusal(name)) is not None}
        for name in wanted or ():
            if name in refused:
                raise ControllerConfigError(f'{active_name}: {refused[name]}')
        active_names -= set(refused)
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
        for name in active_names:
            following = self._following_problem(name, active_names, set())
            if following is not None:
                raise ControllerConfigError(
                    f"{active_name}: could not activate controller with name '{name}': "
                    f'{following}')
        chain = self._chain_problem(active_names)
        if chain is not None:
            raise ControllerConfigError(f'{active_name}: {chain}')
        refusal = self._hardware_refusal([name for name in self._by_name if name in active_names],
                                         [])
        if refusal is not None:
            where = self._source if wanted is None else active_name
            raise ControllerConfigError(f'{where}: {refusal}')
        return _StartActivation(frozenset(active_names), refused)

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
    def step_clocks(self) -> list[tuple[int, float]]:
        """Each of :attr:`step_members`' clock: (update every so many physics steps, period s).

        The period is that many physics steps: the time since the last update.
        """
        return self._step_clocks

    @property
    def actuations(self) -> list[Callable[[float], None]]:
        """What the hardware does every physics step with held commands, in update order.

        The :meth:`~pan_tilt_sim.controllers.framework.base.Controller.actuation` of every
        step member that updates less often than every physics step; called
        with the physics step (s) after the step's updates.
        """
        return self._actuations

    def update_rate_of(self, name: str) -> float | None:
        """Return the rate (Hz) the loaded controller ``name`` updates at.

        Its own ``update_rate``, else the controller_manager's (a ros2_control
        style file gives every controller that one); None for a ROS 1 file's
        controller, which updates at every physics step.
        """
        return self._rates[name]

    def clock_of(self, controller: Controller) -> tuple[int, float]:
        """Return the loaded ``controller``'s clock: (every so many physics steps, period s).

        Every step for a ROS 1 file's controller, and for one that keeps its
        rate itself (:attr:`~pan_tilt_sim.controllers.framework.base.Controller.own_clock`);
        otherwise the first step at which ``1 / update_rate`` has passed since
        the last update, as gz_ros2_control counts (at least one step).
        """
        dt = self._time_step
        rate = self._rates.get(controller.name)
        if dt is None:
            return 1, 0.0
        if rate is None or controller.own_clock:
            return 1, dt
        steps = steps_per_update(1.0 / rate, dt)
        return steps, steps * dt

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

    def chain_connections(self, name: str) -> dict[str, tuple[str, ...]]:
        """Return the controllers the loaded controller ``name`` precedes, with what it claims.

        By following controller (in claim order): the full names of the
        reference interfaces ``name`` claims of it.  As controller_manager, a
        claimed interface is a reference interface when its first name part
        (before the first '/') is a loaded controller's name -- unless it is
        a joint of the robot.
        """
        connections: dict[str, list[str]] = {}
        for entry, interfaces in self._by_name[name].command_interfaces().items():
            if entry in self._handles or entry in self.hardware.gpios:
                continue
            owner = entry.partition('/')[0]
            if owner != name and owner in self._by_name:
                connections.setdefault(owner, []).extend(
                    f'{entry}/{interface}' for interface in interfaces)
        return {owner: tuple(claimed) for owner, claimed in connections.items()}

    def references(self) -> dict[str, Reference]:
        """Return every reference interface the loaded controllers export, by full name."""
        return {name: reference for controller in self._controllers
                for name, reference in controller.reference_interfaces().items()}

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
        controller.notices.extend(self._clock_notes([controller]))
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
        self._configure(controller)
        return controller

    def _configure(self, controller: Controller) -> None:
        """Configure ``controller`` against the joints and the loaded controllers' references."""
        name = controller.name
        self._states[name] = UNCONFIGURED
        self._bound.pop(name, None)
        references = self.references()
        controller.set_available_references(references)
        controller.set_hardware(self.hardware)
        controller.configure(self._handles)
        self._bound[name] = {claimed: references[claimed] for entry, interfaces
                             in controller.command_interfaces().items()
                             if entry not in self._handles for interface in interfaces
                             if (claimed := f'{entry}/{interface}') in references}
        self._states[name] = INACTIVE

    def cleanup(self, name: str) -> Controller:
        """Return an inactive controller to unconfigured (an unconfigured one stays so)."""
        controller = self._loaded(name, 'cleanup')
        if self._states[name] == ACTIVE:
            raise ControllerConfigError(
                f"controller '{name}' can not be cleaned-up from '{ACTIVE}' state")
        self._states[name] = UNCONFIGURED
        self._bound.pop(name, None)
        return controller

    def unload(self, name: str) -> Controller:
        """Remove a controller that is not active."""
        controller = self._loaded(name, 'unload')
        if self._states[name] == ACTIVE:
            raise ControllerConfigError(
                f"could not unload controller with name '{name}' because it is still active")
        self._controllers.remove(controller)
        del self._by_name[name], self._states[name], self._rates[name]
        self._bound.pop(name, None)
        return controller

    def switch(self, activate: Iterable[str] = (), deactivate: Iterable[str] = (), *,
               strict: bool = True) -> list[str]:
        """Deactivate, then activate, controllers: all or nothing.

        As controller_manager's switch_controller: every name must be a loaded
        controller, every one to activate inactive (or active and being
        deactivated in the same call), every one to deactivate active.
        So must the chains (see the module's description): a controller whose
        following controllers would not all be active, or a following
        controller whose active preceding controller stays active.
        ``strict`` (STRICT): any of these problems refuses the whole switch;
        otherwise (BEST_EFFORT) the controllers concerned are left out -- one
        line each in the returned list -- and only a list naming no loaded
        controller at all is refused.  Either way the switch is refused when
        afterwards a joint would be claimed by two active controllers or lack
        an interface one claims, a claimed reference interface would be
        missing, or a ``<ros2_control>`` block's hardware refuses the
        interfaces it starts and stops (:mod:`~pan_tilt_sim.model.command_modes`).
        Refusals raise :class:`ControllerSwitchError` and change nothing.
        Activated controllers start from the joints' present state;
        deactivated ones leave their joints with the last command applied.
        """
        plan = self.plan_switch(activate, deactivate, strict=strict)
        self._change_active(set(plan.active), set(plan.activate))
        for listener in self._switch_listeners:
            listener()
        return list(plan.dropped)

    def plan_switch(self, activate: Iterable[str] = (), deactivate: Iterable[str] = (), *,
                    strict: bool = True) -> SwitchPlan:
        """Return what :meth:`switch` would do, or raise what it would raise; change nothing.

        Its validation step: the controllers left out (BEST_EFFORT), then the
        resulting active set's joints, chains and hardware.
        """
        refuse = _Refusals(strict)
        activate, deactivate = list(dict.fromkeys(activate)), list(dict.fromkeys(deactivate))
        self._drop_unloaded(activate, deactivate, refuse)
        self._drop_by_state(activate, deactivate, refuse)
        self._drop_broken_chains(activate, deactivate, refuse)
        names = (self._active_names - set(deactivate)) | set(activate)
        problem = self._problem(names)
        if problem is not None:
            joint, first, second, interface = problem
            if interface is not None:
                raise ControllerSwitchError(self._interface_problem(first, joint, interface))
            raise ControllerSwitchError(
                f"'{first}' and '{second}' would both claim joint '{joint}'; "
                'only one active controller can command a joint')
        chain = self._chain_problem(names)
        if chain is not None:
            raise ControllerSwitchError(chain)
        refusal = self._hardware_refusal(activate, deactivate)
        if refusal is not None:
            raise ControllerSwitchError(refusal)
        return SwitchPlan(tuple(activate), tuple(deactivate), frozenset(names),
                          tuple(refuse.dropped))

    def _drop_unloaded(self, activate: list[str], deactivate: list[str],
                       refuse: _Refusals) -> None:
        """Leave out the names no controller is loaded under; refuse a list of only those."""
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

    def _drop_by_state(self, activate: list[str], deactivate: list[str],
                       refuse: _Refusals) -> None:
        """Leave out the controllers whose lifecycle state or claims forbid the change."""
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
        for name in list(activate):
            refusal = self.activation_refusal(name)
            if refusal is not None:
                activate.remove(name)
                refuse(refusal)

    def _drop_broken_chains(self, activate: list[str], deactivate: list[str],
                            refuse: _Refusals) -> None:
        """Leave out the controllers whose chains the switch would break, until none is left.

        As controller_manager's check_following_controllers_for_activate and
        check_preceding_controllers_for_deactivate; leaving one out may fail another.
        """
        changed = True
        while changed:
            changed = False
            for name in list(activate):
                problem = self._following_problem(name, set(activate), set(deactivate))
                if problem is not None:
                    activate.remove(name)
                    changed = True
                    refuse(f"could not activate controller with name '{name}': {problem}")
            for name in list(deactivate):
                problem = self._preceding_problem(name, set(deactivate))
                if problem is not None:
                    deactivate.remove(name)
                    changed = True
                    refuse(problem)

    def activation_refusal(self, name: str) -> str | None:
        """Return why the loaded controller ``name`` cannot be activated here, or None.

        A claimed command interface the joint's ``<ros2_control>`` block
        declares but the simulation cannot drive: one line naming the joint
        and the interface, as controller_manager words a claim it cannot serve.
        """
        undrivable = self._by_name[name].undrivable_interfaces()
        if not undrivable:
            return None
        joint, interface = next(iter(undrivable.items()))
        return (f"Unable to activate controller '{name}' since the command interface "
                f"'{joint}/{interface}' is not available: the simulation can drive "
                f'{DRIVABLE}')

    def add_switch_listener(self, listener: Callable[[], None]) -> None:
        """Call ``listener()`` after every switch (the simulation re-drives the joints)."""
        self._switch_listeners.append(listener)

    def _change_active(self, names: set[str], started: set[str]) -> None:
        """Make ``names`` the active set; ``started`` are (re)activated even if active already.

        Deactivation runs preceding controllers first; chained modes change
        while the controllers concerned are stopped (an active one whose mode
        changes is restarted); activation runs following controllers first.
        """
        chained = {following for name in names for following in self.chain_connections(name)}
        # In the old update order: preceding controllers first.
        stopped = [c for c in self._active if c.name not in names or c.name in started
                   or c.is_chained != (c.name in chained)]
        self._set_active(names)
        for controller in stopped:
            controller.deactivate()
        for controller in self._controllers:
            if controller.is_chained != (controller.name in chained):
                controller.set_chained_mode(controller.name in chained)
        restarted = {c.name for c in stopped} | started
        for controller in reversed(self._active):
            if controller.name in restarted:
                controller.reset()

    def _set_active(self, names: set[str]) -> None:
        self._active_names = frozenset(names)
        for name, state in self._states.items():
            if name in names:
                self._states[name] = ACTIVE
            elif state == ACTIVE:
                self._states[name] = INACTIVE
        active = [c for c in self._controllers if c.name in self._active_names]
        ordered = self._chain_order(active)  # None only for loops, which switch() refuses
        self._active = active if ordered is None else ordered
        members: list[Controller] = []
        clocks: list[tuple[int, float]] = []
        actuations: list[Callable[[float], None]] = []
        for controller in self._active:
            clock = self.clock_of(controller)
            for member in controller.step_members():
                members.append(member)
                clocks.append(clock)
                actuation = member.actuation() if clock[0] > 1 else None
                if actuation is not None:
                    actuations.append(actuation)
        self._step_members, self._step_clocks, self._actuations = members, clocks, actuations
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
        # A ROS 1 diff drive without wheel geometry reads it from the URDF, as noetic's does.
        params = ros1_diff_drive.with_urdf_geometry(type_name, params, self._model)
        controller = create_controller(name, type_name, params, source)
        for joint in controller.joint_names:
            if joint in self._unmovable:
                raise ControllerConfigError(
                    f"{source}: {name}: joint '{joint}' is a "
                    f'{self._unmovable[joint].value} joint; a controller can only drive '
                    'revolute, continuous and prismatic joints')
        rate = params.get(UPDATE_RATE_FIELD)
        if rate is not None:  # checked here for every type: not all of them declare it
            if isinstance(rate, bool) or not isinstance(rate, int | float):
                raise ControllerConfigError(
                    f'{source}: {name}.{UPDATE_RATE_FIELD}: {rate!r} is not a number of Hz')
            problem = rate_problem(rate)
            if problem is not None:
                raise ControllerConfigError(f'{source}: {name}.{UPDATE_RATE_FIELD}: {problem}')
            rate = float(rate)
        self._rates[name] = rate
        return controller

    def _clock_notes(self, controllers: Iterable[Controller]) -> list[str]:
        """Return one line per rate whose period is not a whole number of physics steps.

        Naming the controllers on it (only those on the stepping loop's clock)
        and the rate they update at instead.
        """
        dt = self._time_step
        if dt is None:
            return []
        uneven: dict[float, list[str]] = {}
        for controller in controllers:
            rate = self._rates.get(controller.name)
            if rate is None or controller.own_clock or controller.schedule() is not None:
                continue
            if abs(self.clock_of(controller)[1] - 1.0 / rate) > DUE_EPSILON:
                uneven.setdefault(rate, []).append(controller.name)
        notes = []
        for rate, names in uneven.items():
            steps = steps_per_update(1.0 / rate, dt)
            period = steps * dt
            notes.append(
                f"update_rate {rate:g} Hz of {', '.join(names)} is not a whole number of "
                f'physics steps ({dt:g} s): updates every {steps} step'
                f"{'s' if steps > 1 else ''}, {1.0 / period:.4g} Hz (period {period:g} s), at "
                'the first step where 1 / update_rate has passed since the last update, '
                'as gz_ros2_control runs it')
        return notes

    def _add(self, controller: Controller, state: str) -> None:
        self._controllers.append(controller)
        # Controllers that command joints first: broadcasters then sample this step's efforts.
        self._controllers.sort(key=lambda c: not c.commands_joints)
        self._by_name[controller.name] = controller
        self._states[controller.name] = state

    def _problem(self, names: set[str]) -> tuple[str, str, str | None, str | None] | None:
        """Return what is wrong with ``names`` as the active set, or None.

        (joint, controller, other controller, None) for a joint claimed twice,
        (joint, controller, None, interface) for an interface the joint lacks.
        Only joints of the robot: claimed reference interfaces are
        :meth:`_chain_problem`'s.
        """
        owners: dict[str, str] = {}
        for controller in self._controllers:
            if controller.name not in names:
                continue
            for joint in controller.joint_names:
                if joint not in self._handles:
                    continue
                if joint in owners:
                    return joint, owners[joint], controller.name, None
                owners[joint] = controller.name
            for joint, interfaces in controller.command_interfaces().items():
                if joint not in self._handles:
                    continue
                for interface in interfaces:
                    if interface not in self._interfaces_of(joint, interface):
                        return joint, controller.name, None, interface
        return None

    def _chain_order(self, controllers: list[Controller]) -> list[Controller] | None:
        """Return ``controllers`` with every preceding controller before those it feeds.

        Otherwise in the given order; None when the chains among them loop.
        """
        names = {controller.name for controller in controllers}
        preceding: dict[str, list[Controller]] = {name: [] for name in names}
        for controller in controllers:
            for following in self.chain_connections(controller.name):
                if following in names:
                    preceding[following].append(controller)
        ordered: list[Controller] = []
        placed: set[str] = set()
        placing: set[str] = set()

        def place(controller: Controller) -> bool:
            if controller.name in placed:
                return True
            if controller.name in placing:
                return False
            placing.add(controller.name)
            if not all(place(before) for before in preceding[controller.name]):
                return False
            placed.add(controller.name)
            ordered.append(controller)
            return True

        return ordered if all(place(controller) for controller in controllers) else None

    def _following_problem(self, name: str, activate: set[str], deactivate: set[str],
                           seen: frozenset[str] = frozenset()) -> str | None:
        """Return why ``name`` cannot be activated as things stand in its chain, or None.

        Every controller it precedes must be chainable, and active (and not
        being deactivated) or being activated; and so on down the chain.
        The texts are controller_manager's.
        """
        for following, claimed in self.chain_connections(name).items():
            if following in seen:
                continue
            if not self._by_name[following].chainable:
                return (f"No state/reference interface from controller : '{claimed[0]}' exist, "
                        f"since the following controller with name '{following}' is not "
                        'chainable.')
            if self.is_active(following):
                if following in deactivate:
                    return (f"The following controller with name '{following}' is currently "
                            'active but it is requested to be deactivated.')
            elif following not in activate:
                return (f"The following controller with name '{following}' is currently "
                        'inactive and it is not requested to be activated.')
            problem = self._following_problem(following, activate, deactivate, seen | {name})
            if problem is not None:
                return problem
        return None

    def _preceding_problem(self, name: str, deactivate: set[str]) -> str | None:
        """Return why ``name`` cannot be deactivated while its preceding controllers run, or None.

        (A preceding controller being activated is refused by its own check.)
        The text is controller_manager's.
        """
        for other in self._controllers:
            if other.name == name or name not in self.chain_connections(other.name):
                continue
            if self.is_active(other.name) and other.name not in deactivate:
                return (f"Unable to deactivate controller with name '{name}' because preceding "
                        f"controller with name '{other.name}' is currently active and will not "
                        'be deactivated.')
        return None

    def _chain_problem(self, names: set[str]) -> str | None:
        """Return what is wrong with the chains if ``names`` were the active set, or None.

        Every reference interface a controller of ``names`` claims must be
        exported by a loaded controller -- the very one it was configured
        against -- and claimed by no other, as every gpio command interface;
        the chains must not loop.
        """
        exported = self.references()
        claimers: dict[str, str] = {}
        for controller in self._controllers:
            if controller.name not in names:
                continue
            bound = self._bound.get(controller.name, {})
            for entry, interfaces in controller.command_interfaces().items():
                if entry in self._handles:
                    continue
                for interface in interfaces:
                    claimed = f'{entry}/{interface}'
                    if entry in self.hardware.gpios:
                        if claimed in claimers:
                            return (f"'{claimers[claimed]}' and '{controller.name}' would both "
                                    f"claim the command interface '{claimed}'; only one "
                                    'active controller can command it')
                        claimers[claimed] = controller.name
                        continue
                    reference = exported.get(claimed)
                    if reference is None or reference is not bound.get(claimed):
                        return (f"Unable to activate controller '{controller.name}' since the "
                                f"command interface '{claimed}' is not available.")
                    if claimed in claimers:
                        return (f"'{claimers[claimed]}' and '{controller.name}' would both "
                                f"claim the reference interface '{claimed}'; only one active "
                                'controller can command it')
                    claimers[claimed] = controller.name
        active = [controller for controller in self._controllers if controller.name in names]
        if self._chain_order(active) is None:
            looping = sorted(name for name in names if self.chain_connections(name))
            return (f"the chains of {', '.join(repr(name) for name in looping)} loop: a "
                    'controller cannot feed, through others, the ones that feed it')
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
