"""step_response: metrics on synthetic signals, and the pan/tilt pan against a hand computation."""

import json
import math
import subprocess
import sys

import pytest
from robot_fixtures import two_link_arm_urdf, write_text
from ros2_control_fixtures import write_arm

from pan_tilt_sim.tools import step_response
from pan_tilt_sim.tools.step_response import (
    StepRecord,
    overshoot_percent,
    rise_time,
    settling_time,
    step_metrics,
)

DT = 0.001


def sampled(function, duration, dt=DT):
    """Return times and values of ``function`` sampled every ``dt`` over ``duration``."""
    times = [index * dt for index in range(round(duration / dt) + 1)]
    return times, [function(t) for t in times]


def first_order(tau, initial=0.0, target=1.0):
    """Return the step response of a first-order lag with time constant ``tau``."""
    return lambda t: target + (initial - target) * math.exp(-t / tau)


def second_order(zeta, omega):
    """Return the unit step response of an underdamped second-order system."""
    damped = omega * math.sqrt(1 - zeta * zeta)
    phase = math.acos(zeta)
    return lambda t: 1 - math.exp(-zeta * omega * t) * math.sin(damped * t + phase) / math.sqrt(
        1 - zeta * zeta)


# --- metrics on synthetic signals -------------------------------------------------

def test_rise_time_of_a_first_order_lag_is_tau_ln_9():
    times, values = sampled(first_order(0.5), 5.0)
    assert rise_time(times, values, 0.0, 1.0) == pytest.approx(0.5 * math.log(9), abs=1e-5)


def test_settling_time_of_a_first_order_lag_is_tau_ln_50():
    times, values = sampled(first_order(0.5), 5.0)
    assert settling_time(times, values, 0.0, 1.0) == pytest.approx(0.5 * math.log(50),
                                                                   abs=DT)


def test_a_first_order_lag_does_not_overshoot():
    _, values = sampled(first_order(0.5), 5.0)
    assert overshoot_percent(values, 0.0, 1.0) == 0.0


def test_overshoot_of_a_second_order_system_matches_the_textbook_formula():
    zeta = 0.3
    _, values = sampled(second_order(zeta, 4.0), 10.0)
    expected = 100 * math.exp(-zeta * math.pi / math.sqrt(1 - zeta * zeta))  # 37.2 %
    assert overshoot_percent(values, 0.0, 1.0) == pytest.approx(expected, abs=0.01)


def test_settling_waits_for_the_last_excursion_out_of_the_band():
    zeta, omega = 0.3, 4.0
    times, values = sampled(second_order(zeta, omega), 10.0)
    settled = settling_time(times, values, 0.0, 1.0)
    assert all(abs(v - 1.0) <= 0.02 for t, v in zip(times, values, strict=True) if t >= settled)
    before = times[times.index(settled) - 1]
    assert abs(values[times.index(before)] - 1.0) > 0.02
    # The envelope bound 4 / (zeta * omega) is an upper limit for 2 %.
    assert settled < 4.0 / (zeta * omega)


def test_downward_steps_are_measured_like_upward_ones():
    times, values = sampled(first_order(0.5, initial=2.0, target=1.0), 5.0)
    assert rise_time(times, values, 2.0, 1.0) == pytest.approx(0.5 * math.log(9), abs=1e-5)
    assert overshoot_percent(values, 2.0, 1.0) == 0.0


def test_a_response_that_never_arrives_has_no_rise_or_settling_time():
    times, values = sampled(lambda t: 0.5 * t, 1.0)  # reaches 0.5 of a unit step
    assert rise_time(times, values, 0.0, 1.0) is None
    assert settling_time(times, values, 0.0, 1.0) is None


def test_a_setpoint_that_jumps_means_the_velocity_limit_was_not_active():
    times, positions = sampled(first_order(0.2), 2.0)
    record = StepRecord('j', 'c', 0.0, 1.0, math.inf, 'rad', 'N m', tuple(times),
                        tuple(positions), (0.0,) + (1.0,) * (len(times) - 1),
                        (0.0,) * len(times))
    metrics = step_metrics(record)
    assert not metrics.velocity_limit_active
    assert metrics.setpoint_reached_s == pytest.approx(DT)


# --- the pan/tilt example's pan, against a hand computation -----------------------------------

@pytest.fixture(scope='module')
def pan_step():
    """Return the JSON the tool prints for the pan/tilt example's pan stepped from 0 to 1 rad."""
    completed = subprocess.run(
        [sys.executable, '-c', 'import sys; from pan_tilt_sim.tools import step_response; '
         "step_response.main(sys.argv[1:]); assert 'rclpy' not in sys.modules, 'rclpy'",
         '--joint', 'pan_joint', '--target', '1.0'],
        capture_output=True, text=True, timeout=120, check=False)
    assert completed.returncode == 0, completed.stderr
    return json.loads(completed.stdout)


