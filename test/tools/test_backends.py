"""Back ends: results in the order asked, the same numbers in any process, Ray only when asked."""

import sys

import pytest

from pan_tilt_sim.tools.backends import (
    BackendError,
    InProcess,
    LocalProcesses,
    RayCluster,
    make_backend,
)
from pan_tilt_sim.tools.evaluation import Case, evaluate, load_scenario


@pytest.fixture(scope='module')
def scenario(request):
    root = request.config.rootpath
    return load_scenario(root / 'urdf' / 'pan_tilt.xacro',
                         root / 'config' / 'pan_tilt_control.yaml', 0.001)


def test_local_processes_return_results_in_the_order_asked_not_finished(scenario):
    # The first case takes ~20 times longer than the others, so it finishes last.
    durations = [2.0, 0.1, 0.1, 0.1]
    cases = [Case('pan_joint', (0.3,), duration=duration) for duration in durations]
    with LocalProcesses(2) as backend:
        results = backend.map(evaluate, scenario, cases)
    assert [result.steps[0].duration_s for result in results] == pytest.approx(durations)


def test_worker_processes_compute_exactly_what_this_process_does(scenario):
    cases = [Case('pan_joint', (target,)) for target in (1.0, -0.4, 0.25)]
    here = InProcess().map(evaluate, scenario, cases)
    with LocalProcesses(2) as backend:
        there = backend.map(evaluate, scenario, cases)
    assert [result.steps for result in there] == [result.steps for result in here]


def test_make_backend_picks_in_process_local_or_ray(monkeypatch):
    assert isinstance(make_backend(0, None), InProcess)
    with make_backend(1, None) as backend:
        assert isinstance(backend, LocalProcesses) and backend.parallelism == 1
    monkeypatch.setitem(sys.modules, 'ray', None)  # as if Ray were not installed
    with pytest.raises(BackendError, match='pip install ray'):
        make_backend(None, 'auto')


def test_a_ray_back_end_without_an_address_needs_a_running_instance(monkeypatch):
    ray = pytest.importorskip('ray')
    if ray.is_initialized():
        pytest.skip('a Ray instance is running in this process')
    with pytest.raises(BackendError, match='no Ray address'):
        RayCluster(None)


def test_an_address_ray_cannot_use_is_a_backend_error():
    pytest.importorskip('ray')
    with pytest.raises(BackendError, match='--address no-port-here: cannot connect to Ray'):
        RayCluster('no-port-here')


def test_fewer_than_one_worker_is_refused():
    with pytest.raises(BackendError, match='--workers'):
        LocalProcesses(0)
