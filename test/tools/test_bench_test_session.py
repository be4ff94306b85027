"""bench --test-session: a pytest session of go-to-goal tests, measured (no timing asserted)."""

from __future__ import annotations

import ast

import pytest
from pytest_runs import spare_domain_base

from pan_tilt_sim.tools import bench_test_session

KEYS = {'tests', 'setup_teardown_s_p50', 'setup_teardown_s_max', 'call_s_p50', 'rss_growth_mb',
        'fd_growth', 'wall_s_n1', 'wall_s_n2', 'speedup_n2'}


def test_the_session_is_a_user_package_of_python_files(tmp_path):
    bench_test_session.write_session(tmp_path, 7)
    for name in ('go_to_goal.py', 'test_session.py', 'conftest.py'):
        ast.parse((tmp_path / name).read_text())
    assert 'range(7)' in (tmp_path / 'test_session.py').read_text()


@pytest.mark.slow
def test_a_quick_session_gives_every_figure():
    figures = bench_test_session.measure(quick=True, domain_base=spare_domain_base())
    assert set(figures) == KEYS
    assert figures['tests'] == bench_test_session.QUICK_TESTS
    assert 0.0 < figures['setup_teardown_s_p50'] <= figures['setup_teardown_s_max']
    assert figures['wall_s_n1'] > 0.0 and figures['wall_s_n2'] > 0.0
