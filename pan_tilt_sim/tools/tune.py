r"""tune: search PID gains that meet a step-response specification, in parallel. No ROS graph.

::

    ros2 run pan_tilt_sim tune --joint pan_joint --target 1.0 \\
        --max-error 0.002 --max-settling 15 --out tuned.yaml --plot tune.png
    ros2 run pan_tilt_sim tune ... --address auto          # the same on a Ray cluster

Design notes: docs/design/tools.md#tunepy.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import pathlib
import sys
import tempfile
import warnings
from collections.abc import Callable, Mapping, Sequence

from pan_tilt_sim.controllers.toolbox.pid import PidGains
from pan_tilt_sim.errors import ConfigurationError, ControllerConfigError
from pan_tilt_sim.model.controller_config import (
    load_controllers_config,
    parse_controllers_args,
    read_text,
)
from pan_tilt_sim.model.gains_yaml import (
    GainsUpdate,
    clamp_values,
    gain_fields,
    loaded_gains,
    rewrite_gains,
)
from pan_tilt_sim.model.robot import JointKind, JointSpec
from pan_tilt_sim.tools import step_response
from pan_tilt_sim.tools.backends import Backend, BackendError, InProcess, make_backend
from pan_tilt_sim.tools.evaluation import (
    CONSTRAINTS,
    Case,
    Evaluation,
    Scenario,
    Spec,
    evaluate,
    load_scenario,
    simulation_for,
    violations,
)

PROGRAM = 'tune'
EXIT_NOT_MET = 1
EXIT_CONFIGURATION_ERROR = 2
DEFAULT_TRIALS = 64
DEFAULT_BATCH = 8
DEFAULT_SEED = 0
DEFAULT_OVERSHOOT_PERCENT = 5.0
SIGNIFICANT_DIGITS = 4  # candidates are rounded so the YAML holds exactly what was evaluated
PARAMETERS = ('p', 'i', 'd', 'i_clamp')
# Search ranges (log-uniform) around the YAML's gains, as factors.
P_SPAN = 100.0
I_LOW, I_HIGH = 1e-4, 10.0  # times p: integral time constants from 10,000 s to 0.1 s
D_SPAN = 100.0
CLAMP_LOW = 1e-3  # times the effort limit
FALLBACK_P = 100.0  # the pan/tilt example's p, when the YAML's is 0
# Optuna takes finite numbers; an unstable candidate gets these.
WORST_COST = 1e12
WORST_VIOLATION = 1e6
OPTUNA_HINT = 'tune needs Optuna: pip install optuna'
UNIT = {True: ('rad', 'N m'), False: ('m', 'N')}


@dataclasses.dataclass(frozen=True)
class SearchSpace:
    """Log-uniform ranges of the searched gains."""

    ranges: Mapping[str, tuple[float, float]]


def search_space(gains: PidGains, joint: JointSpec,
                 overrides: Mapping[str, tuple[float, float]] | None = None) -> SearchSpace:
    """Return log ranges around ``gains``: p, d x/÷ 100, i up to 10 p, clamp up to the limit."""
    p = gains.p if gains.p > 0.0 else FALLBACK_P
    d = gains.d if gains.d > 0.0 else p / 10.0
    limit = joint.effort_limit if math.isfinite(joint.effort_limit) else 100.0 * p
    ranges = {'p': (p / P_SPAN, p * P_SPAN), 'i': (p * I_LOW, p * I_HIGH),
              'd': (d / D_SPAN, d * D_SPAN), 'i_clamp': (limit * CLAMP_LOW, limit)}
    ranges.update(overrides or {})
    return SearchSpace(ranges)


def rounded(value: float, digits: int = SIGNIFICANT_DIGITS) -> float:
    """Return ``value`` rounded to ``digits`` significant digits."""
    return float(f'{value:.{digits}g}')


def candidate_gains(base: PidGains, params: Mapping[str, float]) -> PidGains:
    """Return the gains of one candidate: ``base`` with p, i, d and a symmetric clamp replaced."""
    clamp = rounded(params['i_clamp'])
    return dataclasses.replace(base, p=rounded(params['p']), i=rounded(params['i']),
                               d=rounded(params['d']), i_clamp_min=-clamp, i_clamp_max=clamp)


def starting_params(gains: PidGains, space: SearchSpace) -> dict[str, float]:
    """Return the YAML's gains as a point of the search space (clipped into its ranges)."""
    clamp = max(abs(gains.i_clamp_min), abs(gains.i_clamp_max))
    values = {'p': gains.p, 'i': gains.i, 'd': gains.d, 'i_clamp': clamp}
    return {name: min(max(values[name], low), high)
            for name, (low, high) in space.ranges.items()}


