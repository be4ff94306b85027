"""One evaluation -- a joint stepped to each target in a fresh simulation: tune's and sweep's unit.

:func:`evaluate` runs in whatever process the back end chose (this one, a
local worker process, a Ray worker on another machine): it takes the robot
as loaded once by the caller (:class:`Scenario`, shipped by value: no file
needs to exist where it runs) and one :class:`Case` (which joint, which
targets, which gains, which physical variation, which time step), builds
its own :class:`~pan_tilt_sim.sim.engine.Simulation` (its own PyBullet
client), records each step with ``step_response`` and returns plain values.
A fresh simulation per evaluation, and the targets always in the same
order, make the result a function of the case alone: the same case gives
the same numbers on any worker, in any order.

What is measured (``step_response``'s metrics, plus) (see the design notes).

Design notes: docs/design/tools.md#evaluationpy.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import pathlib
import sys
import time
from collections.abc import Iterator, Mapping, Sequence

from pan_tilt_sim.controllers import CommandController, Controller
from pan_tilt_sim.controllers.toolbox.pid import PidGains
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.model.controller_config import (
    ControllersConfig,
    controllers_files_for,
    load_controllers_config,
    parse_controllers_args,
)
from pan_tilt_sim.model.description import RobotDescription, load_description
from pan_tilt_sim.model.variation import PhysicalVariation, vary_description
from pan_tilt_sim.plugins.registry import runs_by_plugins
from pan_tilt_sim.sim.engine import Simulation
from pan_tilt_sim.tools.step_response import (
    StepMetrics,
    StepRecord,
    activate_the_rest,
    position_controller,
    record_step,
    step_metrics,
)

FINAL_WINDOW_S = 0.5
# A record shorter than this many windows uses its last tenth instead.
FINAL_WINDOW_FRACTION = 0.1
# At or beyond this share of the limit the effort counts as saturated.
SATURATION_SHARE = 1.0 - 1e-9
# PyBullet caps joint speeds at 100 rad/s (m/s); a joint this close to it is out of control.
SPEED_CAP = 99.0


@dataclasses.dataclass(frozen=True)
class Scenario:
    """The robot and its controllers, loaded once by the caller; sent to workers by value.

    ``active_controllers`` as ``step_response --active-controllers``: None
    activates the stepped joint's position controller, then every other that
    claims no joint an earlier one claims.
    """

    description: RobotDescription
    controllers: ControllersConfig
    time_step: float
    active_controllers: tuple[str, ...] | None = None
    controllers_args: tuple[str, ...] = ()  # NAME:=VALUE, as read (to read the YAML again)


def load_scenario(model: str | pathlib.Path, controllers: str | pathlib.Path | None,
                  time_step: float, xacro_args: Sequence[str] = (), *,
                  controllers_args: Sequence[str] = (),
                  active_controllers: Sequence[str] | None = None) -> Scenario:
    """Read the robot description and its controllers YAML as sim_node and step_response do.

    ``controllers`` empty or None: the file(s) the URDF's control plugin
    names, else the shipped pan/tilt's own.  ``controllers_args`` are the
    ``NAME:=VALUE`` values of the YAML's ``$(var NAME)``.
    """
    if not (math.isfinite(time_step) and 0.0 < time_step <= 0.1):
        raise ConfigurationError(f'--time-step: {time_step} must be > 0 and <= 0.1 s')
    description = load_description(model, xacro_args)
    files = controllers_files_for(str(controllers or ''), description, given_as='--controllers',
                                  runs_by_plugins=runs_by_plugins(description.model))
    config = load_controllers_config(
        files, parse_controllers_args(controllers_args, '--controllers-args'),
        args_name='--controllers-args')
    return Scenario(description, config, time_step,
                    None if not active_controllers else tuple(active_controllers),
                    tuple(controllers_args))


@contextlib.contextmanager
def simulation_for(scenario: Scenario, joint: str, description: RobotDescription | None = None,
                   time_step: float | None = None) -> Iterator[tuple[Simulation,
                                                                      CommandController]]:
    """Build the scenario's simulation with ``joint``'s stepping controller active.

    Yields the simulation and that controller, activated as ``step_response``
    activates them.
    """
    active = scenario.active_controllers
    with Simulation(description or scenario.description, scenario.controllers,
                    time_step or scenario.time_step,
                    active_controllers=list(active) if active else []) as simulation:
        driver = position_controller(simulation, joint)
        if not active:
            activate_the_rest(simulation)
        yield simulation, driver


@dataclasses.dataclass(frozen=True)
class Case:
    """What one evaluation simulates."""

    joint: str
    targets: tuple[float, ...]
    # Gains replacing the YAML's, by joint (the joint under test and any others).
    gains: tuple[tuple[str, PidGains], ...] = ()
    variation: PhysicalVariation = PhysicalVariation()
    time_step: float | None = None  # None: the scenario's
    duration: float | None = None  # s of sim time per step; None: ramp + 5 s
    keep_records: bool = False  # return the sampled responses too (for plots)
    # Record each step as a rosbag2 bag in <record>/<joint>_<n> (n from 1); None: no bags.
    record: str | None = None


@dataclasses.dataclass(frozen=True)
class StepResult:
    """One step of one evaluation: ``step_response``'s metrics and the tuner's figures."""

    target: float
    initial: float
    metrics: StepMetrics
    itae: float
    final_error: float
    saturated_s: float
    effort_limit: float
    stable: bool
    duration_s: float
    record: StepRecord | None = None


@dataclasses.dataclass(frozen=True)
class Evaluation:
    """Every step of one case, and what it cost to simulate."""

    joint: str
    steps: tuple[StepResult, ...]
    cpu_s: float  # CPU time of the evaluation in the process that ran it

    @property
    def itae(self) -> float:
        """The cost: the sum of every step's ITAE (infinite if a step was unstable)."""
        if not all(step.stable for step in self.steps):
            return math.inf
        return sum(step.itae for step in self.steps)


