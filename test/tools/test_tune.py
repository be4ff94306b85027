"""tune: gains that meet a spec the pan/tilt example's fail, written back as the user wrote them.

The same seed gives the same gains on every back end.
"""

import dataclasses
import json
import math
import subprocess
import sys
import textwrap
import types

import pytest

from pan_tilt_sim.controllers.toolbox.pid import PidGains
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.model.controller_config import load_controllers_config
from pan_tilt_sim.model.robot import JointKind, JointSpec
from pan_tilt_sim.tools import tune
from pan_tilt_sim.tools.backends import InProcess, LocalProcesses, RayCluster
from pan_tilt_sim.tools.evaluation import Spec, load_scenario

TIMEOUT_S = 300
# The specification of docs/tune-and-sweep.md: the pan/tilt example's pan stepped to 1 rad must
# end within 0.002 rad of it and settle within 15 s.  The example's gains leave 0.0099 rad
# (friction 1 N m against p = 100).
SPEC_ARGS = ['--joint', 'pan_joint', '--target', '1.0', '--max-error', '0.002',
             '--max-settling', '15']
BUDGET_ARGS = ['--trials', '16', '--batch', '8', '--seed', '0']


def run_tool(module, args, blocked=()):
    """Run ``python -m pan_tilt_sim.tools.<module> args``; ``blocked`` modules fail to import."""
    code = (f'import sys\nfor name in {list(blocked)!r}:\n    sys.modules[name] = None\n'
            f'from pan_tilt_sim.tools import {module}\n{module}.main(sys.argv[1:])\n')
    return subprocess.run([sys.executable, '-c', code, *args], capture_output=True, text=True,
                          timeout=TIMEOUT_S, check=False)


def step_response_json(controllers, joint='pan_joint', target='1.0'):
    result = run_tool('step_response', ['--joint', joint, '--target', target,
                                        '--controllers', str(controllers)])
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


@pytest.fixture(scope='module')
def tuned(tmp_path_factory):
    """Tune the pan/tilt's pan to the spec with 2 local workers; return (result, out, plot).

    The tuned steps are recorded too, in ``bags`` beside ``out``.
    """
    folder = tmp_path_factory.mktemp('tune')
    out, plot = folder / 'tuned.yaml', folder / 'tune.png'
    result = run_tool('tune', [*SPEC_ARGS, *BUDGET_ARGS, '--workers', '2', '--out', str(out),
                               '--plot', str(plot), '--record', str(folder / 'bags')])
    return result, out, plot


def test_the_pan_tilt_examples_gains_fail_the_spec(repo_root):
    example = step_response_json(repo_root / 'config' / 'pan_tilt_control.yaml')
    assert example['steady_state_error'] > 0.002


def test_tuning_ends_with_gains_that_an_independent_step_response_finds_within_spec(tuned):
    result, out, _ = tuned
    assert result.returncode == 0, result.stdout + result.stderr
    assert 'pan_joint: meets the specification' in result.stdout
    checked = step_response_json(out)
    assert abs(checked['steady_state_error']) <= 0.002
    assert checked['settling_time_s'] is not None and checked['settling_time_s'] <= 15.0
    assert checked['overshoot_percent'] <= tune.DEFAULT_OVERSHOOT_PERCENT
    assert checked['peak_effort'] < 300.0
    assert checked['gains'] != {'p': 100.0, 'i': 0.01, 'd': 10.0}


def test_record_keeps_the_tuned_step_as_a_bag_that_ends_within_spec(tuned):
    from bag_fixtures import read, topic_messages

    result, out, _ = tuned
    assert result.returncode == 0, result.stderr
    bags = out.parent / 'bags'
    assert [path.name for path in bags.iterdir()] == ['pan_joint_1']
    content = read(bags / 'pan_joint_1')
    (command,) = topic_messages(content, '/ex_urdf_pan_tilt/joint1_position_controller/command')
    assert command[1].data == 1.0
    states = topic_messages(content, '/ex_urdf_pan_tilt/joint_states')
    assert abs(states[-1][1].position[0] - 1.0) <= 0.002