def limit_notes(joint: JointSpec, initial: float, target: float, spec: Spec) -> dict[str, str]:
    """Return, per constraint, why the URDF's limits alone make it impossible (if they do)."""
    notes = {}
    rotates = joint.kind is not JointKind.PRISMATIC
    position_unit, effort_unit = UNIT[rotates]
    if joint.effort_limit <= joint.friction:
        notes['effort'] = (
            f'the URDF effort limit of {joint.name} ({joint.effort_limit:g} {effort_unit}) is '
            f'not above its friction ({joint.friction:g} {effort_unit}): it cannot move')
        return notes
    speed, why = joint.velocity_limit, f'the URDF velocity limit ({joint.velocity_limit:g} ' \
        f'{position_unit}/s) ramps the setpoint'
    if joint.damping > 0.0 and math.isfinite(joint.effort_limit):
        pushed = (joint.effort_limit - joint.friction) / joint.damping
        if pushed < speed:
            speed, why = pushed, (
                f'its effort limit ({joint.effort_limit:g} {effort_unit}) against damping '
                f'{joint.damping:g} and friction {joint.friction:g} allows at most '
                f'{pushed:.3g} {position_unit}/s')
    if spec.max_settling_s is not None and math.isfinite(speed):
        travel = abs(target - initial) * (1.0 - step_response.SETTLING_BAND)
        earliest = travel / speed
        if earliest > spec.max_settling_s:
            notes['settling'] = (
                f'{joint.name} cannot settle at {target:g} {position_unit} within '
                f'{spec.max_settling_s:g} s: {why}, so it reaches the 2 % band only after '
                f'{earliest:.3g} s')
    return notes


@dataclasses.dataclass(frozen=True)
class Trial:
    """One evaluated candidate."""

    number: int
    gains: PidGains
    evaluation: Evaluation
    violations: Mapping[str, float]

    @property
    def feasible(self) -> bool:
        """Whether it meets the specification."""
        return all(value <= 0.0 for value in self.violations.values())

    @property
    def excess(self) -> float:
        """How far it is from the specification (0 when it meets it)."""
        return sum(max(0.0, min(value, WORST_VIOLATION)) for value in self.violations.values())


@dataclasses.dataclass(frozen=True)
class JointTuning:
    """The search for one joint: every trial, and the one chosen."""

    joint: str
    controller: str
    gains_field: str
    before: PidGains
    trials: tuple[Trial, ...]
    notes: Mapping[str, str]

    @property
    def best(self) -> Trial:
        """The cheapest trial that meets the spec (excess 0); else the one closest to it."""
        return min(self.trials, key=lambda trial: (trial.excess, trial.evaluation.itae,
                                                   trial.number))

    @property
    def met(self) -> bool:
        """Whether any trial met the specification."""
        return self.best.feasible


def _optuna():  # noqa: ANN202 -- the optuna module
    try:
        import optuna
    except ImportError:
        raise ConfigurationError(OPTUNA_HINT) from None
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    warnings.filterwarnings('ignore', category=optuna.exceptions.ExperimentalWarning)
    return optuna


def _constraints(trial) -> list[float]:  # noqa: ANN001 -- optuna.trial.FrozenTrial
    """Optuna < 5: the constraints the sampler reads back from each finished trial."""
    return trial.user_attrs['constraints']


