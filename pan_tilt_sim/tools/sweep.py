r"""sweep: how much margin do the gains have?  Step the joints over many physical variations.

::

    ros2 run pan_tilt_sim sweep --joint pan_joint --target 1.0 --max-error 0.002 \\
        --vary mass=-50:50:5 --vary friction=-100,0,100,400 \\
        --report sweep.csv --heatmap sweep.png
    ros2 run pan_tilt_sim sweep ... --address auto        # the same on a Ray cluster

Each ``--vary NAME=VALUES`` is an axis; the sweep runs every combination
(a grid) or, with ``--samples N``, N random combinations (seeded by
``--seed``).  VALUES is a list (``-20,0,20``) or ``LOW:HIGH:COUNT`` (COUNT
evenly spaced values; with ``--samples``, ``LOW:HIGH`` is a uniform range).
The axes (see the design notes).

Design notes: docs/design/tools.md#sweeppy.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import itertools
import json
import math
import pathlib
import random
import sys
from collections.abc import Callable, Mapping, Sequence

from pan_tilt_sim.controllers.toolbox.pid import PidGains
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.model.variation import Payload, PhysicalVariation
from pan_tilt_sim.tools import tune
from pan_tilt_sim.tools.backends import Backend, BackendError, InProcess, make_backend
from pan_tilt_sim.tools.evaluation import (
    Case,
    Evaluation,
    Scenario,
    Spec,
    evaluate,
    load_scenario,
    step_violations,
)

PROGRAM = 'sweep'
EXIT_CONFIGURATION_ERROR = 2
PERCENT_AXES = ('mass', 'inertia', 'friction', 'damping')
GAIN_AXES = ('p', 'i', 'd')
AXES = (*PERCENT_AXES, 'payload', 'time_step', *GAIN_AXES)
AXIS_UNITS = {'payload': 'kg', 'time_step': 's', **{name: '%' for name in PERCENT_AXES},
              **{name: '%' for name in GAIN_AXES}}
HEATMAP_BINS = 8  # per axis, for random samples
CHUNK_PER_WORKER = 8  # evaluations per worker between progress lines
MIN_CHUNK = 64
METRICS = ('overshoot_percent', 'settling_time_s', 'final_error', 'peak_effort', 'itae',
           'saturated_s')


@dataclasses.dataclass(frozen=True)
class Axis:
    """One varied quantity: its name and its values (grid) or range (random)."""

    name: str
    values: tuple[float, ...]
    low: float
    high: float
    is_list: bool  # given as a list: random samples pick from it


def parse_axis(text: str) -> Axis:
    """Read ``NAME=V1,V2,...`` or ``NAME=LOW:HIGH[:COUNT]``."""
    name, separator, spec = text.partition('=')
    if not separator or name not in AXES:
        raise ConfigurationError(f'--vary: {text!r} must be NAME=VALUES with NAME one of '
                                 f"{', '.join(AXES)}")
    try:
        if ':' in spec:
            parts = spec.split(':')
            if len(parts) not in (2, 3):
                raise ValueError
            low, high = float(parts[0]), float(parts[1])
            count = int(parts[2]) if len(parts) == 3 else 2
            if count < 1 or not low <= high:
                raise ValueError
            values = tuple(low + (high - low) * k / (count - 1) for k in range(count)) \
                if count > 1 else (low,)
            axis = Axis(name, values, low, high, is_list=False)
        else:
            values = tuple(float(value) for value in spec.split(','))
            axis = Axis(name, values, min(values), max(values), is_list=True)
    except ValueError:
        raise ConfigurationError(
            f'--vary: {text!r}: VALUES must be numbers V1,V2,... or LOW:HIGH[:COUNT] with '
            'LOW <= HIGH and COUNT >= 1') from None
    check_axis_values(axis)
    return axis


def check_axis_values(axis: Axis) -> None:
    """Refuse values that make no physical sense on this axis."""
    for value in (*axis.values, axis.low, axis.high):
        if not math.isfinite(value):
            raise ConfigurationError(f'--vary {axis.name}: {value} is not finite')
        if axis.name in ('mass', 'inertia') and value <= -100.0:
            raise ConfigurationError(f'--vary {axis.name}: {value:g} % would leave no mass')
        if axis.name in (*PERCENT_AXES, *GAIN_AXES) and value < -100.0:
            raise ConfigurationError(f'--vary {axis.name}: {value:g} % is below -100 %')
        if axis.name == 'payload' and value < 0.0:
            raise ConfigurationError(f'--vary payload: {value:g} kg is negative')
        if axis.name == 'time_step' and not 0.0 < value <= 0.1:
            raise ConfigurationError(f'--vary time_step: {value:g} s must be > 0 and <= 0.1')


def combinations(axes: Sequence[Axis], samples: int | None, seed: int) -> list[dict[str, float]]:
    """Return the grid of ``axes``, or ``samples`` random points of it (seeded)."""
    if samples is None:
        return [dict(zip([axis.name for axis in axes], point, strict=True))
                for point in itertools.product(*(axis.values for axis in axes))]
    generator = random.Random(seed)
    points = []
    for _ in range(samples):
        points.append({axis.name: generator.choice(axis.values) if axis.is_list
                       else generator.uniform(axis.low, axis.high) for axis in axes})
    return points


def variation_of(point: Mapping[str, float], payload_link: str | None,
                 payload_offset: tuple[float, float, float]) -> PhysicalVariation:
    """Return the physical variation a combination describes."""
    def scale(name: str) -> float:
        return 1.0 + point.get(name, 0.0) / 100.0

    payload = None
    if point.get('payload', 0.0) > 0.0:
        payload = Payload(payload_link or '', point['payload'], payload_offset)
    return PhysicalVariation(mass_scale=scale('mass'), inertia_scale=scale('inertia'),
                             friction_scale=max(0.0, scale('friction')),
                             damping_scale=max(0.0, scale('damping')), payload=payload)


def gains_of(base: PidGains, point: Mapping[str, float]) -> PidGains:
    """Return ``base`` with p, i, d changed by the combination's percentages."""
    return dataclasses.replace(base, **{
        name: max(0.0, getattr(base, name) * (1.0 + point[name] / 100.0))
        for name in GAIN_AXES if name in point})


