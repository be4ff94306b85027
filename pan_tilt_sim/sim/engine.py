"""The simulation loop: physics and controllers, stepped together, no ROS.

Each step is ros2_control's read / update / write around one physics step:
measured joint states go into the joint handles, every active controller
due on its own clock updates (command controllers first, so broadcasters
sample fresh efforts; clocks: :mod:`pan_tilt_sim.controllers.framework.manager`),
the hardware's per-step part runs on the held commands, the efforts and
velocity targets go to PyBullet, and PyBullet advances one ``time_step``.
Sim time is kept as a step count, so it never accumulates rounding error.
Which controllers are loaded and active is the
:class:`~pan_tilt_sim.controllers.framework.manager.ControllerManager`'s
business; a joint no active controller claims is passive (it keeps the
last effort applied).

The robot's base is welded to the world unless it is mobile
(:func:`base_is_fixed`, :mod:`pan_tilt_sim.model.base_pose`); a free base
starts resting on the ground and a reset puts it back there.

Design notes: docs/design/sim.md#enginepy.
"""

from __future__ import annotations

import logging
import math
import pathlib
import time as wall_time
from collections.abc import Mapping, Sequence
from typing import Protocol

import numpy

from pan_tilt_sim.controllers import CommandController, Controller, JointHandle
from pan_tilt_sim.controllers.framework.base import Drive, idle_actuator
from pan_tilt_sim.controllers.framework.manager import ControllerManager
from pan_tilt_sim.controllers.framework.registry import drives_base
from pan_tilt_sim.controllers.toolbox import step_law
from pan_tilt_sim.controllers.toolbox.actuator import TRACKING_GAIN
from pan_tilt_sim.controllers.toolbox.gains import plugin_gains
from pan_tilt_sim.model.base_pose import FIXED_BASE, ORIGIN, BasePose
from pan_tilt_sim.model.controller_config import ControllersConfig
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.model.initial_positions import FROM_DEFAULT, StartPosition, start_positions
from pan_tilt_sim.model.physics_plan import plan_physics
from pan_tilt_sim.model.physics_settings import DEFAULT_PHYSICS, PhysicsSettings
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.plugins.framework.plugin import Plugin, PluginWorld
from pan_tilt_sim.plugins.registry import base_drivers, create_plugins, runs_by_plugins
from pan_tilt_sim.schedule import DUE_EPSILON
from pan_tilt_sim.sim.hardware import SimulatedHardware
from pan_tilt_sim.sim.physics import (
    STATE_MOTOR_TORQUE,
    STATE_POSITION,
    STATE_VELOCITY,
    UNLIMITED_FORCE,
    Physics,
    health_problem,
)
from pan_tilt_sim.sim.roller_wheels import RollerWheels
from pan_tilt_sim.sim.sensors.mount import LinkReader
from pan_tilt_sim.sim.stability import check_startup_stability, pid_stability_warnings

LOGGER_NAME = 'pan_tilt_sim'
# A joint this close to PyBullet's speed cap is riding it.
AT_CAP = 0.99
WARNING_THROTTLE_S = 1.0  # wall seconds between two warnings about one joint
TIPPED_TILT = 60.0  # deg: a free base tilted more than this from upright has tipped over
# deg and sim seconds: a free base tilted more than LEANING_TILT for LEANING_TIME leans on
# something besides its wheels (its nose, a side) or stands on a slope; its braking and
# accelerating rock it by a few degrees for a fraction of a second only.
LEANING_TILT = 5.0
LEANING_TIME = 0.5
BELOW_GROUND = -1.0  # m: a free base frame this far below the ground plane fell off it
# The fewest steps handed to the compiled laws at once: below it, collecting
# the laws and taking their state back costs more than the steps save.
MIN_COMPILED_STEPS = 4
INFO, WARNING = 'info', 'warning'


class Logger(Protocol):
    """What the simulation logs through: rclpy's node logger and logging.Logger both fit."""

    def info(self, message: str) -> object:
        """Log ``message`` as information."""

    def warning(self, message: str) -> object:
        """Log ``message`` as a warning."""