def controller_of(simulation: Simulation, joint: str) -> Controller:
    """Return the active controller driving ``joint``; ConfigurationError if none does."""
    for controller in simulation.manager.active:
        if joint in controller.joint_names:
            return controller
    raise ConfigurationError(f"--joint: no active controller drives '{joint}'")


def apply_gains(simulation: Simulation, gains: Mapping[str, PidGains]) -> None:
    """Give each joint's PID the gains of ``gains`` (its active controller must have a PID)."""
    for joint, joint_gains in gains.items():
        pid = controller_of(simulation, joint).pids().get(joint)
        if pid is None:
            raise ConfigurationError(f"--joint: '{joint}' is not driven by a PID")
        pid.gains = joint_gains


def evaluate(scenario: Scenario, case: Case) -> Evaluation:
    """Simulate ``case``: a fresh simulation, each target stepped from the initial state."""
    started = time.process_time()
    description = vary_description(scenario.description, case.variation)
    steps = []
    with simulation_for(scenario, case.joint, description, case.time_step) as (simulation,
                                                                              driver):
        apply_gains(simulation, dict(case.gains))
        effort_limit = simulation.handles[case.joint].spec.effort_limit
        for index, target in enumerate(case.targets):
            if index:
                simulation.reset()
            with _recording(scenario, case, index, simulation) as bag:
                record = record_step(simulation, case.joint, target, case.duration,
                                     driver.name, bag)
            steps.append(step_result(record, effort_limit, case.keep_records))
    return Evaluation(case.joint, tuple(steps), time.process_time() - started)


@contextlib.contextmanager
def _recording(scenario: Scenario, case: Case, index: int,
               simulation: Simulation) -> Iterator[object | None]:
    """Record step ``index`` of ``case`` where it asks for bags (rclpy and mcap load only then)."""
    if case.record is None:
        yield None
        return
    from pan_tilt_sim.model import naming
    from pan_tilt_sim.tools.bag_recording import SimulationRecording

    namespace = naming.resolve_robot_namespace(
        '', '', scenario.controllers.namespace, scenario.description.plugin_namespace)
    bag = SimulationRecording(
        str(pathlib.Path(case.record, f'{case.joint}_{index + 1}')), simulation, namespace,
        field='--record', warn=lambda line: print(f'warning: {line}', file=sys.stderr))
    try:
        yield bag
    finally:
        bag.close()