def test_the_tool_reports_that_the_velocity_limit_ramped_the_setpoint(pan_step):
    # The ramp itself is the position controller's (tested there); the tool says so.
    assert pan_step['velocity_limit_active'] is True
    assert pan_step['setpoint_reached_s'] > pan_step['rise_time_s']


def test_the_pan_rise_time_is_the_ramp_time_from_10_to_90_percent(pan_step):
    # Following the ramp with a constant lag, 0.1 -> 0.9 rad takes 0.8 / 0.1 = 8 s.
    assert pan_step['rise_time_s'] == pytest.approx(8.0, abs=0.1)


def test_the_pan_cannot_settle_before_its_setpoint_arrives(pan_step):
    # Within 2 % means >= 0.98 rad, and during the ramp the joint lags by
    # (50*0.1 + 1 + 10*0.1)/100 = 0.07 rad, so not before the ramp ends at 10 s;
    # then the lag decays with time constant (damping + d) / p = 0.6 s.
    assert 10.0 <= pan_step['settling_time_s'] <= 10.0 + 0.6 * math.log(0.07 / 0.01) + 0.5


def test_the_pan_effort_peaks_at_what_damping_and_friction_need_at_0_1_rad_s(pan_step):
    assert pan_step['peak_effort'] == pytest.approx(50.0 * 0.1 + 1.0, rel=0.03)  # 6 N m


def test_the_pan_ends_within_friction_over_p_without_overshoot(pan_step):
    # Coulomb friction 1 N m against P = 100 holds up to 0.01 rad of error.
    assert 0.0 <= pan_step['steady_state_error'] <= 1.0 / 100.0 + 1e-3
    assert pan_step['overshoot_percent'] < 0.5
    assert pan_step['gains'] == {'p': 100.0, 'i': 0.01, 'd': 10.0}
    assert pan_step['actuator'] == 'position PID on effort'


def test_a_joint_without_gains_steps_through_the_ideal_actuator(tmp_path, capsys):
    robot = write_text(tmp_path, 'arm.urdf', two_link_arm_urdf())
    yaml = write_text(tmp_path, 'c.yaml', 'shoulder: {type: position_controllers/'
                      'JointPositionController, joint: joint1}\n')
    step_response.main(['--joint', 'joint1', '--target', '0.5', '--model', str(robot),
                        '--controllers', str(yaml), '--duration', '2'])
    summary = json.loads(capsys.readouterr().out)
    assert (summary['actuator'], summary['gains']) == ('ideal position actuator', None)
    assert abs(summary['steady_state_error']) < 0.001
    assert summary['overshoot_percent'] < 0.5


def test_the_plot_is_a_png(tmp_path):
    path = tmp_path / 'step.png'
    step_response.main(['--joint', 'tilt_joint', '--target', '-1.8', '--duration', '3',
                        '--plot', str(path)])
    assert path.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'


@pytest.mark.parametrize(('argv', 'message'), [
    (['--joint', 'elbow', '--target', '1'], "--joint: 'elbow' is not a movable joint"),
    (['--joint', 'pan_joint', '--target', 'nan'], '--target: nan is not a finite number'),
    (['--joint', 'pan_joint', '--target', '0'], 'there is no step'),
    (['--joint', 'pan_joint', '--target', '1', '--duration', '-2'], '--duration'),
    (['--joint', 'pan_joint', '--target', '1', '--model', '/nonexistent.urdf'],
     '/nonexistent.urdf'),
])
def test_user_errors_exit_2_with_one_line(capsys, argv, message):
    with pytest.raises(SystemExit) as exit_info:
        step_response.main(argv)
    err = capsys.readouterr().err
    assert exit_info.value.code == 2
    assert message in err and err.count('\n') == 1


# --- any controller that takes positions: groups, forward commands, trajectories ----------

@pytest.fixture
def ur_style_arm(tmp_path):
    """Return the step_response arguments for the UR-style arm (three controllers per joint)."""
    xacro = write_arm(tmp_path)
    return ['--model', str(xacro), '--controllers-args', 'prefix:=', '--duration', '2']


def run_tool(argv):
    return step_response.run(step_response.parse_args(argv))


@pytest.mark.parametrize(('controller', 'expected'), [
    ([], 'joint_trajectory_controller'),  # the first that takes positions
    (['--controller', 'forward_position_controller'], 'forward_position_controller'),
])
def test_the_joint_steps_through_whichever_controller_takes_positions(ur_style_arm, controller,
                                                                      expected):
    summary = run_tool([*ur_style_arm, '--joint', 'joint2', '--target', '0.5', *controller])
    assert summary['controller'] == expected
    assert summary['target'] == 0.5
    assert summary['steady_state_error'] == pytest.approx(0.0, abs=0.01)
    # No gains in the file: the ideal actuator, as in Gazebo.
    assert (summary['actuator'], summary['gains']) == ('ideal position actuator', None)