@dataclasses.dataclass(frozen=True)
class Job:
    """One combination for one joint."""

    point: Mapping[str, float]
    joint: str
    case: Case


def jobs(points: Sequence[Mapping[str, float]], plans: Sequence[tune.JointPlan],
         payload_link: str | None, payload_offset: tuple[float, float, float],
         duration: float | None) -> list[Job]:
    """Return every (combination, joint) evaluation to run."""
    found = []
    for point in points:
        variation = variation_of(point, payload_link, payload_offset)
        for plan in plans:
            case = Case(plan.joint.name, plan.targets,
                        gains=((plan.joint.name, gains_of(plan.gains, point)),),
                        variation=variation, time_step=point.get('time_step'),
                        duration=duration)
            found.append(Job(point, plan.joint.name, case))
    return found


def rows(job: Job, evaluation: Evaluation, spec: Spec) -> list[dict]:
    """Return the report rows of one evaluation: one per target."""
    found = []
    for step in evaluation.steps:
        missed = [name for name, value in step_violations(step, spec).items() if value > 0.0]
        metrics = {
            'overshoot_percent': step.metrics.overshoot_percent,
            'settling_time_s': step.metrics.settling_time_s,
            'final_error': step.final_error,
            'peak_effort': step.metrics.peak_effort,
            'itae': step.itae,
            'saturated_s': step.saturated_s,
        }
        found.append({**job.point, 'joint': job.joint, 'target': step.target,
                      'passed': not missed, 'failed': ' '.join(missed),
                      **{name: _number(value) for name, value in metrics.items()}})
    return found


def _number(value: float | None) -> float | None:
    if value is None or not math.isfinite(value):
        return None
    return float(f'{value:.6g}')


def run_sweep(scenario: Scenario, plans: Sequence[tune.JointPlan], axes: Sequence[Axis],
              spec: Spec, backend: Backend, *, samples: int | None = None, seed: int = 0,
              payload_link: str | None = None,
              payload_offset: tuple[float, float, float] = (0.0, 0.0, 0.0),
              duration: float | None = None,
              progress: Callable[[str], None] = lambda text: None) -> list[dict]:
    """Run every combination for every joint; return the report rows in a fixed order."""
    points = combinations(axes, samples, seed)
    todo = jobs(points, plans, payload_link, payload_offset, duration)
    # The first combination once in this process: arguments that cannot work fail here.
    InProcess().map(evaluate, scenario, [job.case for job in todo[:len(plans)]])
    chunk = max(MIN_CHUNK, CHUNK_PER_WORKER * backend.parallelism)
    found: list[dict] = []
    failures = 0
    for start in range(0, len(todo), chunk):
        part = todo[start:start + chunk]
        for job, evaluation in zip(part, backend.map(evaluate, scenario,
                                                     [job.case for job in part]), strict=True):
            new = rows(job, evaluation, spec)
            failures += sum(1 for row in new if not row['passed'])
            found.extend(new)
        progress(f'{min(start + chunk, len(todo))}/{len(todo)} evaluations, '
                 f'{failures} failing steps so far')
    return found