def search(scenario: Scenario, joint: str, targets: Sequence[float], spec: Spec,
           base: PidGains, space: SearchSpace, backend: Backend, *, trials: int, batch: int,
           seed: int, fixed: Mapping[str, PidGains] | None = None,
           duration: float | None = None,
           progress: Callable[[str], None] = lambda text: None) -> list[Trial]:
    """Search gains for ``joint``; return every trial in the order it was asked for.

    ``fixed``: other joints' gains to use meanwhile.  The result depends on
    ``seed``, ``trials``, ``batch`` and the inputs only: each batch is asked
    in full, evaluated, and told in the order it was asked.
    """
    optuna = _optuna()
    # Optuna 5 takes constraints per trial (Trial.set_constraint); older ones through a callback.
    per_trial = hasattr(optuna.trial.Trial, 'set_constraint')
    sampler = optuna.samplers.TPESampler(
        seed=seed, multivariate=True, constant_liar=True,
        **({} if per_trial else {'constraints_func': _constraints}))
    study = optuna.create_study(direction='minimize', sampler=sampler)
    distributions = {name: optuna.distributions.FloatDistribution(low, high, log=True)
                     for name, (low, high) in space.ranges.items()}
    study.enqueue_trial(starting_params(base, space))
    others = tuple((name, gains) for name, gains in (fixed or {}).items() if name != joint)
    done: list[Trial] = []
    while len(done) < trials:
        asked = [study.ask(distributions) for _ in range(min(batch, trials - len(done)))]
        candidates = [candidate_gains(base, trial.params) for trial in asked]
        cases = [Case(joint, tuple(targets), gains=(*others, (joint, gains)), duration=duration)
                 for gains in candidates]
        for trial, gains, evaluation in zip(asked, candidates,
                                            backend.map(evaluate, scenario, cases), strict=True):
            found = violations(evaluation, spec)
            bounded = {name: min(found[name], WORST_VIOLATION) for name in CONSTRAINTS}
            if per_trial:
                for name, value in bounded.items():
                    trial.set_constraint(name, value)
            else:
                trial.set_user_attr('constraints', list(bounded.values()))
            study.tell(trial, min(evaluation.itae, WORST_COST))
            done.append(Trial(trial.number, gains, evaluation, found))
        best = JointTuning(joint, '', '', base, tuple(done), {}).best
        progress(f'{joint}: {len(done)}/{trials} evaluated; best so far: '
                 f"{'meets the spec' if best.feasible else 'misses the spec'}, "
                 f'cost {best.evaluation.itae:.4g}, {describe_gains(best.gains)}')
    return done


def describe_gains(gains: PidGains) -> str:
    """Return ``p=.. i=.. d=.. i_clamp=..`` for messages."""
    clamp = max(abs(gains.i_clamp_min), abs(gains.i_clamp_max))
    return f'p={gains.p:g} i={gains.i:g} d={gains.d:g} i_clamp={clamp:g}'


@dataclasses.dataclass(frozen=True)
class JointPlan:
    """What ``tune`` knows about a joint before searching."""

    joint: JointSpec
    controller: str
    gains_field: str
    gains: PidGains
    targets: tuple[float, ...]


def plan_joints(scenario: Scenario, joints: Sequence[str],
                targets: Mapping[str, Sequence[float]]) -> list[JointPlan]:
    """Check every joint can be tuned (a PID with gains in the YAML); return what to tune."""
    plans = []
    specs = {spec.name: spec for spec in scenario.controllers.controllers}
    for joint in joints:
        with simulation_for(scenario, joint) as (sim, controller):
            pid = controller.pids().get(joint)
            params = specs[controller.name].params
            if pid is None or loaded_gains(params, controller.gains_field, joint) is None:
                field = 'pid' if controller.gains_field == 'pid' else f'gains.{joint}'
                raise ConfigurationError(
                    f"--joint: '{joint}': its controller '{controller.name}' has no {field} "
                    f'entry in {scenario.controllers.label}; tune changes the gains a file '
                    f'gives (add e.g. {field}: {{p: 100.0, i: 0.01, d: 10.0}})')
            plans.append(JointPlan(sim.handles[joint].spec, controller.name,
                                   controller.gains_field, pid.gains, tuple(targets[joint])))
    return plans


