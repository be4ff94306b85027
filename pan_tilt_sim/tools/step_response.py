"""step_response: step a joint by position and measure the response. No ROS graph.

::

    ros2 run pan_tilt_sim step_response --joint pan_joint --target 1.0 --plot step.png

runs the simulation in this process as fast as it goes (without ``--record`` it never imports
rclpy), commands the joint to ``--target`` at t = 0 through the controller
that drives it by position, records position, setpoint and effort every
physics step for ``--duration`` seconds of sim time, and prints JSON.

Design notes: docs/design/tools.md#step_responsepy.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import math
import pathlib
import sys
from collections.abc import Sequence
from typing import Any

from pan_tilt_sim.controllers import CommandController, CommandResult
from pan_tilt_sim.controllers.commands.forward_command_controller import ForwardCommandController
from pan_tilt_sim.controllers.commands.joint_position_controller import JointPositionController
from pan_tilt_sim.controllers.trajectory.joint_trajectory_controller import (
    JointTrajectoryController,
)
from pan_tilt_sim.controllers.trajectory.trajectory import JointTrajectory, TrajectoryPoint
from pan_tilt_sim.errors import ConfigurationError, ControllerSwitchError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.controller_config import (
    controllers_files_for,
    load_controllers_config,
    parse_controllers_args,
)
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.robot import JointKind
from pan_tilt_sim.plugins.registry import runs_by_plugins
from pan_tilt_sim.share import DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.sim.engine import Simulation

PROGRAM = 'step_response'
EXIT_CONFIGURATION_ERROR = 2
DEFAULT_TIME_STEP = 0.001  # s, sim_node's default
SETTLE_ALLOWANCE_S = 5.0  # s of sim time after the setpoint ramp, by default
RISE_LOW = 0.1
RISE_HIGH = 0.9
SETTLING_BAND = 0.02
PERCENT = 100.0
# A setpoint this close to the target has reached it.
SETPOINT_TOLERANCE = 1e-9
PLOT_SIZE_IN = (8.0, 4.5)
PLOT_DPI = 80
DIGITS = 4
ANGULAR_UNITS = ('rad', 'N m')  # position, effort
LINEAR_UNITS = ('m', 'N')


@dataclasses.dataclass(frozen=True)
class StepRecord:
    """One step response, sampled every physics step (t = 0 is the step)."""

    joint: str
    controller: str
    initial: float
    target: float
    velocity_limit: float
    position_unit: str
    effort_unit: str
    times: tuple[float, ...]
    positions: tuple[float, ...]
    setpoints: tuple[float, ...]
    efforts: tuple[float, ...]


@dataclasses.dataclass(frozen=True)
class StepMetrics:
    """The usual figures of merit of a step response."""

    rise_time_s: float | None
    overshoot_percent: float
    settling_time_s: float | None
    steady_state_error: float
    peak_effort: float
    velocity_limit_active: bool
    setpoint_reached_s: float | None


def crossing_time(times: Sequence[float], values: Sequence[float], level: float) -> float | None:
    """Return when ``values`` (rising) first reach ``level``, interpolated; None if never."""
    for index, value in enumerate(values):
        if value >= level:
            if index == 0:
                return times[0]
            before, t_before = values[index - 1], times[index - 1]
            fraction = (level - before) / (value - before)
            return t_before + fraction * (times[index] - t_before)
    return None


def normalized(values: Sequence[float], initial: float, target: float) -> list[float]:
    """Map ``values`` so that ``initial`` is 0 and ``target`` is 1 (steps either way)."""
    step = target - initial
    if step == 0.0:
        raise ValueError('the step is zero: initial and target are equal')
    return [(value - initial) / step for value in values]


def rise_time(times: Sequence[float], values: Sequence[float], initial: float,
              target: float) -> float | None:
    """Return the 10 %-90 % rise time; None if the response never reaches 90 %."""
    fractions = normalized(values, initial, target)
    low = crossing_time(times, fractions, RISE_LOW)
    high = crossing_time(times, fractions, RISE_HIGH)
    return None if low is None or high is None else high - low


def overshoot_percent(values: Sequence[float], initial: float, target: float) -> float:
    """Return the peak's excursion past the target in % of the step (0 if none)."""
    return max(0.0, max(normalized(values, initial, target)) - 1.0) * PERCENT


