"""sweep: the combinations that fail are the ones built to fail; reports and heatmap follow."""

import csv
import json
import subprocess
import sys

import pytest

from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.tools import sweep

TIMEOUT_S = 300


def run_sweep(args, blocked=()):
    code = (f'import sys\nfor name in {list(blocked)!r}:\n    sys.modules[name] = None\n'
            'from pan_tilt_sim.tools import sweep\nsweep.main(sys.argv[1:])\n')
    return subprocess.run([sys.executable, '-c', code, *args], capture_output=True, text=True,
                          timeout=TIMEOUT_S, check=False)


@pytest.fixture(scope='module')
def friction_grid(tmp_path_factory):
    """Sweep the pan/tilt example's pan over friction x p, with a final-error bound of 0.03 rad."""
    folder = tmp_path_factory.mktemp('sweep')
    report, heatmap = folder / 'sweep.csv', folder / 'sweep.png'
    result = run_sweep(['--joint', 'pan_joint', '--target', '1.0', '--max-error', '0.03',
                        '--vary', 'friction=-100,0,400', '--vary', 'p=0,100', '--workers', '2',
                        '--report', str(report), '--heatmap', str(heatmap)])
    return result, report, heatmap


def test_the_failing_combinations_are_the_ones_friction_over_p_puts_past_the_bound(
        friction_grid):
    # Coulomb friction f holds an error of up to f / p: friction 0, 1 and 5 N m against
    # p 100 and 200 leave 0, 0.01, 0.05 and 0, 0.005, 0.025 rad; only 5 / 100 > 0.03.
    result, report, _ = friction_grid
    assert result.returncode == 0, result.stderr
    with open(report, newline='') as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) == 6
    failing = {(float(row['friction']), float(row['p'])) for row in rows
               if row['passed'] == 'False'}
    assert failing == {(400.0, 0.0)}
    assert [row['failed'] for row in rows if row['passed'] == 'False'] == ['error']
    assert '6 steps (6 combinations): 1 fail the specification' in result.stdout
    assert 'FAIL pan_joint -> 1: friction 400 %, p 0 %: misses error' in result.stdout


def test_the_heatmap_is_a_png(friction_grid):
    _, _, heatmap = friction_grid
    assert heatmap.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'


def test_a_payload_far_from_the_tilt_axis_makes_gravity_pull_it_off_target(tmp_path):
    # 4 kg, 0.25 m out along the tilt link, whose x axis is tilted -2 rad about y: a lever
    # of 0.25 |cos 2| = 0.104 m, 4.1 N m of gravity against p = 100 and 1 N m of friction,
    # so 0.031 to 0.051 rad off; without it the tilt ends within friction / p = 0.01 rad.
    report = tmp_path / 'payload.json'
    result = run_sweep(['--joint', 'tilt_joint', '--target', '-2.0', '--max-error', '0.02',
                        '--vary', 'payload=0,4', '--payload-offset', '0.25', '0', '0',
                        '--workers', '0', '--report', str(report)])
    assert result.returncode == 0, result.stderr
    rows = json.loads(report.read_text())['rows']
    assert [(row['payload'], row['passed']) for row in rows] == [(0.0, True), (4.0, False)]
    assert 0.031 <= rows[1]['final_error'] <= 0.051


def test_random_samples_follow_the_seed(tmp_path):
    axes = [sweep.parse_axis('mass=-20:20'), sweep.parse_axis('time_step=0.001,0.002')]
    first = sweep.combinations(axes, 5, seed=7)
    assert first == sweep.combinations(axes, 5, seed=7)
    assert first != sweep.combinations(axes, 5, seed=8)
    assert all(-20.0 <= point['mass'] <= 20.0 for point in first)
    assert {point['time_step'] for point in first} <= {0.001, 0.002}


def test_a_grid_is_every_combination():
    axes = [sweep.parse_axis('mass=-50:50:3'), sweep.parse_axis('d=0,10')]
    assert sweep.combinations(axes, None, seed=0) == [
        {'mass': -50.0, 'd': 0.0}, {'mass': -50.0, 'd': 10.0}, {'mass': 0.0, 'd': 0.0},
        {'mass': 0.0, 'd': 10.0}, {'mass': 50.0, 'd': 0.0}, {'mass': 50.0, 'd': 10.0}]