def test_record_into_a_folder_that_exists_is_refused_before_tuning(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        tune.main([*SPEC_ARGS, *BUDGET_ARGS, '--record', str(tmp_path)])
    assert exit_info.value.code == 2
    assert capsys.readouterr().err == (
        f"tune: error: --record: the folder '{tmp_path}' already exists (give a new one)\n")


def test_the_written_yaml_changes_only_the_pan_gains_in_their_line(tuned, repo_root):
    _, out, _ = tuned
    original = (repo_root / 'config' / 'pan_tilt_control.yaml').read_text()
    written = out.read_text()
    changed = [(old, new) for old, new in zip(original.splitlines(), written.splitlines(),
                                              strict=True) if old != new]
    assert len(changed) == 1
    assert changed[0][0] == '    pid: {p: 100.0, i: 0.01, d: 10.0}'
    assert changed[0][1].startswith('    pid: {p: ') and 'i_clamp: ' in changed[0][1]
    before = {s.name: dict(s.params) for s in load_controllers_config(
        repo_root / 'config' / 'pan_tilt_control.yaml').controllers}
    after = {s.name: dict(s.params) for s in load_controllers_config(out).controllers}
    new_pid = after['joint1_position_controller'].pop('pid')
    before['joint1_position_controller'].pop('pid')
    assert after == before
    assert set(new_pid) == {'p', 'i', 'd', 'i_clamp'}


def test_the_table_shows_before_and_after_and_the_plot_is_a_png(tuned):
    result, _, plot = tuned
    assert 'before' in result.stdout and 'after' in result.stdout
    assert 'final error [rad]' in result.stdout and '<= 0.002' in result.stdout
    assert plot.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'


ROS2_CONTROLLERS = textwrap.dedent("""\
    controller_manager:
      ros__parameters:
        update_rate: 100
        tilt_controller:
          type: effort_controllers/JointPositionController  # one joint, ROS 2 file
    tilt_controller:
      ros__parameters:
        joint: tilt_joint
        # tuned by hand once
        pid:
          p: 100.0
          i: 0.01
          d: 10.0
    """)


def test_a_ros2_control_style_file_is_written_back_in_its_own_block_style(tmp_path):
    source = tmp_path / 'controllers.yaml'
    source.write_text(ROS2_CONTROLLERS)
    out = tmp_path / 'tuned.yaml'
    # A spec the file's own gains meet: the first candidate already qualifies.
    result = run_tool('tune', ['--controllers', str(source), '--joint', 'tilt_joint',
                               '--target', '-2.0', '--max-error', '0.02', '--trials', '8',
                               '--workers', '0', '--out', str(out)])
    assert result.returncode == 0, result.stdout + result.stderr
    written = out.read_text()
    lines = written.splitlines()
    assert lines[:10] == ROS2_CONTROLLERS.splitlines()[:10]
    assert [line.split(':')[0] for line in lines[10:]] == ['      p', '      i', '      d',
                                                          '      i_clamp']
    pid = load_controllers_config(out).controllers[0].params['pid']
    assert set(pid) == {'p', 'i', 'd', 'i_clamp'}


def test_the_same_seed_gives_the_same_gains_in_process_locally_and_on_ray(repo_root):
    ray = pytest.importorskip('ray')
    scenario = load_scenario(repo_root / 'urdf' / 'pan_tilt.xacro',
                             repo_root / 'config' / 'pan_tilt_control.yaml', 0.001)
    # Short steps (0.2 rad: a 2 s ramp, 3 s recorded) keep the three searches quick.
    plans = tune.plan_joints(scenario, ['pan_joint'], {'pan_joint': [0.2]})
    spec = Spec(max_error=0.002, max_settling_s=2.5, max_overshoot_percent=5.0)

    def tried(backend, seed=3):
        result = tune.tune(scenario, plans, spec, backend, trials=12, batch=6, seed=seed,
                           duration=3.0)
        return [trial.gains for trial in result.tunings[0].trials], result.gains

    with LocalProcesses(2) as backend:
        local = tried(backend)
    ray.init(address='local', num_cpus=2, include_dashboard=False, log_to_driver=False,
             object_store_memory=80 * 1024 * 1024, logging_level='WARNING')
    try:
        with RayCluster() as backend:
            assert backend.parallelism == 2
            on_ray = tried(backend)
    finally:
        ray.shutdown()
    assert on_ray == local
    assert tried(InProcess()) == local
    assert tried(InProcess(), seed=4)[0] != local[0]  # the seed matters, so this can fail


def test_an_impossible_settling_time_is_explained_by_the_velocity_limit(tmp_path):
    out = tmp_path / 'tuned.yaml'
    result = run_tool('tune', ['--joint', 'pan_joint', '--target', '1.0', '--max-settling',
                               '5', '--trials', '3', '--workers', '0', '--out', str(out)])
    assert result.returncode == tune.EXIT_NOT_MET, result.stderr
    assert 'pan_joint: no candidate meets the specification (3 tried)' in result.stdout
    assert 'which misses settling' in result.stdout
    assert 'every candidate missed settling' in result.stdout
    assert ('settling binds: pan_joint cannot settle at 1 rad within 5 s: the URDF velocity '
            'limit (0.1 rad/s) ramps the setpoint, so it reaches the 2 % band only after '
            '9.8 s') in result.stdout
    assert f'{out} not written' in result.stdout and not out.exists()
    assert 'warning: pan_joint cannot settle' in result.stderr


def test_limits_tell_when_the_effort_limit_cannot_beat_friction():
    stuck = JointSpec('j', JointKind.REVOLUTE, effort_limit=1.0, friction=2.0)
    notes = tune.limit_notes(stuck, 0.0, 1.0, Spec())
    assert 'not above its friction' in notes['effort']
    # Damping 50 with 300 N m lets the joint reach 5.98 rad/s at most: no settling bound
    # at a 1 rad/s velocity limit for a 10 s spec, but one for 0.5 s.
    free = JointSpec('j', JointKind.REVOLUTE, effort_limit=300.0, velocity_limit=1.0,
                     damping=50.0, friction=1.0)
    assert tune.limit_notes(free, 0.0, 1.0, Spec(max_settling_s=10.0)) == {}
    assert '0.98 s' in tune.limit_notes(free, 0.0, 1.0, Spec(max_settling_s=0.5))['settling']
    slow = JointSpec('j', JointKind.REVOLUTE, effort_limit=300.0, velocity_limit=100.0,
                     damping=100.0)
    assert 'allows at most 3 rad/s' in tune.limit_notes(
        slow, 0.0, 3.0, Spec(max_settling_s=0.5))['settling']


def test_the_search_space_holds_the_yaml_gains_and_candidates_are_what_gets_written():
    joint = JointSpec('j', JointKind.REVOLUTE, effort_limit=300.0)
    gains = PidGains(p=100.0, i=0.01, d=10.0, antiwindup=True)
    space = tune.search_space(gains, joint, {'d': (1.0, 2.0)})
    assert space.ranges['p'] == (1.0, 10000.0) and space.ranges['d'] == (1.0, 2.0)
    assert space.ranges['i_clamp'] == (0.3, 300.0)
    start = tune.starting_params(gains, space)
    assert start == {'p': 100.0, 'i': 0.01, 'd': 2.0, 'i_clamp': 300.0}
    candidate = tune.candidate_gains(gains, {'p': 1234.5678, 'i': 0.00123456, 'd': 1.5,
                                             'i_clamp': 7.777777})
    assert (candidate.p, candidate.i, candidate.i_clamp_max) == (1235.0, 0.001235, 7.778)
    assert candidate.i_clamp_min == -7.778 and candidate.antiwindup


def test_targets_go_to_every_joint_or_the_one_named():
    assert tune.parse_targets(['a', 'b'], ['1', 'b=-2']) == {'a': [1.0], 'b': [1.0, -2.0]}
    with pytest.raises(ConfigurationError, match="'c', which is not a --joint"):
        tune.parse_targets(['a'], ['c=1'])
    with pytest.raises(ConfigurationError, match="no target for 'b'"):
        tune.parse_targets(['a', 'b'], ['a=1'])
    with pytest.raises(ConfigurationError, match='not a finite number'):
        tune.parse_targets(['a'], ['nan'])


NO_PID = textwrap.dedent("""\
    ex_urdf_pan_tilt:
      joint1_position_controller:
        type: position_controllers/JointPositionController
        joint: pan_joint
    """)


@pytest.mark.parametrize(('args', 'message'), [
    (['--joint', 'pan_joint', '--target', '1', '--controllers', '{no_pid}'],
     "its controller 'joint1_position_controller' has no pid entry"),
    (['--joint', 'pan_joint', '--target', '0'], 'there is no step'),
    (['--joint', 'elbow', '--target', '1'], "'elbow' is not a movable joint"),
    (['--joint', 'pan_joint', '--target', '1', '--range', 'p=5:1'], '--range'),
    (['--joint', 'pan_joint', '--target', '1', '--max-error', '-1'], '--max-error'),
    (['--joint', 'pan_joint', '--target', '1', '--trials', '0'], '--trials'),
])
def test_user_errors_exit_2_with_one_line(tmp_path, capsys, args, message):
    no_pid = tmp_path / 'no_pid.yaml'
    no_pid.write_text(NO_PID)
    with pytest.raises(SystemExit) as exit_info:
        tune.main([arg.format(no_pid=no_pid) for arg in args])
    err = capsys.readouterr().err
    assert exit_info.value.code == 2, err
    assert message in err and err.count('\n') == 1, err


def test_without_ray_it_runs_on_local_processes_and_says_how_to_get_ray_for_address():
    args = ['--joint', 'pan_joint', '--target', '0.2', '--max-error', '0.02', '--trials', '2',
            '--batch', '2', '--workers', '2', '--duration', '3']
    local = run_tool('tune', args, blocked=['ray'])
    assert local.returncode == 0, local.stdout + local.stderr
    assert 'local processes (2 at a time)' in local.stderr
    remote = run_tool('tune', [*args, '--address', 'auto'], blocked=['ray'])
    assert remote.returncode == 2
    assert 'needs Ray, which is not installed: pip install ray' in remote.stderr
    assert remote.stderr.count('\n') == 1


def test_without_optuna_it_says_how_to_get_it():
    result = run_tool('tune', ['--joint', 'pan_joint', '--target', '1'], blocked=['optuna'])
    assert result.returncode == 2
    assert 'pip install optuna' in result.stderr


def test_itae_and_violations_rank_the_trials():
    # A tuning's best: the cheapest feasible trial, else the least infeasible.
    class Evaluation:
        def __init__(self, itae):
            self.itae = itae

    def trial(number, itae, **violated):
        found = dict.fromkeys(('overshoot', 'settling', 'error', 'effort'), -1.0)
        found.update(violated)
        return tune.Trial(number, PidGains(p=float(number)), Evaluation(itae), found)

    tuning = tune.JointTuning('j', 'c', 'pid', PidGains(), (
        trial(0, 1.0, error=0.5), trial(1, 3.0), trial(2, 2.0), trial(3, 0.1, settling=2.0)),
        {})
    assert tuning.best.number == 2 and tuning.met
    infeasible = tune.JointTuning('j', 'c', 'pid', PidGains(), (
        trial(0, 1.0, error=0.5), trial(1, 0.1, settling=2.0)), {})
    assert infeasible.best.number == 0 and not infeasible.met
    assert math.isclose(infeasible.best.excess, 0.5)


def test_with_several_controller_files_the_one_whose_gains_win_is_rewritten(repo_root,
                                                                            tmp_path):
    # ros2_control reads the files in order, later ones winning: the second file's pid
    # is the one in force, so that is the file tune writes (the first stays as it is).
    first, second = tmp_path / 'a' / 'base.yaml', tmp_path / 'b' / 'override.yaml'
    first.parent.mkdir()
    second.parent.mkdir()
    first.write_text(ROS2_CONTROLLERS)
    second.write_text('tilt_controller:\n  ros__parameters:\n    pid: {p: 50.0, d: 5.0}\n')
    scenario = load_scenario(repo_root / 'urdf' / 'pan_tilt.xacro', first, 0.001)
    scenario = dataclasses.replace(scenario, controllers=load_controllers_config([first,
                                                                                  second]))
    tuned = PidGains(p=75.0, i=0.5, d=4.0, i_clamp_min=-2.0, i_clamp_max=2.0)
    result = tune.TuneResult((tune.JointTuning(
        'tilt_joint', 'tilt_controller', 'pid', PidGains(), (tune.Trial(
            0, tuned, types.SimpleNamespace(itae=1.0), {'effort': -1.0}),), {}),), {}, {},
        Spec())
    out = tmp_path / 'out.yaml'
    tune.write_yaml(scenario, result, out)
    assert out.read_text() == ('tilt_controller:\n  ros__parameters:\n'
                               '    pid: {p: 75.0, d: 4.0, i: 0.5, i_clamp: 2.0}\n')