def settling_time(times: Sequence[float], values: Sequence[float], initial: float,
                  target: float, band: float = SETTLING_BAND) -> float | None:
    """Return when the response enters, for good, the band of ``band`` x step around target.

    None if the last sample is outside the band (not settled within the record).
    """
    fractions = normalized(values, initial, target)
    settled_from = None
    for time, fraction in zip(times, fractions, strict=True):
        if abs(fraction - 1.0) > band:
            settled_from = None
        elif settled_from is None:
            settled_from = time
    return settled_from


def setpoint_reached(times: Sequence[float], setpoints: Sequence[float],
                     target: float) -> float | None:
    """Return when the setpoint first equals the target; None if it never does."""
    for time, setpoint in zip(times, setpoints, strict=True):
        if abs(setpoint - target) <= SETPOINT_TOLERANCE:
            return time
    return None


def step_metrics(record: StepRecord) -> StepMetrics:
    """Compute every metric of ``record``."""
    times, positions = record.times, record.positions
    reached = setpoint_reached(times, record.setpoints, record.target)
    # Without a velocity limit the setpoint jumps at the first step.
    first_step = times[1] if len(times) > 1 else times[0]
    return StepMetrics(
        rise_time_s=rise_time(times, positions, record.initial, record.target),
        overshoot_percent=overshoot_percent(positions, record.initial, record.target),
        settling_time_s=settling_time(times, positions, record.initial, record.target),
        steady_state_error=record.target - positions[-1],
        peak_effort=max(abs(effort) for effort in record.efforts),
        velocity_limit_active=reached is None or reached > first_step,
        setpoint_reached_s=reached,
    )


def takes_positions(controller: CommandController) -> bool:
    """Whether ``controller`` takes position commands for its joints."""
    if isinstance(controller, ForwardCommandController):
        return controller.interface_name == 'position'
    return isinstance(controller, JointPositionController | JointTrajectoryController)


def position_controller(simulation: Simulation, joint: str,
                        name: str | None = None) -> CommandController:
    """Return the controller that steps ``joint`` by position, activated.

    ``name`` picks it; else the joint's active controller when it takes
    positions, else the first loaded one that does (the controllers that
    claim its joints are deactivated).  ConfigurationError if there is none.
    """
    if joint not in simulation.handles:
        raise ConfigurationError(
            f"--joint: '{joint}' is not a movable joint of the robot "
            f"(movable joints: {', '.join(simulation.handles)})")
    manager = simulation.manager
    drivers = [c for c in simulation.command_controllers() if joint in c.joint_names]
    if name is not None:
        chosen = next((c for c in drivers if c.name == name), None)
        if chosen is None or not takes_positions(chosen):
            raise ConfigurationError(
                f"--controller: '{name}' is not a loaded controller that drives '{joint}' by "
                f"position (controllers of '{joint}': "
                f"{', '.join(_described(c) for c in drivers) or 'none'})")
    else:
        candidates = [c for c in drivers if takes_positions(c)]
        active = [c for c in candidates if manager.is_active(c.name)]
        chosen = (active or candidates or [None])[0]
        if chosen is None:
            if not drivers:
                raise ConfigurationError(f"--joint: no controller drives '{joint}'")
            raise ConfigurationError(
                f"--joint: no controller takes position commands for '{joint}' (its "
                f"controllers: {', '.join(_described(c) for c in drivers)}); step_response "
                'steps position, forward-command (position) and trajectory controllers')
    if not manager.is_active(chosen.name):
        rivals = [c.name for c in manager.active if set(c.joint_names) & set(chosen.joint_names)]
        try:
            manager.switch(activate=[chosen.name], deactivate=rivals)
        except ControllerSwitchError as err:
            raise ConfigurationError(f'--controller: {err}') from None
    return chosen


def _described(controller: CommandController) -> str:
    return f'{controller.name} ({controller.type_name})'


