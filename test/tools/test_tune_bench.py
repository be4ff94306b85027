"""bench --tune: every back end's figures in one JSON object, and no Ray process left behind.

No timing is asserted: the figures come from running the command.
"""

import json
import subprocess
import sys
import time

import psutil
import pytest
import sim_process

from pan_tilt_sim.tools import tune_bench
from pan_tilt_sim.tools.evaluation import Case

QUICK_TIMEOUT_S = 300
RAY_PROCESS_NAMES = ('raylet', 'gcs_server')


def ray_processes_started_since(started: float) -> list[str]:
    """Return Ray node processes (raylet, gcs_server) started after ``started`` and alive."""
    return [f"{process.info['name']} {process.info['pid']}"
            for process in psutil.process_iter(['pid', 'name', 'create_time'])
            if process.info['name'] in RAY_PROCESS_NAMES
            and process.info['create_time'] >= started]


@pytest.fixture(scope='module')
def quick():
    started = time.time() - 1.0  # create_time has a coarser clock
    result = subprocess.run(
        [sys.executable, '-m', 'pan_tilt_sim.tools.bench', '--tune', '--quick'],
        capture_output=True, text=True, env=sim_process.environment(),
        timeout=QUICK_TIMEOUT_S, check=False)
    return result, ray_processes_started_since(started)


@pytest.mark.timeout(QUICK_TIMEOUT_S + 30)
def test_bench_tune_quick_prints_one_json_object_with_every_back_end(quick):
    result, _ = quick
    assert result.returncode == 0, result.stderr
    assert result.stdout.count('\n') == 1
    figures = json.loads(result.stdout)
    names = {'in_process', 'local_1', 'local_2', 'ray_2_nodes'}
    assert set(figures['evaluations_per_s']) == names
    assert all(rate > 0 for rate in figures['evaluations_per_s'].values())
    assert set(figures['overhead_ms_per_evaluation']) == names
    assert set(figures['dispatch_ms_per_task']) == names
    assert all(cpu > 0 for cpu in figures['worker_cpu_s_per_evaluation'].values())
    assert figures['cpu_s_per_evaluation'] > 0
    assert figures['ray_cluster_start_s'] > 0 and figures['ray_connect_s'] > 0
    assert figures['ray_submit_ms_per_task'] > 0
    assert figures['tpe_ms_per_trial']['16'] > 0
    assert figures['evaluation']['steps'] == 1000


@pytest.mark.timeout(QUICK_TIMEOUT_S + 30)
def test_bench_tune_stops_the_ray_nodes_it_started(quick):
    result, left = quick
    assert result.returncode == 0, result.stderr
    assert left == []


def test_overhead_is_wall_per_evaluation_times_parallelism_less_its_cpu():
    rounds = [{'cpu_s_per_evaluation': 0.2, 'in_process_cpu_share': 1.0,
               'local_2': {'wall_s': 1.2, 'evaluations': 10, 'parallelism': 2,
                           'worker_cpu_s': 0.21, 'echo_ms': 0.5}}]
    figures = tune_bench.summarise(rounds, ['local_2'], None, None, 0.5, 1,
                                   Case('pan_joint', (1.0,)), _Scenario())
    assert figures['evaluations_per_s'] == {'local_2': pytest.approx(10 / 1.2)}
    # 1.2 s for 10 on 2 workers: 0.24 core-s each, 0.04 more than the 0.2 s of simulation.
    assert figures['overhead_ms_per_evaluation'] == {'local_2': pytest.approx(40.0)}
    assert figures['worker_busy_share'] == {'local_2': pytest.approx(0.21 * 10 / 2.4)}
    assert figures['evaluation']['steps'] == 15000


class _Scenario:
    time_step = 0.001