@dataclasses.dataclass(frozen=True)
class TuneResult:
    """Everything ``tune`` found: per joint the search, and the before/after evaluations."""

    tunings: tuple[JointTuning, ...]
    before: Mapping[str, Evaluation]
    after: Mapping[str, Evaluation]
    spec: Spec

    @property
    def met(self) -> bool:
        """Whether every joint met the specification, evaluated with all the new gains."""
        return all(tuning.met for tuning in self.tunings) and all(
            all(v <= 0.0 for v in violations(evaluation, self.spec).values())
            for evaluation in self.after.values())

    @property
    def gains(self) -> dict[str, PidGains]:
        """The chosen gains by joint."""
        return {tuning.joint: tuning.best.gains for tuning in self.tunings}


def evaluate_plans(scenario: Scenario, plans: Sequence[JointPlan],
                   gains: Mapping[str, PidGains], duration: float | None = None,
                   record: str | None = None) -> dict[str, Evaluation]:
    """Evaluate every planned joint in this process with ``gains``, records kept (for plots).

    With no gains given this is the "before" of the report, and it checks the
    targets (a target where the joint already is has no step) before any
    worker starts.  ``record``: a folder for a rosbag2 bag of each step.
    """
    cases = [Case(plan.joint.name, plan.targets, gains=tuple(gains.items()),
                  duration=duration, keep_records=True, record=record) for plan in plans]
    return {plan.joint.name: result for plan, result in
            zip(plans, InProcess().map(evaluate, scenario, cases), strict=True)}


def tune(scenario: Scenario, plans: Sequence[JointPlan], spec: Spec, backend: Backend, *,
         trials: int = DEFAULT_TRIALS, batch: int = DEFAULT_BATCH, seed: int = DEFAULT_SEED,
         duration: float | None = None,
         ranges: Mapping[str, tuple[float, float]] | None = None,
         before: Mapping[str, Evaluation] | None = None,
         progress: Callable[[str], None] = lambda text: None,
         record: str | None = None) -> TuneResult:
    """Tune each planned joint in turn; evaluate before (unless given) and after.

    ``record``: a new folder for the after evaluation's bags, one per joint and
    target (``<joint>_<n>``, see :mod:`.evaluation`).
    """
    if before is None:
        before = evaluate_plans(scenario, plans, {}, duration)
    chosen: dict[str, PidGains] = {}
    tunings = []
    for index, plan in enumerate(plans):
        notes: dict[str, str] = {}
        for step in before[plan.joint.name].steps:
            for name, note in limit_notes(plan.joint, step.initial, step.target, spec).items():
                notes.setdefault(name, note)
        for note in notes.values():
            progress(f'warning: {note}; searching anyway')
        found = search(scenario, plan.joint.name, plan.targets, spec, plan.gains,
                       search_space(plan.gains, plan.joint, ranges), backend, trials=trials,
                       batch=batch, seed=seed + index, fixed=chosen, duration=duration,
                       progress=progress)
        tuning = JointTuning(plan.joint.name, plan.controller, plan.gains_field, plan.gains,
                             tuple(found), notes)
        tunings.append(tuning)
        chosen[plan.joint.name] = tuning.best.gains
    return TuneResult(tuple(tunings), before,
                      evaluate_plans(scenario, plans, chosen, duration, record), spec)


# --- reporting ----------------------------------------------------------------------------

def _shown(value: float | None, digits: int = 4) -> str:
    if value is None:
        return 'n/a'
    if math.isinf(value):
        return 'unstable'
    return f'{value:.{digits}g}'