def position_command(controller: CommandController, joint: str, target: float) -> Any:
    """Return the command that moves ``joint`` to ``target``, the other joints holding."""
    if isinstance(controller, JointPositionController):
        return target
    setpoints = controller.setpoints()
    setpoints[joint] = target
    values = [setpoints[name] for name in controller.joint_names]
    if isinstance(controller, JointTrajectoryController):
        # One point due at once: the desired position steps, as a position command does.
        return JointTrajectory(controller.joint_names, (TrajectoryPoint(0.0, tuple(values)),))
    return values


def command_position(controller: CommandController, joint: str,
                     target: float) -> CommandResult:
    """Command ``joint`` to ``target``; the controller's other joints keep their setpoints."""
    return controller.set_command(position_command(controller, joint, target))


def record_step(simulation: Simulation, joint: str, target: float,
                duration: float | None = None, controller: str | None = None,
                bag: Any = None) -> StepRecord:
    """Step ``joint`` to ``target`` at the present state and record the response.

    ``duration`` (s of sim time) defaults to the velocity-limited ramp's
    length plus ``SETTLE_ALLOWANCE_S``; ``controller`` names the controller
    to step with (see :func:`position_controller`).  ``bag`` (a
    :class:`~pan_tilt_sim.tools.bag_recording.SimulationRecording`) records
    the command and every step.
    """
    driver = position_controller(simulation, joint, controller)
    spec = simulation.handles[joint].spec
    initial = simulation.joint_positions()[joint]
    if not math.isfinite(target):
        raise ConfigurationError(f'--target: {target!r} is not a finite number')
    command = position_command(driver, joint, target)
    result = driver.set_command(command)
    if bag is not None:
        bag.command(driver, command)
    if result is CommandResult.REJECTED:
        raise ConfigurationError(
            f'--target: {target!r}: {driver.command_problem(target, result)}')
    commanded = spec.clamp_position(target)
    if commanded == initial:
        raise ConfigurationError(
            f"--target: {commanded} is where '{joint}' already is; there is no step")
    if duration is None:
        ramp = abs(commanded - initial) / spec.velocity_limit
        duration = ramp + SETTLE_ALLOWANCE_S
    if not (math.isfinite(duration) and duration > 0.0):
        raise ConfigurationError(f'--duration: {duration} must be a number of seconds > 0')
    steps = max(1, round(duration / simulation.time_step))
    start = simulation.time
    handle = simulation.handles[joint]
    setpoints = driver.setpoints
    times, positions = [0.0], [initial]
    recorded_setpoints, efforts = [setpoints()[joint]], [handle.effort]
    for _ in range(steps):
        simulation.advance(1)
        if bag is not None:
            bag.after_steps()
        times.append(simulation.time - start)
        positions.append(simulation.joint_positions()[joint])
        recorded_setpoints.append(setpoints()[joint])
        efforts.append(handle.effort)
    units = LINEAR_UNITS if spec.kind is JointKind.PRISMATIC else ANGULAR_UNITS
    return StepRecord(joint=joint, controller=driver.name, initial=initial,
                      target=commanded, velocity_limit=spec.velocity_limit,
                      position_unit=units[0], effort_unit=units[1],
                      times=tuple(times), positions=tuple(positions),
                      setpoints=tuple(recorded_setpoints), efforts=tuple(efforts))


def report(record: StepRecord, metrics: StepMetrics, gains: dict[str, float] | None,
           actuator: str = '') -> dict:
    """Return the JSON-ready summary of one step response."""
    def rounded(value: float | None) -> float | None:
        return None if value is None or not math.isfinite(value) else round(value, DIGITS)

    summary = {
        'joint': record.joint,
        'controller': record.controller,
        'initial': rounded(record.initial),
        'target': rounded(record.target),
        'duration_s': rounded(record.times[-1]),
        'actuator': actuator,
        'gains': None if gains is None else {
            name: rounded(value) for name, value in gains.items()},
        'velocity_limit': rounded(record.velocity_limit),
    }
    for field in dataclasses.fields(metrics):
        value = getattr(metrics, field.name)
        summary[field.name] = value if isinstance(value, bool) else rounded(value)
    return summary


