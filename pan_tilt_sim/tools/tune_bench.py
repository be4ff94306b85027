"""tune_bench: how many tuner evaluations per second each back end gives, measured side by side.

``ros2 run pan_tilt_sim bench --tune`` (or ``python -m pan_tilt_sim.tools.tune_bench``)
times the unit of work of ``tune`` and ``sweep`` -- one evaluation: the
pan/tilt example's pan stepped 0 -> 1 rad with its own gains, 15 s of sim time at
1 ms, in a fresh simulation (:func:`pan_tilt_sim.tools.evaluation.evaluate`)
-- and prints one JSON object (see the design notes).

Design notes: docs/design/tools.md#tune_benchpy.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from typing import Any

from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.tools.backends import Backend, InProcess, LocalProcesses, RayCluster
from pan_tilt_sim.tools.evaluation import Case, Scenario, evaluate, load_scenario

PROGRAM = 'tune_bench'
JOINT = 'pan_joint'
TARGET = 1.0  # rad: 10 s of ramp at the pan/tilt example's 0.1 rad/s, plus 5 s to settle
TIME_STEP = 0.001
FULL_EVALUATIONS = 24  # per back end and round
QUICK_EVALUATIONS = 4
QUICK_DURATION_S = 1.0
ECHO_TASKS = 200
QUICK_ECHO_TASKS = 20
CLUSTER_START_TIMEOUT_S = 120.0
CLUSTER_STOP_TIMEOUT_S = 30.0
NODE_OBJECT_STORE_BYTES = 100 * 1024 * 1024
LOOPBACK = '127.0.0.1'
# Keeps every Ray address on 127.0.0.1 (see the module's design notes).
RAY_LOOPBACK_ENV = {'RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER': '0', 'RAY_USAGE_STATS_ENABLED': '0'}
MILLISECONDS = 1e3
# Optuna's cost per trial is measured with this many trials already told.
FULL_TPE_HISTORY = (64, 512)
QUICK_TPE_HISTORY = (16,)

# Run by the child process that holds the two Ray nodes: print the address, wait for SIGTERM.
_CLUSTER_SCRIPT = f'''
import signal, sys, threading
from ray.cluster_utils import Cluster
cluster = Cluster(initialize_head=True, head_node_args={{
    'num_cpus': 1, 'node_ip_address': {LOOPBACK!r}, 'include_dashboard': False,
    'object_store_memory': {NODE_OBJECT_STORE_BYTES}}})
cluster.add_node(num_cpus=1, node_ip_address={LOOPBACK!r},
                 object_store_memory={NODE_OBJECT_STORE_BYTES})
cluster.wait_for_nodes()
stop = threading.Event()
signal.signal(signal.SIGTERM, lambda *_: stop.set())
print('ADDRESS ' + cluster.address, flush=True)
stop.wait()
cluster.shutdown()
'''


def echo(shared: Any, item: Any) -> Any:
    """Receive the payload and return: a task that costs only the back end's own overhead."""
    return item