def table(result: TuneResult) -> str:
    """Return the before/after table of every metric, target and joint, and the gains."""
    spec = result.spec
    lines = [f"{'joint':<16}{'target':>9}  {'metric':<24}{'before':>11}{'after':>11}  bound"]
    for tuning in result.tunings:
        before, after = result.before[tuning.joint], result.after[tuning.joint]
        for old, new in zip(before.steps, after.steps, strict=True):
            position_unit, effort_unit = old.record.position_unit, old.record.effort_unit
            rows = [
                ('rise 10-90 % [s]', old.metrics.rise_time_s, new.metrics.rise_time_s, ''),
                ('overshoot [%]', old.metrics.overshoot_percent, new.metrics.overshoot_percent,
                 _bound(spec.max_overshoot_percent)),
                ('settling 2 % [s]', old.metrics.settling_time_s, new.metrics.settling_time_s,
                 _bound(spec.max_settling_s)),
                (f'final error [{position_unit}]', old.final_error, new.final_error,
                 _bound(spec.max_error)),
                (f'peak effort [{effort_unit}]', old.metrics.peak_effort,
                 new.metrics.peak_effort, f'< {old.effort_limit:g} (URDF)'),
                ('ITAE [s^2]', old.itae, new.itae, 'minimised'),
            ]
            for number, (name, was, now, bound) in enumerate(rows):
                joint = tuning.joint if number == 0 else ''
                target = f'{old.target:g}' if number == 0 else ''
                lines.append(f'{joint:<16}{target:>9}  {name:<24}{_shown(was):>11}'
                             f'{_shown(now):>11}  {bound}'.rstrip())
        lines.append(f'{tuning.joint:<16}{"":>9}  gains: {describe_gains(tuning.before)}'
                     f' -> {describe_gains(tuning.best.gains)}')
    return '\n'.join(lines)


def _bound(value: float | None) -> str:
    return '' if value is None else f'<= {value:g}'


def verdict(result: TuneResult) -> list[str]:
    """Return the closing lines: met, or for each joint that is not, what binds and why."""
    lines = []
    for tuning in result.tunings:
        best = tuning.best
        count = len(tuning.trials)
        feasible = sum(1 for trial in tuning.trials if trial.feasible)
        after = violations(result.after[tuning.joint], result.spec)
        if tuning.met and all(value <= 0.0 for value in after.values()):
            lines.append(f'{tuning.joint}: meets the specification ({feasible} of {count} '
                         f'candidates did); cost {best.evaluation.itae:.4g} '
                         f'(was {result.before[tuning.joint].itae:.4g})')
            continue
        if tuning.met:
            lines.append(f'{tuning.joint}: met the specification while tuned, but not with the '
                         'gains chosen for the joints tuned after it: ' + ', '.join(
                             name for name, value in after.items() if value > 0.0))
            continue
        binding = [name for name, value in best.violations.items() if value > 0.0]
        everyone = [name for name in CONSTRAINTS
                    if all(trial.violations[name] > 0.0 for trial in tuning.trials)]
        text = (f'{tuning.joint}: no candidate meets the specification ({count} tried); best '
                f'found: {describe_gains(best.gains)}, which misses {", ".join(binding)}')
        if everyone:
            text += f'; every candidate missed {", ".join(everyone)}'
        lines.append(text)
        for name in binding:
            if name in tuning.notes:
                lines.append(f'  {name} binds: {tuning.notes[name]}')
    return lines


def plot(result: TuneResult, path: pathlib.Path) -> None:
    """Write one PNG: for every joint and target, the step response before and after.

    Each target gets two panels: position (and the setpoint) over time, and
    ``|target - position|`` on a log scale, where the final error shows.
    """
    import matplotlib

    matplotlib.use('Agg')
    from matplotlib import pyplot

    panels = [(tuning.joint, old, new) for tuning in result.tunings
              for old, new in zip(result.before[tuning.joint].steps,
                                  result.after[tuning.joint].steps, strict=True)]
    figure, axes = pyplot.subplots(
        2 * len(panels), 1, squeeze=False, figsize=(8.0, 5.0 * len(panels)), dpi=80,
        gridspec_kw={'height_ratios': [3, 2] * len(panels)})
    for index, (joint, old, new) in enumerate(panels):
        position_axis, error_axis = axes[2 * index, 0], axes[2 * index + 1, 0]
        for step, name, colour in ((old, 'before', 'tab:orange'), (new, 'after', 'tab:blue')):
            record, metrics = step.record, step.metrics
            position_axis.plot(record.times, record.positions, color=colour, label=(
                f'{name}: overshoot {_shown(metrics.overshoot_percent, 3)} %, settling '
                f'{_shown(metrics.settling_time_s, 3)} s, final error '
                f'{_shown(step.final_error, 3)} {record.position_unit}'))
            error_axis.semilogy(record.times, [max(abs(record.target - p), 1e-9)
                                               for p in record.positions], color=colour)
        position_axis.plot(new.record.times, new.record.setpoints, ':', color='black',
                           linewidth=1.0, label='setpoint (after)')
        if result.spec.max_error is not None:
            error_axis.axhline(result.spec.max_error, color='tab:red', linestyle='--',
                               linewidth=1.0, label=f'--max-error {result.spec.max_error:g}')
            error_axis.legend(loc='upper right', fontsize='small')
        position_axis.set_title(f'{joint}: step {old.initial:g} -> {old.target:g}')
        position_axis.set_ylabel(f'position [{old.record.position_unit}]')
        position_axis.legend(loc='lower right', fontsize='small')
        error_axis.set_ylabel(f'|target - position| [{old.record.position_unit}]')
        error_axis.set_xlabel('sim time after the step [s]')
        for axis in (position_axis, error_axis):
            axis.grid(True, alpha=0.3)
    figure.tight_layout()
    figure.savefig(path)
    pyplot.close(figure)