def base_is_fixed(fixed_base: bool | None, description: RobotDescription,
                  controllers: ControllersConfig, active: Sequence[str] | None,
                  autostart: bool) -> tuple[bool, str]:
    """Decide whether the robot's base is welded to the world; return that and why.

    ``fixed_base`` True or False is the answer, None is ``auto``: free if a
    controller that drives the base will be active -- with ``autostart``,
    one of ``active`` (None: every controller of the file); waiting for
    spawners, any the file declares -- or if the URDF has a Gazebo plugin
    that drives the base (:func:`pan_tilt_sim.plugins.registry.base_drivers`).
    Waiting for spawners, whose controllers are not known yet (a robot's own launch file), a robot
    that stands on wheels (``RobotModel.ground_wheels``) is free too.  A
    robot hung on a ``world`` link by a fixed joint is welded whatever
    ``fixed_base`` says, as in Gazebo.
    """
    if description.model.welded_to_world:
        return True, "its root link 'world' holds it by a fixed joint, as in Gazebo"
    if fixed_base is not None:
        return fixed_base, f'{FIXED_BASE} is {str(fixed_base).lower()}'
    plugins = base_drivers(description.model)
    if plugins:
        name, filename = plugins[0]
        return False, (f"{FIXED_BASE} is auto and Gazebo plugin '{name}' "
                       f'({filename}) drives the base')
    candidates = [spec for spec in controllers.controllers
                  if not autostart or active is None or spec.name in active]
    drivers = [spec for spec in candidates if drives_base(spec.type)]
    if drivers:
        return False, (f"{FIXED_BASE} is auto and controller '{drivers[0].name}' "
                       f'({drivers[0].type}) drives the base')
    wheels = description.model.ground_wheels
    if not autostart and wheels:
        return False, (f'{FIXED_BASE} is auto, the spawners choose its controllers and it '
                       f"stands on wheels ({', '.join(wheels)}): it drives, as in Gazebo")
    return True, f'{FIXED_BASE} is auto and no controller drives the base'