def plot(record: StepRecord, metrics: StepMetrics, path: pathlib.Path) -> None:
    """Write a PNG: position and setpoint, effort on a second axis, metrics in the legend."""
    import matplotlib

    matplotlib.use('Agg')
    from matplotlib import pyplot
    from matplotlib.lines import Line2D

    figure, position_axis = pyplot.subplots(figsize=PLOT_SIZE_IN, dpi=PLOT_DPI)
    effort_axis = position_axis.twinx()
    lines = [
        position_axis.plot(record.times, record.setpoints, '--', color='tab:gray',
                           label='setpoint')[0],
        position_axis.plot(record.times, record.positions, color='tab:blue',
                           label='position')[0],
        effort_axis.plot(record.times, record.efforts, color='tab:orange', alpha=0.7,
                         label='effort')[0],
    ]
    position_axis.set_xlabel('sim time after the step [s]')
    position_axis.set_ylabel(f'{record.joint} position [{record.position_unit}]')
    effort_axis.set_ylabel(f'effort [{record.effort_unit}]')

    def shown(value: float | None, unit: str) -> str:
        return 'n/a' if value is None else f'{value:.3g} {unit}'

    facts = [
        f'rise 10-90 %: {shown(metrics.rise_time_s, "s")}',
        f'overshoot: {metrics.overshoot_percent:.2f} %',
        f'settling 2 %: {shown(metrics.settling_time_s, "s")}',
        f'steady-state error: {metrics.steady_state_error:.3g} {record.position_unit}',
        f'peak effort: {metrics.peak_effort:.3g} {record.effort_unit}',
        f'velocity limit active: {"yes" if metrics.velocity_limit_active else "no"}',
    ]
    blanks = [Line2D([], [], linestyle='none') for _ in facts]
    position_axis.legend(lines + blanks, [line.get_label() for line in lines] + facts,
                         loc='lower right', fontsize='small')
    position_axis.set_title(f'{record.controller}: step {record.initial:g} -> {record.target:g}')
    position_axis.grid(True, alpha=0.3)
    figure.tight_layout()
    figure.savefig(path)
    pyplot.close(figure)


def add_robot_arguments(parser: argparse.ArgumentParser, active_default: str) -> None:
    """Add the options that say which robot and controllers to load (step_response, tune)."""
    parser.add_argument('--model', default=str(package_share() / DEFAULT_DESCRIPTION),
                        help='.urdf or .xacro file (default: the pan/tilt model)')
    parser.add_argument('--xacro-args', nargs='*', default=[], metavar='NAME:=VALUE',
                        help='xacro mappings for a .xacro model')
    parser.add_argument('--controllers', default='',
                        help="controllers YAML (default: the one the URDF's control plugin "
                        'names; for the pan/tilt model its own)')
    parser.add_argument('--controllers-args', nargs='*', default=[], metavar='NAME:=VALUE',
                        help="values of the YAML's $(var NAME) substitutions")
    parser.add_argument('--active-controllers', nargs='*', default=None, metavar='NAME',
                        help=f'controllers to activate (default: {active_default})')


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    """Read the command line."""
    parser = argparse.ArgumentParser(
        prog=PROGRAM, description='Step a joint by position in the simulator (no ROS graph) '
        'and print rise time, overshoot, settling time, ... as JSON.')
    parser.add_argument('--joint', required=True, help='joint to step, e.g. pan_joint')
    parser.add_argument('--target', required=True, type=float, help='position to step to')
    add_robot_arguments(parser, 'every one that claims no joint an earlier one claims')
    parser.add_argument('--controller', default=None, metavar='NAME',
                        help="the controller to step with (default: the joint's active one "
                        'if it takes positions, else the first that does)')
    parser.add_argument('--time-step', type=float, default=DEFAULT_TIME_STEP,
                        help=f'physics step in s (default {DEFAULT_TIME_STEP})')
    parser.add_argument('--duration', type=float, default=None,
                        help='seconds of sim time to record (default: the velocity-limited '
                        f'ramp plus {SETTLE_ALLOWANCE_S:g} s)')
    parser.add_argument('--plot', type=pathlib.Path, default=None, metavar='FILE.png',
                        help='also write a plot of the response to this PNG file '
                        '(needs matplotlib)')
    parser.add_argument('--record', default=None, metavar='FOLDER',
                        help='also record the run as a rosbag2 bag (MCAP storage) in this new '
                        "folder, as sim_node's record:= does (needs mcap)")
    return parser.parse_args(argv)