class RayNodes:
    """Two Ray nodes (head + one more, 1 CPU each) on loopback, in a child process."""

    def __init__(self, folder: str) -> None:
        env = dict(os.environ, **RAY_LOOPBACK_ENV)
        self._log = open(os.path.join(folder, 'ray_nodes.log'), 'w+b')  # noqa: SIM115
        started = time.monotonic()
        self.process = subprocess.Popen(
            [sys.executable, '-c', _CLUSTER_SCRIPT], stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE, stderr=self._log, env=env, text=True)
        self.address = ''
        deadline = started + CLUSTER_START_TIMEOUT_S
        while time.monotonic() < deadline:
            line = self.process.stdout.readline()
            if line.startswith('ADDRESS '):
                self.address = line.split()[1]
                break
            if not line and self.process.poll() is not None:
                break
        if not self.address:
            self.stop()
            self._log.seek(0)
            tail = self._log.read().decode(errors='replace')[-2000:]
            raise RuntimeError(f'the Ray nodes did not start:\n{tail}')
        self.start_s = time.monotonic() - started

    def stop(self) -> None:
        """Shut both nodes down (SIGTERM to our child; kill it if it hangs)."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(CLUSTER_STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self._log.close()


def pan_scenario() -> Scenario:
    """Return the pan/tilt example with its own controllers YAML."""
    share = package_share()
    return load_scenario(share / DEFAULT_DESCRIPTION, share / DEFAULT_CONTROLLERS, TIME_STEP)


def timed_map(backend: Backend, function: Callable[[Any, Any], Any], shared: Any,
              items: Sequence[Any]) -> tuple[float, list[Any]]:
    """Return the wall seconds of one ``backend.map``, and its results."""
    started = time.perf_counter()
    results = backend.map(function, shared, items)
    return time.perf_counter() - started, results


def measure_backend(backend: Backend, scenario: Scenario, cases: Sequence[Case],
                    echoes: int) -> dict[str, float]:
    """Warm ``backend`` up, then time ``cases`` and ``echoes`` echo tasks on it."""
    backend.map(evaluate, scenario, cases[:2 * backend.parallelism])
    backend.map(echo, scenario, range(2 * backend.parallelism))
    wall, results = timed_map(backend, evaluate, scenario, cases)
    echo_wall, _ = timed_map(backend, echo, scenario, list(range(echoes)))
    return {'wall_s': wall, 'evaluations': len(cases), 'parallelism': backend.parallelism,
            'worker_cpu_s': statistics.median(result.cpu_s for result in results),
            'echo_ms': echo_wall / echoes * MILLISECONDS}


def ray_submit_ms(scenario: Scenario, tasks: int) -> float:
    """Return the driver's own cost of submitting one Ray task (no waiting), in ms.

    The rate at which one driver can hand out tasks bounds how many cores it
    can keep busy: about ``cpu_s_per_evaluation / submit`` of them.
    """
    import ray

    remote = ray.remote(num_cpus=1)(echo)
    shared = ray.put(scenario)
    started = time.perf_counter()
    refs = [remote.remote(shared, index) for index in range(tasks)]
    submitted = time.perf_counter() - started
    ray.get(refs)
    return submitted / tasks * MILLISECONDS


def tpe_ms_per_trial(history: int, batch: int = 8) -> float | None:
    """Return the driver's Optuna cost per trial (ask + tell) of the last batch of ``history``.

    The same sampler, search space and constraints as ``tune``, told cheap
    made-up costs: what ``tune``'s driver spends per candidate when ``history``
    candidates are known.  None without Optuna.
    """
    if importlib.util.find_spec('optuna') is None:
        return None
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.create_study(direction='minimize', sampler=optuna.samplers.TPESampler(
        seed=0, multivariate=True, constant_liar=True))
    space = {name: optuna.distributions.FloatDistribution(1e-3, 1e3, log=True)
             for name in ('p', 'i', 'd', 'i_clamp')}
    generator = random.Random(0)
    last = 0.0
    for _ in range(history // batch):
        started = time.perf_counter()
        for trial in [study.ask(space) for _ in range(batch)]:
            for name in ('overshoot', 'settling', 'error', 'effort'):
                trial.set_constraint(name, generator.uniform(-1.0, 1.0))
            study.tell(trial, sum(math.log(value) ** 2 for value in trial.params.values()))
        last = (time.perf_counter() - started) / batch
    return last * MILLISECONDS


def cpu_per_evaluation(scenario: Scenario, case: Case, count: int) -> tuple[float, float]:
    """Return the median CPU seconds of one evaluation here, and CPU/wall over all of them."""
    cpu, started, wall_started = [], time.process_time(), time.perf_counter()
    for _ in range(count):
        cpu.append(evaluate(scenario, case).cpu_s)
    share = (time.process_time() - started) / (time.perf_counter() - wall_started)
    return statistics.median(cpu), share


def run(*, quick: bool = False, runs: int = 1,
        log: Callable[[str], None] = lambda text: None) -> dict:
    """Measure every figure ``runs`` times; return the medians (see the module's design notes)."""
    scenario = pan_scenario()
    case = Case(JOINT, (TARGET,), duration=QUICK_DURATION_S if quick else None)
    evaluations = QUICK_EVALUATIONS if quick else FULL_EVALUATIONS
    echoes = QUICK_ECHO_TASKS if quick else ECHO_TASKS
    cases = [case] * evaluations
    load_before = os.getloadavg()[0]
    tpe = {str(history): tpe_ms_per_trial(history)
           for history in (QUICK_TPE_HISTORY if quick else FULL_TPE_HISTORY)}
    rounds: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory(prefix='pan_tilt_tune_bench_') as folder:
        nodes, ray_backend, connect_s = _start_ray(folder, log)
        try:
            backends: dict[str, Callable[[], Backend]] = {
                'local_1': lambda: LocalProcesses(1), 'local_2': lambda: LocalProcesses(2)}
            for number in range(runs):
                log(f'round {number + 1} of {runs}')
                figures: dict[str, Any] = {}
                cpu, share = cpu_per_evaluation(scenario, case, evaluations)
                figures['cpu_s_per_evaluation'] = cpu
                figures['in_process_cpu_share'] = share
                figures['in_process'] = measure_backend(InProcess(), scenario, cases, echoes)
                for name, make in backends.items():
                    log(f'  {name}')
                    with make() as backend:
                        figures[name] = measure_backend(backend, scenario, cases, echoes)
                if ray_backend is not None:
                    log('  ray_2_nodes')
                    figures['ray_2_nodes'] = measure_backend(ray_backend, scenario, cases,
                                                             echoes)
                    figures['ray_submit_ms'] = ray_submit_ms(scenario, echoes)
                rounds.append(figures)
        finally:
            if ray_backend is not None:
                ray_backend.close()
            if nodes is not None:
                nodes.stop()
    names = ['in_process', *backends, *(['ray_2_nodes'] if ray_backend is not None else [])]
    figures = summarise(rounds, names, nodes, connect_s, load_before, runs, case, scenario)
    figures['tpe_ms_per_trial'] = tpe
    return figures


def _start_ray(folder: str, log: Callable[[str], None]
               ) -> tuple[RayNodes | None, RayCluster | None, float | None]:
    if importlib.util.find_spec('ray') is None:
        log('Ray is not installed: no Ray figures')
        return None, None, None
    log('starting two Ray nodes on 127.0.0.1')
    nodes = RayNodes(folder)
    # Before Ray is first imported here: it reads the switch once, at import.
    saved = {name: os.environ.get(name) for name in RAY_LOOPBACK_ENV}
    os.environ.update(RAY_LOOPBACK_ENV)
    try:
        started = time.perf_counter()
        backend = RayCluster(nodes.address)
        connect_s = time.perf_counter() - started
    except BaseException:
        nodes.stop()
        raise
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
    return nodes, backend, connect_s


def summarise(rounds: Sequence[dict], names: Sequence[str], nodes: RayNodes | None,
              connect_s: float | None, load_before: float, runs: int, case: Case,
              scenario: Scenario) -> dict:
    """Return the medians over rounds, derived figures included."""
    def median(get: Callable[[dict], float]) -> float:
        return statistics.median(get(figures) for figures in rounds)

    cpu = median(lambda f: f['cpu_s_per_evaluation'])
    throughput = {name: median(lambda f, n=name: f[n]['evaluations'] / f[n]['wall_s'])
                  for name in names}
    overhead = {name: median(lambda f, n=name: (
        f[n]['wall_s'] / f[n]['evaluations'] * f[n]['parallelism']
        - f['cpu_s_per_evaluation']) * MILLISECONDS) for name in names}
    dispatch = {name: median(lambda f, n=name: f[n]['echo_ms']) for name in names}
    worker_cpu = {name: median(lambda f, n=name: f[n]['worker_cpu_s']) for name in names}
    busy = {name: median(lambda f, n=name: f[n]['worker_cpu_s'] * f[n]['evaluations']
                         / (f[n]['wall_s'] * f[n]['parallelism'])) for name in names}
    duration = case.duration or (TARGET / 0.1 + 5.0)
    return {
        'evaluation': {'joint': JOINT, 'target': TARGET, 'sim_s': duration,
                       'steps': round(duration / scenario.time_step)},
        'cpu_s_per_evaluation': cpu,
        'in_process_cpu_share': median(lambda f: f['in_process_cpu_share']),
        'worker_cpu_s_per_evaluation': worker_cpu,
        'evaluations_per_s': throughput,
        'worker_busy_share': busy,
        'overhead_ms_per_evaluation': overhead,
        'dispatch_ms_per_task': dispatch,
        'ray_submit_ms_per_task': None if nodes is None else median(
            lambda f: f['ray_submit_ms']),
        'ray_cluster_start_s': None if nodes is None else nodes.start_s,
        'ray_connect_s': connect_s,
        'load_average_1min': {'before': load_before, 'after': os.getloadavg()[0]},
        'cpu_count': os.cpu_count(),
        'runs': runs,
    }


def rounded(value: Any) -> Any:
    """Round every float in ``value`` to 4 significant digits."""
    if isinstance(value, dict):
        return {key: rounded(item) for key, item in value.items()}
    if isinstance(value, float):
        return float(f'{value:.4g}')
    return value


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    """Read the command line."""
    parser = argparse.ArgumentParser(
        prog=PROGRAM, description='Evaluations per second of tune/sweep on each back end.')
    parser.add_argument('--quick', action='store_true', help='a smoke run (timing meaningless)')
    parser.add_argument('--runs', type=int, default=1,
                        help='rounds; every figure is the median (default 1)')
    parser.add_argument('--verbose', action='store_true', help='progress on stderr')
    args = parser.parse_args(argv)
    if args.runs < 1:
        parser.error('--runs must be at least 1')
    return args


def main(argv: Sequence[str] | None = None) -> None:
    """Print the tune throughput figures as one JSON object."""
    args = parse_args(argv)

    def log(text: str) -> None:
        if args.verbose:
            print(f'{PROGRAM}: {text}', file=sys.stderr, flush=True)

    print(json.dumps(rounded(run(quick=args.quick, runs=args.runs, log=log))), flush=True)


if __name__ == '__main__':
    main()