def summary(found: Sequence[dict], axes: Sequence[Axis], limit: int = 20) -> list[str]:
    """Return what to print: counts, and the failing combinations."""
    failing = [row for row in found if not row['passed']]
    lines = [f'{len(found)} steps ({len({_key(row, axes) for row in found})} combinations): '
             f'{len(failing)} fail the specification']
    for row in failing[:limit]:
        point = ', '.join(f'{axis.name} {row[axis.name]:.4g} {AXIS_UNITS[axis.name]}'
                          for axis in axes)
        lines.append(f"  FAIL {row['joint']} -> {row['target']:g}: {point or 'nominal'}: "
                     f"misses {row['failed']}")
    if len(failing) > limit:
        lines.append(f'  ... and {len(failing) - limit} more (see --report)')
    return lines


def _key(row: Mapping, axes: Sequence[Axis]) -> tuple:
    return tuple(row[axis.name] for axis in axes)


def write_report(found: Sequence[dict], axes: Sequence[Axis], spec: Spec,
                 path: pathlib.Path) -> None:
    """Write the rows as CSV, or as JSON (with the axes and the spec) for a .json name."""
    columns = [axis.name for axis in axes] + ['joint', 'target', 'passed', 'failed', *METRICS]
    try:
        if path.suffix.lower() == '.json':
            path.write_text(json.dumps({
                'spec': dataclasses.asdict(spec),
                'axes': {axis.name: AXIS_UNITS[axis.name] for axis in axes},
                'failing': sum(1 for row in found if not row['passed']),
                'rows': [{column: row[column] for column in columns} for row in found],
            }, indent=1) + '\n', encoding='utf-8')
            return
        with open(path, 'w', newline='', encoding='utf-8') as stream:
            writer = csv.DictWriter(stream, fieldnames=columns, extrasaction='ignore')
            writer.writeheader()
            writer.writerows(found)
    except OSError as err:
        raise ConfigurationError(f'--report: cannot write {path}: {err}') from None


def heatmap_cells(found: Sequence[dict], x: Axis, y: Axis | None,
                  binned: bool) -> tuple[list[float], list[float], list[list[tuple[int, int]]]]:
    """Return the x and y cell centres and, per cell, (failing, total) steps."""
    def centres(axis: Axis) -> list[float]:
        if not binned:
            return sorted({float(value) for value in axis.values})
        width = (axis.high - axis.low) / HEATMAP_BINS
        return [axis.low + width * (k + 0.5) for k in range(HEATMAP_BINS)] if width > 0 \
            else [axis.low]

    def index(axis: Axis, cells: list[float], value: float) -> int:
        if not binned:
            return cells.index(float(value))
        if len(cells) == 1:
            return 0
        width = (axis.high - axis.low) / HEATMAP_BINS
        return min(HEATMAP_BINS - 1, int((value - axis.low) / width))

    xs = centres(x)
    ys = centres(y) if y is not None else [0.0]
    counts = [[(0, 0) for _ in xs] for _ in ys]
    for row in found:
        column = index(x, xs, row[x.name])
        line = index(y, ys, row[y.name]) if y is not None else 0
        failing, total = counts[line][column]
        counts[line][column] = (failing + (not row['passed']), total + 1)
    return xs, ys, counts


def write_heatmap(found: Sequence[dict], axes: Sequence[Axis], names: Sequence[str] | None,
                  binned: bool, path: pathlib.Path) -> None:
    """Write a PNG: share of failing steps per cell of two axes (the others folded in)."""
    import matplotlib

    matplotlib.use('Agg')
    from matplotlib import pyplot

    by_name = {axis.name: axis for axis in axes}
    chosen = [by_name[name] for name in names] if names else list(axes[:2])
    x = chosen[0]
    y = chosen[1] if len(chosen) > 1 else None
    xs, ys, counts = heatmap_cells(found, x, y, binned)
    shares = [[failing / total if total else math.nan for failing, total in line]
              for line in counts]
    figure, axis = pyplot.subplots(figsize=(max(5.0, 0.9 * len(xs) + 2.5),
                                            max(3.0, 0.6 * len(ys) + 2.0)), dpi=80)
    image = axis.imshow(shares, origin='lower', aspect='auto', cmap='RdYlGn_r', vmin=0.0,
                        vmax=1.0)
    for line, cells in enumerate(counts):
        for column, (failing, total) in enumerate(cells):
            if total:
                axis.text(column, line, f'{failing}/{total}', ha='center', va='center',
                          fontsize='small')
    axis.set_xticks(range(len(xs)), [f'{value:.3g}' for value in xs])
    axis.set_xlabel(f'{x.name} [{AXIS_UNITS[x.name]}]')
    if y is not None:
        axis.set_yticks(range(len(ys)), [f'{value:.3g}' for value in ys])
        axis.set_ylabel(f'{y.name} [{AXIS_UNITS[y.name]}]')
    else:
        axis.set_yticks([])
    figure.colorbar(image, ax=axis, label='share of steps failing the spec')
    axis.set_title('failing / total steps' + (' (binned)' if binned else ''))
    figure.tight_layout()
    try:
        figure.savefig(path)
    except OSError as err:
        raise ConfigurationError(f'--heatmap: cannot write {path}: {err}') from None
    finally:
        pyplot.close(figure)


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    """Read the command line."""
    parser = argparse.ArgumentParser(
        prog=PROGRAM, description='Step the joints over variations of mass, inertia, '
        'friction, damping, payload, time step and gains; report which fail the spec.')
    tune.add_robot_arguments(parser)
    parser.add_argument('--vary', action='append', default=[], metavar='NAME=VALUES',
                        help=f"an axis: NAME one of {', '.join(AXES)}; VALUES V1,V2,... or "
                        'LOW:HIGH[:COUNT] (repeatable)')
    parser.add_argument('--samples', type=int, default=None, metavar='N',
                        help='N random combinations instead of the full grid')
    parser.add_argument('--payload-link', default=None, metavar='LINK',
                        help='where the payload goes (default: the child link of the last '
                        '--joint)')
    parser.add_argument('--payload-offset', type=float, nargs=3, default=(0.0, 0.0, 0.0),
                        metavar=('X', 'Y', 'Z'), help="payload position in the link's frame, m")
    parser.add_argument('--report', type=pathlib.Path, default=None,
                        metavar='FILE.csv|FILE.json', help='write every step here')
    parser.add_argument('--heatmap', type=pathlib.Path, default=None, metavar='FILE.png',
                        help='write the share of failing steps over two axes to this PNG')
    parser.add_argument('--heatmap-axes', nargs='+', default=None, metavar='NAME',
                        help='the one or two axes of the heatmap (default: the first two)')
    return parser.parse_args(argv)