def test_the_other_joints_of_a_group_hold_while_one_steps(ur_style_arm):
    args = step_response.parse_args([*ur_style_arm, '--joint', 'joint2', '--target', '0.5',
                                     '--controller', 'forward_position_controller'])
    with step_response.build_simulation(args) as simulation:
        record = step_response.record_step(simulation, 'joint2', 0.5, 1.0,
                                           'forward_position_controller')
        assert record.positions[-1] == pytest.approx(0.5, abs=0.02)
        assert simulation.joint_positions()['joint1'] == pytest.approx(0.0, abs=0.05)


def test_a_controller_that_does_not_take_positions_is_refused(ur_style_arm, capsys):
    with pytest.raises(SystemExit) as exit_info:
        step_response.main([*ur_style_arm, '--joint', 'joint1', '--target', '0.5',
                            '--controller', 'forward_velocity_controller'])
    err = capsys.readouterr().err
    assert exit_info.value.code == 2 and err.count('\n') == 1
    assert ("--controller: 'forward_velocity_controller' is not a loaded controller that "
            "drives 'joint1' by position") in err


def test_a_joint_driven_only_by_velocity_says_so(tmp_path, capsys):
    xacro = write_arm(tmp_path, """
        velocity_controller:
          type: velocity_controllers/JointVelocityController
          joint: joint1
        """)
    with pytest.raises(SystemExit):
        step_response.main(['--model', str(xacro), '--joint', 'joint1', '--target', '0.5'])
    assert ("no controller takes position commands for 'joint1' (its controllers: "
            'velocity_controller (velocity_controllers/JointVelocityController))') in (
                capsys.readouterr().err)


def test_plot_without_matplotlib_is_one_line_before_the_run(monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, 'matplotlib', None)  # import matplotlib -> ImportError

    def no_run(args):
        raise AssertionError('the simulation ran before the missing matplotlib was reported')
    monkeypatch.setattr(step_response, 'build_simulation', no_run)
    with pytest.raises(SystemExit) as exit_info:
        step_response.main(['--joint', 'pan_joint', '--target', '1',
                            '--plot', str(tmp_path / 'step.png')])
    err = capsys.readouterr().err
    assert exit_info.value.code == 2
    assert err == 'step_response: error: --plot: matplotlib is not installed ' \
                  '(pip install matplotlib)\n'


def test_plot_into_a_missing_folder_is_refused_before_the_run(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(step_response, 'build_simulation', lambda args: pytest.fail('ran'))
    with pytest.raises(SystemExit):
        step_response.main(['--joint', 'pan_joint', '--target', '1',
                            '--plot', str(tmp_path / 'no' / 'step.png')])
    assert f"no folder {tmp_path / 'no'}" in capsys.readouterr().err


# --- --record: the run as a rosbag2 bag ---------------------------------------------------

def test_record_writes_the_run_as_sim_node_would_name_it(tmp_path, capsys):
    from bag_fixtures import NANOSECONDS_PER_SECOND, read, topic_messages

    folder = tmp_path / 'step'
    step_response.main(['--joint', 'pan_joint', '--target', '0.2', '--duration', '0.5',
                        '--record', str(folder)])
    assert json.loads(capsys.readouterr().out)['joint'] == 'pan_joint'
    content = read(folder)
    ns = '/ex_urdf_pan_tilt'
    (command,) = topic_messages(content, f'{ns}/joint1_position_controller/command')
    assert command == (0, command[1]) and command[1].data == 0.2
    clock = [time for time, _ in topic_messages(content, '/clock')]
    assert clock == list(range(0, NANOSECONDS_PER_SECOND // 2 + 1, 10_000_000))
    states = topic_messages(content, f'{ns}/joint_states')
    assert len(states) == 25  # 50 Hz of the broadcaster over 0.5 s
    assert all(time == message.header.stamp.sec * NANOSECONDS_PER_SECOND
               + message.header.stamp.nanosec for time, message in states)
    assert states[-1][1].position[0] > 0.0  # the pan moved towards its target
    assert (folder / 'metadata.yaml').is_file()


def test_record_refuses_a_folder_that_exists_in_one_line_before_the_run(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        step_response.main(['--joint', 'pan_joint', '--target', '0.2', '--record',
                            str(tmp_path)])
    captured = capsys.readouterr()
    assert exit_info.value.code == 2 and captured.out == ''
    assert captured.err == (f"step_response: error: --record: the bag folder '{tmp_path}' "
                            'already exists (give a new one)\n')


def test_record_of_a_trajectory_step_holds_the_trajectory_and_tf(ur_style_arm, tmp_path):
    from bag_fixtures import read, topic_messages

    folder = tmp_path / 'arm'
    run_tool([*ur_style_arm, '--joint', 'joint2', '--target', '0.5', '--record', str(folder)])
    content = read(folder)
    (command,) = topic_messages(content, '/joint_trajectory_controller/joint_trajectory')
    assert list(command[1].joint_names) == ['joint1', 'joint2']
    (point,) = command[1].points
    assert list(point.positions) == [0.0, 0.5]
    tf = topic_messages(content, '/tf')
    assert [time for time, _ in tf] == list(range(0, 2_000_000_001, 20_000_000))
    assert topic_messages(content, '/tf_static')
