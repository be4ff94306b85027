"""The same closed-loop test gives bit-identical joint trajectories: twice, in any order, -n 2.

The loop (determinism_scenario.py) runs a user's node that answers each
odometry message with a command: the physics, the message order and the
moment each command lands must all repeat for the trajectories to match.
"""

from __future__ import annotations

import determinism_scenario as scenario
from pytest_runs import run_pytest, spare_domain_base, write_tests

TWO_RUNS = '''
    import pathlib

    import determinism_scenario as scenario

    def _note(sim, name):
        pathlib.Path(name).write_text(scenario.digest(scenario.trajectory(sim)))

    def test_a(sim):
        _note(sim, 'a.txt')

    def test_b(sim):
        _note(sim, 'b.txt')
    '''


def test_twice_in_one_process_the_trajectories_are_bit_identical(sim):
    first = scenario.trajectory(sim)
    second = scenario.trajectory(sim)
    assert len(first) > 100
    assert first[-1][-4:] != first[0][-4:]  # the rover went somewhere
    assert first == second


def test_in_either_order_and_under_n_2_the_trajectories_are_bit_identical(sim, tmp_path):
    expected = scenario.digest(scenario.trajectory(sim))
    runs = {
        'in order': ('test_twice.py::test_a', 'test_twice.py::test_b'),
        'reversed': ('test_twice.py::test_b', 'test_twice.py::test_a'),
        '-n 2': ('-n', '2', '--ros-domain-base', str(spare_domain_base()), 'test_twice.py'),
    }
    for label, args in runs.items():
        folder = tmp_path / label.replace(' ', '_')
        write_tests(folder, 'test_twice.py', TWO_RUNS)
        result = run_pytest(folder, *args)
        assert result.returncode == 0, f'{label}:\n{result.stdout}{result.stderr}'
        assert (folder / 'a.txt').read_text() == expected, label
        assert (folder / 'b.txt').read_text() == expected, label