def test_percentages_become_factors_and_gains():
    from pan_tilt_sim.controllers.toolbox.pid import PidGains

    variation = sweep.variation_of({'mass': -20.0, 'friction': -100.0, 'payload': 1.5},
                                   'tilt_link', (0.0, 0.0, 0.1))
    assert variation.mass_scale == pytest.approx(0.8) and variation.friction_scale == 0.0
    assert variation.payload.mass == 1.5 and variation.payload.link == 'tilt_link'
    gains = sweep.gains_of(PidGains(p=100.0, i=1.0, d=10.0), {'p': 50.0, 'd': -100.0})
    assert (gains.p, gains.i, gains.d) == (150.0, 1.0, 0.0)


@pytest.mark.parametrize(('text', 'message'), [
    ('mass=-100,0', 'would leave no mass'), ('weight=1,2', 'NAME one of'),
    ('time_step=0.5', 'must be > 0 and <= 0.1'), ('payload=-1', 'negative'),
    ('friction=3:1', 'LOW <= HIGH'), ('p=a,b', 'VALUES must be numbers'),
])
def test_axes_that_make_no_sense_are_refused(text, message):
    with pytest.raises(ConfigurationError, match=message):
        sweep.parse_axis(text)


def test_a_time_step_axis_changes_the_physics_step(tmp_path):
    report = tmp_path / 'steps.json'
    result = run_sweep(['--joint', 'pan_joint', '--target', '1.0',
                        '--vary', 'time_step=0.001,0.004', '--workers', '0',
                        '--report', str(report)])
    assert result.returncode == 0, result.stderr
    rows = json.loads(report.read_text())['rows']
    # Both settle (~11 s); each settling time is a multiple of the step it was sampled at.
    assert rows[0]['settling_time_s'] != rows[1]['settling_time_s']
    assert round(rows[1]['settling_time_s'] / 0.004, 6).is_integer()
    assert not round(rows[0]['settling_time_s'] / 0.004, 6).is_integer()


def test_without_ray_it_runs_locally_and_says_how_to_get_ray_for_address():
    args = ['--joint', 'pan_joint', '--target', '0.2', '--duration', '3', '--vary',
            'mass=0,10', '--workers', '2']
    local = run_sweep(args, blocked=['ray'])
    assert local.returncode == 0, local.stderr
    assert '2 steps (2 combinations): 0 fail' in local.stdout
    remote = run_sweep([*args, '--address', 'auto'], blocked=['ray'])
    assert remote.returncode == 2
    assert 'needs Ray, which is not installed: pip install ray' in remote.stderr


@pytest.mark.parametrize(('args', 'message'), [
    (['--vary', 'mass=0,1', '--vary', 'mass=2'], 'an axis is given twice'),
    (['--vary', 'mass=0,1', '--heatmap-axes', 'p'], '--heatmap-axes'),
    (['--vary', 'payload=1', '--payload-link', 'hand'], "'hand' is not a link"),
    (['--samples', '0'], '--samples'),
])
def test_user_errors_exit_2_with_one_line(args, message):
    result = run_sweep(['--joint', 'pan_joint', '--target', '1', *args])
    assert result.returncode == 2, result.stdout + result.stderr
    assert message in result.stderr and result.stderr.count('\n') == 1, result.stderr


def test_random_samples_are_binned_for_the_heatmap():
    x = sweep.parse_axis('mass=0:80')
    rows = [{'mass': 1.0, 'passed': True}, {'mass': 9.0, 'passed': False},
            {'mass': 79.0, 'passed': False}, {'mass': 80.0, 'passed': True}]
    xs, ys, counts = sweep.heatmap_cells(rows, x, None, binned=True)
    assert xs == [5.0 + 10.0 * k for k in range(sweep.HEATMAP_BINS)] and ys == [0.0]
    assert counts[0][0] == (1, 2)  # 1 and 9 kg share the first 10 % bin, one failing
    assert counts[0][-1] == (1, 2)  # the top of the range goes into the last bin
    assert sum(total for _, total in counts[0]) == 4
