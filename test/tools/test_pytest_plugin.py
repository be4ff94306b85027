"""The pytest plugin as users get it: an installed entry point, xdist domains, failed-run bags.

The runs of pytest here are child processes started in a temporary folder
with test files of their own, so only the installed plugin (not this suite's
conftest) is at work in them.
"""

from __future__ import annotations

import importlib.metadata

import pytest
from pytest_runs import run_pytest, spare_domain_base, write_tests

from pan_tilt_sim.tools import pytest_plugin
from pan_tilt_sim.tools.pytest_plugin import bag_folder_of, worker_domain


def test_the_plugin_is_installed_as_a_pytest11_entry_point():
    entry_points = importlib.metadata.entry_points(group='pytest11')
    ours = [entry for entry in entry_points if entry.value == pytest_plugin.__name__]
    assert [entry.name for entry in ours] == ['pan_tilt_sim']


def test_each_xdist_worker_has_its_own_domain():
    assert worker_domain(40, 'gw0') == 40
    assert worker_domain(40, 'gw3') == 43


def test_a_domain_past_the_dds_range_is_refused():
    with pytest.raises(pytest.UsageError, match='ROS_DOMAIN_ID 233'):
        worker_domain(230, 'gw3')


def test_a_tests_bags_go_under_its_id_made_a_file_name(tmp_path):
    assert bag_folder_of(tmp_path, 'test/x.py::test_y[a b]') == tmp_path / 'test_x.py_test_y_a_b'


def test_under_n_2_the_workers_use_the_base_plus_their_number(tmp_path):
    write_tests(tmp_path, 'test_domains.py', '''
        import os

        import pytest

        @pytest.mark.parametrize('n', range(4))
        def test_note_domain(n, sim, worker_id):
            sim().step(0.01)  # a simulation really runs in this domain
            with open(f'domain_{worker_id}_{n}', 'w') as out:
                out.write(os.environ['ROS_DOMAIN_ID'])
        ''')
    base = spare_domain_base()
    result = run_pytest(tmp_path, '-n', '2', '--dist', 'load', '--ros-domain-base', str(base))
    assert result.returncode == 0, result.stdout + result.stderr
    seen = {path.name.split('_')[1]: path.read_text() for path in tmp_path.glob('domain_*')}
    assert seen == {'gw0': str(base), 'gw1': str(base + 1)}


def test_a_session_without_the_fixtures_keeps_its_domain_and_discovery_range(tmp_path):
    write_tests(tmp_path, 'test_plain.py', '''
        import os

        import pytest

        @pytest.mark.parametrize('n', range(4))
        def test_note_domain(n, worker_id):
            with open(f'domain_{worker_id}_{n}', 'w') as out:
                out.write(os.environ['ROS_DOMAIN_ID'] + ' '
                          + os.environ.get('ROS_AUTOMATIC_DISCOVERY_RANGE', 'unset'))
        ''')
    domain = str(spare_domain_base())
    environment = {'ROS_DOMAIN_ID': domain}
    result = run_pytest(tmp_path, '-n', '2', '--dist', 'load', env=environment,
                        unset=('ROS_AUTOMATIC_DISCOVERY_RANGE',))
    assert result.returncode == 0, result.stdout + result.stderr
    seen = {path.name.split('_')[1]: path.read_text() for path in tmp_path.glob('domain_*')}
    assert seen == {'gw0': f'{domain} unset', 'gw1': f'{domain} unset'}


def test_a_failed_tests_run_is_kept_as_a_bag_and_named_in_its_report(tmp_path):
    write_tests(tmp_path, 'test_bags.py', '''
        def test_fails(sim):
            sim().step(0.2)
            assert False, 'on purpose'

        def test_passes(sim):
            sim().step(0.2)
        ''')
    bags = tmp_path / 'bags'
    result = run_pytest(tmp_path, f'--sim-record-failed={bags}')
    assert result.returncode == 1, result.stdout + result.stderr
    kept = bag_folder_of(bags, 'test_bags.py::test_fails') / 'sim_0'
    assert f'kept the run of this test as a bag: {kept}' in result.stdout
    assert (kept / 'metadata.yaml').is_file()
    assert sorted(path.name for path in bags.iterdir()) == [kept.parent.name]


def test_the_environment_variable_asks_for_the_bags_too(tmp_path):
    write_tests(tmp_path, 'test_env_bags.py', '''
        def test_fails(sim):
            sim().step(0.1)
            assert False
        ''')
    bags = tmp_path / 'bags'
    result = run_pytest(tmp_path, env={pytest_plugin.RECORD_FAILED: str(bags)})
    kept = bag_folder_of(bags, 'test_env_bags.py::test_fails') / 'sim_0'
    assert f'kept the run of this test as a bag: {kept}' in result.stdout
    assert (kept / 'metadata.yaml').is_file()


def test_without_the_option_nothing_is_recorded(tmp_path):
    write_tests(tmp_path, 'test_no_bags.py', '''
        def test_fails(sim):
            s = sim()
            assert s.node.recorder is None
            assert False
        ''')
    result = run_pytest(tmp_path)
    assert 'E       assert False' in result.stdout, result.stdout
    assert 'kept the run' not in result.stdout