def step_result(record: StepRecord, effort_limit: float, keep_record: bool) -> StepResult:
    """Measure one recorded step."""
    times, positions, setpoints = record.times, record.positions, record.setpoints
    stable = all(math.isfinite(p) for p in positions) and all(
        abs(b - a) < SPEED_CAP * (t1 - t0)
        for a, b, t0, t1 in zip(positions, positions[1:], times, times[1:], strict=False))
    step = abs(record.target - record.initial)
    itae = 0.0
    for index in range(1, len(times)):
        itae += times[index] * abs(setpoints[index] - positions[index]) * (
            times[index] - times[index - 1])
    duration = times[-1]
    window = min(FINAL_WINDOW_S, FINAL_WINDOW_FRACTION * duration)
    final_error = max(abs(record.target - p) for t, p in zip(times, positions, strict=True)
                      if t >= duration - window)
    dt = times[1] - times[0] if len(times) > 1 else 0.0
    saturated = sum(1 for effort in record.efforts
                    if abs(effort) >= SATURATION_SHARE * effort_limit) * dt
    metrics = step_metrics(record) if stable else StepMetrics(
        rise_time_s=None, overshoot_percent=math.inf, settling_time_s=None,
        steady_state_error=math.inf, peak_effort=max(map(abs, record.efforts)),
        velocity_limit_active=False, setpoint_reached_s=None)
    return StepResult(
        target=record.target, initial=record.initial, metrics=metrics,
        itae=itae / step if stable else math.inf,
        final_error=final_error if stable else math.inf, saturated_s=saturated,
        effort_limit=effort_limit, stable=stable, duration_s=duration,
        record=record if keep_record else None)


@dataclasses.dataclass(frozen=True)
class Spec:
    """What a step response must achieve; None = no bound.  Effort: never at the URDF limit."""

    max_overshoot_percent: float | None = None
    max_settling_s: float | None = None
    max_error: float | None = None

    def __post_init__(self) -> None:
        for field, option in (('max_overshoot_percent', '--max-overshoot'),
                              ('max_settling_s', '--max-settling'),
                              ('max_error', '--max-error')):
            value = getattr(self, field)
            if value is not None and not (math.isfinite(value) and value >= 0.0):
                raise ConfigurationError(f'{option}: {value} must be a finite number >= 0')


CONSTRAINTS = ('overshoot', 'settling', 'error', 'effort')


def violations(evaluation: Evaluation, spec: Spec) -> dict[str, float]:
    """Return each constraint's worst violation over the steps, scaled to its bound.

    A value <= 0 means met (its size: the margin); > 0 means violated by that
    share of the bound.  An unstable step violates every constraint.
    """
    worst = dict.fromkeys(CONSTRAINTS, -math.inf)
    for step in evaluation.steps:
        for name, value in step_violations(step, spec).items():
            worst[name] = max(worst[name], value)
    return worst


def step_violations(step: StepResult, spec: Spec) -> dict[str, float]:
    """Return one step's scaled violations (see :func:`violations`)."""
    if not step.stable:
        return dict.fromkeys(CONSTRAINTS, math.inf)
    metrics = step.metrics
    found = {'overshoot': -1.0, 'settling': -1.0, 'error': -1.0}
    if spec.max_overshoot_percent is not None:
        bound = max(spec.max_overshoot_percent, 1.0)
        found['overshoot'] = (metrics.overshoot_percent - spec.max_overshoot_percent) / bound
    if spec.max_settling_s is not None:
        settled = metrics.settling_time_s
        # Not settled within the record: at least as late as its end.
        settled = step.duration_s * 1.5 if settled is None else settled
        found['settling'] = (settled - spec.max_settling_s) / max(spec.max_settling_s, 1e-3)
    if spec.max_error is not None:
        found['error'] = (step.final_error - spec.max_error) / max(spec.max_error, 1e-6)
    found['effort'] = step.saturated_s / step.duration_s if step.saturated_s > 0 else -1.0
    return found


def meets(evaluation: Evaluation, spec: Spec) -> bool:
    """Whether every step of ``evaluation`` meets ``spec``."""
    return all(value <= 0.0 for value in violations(evaluation, spec).values())