def write_yaml(scenario: Scenario, result: TuneResult, out: pathlib.Path) -> None:
    """Write the controllers YAML with the new gains; check it loads back to exactly them.

    With several controller files (ros2_control reads them in order, later
    ones win), the one rewritten is the last that gives the tuned gains; all
    of them must be in one file.
    """
    config = scenario.controllers
    files = list(config.sources or (config.source,))
    texts = [read_text(path) for path in files]
    updates: dict[int, list[GainsUpdate]] = {}
    for tuning in result.tunings:
        path = ('pid',) if tuning.gains_field == 'pid' else ('gains', tuning.joint)
        found = [(index, _fields_in(text, str(files[index]), tuning.controller, path))
                 for index, text in enumerate(texts)]
        index, existing = next(((i, f) for i, f in reversed(found) if f), (len(files) - 1, []))
        gains = tuning.best.gains
        values = {'p': gains.p, 'i': gains.i, 'd': gains.d,
                  **clamp_values(gains.i_clamp_max, existing)}
        updates.setdefault(index, []).append(
            GainsUpdate(tuning.controller, tuning.joint, tuning.gains_field, values))
    if len(updates) > 1:
        raise ConfigurationError(
            f"--out: the tuned joints' gains are in several files ("
            f"{', '.join(str(files[index]) for index in sorted(updates))}); tune writes one: "
            'tune the joints of each file separately')
    (index, file_updates), = updates.items()
    new_text = rewrite_gains(texts[index], str(files[index]), file_updates)
    with tempfile.TemporaryDirectory(prefix='pan_tilt_tune_') as folder:
        copies = []
        for number, (path, text) in enumerate(zip(files, texts, strict=True)):
            copy = pathlib.Path(folder, str(number), path.name)  # the name can name a controller
            copy.parent.mkdir()
            copy.write_text(new_text if number == index else text, encoding='utf-8')
            copies.append(copy)
        written = load_controllers_config(
            copies, parse_controllers_args(scenario.controllers_args, '--controllers-args'),
            args_name='--controllers-args')
    params = {spec.name: spec.params for spec in written.controllers}
    for tuning in result.tunings:
        read = PidGains.from_mapping({k: v for k, v in loaded_gains(
            params[tuning.controller], tuning.gains_field, tuning.joint).items()
            if k in ('p', 'i', 'd', 'i_clamp', 'i_clamp_min', 'i_clamp_max', 'antiwindup')})
        if read != tuning.best.gains:
            raise RuntimeError(f'{out}: the written YAML reads back as {read}, not '
                               f'{tuning.best.gains}')
    try:
        out.write_text(new_text, encoding='utf-8')
    except OSError as err:
        raise ConfigurationError(f'--out: cannot write {out}: {err}') from None


def _fields_in(text: str, source: str, controller: str, path: Sequence[str]) -> list[str]:
    """Return the PID fields ``text`` gives the controller at ``path`` (none: not in it)."""
    try:
        return gain_fields(text, source, controller, path)
    except ControllerConfigError:
        return []


# --- command line -----------------------------------------------------------------------------