def check_plot_target(path: pathlib.Path) -> None:
    """Fail before the run, not after it: matplotlib must import and the folder must exist."""
    try:
        import matplotlib  # noqa: F401 -- only whether it is there
    except ImportError:
        raise ConfigurationError(
            '--plot: matplotlib is not installed (pip install matplotlib)') from None
    if not path.parent.resolve().is_dir():
        raise ConfigurationError(f'--plot: cannot write {path}: no folder {path.parent}')


def build_simulation(args: argparse.Namespace) -> Simulation:
    """Load the model and its controllers as sim_node would, activated as ``args`` say."""
    description = load_description(args.model, args.xacro_args)
    files = controllers_files_for(args.controllers, description, given_as='--controllers',
                                  runs_by_plugins=runs_by_plugins(description.model))
    config = load_controllers_config(
        files, parse_controllers_args(args.controllers_args, '--controllers-args'),
        args_name='--controllers-args')
    active = args.active_controllers or None
    args.controllers_namespace = config.namespace
    return Simulation(description, config, args.time_step,
                      active_controllers=[] if active is None else active)


def start_recording(args: argparse.Namespace, simulation: Simulation) -> Any:
    """Start recording the run into ``args.record`` (rclpy and mcap load only now)."""
    from pan_tilt_sim.tools.bag_recording import SimulationRecording

    description = simulation.description
    namespace = naming.resolve_robot_namespace(
        '', '', args.controllers_namespace, description.plugin_namespace)
    return SimulationRecording(
        args.record, simulation, namespace, field='--record',
        warn=lambda line: print(f'{PROGRAM}: warning: {line}', file=sys.stderr))


def activate_the_rest(simulation: Simulation) -> None:
    """Activate, in order, every inactive controller that claims no joint an active one claims."""
    manager = simulation.manager
    for controller in manager.controllers:
        if not manager.is_active(controller.name):
            try:
                manager.switch(activate=[controller.name])
            except ControllerSwitchError:
                continue


def run(args: argparse.Namespace) -> dict:
    """Simulate the step that ``args`` ask for; return the JSON summary."""
    if not (math.isfinite(args.time_step) and 0.0 < args.time_step):
        raise ConfigurationError(f'--time-step: {args.time_step} must be > 0 s')
    if args.plot is not None:
        check_plot_target(args.plot)
    with build_simulation(args) as simulation, contextlib.ExitStack() as recording:
        driver = position_controller(simulation, args.joint, args.controller)
        if not args.active_controllers:
            activate_the_rest(simulation)
        bag = None if args.record is None else start_recording(args, simulation)
        if bag is not None:
            recording.callback(bag.close)
        record = record_step(simulation, args.joint, args.target, args.duration, driver.name,
                             bag)
        pid = driver.pids().get(args.joint)
        actuator = simulation.handles[args.joint].actuator.kind.label
    metrics = step_metrics(record)
    if args.plot is not None:
        try:
            plot(record, metrics, args.plot)
        except OSError as err:
            raise ConfigurationError(f'--plot: cannot write {args.plot}: {err}') from None
    gains = None if pid is None else {'p': pid.gains.p, 'i': pid.gains.i, 'd': pid.gains.d}
    return report(record, metrics, gains, actuator)


def main(argv: Sequence[str] | None = None) -> None:
    """Run the step_response command line; errors exit with code 2 and one line."""
    args = parse_args(argv)
    try:
        summary = run(args)
    except ConfigurationError as err:
        print(f'{PROGRAM}: error: {err}', file=sys.stderr)
        sys.exit(EXIT_CONFIGURATION_ERROR)
    print(json.dumps(summary, indent=2))


if __name__ == '__main__':
    main()