class Simulation:
    """One robot in PyBullet, driven by its controllers, advanced step by step.

    ``initial_positions`` (joint name -> position) override the URDF's
    ``initial_value`` (see :mod:`pan_tilt_sim.model.initial_positions`).
    ``fixed_base`` welds the base to the world (True, the default for
    tools and tests), frees it (False) or decides by the controllers (None,
    sim_node's ``auto``: see :func:`base_is_fixed`); ``initial_pose`` places it.
    ``physics_settings`` are PyBullet's solver settings
    (:mod:`pan_tilt_sim.model.physics_settings`; :meth:`Physics.apply_settings`
    changes them later).
    What the simulation has to say at start-up waits in
    :attr:`startup_report` until :meth:`report_startup` logs it (the node
    does that once it is completely built, so that a start-up error stays
    the only line); run-time warnings go to ``logger`` at once.

    ``world``: another robot's simulation whose PyBullet world this robot
    joins, as a guest (:meth:`add_guest`): one physics world, each robot with
    its own plugins, controllers and sensors, all stepped by the host's
    :meth:`advance` (docs/design/sim.md#several-robots).
    """

    def __init__(self, description: RobotDescription, controllers: ControllersConfig,
                 time_step: float, *, gui: bool = False,
                 active_controllers: Sequence[str] | None = None,
                 initial_positions: Mapping[str, float] | None = None,
                 logger: Logger | None = None,
                 autostart_controllers: bool = True,
                 fixed_base: bool | None = True,
                 initial_pose: BasePose = ORIGIN,
                 physics_settings: PhysicsSettings = DEFAULT_PHYSICS,
                 world: Simulation | None = None) -> None:
        self.description = description
        # Robots that joined this one's world (add_guest), stepped with it.
        self.guests: list[Simulation] = []
        self._logger: Logger = logger or logging.getLogger(LOGGER_NAME)
        load_messages: list[str] = list(controllers.warnings)  # the file's dropped blocks
        model = description.model
        # The model's Gazebo plugins (drive, joint states, ground truth), read before anything
        # is built (a malformed element ends start-up): always active, updated before the
        # controllers; no controller_manager knows them.
        self.plugins: list[Plugin] = create_plugins(model, controllers.label,
                                                    load_messages.append)
        # What the physics and the joint handles need of the model, decided before anything
        # is built (docs/design/sim.md#start-up-path).
        starts = start_positions(model, initial_positions)
        movable = [joint.name for joint in description.actuated_joints]
        gains = plugin_gains(controllers.pid_gains, movable, controllers.label)
        fixed, why = base_is_fixed(fixed_base, description, controllers, active_controllers,
                                   autostart_controllers)
        plan = plan_physics(description, fixed_base=fixed, initial_pose=initial_pose,
                            initial_positions=[starts[joint].position for joint in movable])
        tracking_gain = model.position_proportional_gain or TRACKING_GAIN
        self.handles = {
            joint.name: JointHandle(joint, position, gains.get(joint.name), tracking_gain,
                                    control=model.control_joint(joint.name))
            for joint, position in zip(plan.joints, plan.initial_positions, strict=True)}
        self.physics = Physics.from_plan(
            plan, time_step, gui=gui, warn=load_messages.append, settings=physics_settings,
            world=None if world is None else world.physics)
        self._base_report = self._describe_base(why, fixed_base, initial_pose)
        self._time_step = time_step
        self._steps = 0 if world is None else world.steps
        try:
            check_startup_stability(self.physics, description)
            # The <ros2_control> sensors and gpios, measured here, read by the controllers.
            self.hardware = SimulatedHardware(self.physics, model, lambda: self._steps)
            self.manager = ControllerManager(controllers, self.handles, model,
                                             active=active_controllers,
                                             autostart=autostart_controllers,
                                             hardware=self.hardware.interfaces,
                                             time_step=time_step)
            self._link_readers: dict[str, LinkReader] = {}
            world = PluginWorld(self.handles, self.base_state, self.base_motion, self.link_state)
            for plugin in self.plugins:
                plugin.attach(world)
            # Planar move sets the base's velocity itself: the step applies what it computed.
            self._base_movers = [plugin for plugin in self.plugins
                                 if plugin.sets_base_velocity]
        except BaseException:
            self.physics.close()
            raise
        self._handle_list = list(self.handles.values())
        self.compiled_steps = 0  # of all steps run, those whose controllers ran in C
        self._states = self.physics.read_states()
        # Waiting for spawners, a joint no controller has driven yet is held where it is, as
        # gz_ros2_control's hold_joints holds it; once driven, it is passive when undriven.
        self._hold_undriven = not autostart_controllers
        # Only the joints its <ros2_control> block gives a command interface (gz_ros2_control's
        # is_actuated); without a block, every joint.
        declared = [handle for handle in self._handle_list if handle.declared_commands is not None]
        self._holdable = ({handle.name for handle in declared if handle.declared_commands}
                          if declared else set(self.handles))
        self._driven: set[str] = set()
        # Per step member (by id), [step at which it next updates, every so many steps,
        # period s, its update]: the controllers' clocks, kept across switches.
        self._clocks: list[list] = []
        # The active controllers' wheels with free rollers (mecanum, omni), and their friction.
        self._roller_angles: dict[str, float] = {}
        self._rollers: RollerWheels | None = None
        self._apply_actuators()
        self.manager.add_switch_listener(self._apply_actuators)
        self._speed_limit = AT_CAP * self.physics.velocity_cap
        self._last_warning: dict[str, float] = {}
        # Sim time since which the free base leans, or stands upright; whether the lean was said.
        self._leaning_since: float | None = None
        self._upright_since: float | None = None
        self._lean_reported = False
        self.startup_report = self._startup_report(description, starts, load_messages)

    def _apply_actuators(self) -> None:
        """Drive every joint as its active controller says (a joint without one: passive).

        While the simulation waits for spawners, a joint that no controller
        has driven yet is held instead (see ``autostart_controllers``).
        """
        actuators = {}
        for plugin in self.plugins:
            actuators.update(plugin.actuators())
        for controller in self.manager.active:
            actuators.update(controller.actuators())
        self._driven.update(actuators)
        for handle in self._handle_list:
            actuator = actuators.get(handle.name)
            if actuator is None:
                actuator = idle_actuator(handle.spec, hold=self._hold_undriven
                                         and handle.name in self._holdable
                                         and handle.name not in self._driven)
                handle.velocity_target = 0.0
            handle.actuator = actuator
            handle.force_limit = handle.spec.effort_limit  # until a controller lowers it
        velocity_driven = [handle.drive is Drive.VELOCITY for handle in self._handle_list]
        self.physics.set_drives(velocity_driven)
        self._effort_handles = [handle for handle, driven in zip(
            self._handle_list, velocity_driven, strict=True) if not driven]
        self._velocity_handles = [handle for handle, driven in zip(
            self._handle_list, velocity_driven, strict=True) if driven]
        self._velocity_slots = [slot for slot, driven in enumerate(velocity_driven) if driven]
        self._set_clocks()
        self._efforts = [0.0] * len(self._effort_handles)
        self._targets = [0.0] * len(self._velocity_handles)
        # The velocity motors' force limits: the effort limits, but a controller's own
        # every step for the joints whose actuator takes it from the controller.
        self._forces = [min(handle.spec.effort_limit, UNLIMITED_FORCE)
                        for handle in self._velocity_handles]
        self._forced = [(index, handle) for index, handle in enumerate(self._velocity_handles)
                        if handle.actuator.force_from_controller]
        self._physics_step = self.physics.stepper()
        self._run_laws = self.physics.law_runner()
        self._apply_rollers()
        self._effort_slot = {handle.name: index
                             for index, handle in enumerate(self._effort_handles)}
        self._state_slot = {handle.name: index for index, handle in enumerate(self._handle_list)}

    def _set_clocks(self) -> None:
        """Give each active step member its clock; those active before keep their next update.

        A controller just activated updates at the next step.
        """
        kept = {id(clock[3].__self__): clock[0] for clock in self._clocks}
        self._clocks = [
            [kept.get(id(member), self._steps), every, period, member.update]
            for member, (every, period) in zip(self.manager.step_members,
                                               self.manager.step_clocks, strict=True)]
        # Every member every step (a ROS 1 file): the loop need not look at the clocks.
        self._every_step = all(clock[1] == 1 for clock in self._clocks)

    def _restart_clocks(self) -> None:
        """Make every controller due at the present step (after a reset)."""
        for clock in self._clocks:
            clock[0] = self._steps

    def _apply_rollers(self) -> None:
        """Give the active controllers' roller wheels their friction (a free base only).

        A controller says which of its wheels carry free rollers
        (:meth:`~pan_tilt_sim.controllers.framework.base.Controller.roller_wheels`);
        while it is active they grip only across their rollers
        (:mod:`pan_tilt_sim.sim.roller_wheels`), the force added before every
        physics step, which therefore runs in Python.
        """
        angles: dict[str, float] = {}
        for controller in self.manager.active:
            angles.update(controller.roller_wheels())
        if self.physics.fixed_base:
            angles = {}
        if angles != self._roller_angles:
            if self._rollers is not None:
                self._rollers.release()
            self._rollers = RollerWheels(self.physics, angles) if angles else None
            self._roller_angles = angles
        if self._rollers is None:
            return
        apply, step = self._rollers.apply, self._physics_step

        def rolling_step(efforts: Sequence[float], targets: Sequence[float] = (),
                         forces: Sequence[float] | None = None) -> Sequence:
            apply()
            return step(efforts, targets, forces)

        self._physics_step = rolling_step
        self._run_laws = None

    def report_startup(self) -> None:
        """Log :attr:`startup_report` (info and warnings), once."""
        for level, message in self.startup_report:
            # One call site per severity: rclpy's logger insists on it.
            if level == WARNING:
                self._logger.warning(message)
            else:
                self._logger.info(message)
        self.startup_report = []

    def _describe_base(self, why: str, asked: bool | None,
                       pose: BasePose) -> tuple[str, str] | None:
        """Return the start-up line about the base: free, or welded against the parameter."""
        frame = self.physics.initial_base_frame
        x, y, z = frame.translation
        if not self.physics.fixed_base:
            # A tilted spawn (create -R -P) names its roll and pitch too, in create's order.
            angles = ''.join(f'{name} {value:.4g} ' for name, value in (
                ('roll', pose.roll), ('pitch', pose.pitch)) if value)
            return (INFO, f'base: free on the ground ({why}); its root link starts at '
                          f'x {x:.4g} y {y:.4g} z {z:.4g} m, {angles}yaw {pose.yaw:.4g} rad')
        if asked is False:
            return (WARNING, f'base: welded to the world although {FIXED_BASE} is false: {why}')
        return None

    def _startup_report(self, description: RobotDescription, starts: Mapping[str, StartPosition],
                        load_messages: Sequence[str]) -> list[tuple[str, str]]:
        report = [(WARNING, message) for message in load_messages]
        report.extend((INFO, note) for note in self.manager.clock_notes)
        if self._base_report is not None:
            report.append(self._base_report)
        for handle in self._handle_list:
            report.append((INFO, f"joint '{handle.name}': "
                                 f'{handle.actuator.describe(handle.spec)}'))
        for handle in self._handle_list:
            start = starts[handle.name]
            line = start.describe(handle.spec.lower, handle.spec.upper)
            if line:
                report.append((WARNING if start.clamped and start.source != FROM_DEFAULT
                               else INFO, line))
        periods = {controller.name: self.manager.clock_of(controller)[1]
                   for controller in self.manager.active}
        report.extend((WARNING, message) for message in pid_stability_warnings(
            self.physics, self._handle_list, self._time_step, periods))
        report.extend(self.hardware.startup_report())
        return report

    @property
    def time_step(self) -> float:
        """Seconds of sim time per step."""
        return self._time_step

    @property
    def steps(self) -> int:
        """Steps taken since the start (or the last reset of time)."""
        return self._steps

    @property
    def time(self) -> float:
        """Sim time in seconds."""
        return self._steps * self._time_step

    @property
    def controllers(self) -> list[Controller]:
        """The loaded controllers (the manager's; they change as controllers are loaded)."""
        return self.manager.controllers

    def command_controllers(self) -> list[CommandController]:
        """Return the (loaded) controllers that take commands from topics."""
        return [c for c in self.controllers if isinstance(c, CommandController)]

    def controller(self, name: str) -> Controller:
        """Return the loaded controller called ``name``; KeyError if there is none."""
        return self.manager.controller(name)

    def advance(self, steps: int) -> None:
        """Run ``steps`` physics steps, updating every active controller at each.

        Where every controller updated each step has a compiled law
        (:mod:`pan_tilt_sim.controllers.toolbox.step_law`) and the physics can run it
        (:meth:`Physics.law_runner`), the steps between two broadcaster
        samples run in C, at least :data:`MIN_COMPILED_STEPS` at a time; a
        step at which a scheduled controller is due runs in Python.  Either
        way the results are the same to the last bit.  A robot with Gazebo
        plugins (:attr:`plugins`) runs in Python: they have no compiled law.
        """
        if self.guests:
            self._advance_world(steps)
            return
        scheduled = self.manager.scheduled_updates
        dt = self._time_step
        shortest = min((schedule.period for schedule, _ in scheduled), default=math.inf)
        if self._run_laws is None or self.plugins or shortest < MIN_COMPILED_STEPS * dt:
            # A broadcaster due (nearly) every step leaves no stretch worth the hand-over.
            self._advance_python(steps)
            return
        count, end = self._steps, self._steps + steps
        while count < end:
            stop = min([end] + [schedule.first_due_step(count, dt) for schedule, _ in scheduled])
            if stop - count >= MIN_COMPILED_STEPS:
                laws = self._compiled_laws()
                if laws is None:  # a controller without a law: Python, as ever
                    self._advance_python(end - count)
                    return
                self._run_compiled(stop - count, laws)
                count = stop
                if count == end:
                    self._check_health(self._states)
                    return
            # The due step (and a stretch too short to hand over), as the Python loop takes it.
            python_steps = min(end, stop + 1) - count
            self._advance_python(python_steps)
            count += python_steps

    @property
    def has_robot(self) -> bool:
        """Whether the robot is in the world (False once :meth:`remove_robot` took it out)."""
        return self.physics.body_id >= 0

    def remove_robot(self) -> None:
        """Take this robot out of the world it hosts; the world, its guests and sim time stay.

        Its plugins, controllers and hardware stop and its body leaves PyBullet;
        each step then advances the world alone (the guests, the objects), as a
        Gazebo world runs on when its first model is deleted.  A guest leaves
        through its host's :meth:`remove_guest` instead.
        """
        if not self.has_robot:
            return
        self.hardware.close()
        if self._rollers is not None:
            self._rollers.release()
            self._rollers, self._roller_angles = None, {}
        self.plugins, self._base_movers = [], []
        self.manager = ControllerManager(ControllersConfig((), pathlib.Path()), {},
                                         time_step=self._time_step)
        self.handles, self._handle_list = {}, []
        self._effort_handles, self._velocity_handles, self._forced = [], [], []
        self._velocity_slots, self._efforts, self._targets, self._forces = [], [], [], []
        self._effort_slot, self._state_slot, self._link_readers = {}, {}, {}
        self._clocks, self._every_step = [], True
        self.physics.remove_robot()
        world_step = self.physics.bare_stepper()

        def step(efforts: Sequence[float], targets: Sequence[float] = (),
                 forces: Sequence[float] | None = None) -> list:
            world_step()
            return []
        self._physics_step, self._run_laws, self._states = step, None, []

    def add_guest(self, guest: Simulation) -> None:
        """Step ``guest`` (built with ``world=self``) with this robot from now on."""
        guest._steps = self._steps
        self.guests.append(guest)

    def remove_guest(self, guest: Simulation) -> None:
        """Stop stepping ``guest`` and take its body out of the world (its close)."""
        self.guests.remove(guest)
        guest.close()

    def _advance_world(self, steps: int) -> None:
        """Run ``steps`` steps of every robot in this world, in Python, one world step each.

        Each step every guest reads its joints, updates its plugins and
        controllers and applies its efforts and motors; then this robot does
        the same and its physics step advances the world; then each guest
        takes its joints' new states.
        """
        robots = [*self.guests, self]
        first = self._steps
        for count in range(first, first + steps):
            for robot in robots:
                robot._one_step(count)
            for guest in self.guests:
                guest._states = guest.physics.take_states()
        for robot in robots:
            robot._steps = first + steps
            robot._check_health(robot._states)

    def _one_step(self, count: int) -> None:
        """Step ``count`` of this robot alone: what :meth:`_advance_python` does per step."""
        states = self._states
        for handle, state in zip(self._handle_list, states, strict=False):
            handle.position = state[STATE_POSITION]
            handle.velocity = state[STATE_VELOCITY]
        for handle, slot in zip(self._velocity_handles, self._velocity_slots, strict=True):
            handle.effort = states[slot][STATE_MOTOR_TORQUE]
        dt = self._time_step
        time = count * dt
        for unit in self.plugins:
            unit.update(time, dt)
        if self._every_step:
            for update in self.manager.updates:
                update(time, dt)
        else:  # controllers on their own clocks; the hardware acts on held commands
            for clock in self._clocks:
                if count >= clock[0]:
                    clock[0] = count + clock[1]
                    clock[3](time, clock[2])
            for actuate in self.manager.actuations:
                actuate(dt)
        for schedule, update in self.manager.scheduled_updates:
            if time + DUE_EPSILON >= schedule.next_due:
                update(time, dt)
        efforts, targets, forces = self._efforts, self._targets, self._forces
        for index, handle in enumerate(self._effort_handles):
            efforts[index] = handle.effort
        for index, handle in enumerate(self._velocity_handles):
            targets[index] = handle.velocity_target
        for index, handle in self._forced:
            force = handle.force_limit
            forces[index] = force if force < UNLIMITED_FORCE else UNLIMITED_FORCE
        for mover in self._base_movers:
            velocity = mover.take_base_velocity()
            if velocity is not None:
                self.physics.set_base_velocity(*velocity)
        self._states = self._physics_step(efforts, targets, forces if self._forced else None)

    def _compiled_laws(self) -> list[tuple[int, int, list[float]]] | None:
        """Return each step member's law with its slots, or None if one has none."""
        effort_slot, state_slot = self._effort_slot, self._state_slot
        laws = []
        count = self._steps
        for member, (next_update, every, period, _) in zip(self.manager.step_members,
                                                            self._clocks, strict=True):
            law = member.step_law()
            if law is None:
                return None
            handle, row = law
            row[step_law.UPDATE_STEPS] = float(every)
            row[step_law.NEXT_UPDATE] = float(max(0, next_update - count))
            row[step_law.PERIOD] = period
            laws.append((effort_slot[handle.name], state_slot[handle.name], row))
        return laws

    def _run_compiled(self, steps: int, laws: list[tuple[int, int, list[float]]]) -> None:
        """Run ``steps`` steps in C, none with a scheduled update due; hand the state back."""
        handles, effort_handles, efforts = self._handle_list, self._effort_handles, self._efforts
        for index, handle in enumerate(effort_handles):
            efforts[index] = handle.effort
        before, states = self._run_laws(steps, self._time_step, efforts, laws, self._states)
        # As the Python loop leaves them: the handles hold the last step's starting state.
        for handle, state in zip(handles, before, strict=False):
            handle.position = state[STATE_POSITION]
            handle.velocity = state[STATE_VELOCITY]
        for handle, effort in zip(effort_handles, efforts, strict=False):
            handle.effort = effort
        end = self._steps + steps
        for member, clock, (_, _, row) in zip(self.manager.step_members, self._clocks, laws,
                                              strict=True):
            member.absorb_step_law(row)
            clock[0] = end + int(row[step_law.NEXT_UPDATE])
        self.compiled_steps += steps
        self._states = states
        self._steps = end

    def _advance_python(self, steps: int) -> None:
        """Run ``steps`` steps, every controller updated in Python."""
        # Everything the loop touches is a local: bound methods, the physics
        # stepper, the handles; group controllers' members are called directly
        # and scheduled ones (the broadcasters) only when due.  This loop's
        # Python is what the compiled laws save (docs/performance.md).
        handles = self._handle_list
        plugin_updates = [unit.update for unit in self.plugins]
        updates = plugin_updates + self.manager.updates
        # Controllers on clocks slower than the physics: each updates when due, with its
        # period, and the hardware acts on the held commands every step (see actuations).
        clocks = None if self._every_step else self._clocks
        actuations = self.manager.actuations
        scheduled = self.manager.scheduled_updates
        effort_handles, efforts = self._effort_handles, self._efforts
        velocity_handles, targets = self._velocity_handles, self._targets
        forced, forces = self._forced, self._forces
        # None: the motors keep the limits they have (no controller sets any).
        motor_forces = forces if forced else None
        readback = list(zip(velocity_handles, self._velocity_slots, strict=True))
        physics_step = self._physics_step
        movers = [mover.take_base_velocity for mover in self._base_movers]
        set_base_velocity = self.physics.set_base_velocity
        dt = self._time_step
        states = self._states
        first = self._steps
        for count in range(first, first + steps):
            # Equal lengths by construction; strict=True would check them every step.
            for handle, state in zip(handles, states, strict=False):
                handle.position = state[STATE_POSITION]
                handle.velocity = state[STATE_VELOCITY]
            for handle, slot in readback:  # what the ideal actuators applied
                handle.effort = states[slot][STATE_MOTOR_TORQUE]
            time = count * dt
            if clocks is None:
                for update in updates:
                    update(time, dt)
            else:
                for update in plugin_updates:
                    update(time, dt)
                for clock in clocks:
                    if count >= clock[0]:
                        clock[0] = count + clock[1]
                        clock[3](time, clock[2])
                for actuate in actuations:
                    actuate(dt)
            for schedule, update in scheduled:
                if time + DUE_EPSILON >= schedule.next_due:
                    update(time, dt)
            for index, handle in enumerate(effort_handles):
                efforts[index] = handle.effort
            for index, handle in enumerate(velocity_handles):
                targets[index] = handle.velocity_target
            for index, handle in forced:
                force = handle.force_limit
                forces[index] = force if force < UNLIMITED_FORCE else UNLIMITED_FORCE
            for take in movers:
                velocity = take()
                if velocity is not None:
                    set_base_velocity(*velocity)
            states = physics_step(efforts, targets, motor_forces)
        self._steps = first + steps
        self._states = states
        self._check_health(states)

    def _check_health(self, states: Sequence[Sequence[float]]) -> None:
        """Warn about any joint at PyBullet's speed cap or with a non-finite state.

        And about a free base that tipped over or fell below the ground plane
        (:meth:`_check_base`): the simulation goes on either way.
        """
        if not self.physics.fixed_base and self.has_robot:
            self._check_base()
        limit = self._speed_limit
        for handle, state in zip(self._handle_list, states, strict=False):
            velocity = state[STATE_VELOCITY]
            if -limit < velocity < limit and math.isfinite(state[STATE_POSITION]):
                continue
            now = wall_time.monotonic()
            if now - self._last_warning.get(handle.name, -math.inf) < WARNING_THROTTLE_S:
                continue
            self._last_warning[handle.name] = now
            self._logger.warning(
                f'at sim time {self.time:.3f} s: '
                f'{health_problem(handle.name, state, self.physics.velocity_cap)}')

    def _check_base(self) -> None:
        """Warn (throttled) when the free base tipped over or fell below the ground plane.

        Tipped over: tilted more than :data:`TIPPED_TILT` from upright; fallen:
        its frame below :data:`BELOW_GROUND`.  Instability is never silent, and
        it does not stop the run.  A base that leans (:meth:`_check_lean`) is
        said once per lean.
        """
        frame = self.physics.base_frame()
        x, y, z = frame.translation
        qx, qy, _qz, _qw = frame.rotation
        tilt = math.degrees(math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (qx * qx + qy * qy)))))
        self._check_lean(frame, tilt)
        problems = []
        if tilt > TIPPED_TILT:
            problems.append(('base tipped over',
                             f'has tipped over: its base is tilted {tilt:.0f} deg from upright'))
        if z < BELOW_GROUND:
            problems.append(('base fell', 'fell below the ground plane'))
        for key, problem in problems:
            now = wall_time.monotonic()
            if now - self._last_warning.get(key, -math.inf) < WARNING_THROTTLE_S:
                continue
            self._last_warning[key] = now
            self._logger.warning(
                f"at sim time {self.time:.3f} s: robot '{self.description.model.name}' {problem} "
                f'(base at x {x:.2f} m, y {y:.2f} m, z {z:.2f} m); the simulation goes on')

    def _check_lean(self, frame: Transform, tilt: float) -> None:
        """Warn once when the free base has leant more than LEANING_TILT for LEANING_TIME.

        A base resting on its nose or a side looks right where only x, y and
        yaw are read (odometry, a planar GetEntityState), but every sensor on
        it is tilted with it: a level lidar's beams meet the floor at its
        height / sin(tilt), wherever the robot drives.  The line gives the
        lean, the links touching the ground and the likely cause; it is
        said again only after the base stood upright for LEANING_TIME (a base
        rocking on its nose is one lean).
        """
        now = self.time
        if tilt <= LEANING_TILT:
            self._leaning_since = None
            if self._upright_since is None:
                self._upright_since = now
            if now - self._upright_since >= LEANING_TIME - DUE_EPSILON:
                self._lean_reported = False
            return
        self._upright_since = None
        if self._leaning_since is None:
            self._leaning_since = now
        if self._lean_reported or now - self._leaning_since < LEANING_TIME - DUE_EPSILON:
            return
        self._lean_reported = True
        if tilt > TIPPED_TILT:
            return  # the tipped-over warning says it
        qx, qy, qz, qw = frame.rotation
        # REP 103 angles of the base: pitch > 0 puts its nose (+x) down, roll > 0 its left up.
        pitch = math.degrees(math.asin(max(-1.0, min(1.0, 2.0 * (qw * qy - qz * qx)))))
        roll = math.degrees(math.atan2(2.0 * (qw * qx + qy * qz), 1.0 - 2.0 * (qx * qx + qy * qy)))
        ways = []
        if abs(pitch) > LEANING_TILT / 2:
            ways.append(f"nose {'down' if pitch > 0 else 'up'} {abs(pitch):.0f} deg")
        if abs(roll) > LEANING_TILT / 2:
            ways.append(f"{'right' if roll > 0 else 'left'} side down {abs(roll):.0f} deg")
        touching = ', '.join(self.physics.links_on_ground()) or 'no link on the ground plane'
        x, y, _ = frame.translation
        self._logger.warning(
            f"at sim time {now:.3f} s: robot '{self.description.model.name}' has leant "
            f"{tilt:.0f} deg from upright for {LEANING_TIME:g} s ({', '.join(ways)}; base at "
            f"x {x:.2f} m, y {y:.2f} m), touching the ground with: {touching}. Sensors on its "
            'base are tilted with it (a level lidar sees the floor). On flat ground its centre '
            'of mass is outside what its wheels and casters hold up, or braking tips it; the '
            'simulation goes on')

    def reset(self, *, reset_time: bool = True) -> None:
        """Put base and joints back at their start, reset controllers; sim time to 0 if asked."""
        for handle in self._handle_list:
            handle.reset()
        if self.has_robot:
            self.physics.reset_base()
            self.physics.reset_joints([handle.position for handle in self._handle_list])
            self._states = self.physics.read_states()
        for controller in [*self.plugins, *self.manager.configured]:
            controller.reset()
        if self._hold_undriven and self.has_robot:  # undriven joints are held again
            self._driven.clear()
            self._apply_actuators()
        if reset_time:
            self._steps = 0
        self._restart_clocks()
        self._leaning_since = self._upright_since = None
        self._lean_reported = False
        self.hardware.reset()
        for guest in self.guests:
            guest.reset(reset_time=reset_time)
            guest._steps = self._steps

    def reset_time(self) -> None:
        """Sim time back to 0, the joints left where they are; controllers hold them there.

        Controllers are reset as after a start (commands and trajectories,
        timed on the old clock, are dropped; position controllers hold the
        present position), and so are the Gazebo plugins (their rates start again).
        """
        for controller in [*self.plugins, *self.controllers]:
            controller.reset()
        self._steps = 0
        self._restart_clocks()
        # A lean, or standing upright, goes on, timed on the new clock.
        if self._leaning_since is not None:
            self._leaning_since = 0.0
        if self._upright_since is not None:
            self._upright_since = 0.0
        for sensor in self.hardware.interfaces.sensors.values():  # their readings' past is gone
            if sensor.source is not None:
                sensor.source.reset()
        for guest in self.guests:
            guest.reset_time()

    def base_state(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """Return the base's planar pose and twist: (x, y, heading), (forward, left, yaw rate).

        The pose of the root link frame in the world (m, rad); the velocity of
        its centre of mass in its own heading's axes (m/s) and the yaw rate (rad/s).
        """
        frame = self.physics.base_frame()
        x, y, _ = frame.translation
        qx, qy, qz, qw = frame.rotation
        heading = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
        (vx, vy, _), (_, _, yaw_rate) = self.physics.base_velocity()
        cos, sin = math.cos(heading), math.sin(heading)
        return (x, y, heading), (cos * vx + sin * vy, cos * vy - sin * vx, yaw_rate)

    def base_motion(self) -> tuple[Transform, tuple[float, float, float],
                                   tuple[float, float, float]]:
        """Return the root link frame in the world and the base's velocities (world axes).

        Linear: the root link's centre of mass (m/s); angular (rad/s).
        """
        linear, angular = self.physics.base_velocity()
        return self.physics.base_frame(), linear, angular

    def link_state(self, link: str) -> tuple[Transform, tuple[float, float, float],
                                              tuple[float, float, float]]:
        """Return ``link``'s frame in the world and its origin's linear and angular velocity.

        Velocities in world axes (m/s, rad/s).
        """
        reader = self._link_readers.get(link)
        if reader is None:
            reader = self._link_readers[link] = LinkReader(self.physics, link)
        state = reader.state()
        frame = state.frame
        linear = state.point_velocity(numpy.array(frame.translation))
        return frame, tuple(linear), tuple(state.angular_velocity)  # type: ignore[return-value]

    def joint_positions(self) -> dict[str, float]:
        """Return the measured position of every movable joint, by name."""
        return {name: state[STATE_POSITION]
                for name, state in zip(self.handles, self._states, strict=True)}

    def joint_velocities(self) -> dict[str, float]:
        """Return the measured velocity of every movable joint, by name."""
        return {name: state[STATE_VELOCITY]
                for name, state in zip(self.handles, self._states, strict=True)}

    def close(self) -> None:
        """Release PyBullet (the guests' bodies first: they live in this robot's client)."""
        while self.guests:
            self.guests.pop().close()
        self.hardware.close()
        self.physics.close()

    def __enter__(self) -> Simulation:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def make_simulation(description_file: str, controllers_file: str | None, time_step: float, *,
                    xacro_args: Sequence[str] = (), gui: bool = False,
                    controllers_args: Mapping[str, str] | None = None,
                    active_controllers: Sequence[str] | None = None,
                    initial_positions: Mapping[str, float] | None = None,
                    logger: Logger | None = None,
                    autostart_controllers: bool = True,
                    fixed_base: bool | None = True,
                    initial_pose: BasePose = ORIGIN,
                    physics_settings: PhysicsSettings = DEFAULT_PHYSICS) -> Simulation:
    """Load both files and build a :class:`Simulation` (for tools and tests); log its report.

    Without ``controllers_file`` the URDF's control plugin names it (see
    :func:`~pan_tilt_sim.model.controller_config.controllers_files_for`).
    """
    from pan_tilt_sim.model.controller_config import (
        controllers_files_for,
        load_controllers_config,
    )
    from pan_tilt_sim.model.description import load_description

    description = load_description(description_file, xacro_args)
    files = controllers_files_for(str(controllers_file or ''), description,
                                  runs_by_plugins=runs_by_plugins(description.model))
    simulation = Simulation(description, load_controllers_config(files, controllers_args),
                            time_step, gui=gui, active_controllers=active_controllers,
                            initial_positions=initial_positions, logger=logger,
                            autostart_controllers=autostart_controllers,
                            fixed_base=fixed_base, initial_pose=initial_pose,
                            physics_settings=physics_settings)
    for warning in description.warnings:
        simulation._logger.warning(warning)
    simulation.report_startup()
    return simulation