def parse_targets(joints: Sequence[str], values: Sequence[str]) -> dict[str, list[float]]:
    """Read ``--target [JOINT=]VALUE``s: a bare value applies to every joint."""
    targets: dict[str, list[float]] = {joint: [] for joint in joints}
    for text in values:
        joint, separator, value = text.rpartition('=')
        try:
            number = float(value)
        except ValueError:
            raise ConfigurationError(f'--target: {text!r} is not [JOINT=]NUMBER') from None
        if not math.isfinite(number):
            raise ConfigurationError(f'--target: {text!r} is not a finite number')
        if separator:
            if joint not in targets:
                raise ConfigurationError(
                    f"--target: {text!r} names '{joint}', which is not a --joint")
            targets[joint].append(number)
        else:
            for joint_targets in targets.values():
                joint_targets.append(number)
    for joint, joint_targets in targets.items():
        if not joint_targets:
            raise ConfigurationError(f"--target: no target for '{joint}'")
    return targets


def parse_ranges(values: Sequence[str]) -> dict[str, tuple[float, float]]:
    """Read ``--range NAME=LOW:HIGH``s (NAME one of p, i, d, i_clamp)."""
    ranges = {}
    for text in values:
        name, _, bounds = text.partition('=')
        low, colon, high = bounds.partition(':')
        try:
            pair = (float(low), float(high))
        except ValueError:
            pair = (math.nan, math.nan)
        if name not in PARAMETERS or not colon or not (0.0 < pair[0] < pair[1] < math.inf):
            raise ConfigurationError(
                f'--range: {text!r} must be NAME=LOW:HIGH with NAME one of '
                f"{', '.join(PARAMETERS)} and 0 < LOW < HIGH")
        ranges[name] = pair
    return ranges