def run(args: argparse.Namespace, log: Callable[[str], None]) -> tuple[list[dict], list[Axis]]:
    """Sweep as ``args`` ask; return the rows and the axes."""
    if args.samples is not None and args.samples < 1:
        raise ConfigurationError(f'--samples: {args.samples} must be at least 1')
    if args.workers is not None and args.workers < 0:
        raise ConfigurationError(f'--workers: {args.workers} must be 0 or more')
    axes = [parse_axis(text) for text in args.vary]
    names = [axis.name for axis in axes]
    if len(set(names)) != len(names):
        raise ConfigurationError('--vary: an axis is given twice')
    if args.heatmap_axes is not None and (
            len(args.heatmap_axes) > 2 or not set(args.heatmap_axes) <= set(names)):
        raise ConfigurationError(f'--heatmap-axes: {" ".join(args.heatmap_axes)}: one or two '
                                 f"of the --vary axes ({', '.join(names) or 'none'})")
    spec = tune.spec_from(args)
    targets = tune.parse_targets(args.joint, args.target)
    scenario = load_scenario(args.model, args.controllers, args.time_step, args.xacro_args,
                             controllers_args=args.controllers_args,
                             active_controllers=args.active_controllers)
    plans = tune.plan_joints(scenario, args.joint, targets)
    payload_link = args.payload_link
    if 'payload' in names:
        payload_link = payload_link or plans[-1].joint.child
        if payload_link not in scenario.description.model.link_names:
            raise ConfigurationError(f"--payload-link: '{payload_link}' is not a link of the "
                                     'robot')
    for name, field in (('friction', 'friction'), ('damping', 'damping')):
        if name in names and all(getattr(p.joint, field) == 0.0 for p in plans):
            log(f'warning: --vary {name} changes nothing: the URDF gives the joints no {field}')
    with make_backend(args.workers, args.address) as backend:
        log(f'evaluating on {backend.name} ({backend.parallelism} at a time)')
        found = run_sweep(scenario, plans, axes, spec, backend, samples=args.samples,
                          seed=args.seed, payload_link=payload_link,
                          payload_offset=tuple(args.payload_offset), duration=args.duration,
                          progress=log)
    if args.report is not None:
        write_report(found, axes, spec, args.report)
    if args.heatmap is not None:
        if axes:
            write_heatmap(found, axes, args.heatmap_axes, args.samples is not None,
                          args.heatmap)
        else:
            log('no heatmap: no --vary axis')
    return found, axes


def main(argv: Sequence[str] | None = None) -> None:
    """Run the sweep command line."""
    args = parse_args(argv)

    def log(text: str) -> None:
        print(f'{PROGRAM}: {text}', file=sys.stderr, flush=True)

    try:
        found, axes = run(args, log)
    except (ConfigurationError, BackendError) as err:
        print(f'{PROGRAM}: error: {err}', file=sys.stderr)
        sys.exit(EXIT_CONFIGURATION_ERROR)
    for line in summary(found, axes):
        print(line)
    for option in ('report', 'heatmap'):
        if getattr(args, option) is not None:
            print(f'{option}: {getattr(args, option)}')


if __name__ == '__main__':
    main()