def add_robot_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the robot, specification and back-end options ``tune`` and ``sweep`` share."""
    parser.add_argument('--joint', action='append', required=True, metavar='NAME',
                        help='joint whose position controller to step (repeatable)')
    parser.add_argument('--target', action='append', required=True, metavar='[JOINT=]VALUE',
                        help='position to step to from the initial position (repeatable; '
                        'JOINT= gives it to one joint only)')
    step_response.add_robot_arguments(
        parser, "the stepped joint's position controller, then every one that claims no "
        'joint an earlier one claims')
    parser.add_argument('--time-step', type=float, default=step_response.DEFAULT_TIME_STEP,
                        help=f'physics step in s (default {step_response.DEFAULT_TIME_STEP})')
    parser.add_argument('--duration', type=float, default=None,
                        help='s of sim time per step (default: the velocity-limited ramp '
                        f'plus {step_response.SETTLE_ALLOWANCE_S:g} s)')
    parser.add_argument('--max-overshoot', type=float, default=DEFAULT_OVERSHOOT_PERCENT,
                        metavar='PCT', help='largest overshoot, %% of the step (default '
                        f'{DEFAULT_OVERSHOOT_PERCENT:g})')
    parser.add_argument('--max-settling', type=float, default=None, metavar='S',
                        help='latest settling time (2 %% band), s after the step')
    parser.add_argument('--max-error', type=float, default=None, metavar='RAD',
                        help='largest |target - position| over the last 0.5 s (rad or m)')
    parser.add_argument('--workers', type=int, default=None, metavar='N',
                        help='local worker processes (default: one per CPU; 0: in this '
                        'process); ignored with --address')
    parser.add_argument('--address', default=None, metavar='ADDR',
                        help='run the evaluations as Ray tasks on this cluster: auto, '
                        'HOST:PORT or ray://HOST:10001')
    parser.add_argument('--seed', type=int, default=DEFAULT_SEED,
                        help=f'random seed (default {DEFAULT_SEED})')


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    """Read the command line."""
    parser = argparse.ArgumentParser(
        prog=PROGRAM, description='Search PID gains that meet a step-response specification '
        '(Optuna TPE, evaluations in parallel on local processes or a Ray cluster).')
    add_robot_arguments(parser)
    parser.add_argument('--trials', type=int, default=DEFAULT_TRIALS,
                        help=f'candidates to evaluate per joint (default {DEFAULT_TRIALS})')
    parser.add_argument('--batch', type=int, default=DEFAULT_BATCH,
                        help='candidates proposed and evaluated together (default '
                        f'{DEFAULT_BATCH}); the result depends on it, not on the workers')
    parser.add_argument('--range', action='append', default=[], metavar='NAME=LOW:HIGH',
                        help='search range of p, i, d or i_clamp (default: around the '
                        "YAML's gains)")
    parser.add_argument('--out', type=pathlib.Path, default=None, metavar='FILE.yaml',
                        help='write the controllers YAML with the new gains here')
    parser.add_argument('--plot', type=pathlib.Path, default=None, metavar='FILE.png',
                        help='write the step responses before and after to this PNG')
    parser.add_argument('--record', default=None, metavar='FOLDER',
                        help="record the tuned gains' steps as rosbag2 bags (MCAP storage) "
                        'in this new folder, one per joint and target: FOLDER/JOINT_N '
                        '(needs mcap)')
    return parser.parse_args(argv)


def spec_from(args: argparse.Namespace) -> Spec:
    """Return the specification the command line gives."""
    return Spec(max_overshoot_percent=args.max_overshoot, max_settling_s=args.max_settling,
                max_error=args.max_error)


def check_counts(args: argparse.Namespace) -> None:
    """Refuse budgets that make no sense."""
    if args.trials < 1:
        raise ConfigurationError(f'--trials: {args.trials} must be at least 1')
    if args.batch < 1:
        raise ConfigurationError(f'--batch: {args.batch} must be at least 1')
    if args.workers is not None and args.workers < 0:
        raise ConfigurationError(f'--workers: {args.workers} must be 0 or more')
    if args.duration is not None and not (math.isfinite(args.duration) and args.duration > 0):
        raise ConfigurationError(f'--duration: {args.duration} must be a number of seconds > 0')
    if len(set(args.joint)) != len(args.joint):
        raise ConfigurationError('--joint: a joint is given twice')
    if args.record is not None and pathlib.Path(args.record).exists():
        raise ConfigurationError(
            f"--record: the folder '{args.record}' already exists (give a new one)")


def run(args: argparse.Namespace, log: Callable[[str], None]) -> tuple[TuneResult, Scenario]:
    """Tune as ``args`` ask; return the result (nothing written yet)."""
    check_counts(args)
    spec = spec_from(args)
    ranges = parse_ranges(args.range)
    targets = parse_targets(args.joint, args.target)
    _optuna()
    scenario = load_scenario(args.model, args.controllers, args.time_step, args.xacro_args,
                             controllers_args=args.controllers_args,
                             active_controllers=args.active_controllers)
    plans = plan_joints(scenario, args.joint, targets)
    before = evaluate_plans(scenario, plans, {}, args.duration)
    with make_backend(args.workers, args.address) as backend:
        log(f'evaluating on {backend.name} ({backend.parallelism} at a time), '
            f'{args.trials} candidates per joint in batches of {args.batch}, seed {args.seed}')
        result = tune(scenario, plans, spec, backend, trials=args.trials, batch=args.batch,
                      seed=args.seed, duration=args.duration, ranges=ranges, before=before,
                      progress=log, record=args.record)
    return result, scenario


def main(argv: Sequence[str] | None = None) -> None:
    """Run the tune command line."""
    args = parse_args(argv)

    def log(text: str) -> None:
        print(f'{PROGRAM}: {text}', file=sys.stderr, flush=True)

    try:
        result, scenario = run(args, log)
        print(table(result))
        for line in verdict(result):
            print(line)
        if args.plot is not None:
            try:
                plot(result, args.plot)
            except OSError as err:
                raise ConfigurationError(f'--plot: cannot write {args.plot}: {err}') from None
            print(f'plot: {args.plot}')
        if args.out is not None:
            if result.met:
                write_yaml(scenario, result, args.out)
                print(f'gains written to {args.out}')
            else:
                print(f'{args.out} not written: the specification is not met')
    except (ConfigurationError, BackendError) as err:
        print(f'{PROGRAM}: error: {err}', file=sys.stderr)
        sys.exit(EXIT_CONFIGURATION_ERROR)
    sys.stdout.flush()
    if not result.met:
        sys.exit(EXIT_NOT_MET)


if __name__ == '__main__':
    main()
