"""The bench command: one JSON object with every figure; its helpers compute them right.

No timing is asserted here: the figures come from running the command.
"""

import json
import math
import statistics
import subprocess
import sys

import pytest
import sim_process
import yaml
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from node_harness import PROBE_QUEUE, sim_node
from sensor_msgs.msg import LaserScan

from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.model.world_file import world_from_parameter
from pan_tilt_sim.share import package_share
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.tools import bench, bench_scenes

QUICK_TIMEOUT_S = 300
RAW = {'step_us_cpu', 'steps_per_s', 'calls_us_cpu', 'compiled_step', 'wall_steps_per_s'}
FACTOR_0 = {
    'no_subscriber': {'steps_per_s', 'node_cpu_us_per_step', 'ratio_to_raw'},
    'clock_subscriber': {'steps_per_s', 'node_cpu_us_per_step', 'ratio_to_raw',
                         'subscriber_cpu_percent'},
    'joint_state_subscriber': {'steps_per_s', 'node_cpu_us_per_step', 'ratio_to_raw',
                               'subscriber_cpu_percent'},
    'recording': {'steps_per_s', 'node_cpu_us_per_step', 'ratio_to_raw'},
}
SERVICE_ROUND_TRIP = {'p50_ms', 'p99_ms', 'answers_per_s', 'unanswered'}
SCENES = {'driving_base': {'on_ground', 'base_fixed', 'on_ground_10_iterations'},
          'grasp': {'holding', 'open'}, 'ur5e_like': {'follow_trajectory'},
          'tb3_sandbox': {'circle'}}
SCENE_CASE = {'steps_per_s', 'node_cpu_us_per_step', 'real_time_multiple', 'contact_points',
              'raw_step_us', 'ratio_to_raw'}
ODOMETRY = SCENE_CASE | {'odometry_error_percent'}
BOX = SCENE_CASE | {'box_height_m', 'box_height_error_m'}
SCENE_CASES = {'on_ground': ODOMETRY, 'base_fixed': SCENE_CASE,
               'on_ground_10_iterations': ODOMETRY, 'holding': BOX, 'open': BOX,
               'follow_trajectory': SCENE_CASE | {'tracking_error_rad'},
               'circle': SCENE_CASE | {'subscriber_cpu_percent', 'lidar_us_per_scan',
                                       'lidar_us_per_step'}}
CHAIN = {'steps_per_s', 'node_cpu_us_per_step', 'raw_step_us', 'ratio_to_raw'}
TIME_STEPS = {'driving_base': bench.DEFAULT_TIME_STEP, 'grasp': bench.DEFAULT_TIME_STEP,
              'ur5e_like': bench.DEFAULT_TIME_STEP,
              'tb3_sandbox': bench_scenes.SANDBOX_STEP}  # the sandbox's world says 3 ms
FACTOR_1 = {'cpu_percent', 'cpu_percent_with_joint_states', 'cpu_percent_recording',
            'clock_subscriber_cpu_percent',
            'joint_states_p50_ms', 'joint_states_p99_ms', 'rtf_error'}


def leaves(figures: dict, prefix: str = '') -> dict:
    """Flatten nested figures to {'a.b': value}."""
    flat = {}
    for key, value in figures.items():
        if isinstance(value, dict):
            flat.update(leaves(value, f'{prefix}{key}.'))
        else:
            flat[f'{prefix}{key}'] = value
    return flat


@pytest.fixture(scope='module')
def quick_run():
    """Run ``python -m pan_tilt_sim.tools.bench --quick`` once; return (stdout, stderr)."""
    result = subprocess.run(
        [sys.executable, '-m', 'pan_tilt_sim.tools.bench', '--quick'], capture_output=True,
        text=True, env=sim_process.environment(), timeout=QUICK_TIMEOUT_S, check=False)
    assert result.returncode == 0, result.stderr
    return result.stdout, result.stderr


@pytest.mark.timeout(QUICK_TIMEOUT_S + 30)
def test_quick_prints_exactly_one_json_object_with_every_figure(quick_run):
    figures = json.loads(quick_run[0])
    assert set(figures) == {'raw', 'factor_0', 'factor_1', 'startup_s', 'startup_floor_s',
                            'scaling', 'scenes', 'sensor_us_per_message',
                            'service_round_trip'}
    assert set(figures['service_round_trip']) == SERVICE_ROUND_TRIP
    assert set(figures['raw']) == RAW
    assert {case: set(values) for case, values in figures['factor_0'].items()} == FACTOR_0
    assert set(figures['factor_1']) == FACTOR_1
    assert set(figures['scaling']) == {str(joints) for joints in bench.CHAIN_JOINTS}
    assert all(set(chain) == CHAIN for chain in figures['scaling'].values())
    # The test run's install is built with its compiled step (.ci/run has a compiler).
    assert figures['raw'].pop('compiled_step') is True
    for key, value in leaves(figures).items():
        kind = int if key.endswith('steps_per_s') else float
        assert isinstance(value, kind), (key, value)
        assert math.isfinite(value) and value >= 0, (key, value)
    assert figures['raw']['steps_per_s'] > 0
    assert all(case['steps_per_s'] > 0 for case in figures['factor_0'].values())


@pytest.mark.timeout(QUICK_TIMEOUT_S + 30)
def test_quick_answers_every_service_call_of_its_concurrent_callers(quick_run):
    figures = json.loads(quick_run[0])['service_round_trip']
    assert figures['unanswered'] == 0.0
    assert figures['answers_per_s'] > 0
    assert 0 < figures['p50_ms'] <= figures['p99_ms']


@pytest.mark.timeout(QUICK_TIMEOUT_S + 30)
def test_quick_reports_the_cost_of_each_sensor_per_message(quick_run):
    costs = json.loads(quick_run[0])['sensor_us_per_message']
    assert set(costs) == {'depth_camera', 'lidar', 'tilt_imu', 'tilt_ft'}
    assert all(isinstance(cost, float) and cost > 0 for cost in costs.values()), costs


@pytest.mark.timeout(QUICK_TIMEOUT_S + 30)
def test_quick_runs_each_contact_scene_in_each_case_and_reports_its_figures(quick_run):
    scenes = json.loads(quick_run[0])['scenes']
    assert {scene: set(cases) for scene, cases in scenes.items()} == SCENES
    for scene, cases in scenes.items():
        for case, values in cases.items():
            assert set(values) == SCENE_CASES[case], case
            assert values['steps_per_s'] > 0, case
            # The multiple of real time is the step rate in sim seconds.
            assert values['real_time_multiple'] == pytest.approx(
                values['steps_per_s'] * TIME_STEPS[scene], rel=1e-3, abs=1e-3), case
            # Both steps are thread CPU; the ratio is PyBullet's alone over the node's.
            assert values['raw_step_us'] > 0, case
            assert values['ratio_to_raw'] == pytest.approx(
                values['raw_step_us'] / values['node_cpu_us_per_step'], rel=2e-3), case
    lidar = scenes['tb3_sandbox']['circle']
    assert lidar['lidar_us_per_scan'] > 0 and 0 < lidar['lidar_us_per_step'] < lidar[
        'lidar_us_per_scan']


@pytest.mark.timeout(QUICK_TIMEOUT_S + 30)
def test_quick_keeps_pybullet_and_node_output_off_stdout(quick_run):
    stdout, _ = quick_run
    assert stdout.count('\n') == 1 and stdout.lstrip().startswith('{')


def test_node_cpu_is_the_busiest_thread_over_the_window_not_the_busiest_so_far():
    # Thread 1 did the start-up (10 s so far) and idles; thread 2 steps the physics.
    before = {1: 10.0, 2: 0.5}
    after = {1: 10.01, 2: 1.5, 3: 0.2}  # thread 3 started during the window
    assert bench.busiest_thread_delta(before, after) == pytest.approx(1.0)


# Burns CPU in threads that then end, reports its own CPU time, waits for a line; three times.
BURN_AND_REPORT = """
import sys, threading, time
def burn(seconds):
    start = time.process_time()
    while time.process_time() - start < seconds:
        pass
for seconds in (0.013, 0.027, 0.041):
    worker = threading.Thread(target=burn, args=(seconds,))
    worker.start()
    worker.join()
    print(time.process_time(), flush=True)
    sys.stdin.readline()
"""


@pytest.mark.skipif(not sys.platform.startswith('linux'), reason="Linux's CPU-time clocks")
def test_a_process_cpu_time_is_read_to_well_under_a_clock_tick_ended_threads_included():
    # The factor-1 share is a fraction of a second of CPU in a 10 s window: whole clock
    # ticks, as /proc counts them, would be a sizeable part of it.
    child = subprocess.Popen([sys.executable, '-c', BURN_AND_REPORT], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True)
    try:
        for _ in range(3):
            own = float(child.stdout.readline())
            assert own <= bench.cpu_seconds(child.pid) < own + 0.002
            child.stdin.write('\n')
            child.stdin.flush()
    finally:
        child.kill()
        child.wait()


@pytest.mark.timeout(QUICK_TIMEOUT_S + 30)
def test_quick_measures_the_physics_thread_at_factor_0(quick_run):
    # The thread measured is the one stepping: at factor 0 it is busy nearly all the time, so
    # its CPU per step is a large share of the wall time per step even when another test
    # process shares the cores (an idle thread's would be ~0).  (A quick run's bare step is
    # too short to be a floor to hold the node's step to.)
    figures = json.loads(quick_run[0])
    measured = {**figures['factor_0'],
                **{f'chain of {joints}': values for joints, values in figures['scaling'].items()}}
    for case, values in measured.items():
        wall_us_per_step = 1e6 / values['steps_per_s']
        assert values['node_cpu_us_per_step'] > 0.25 * wall_us_per_step, case
    # The chains cost more per step the more joints they step: 2, 8, 32 joints.
    raw = figures['raw']['step_us_cpu']
    chains = [figures['scaling'][joints]['node_cpu_us_per_step'] for joints in ('2', '8', '32')]
    assert chains[1] > 1.5 * chains[0] and chains[2] > 2 * chains[1] > raw, chains


def test_children_run_the_installed_package_not_one_in_the_working_directory(tmp_path):
    # A bench started from a source checkout must time what `ros2 run` starts.
    decoy = tmp_path / 'pan_tilt_sim'
    decoy.mkdir()
    (decoy / '__init__.py').write_text("raise SystemExit('decoy pan_tilt_sim imported')\n")
    env = {name: value for name, value in sim_process.environment().items()
           if name != 'PYTHONSAFEPATH'}
    result = subprocess.run(bench.module_command('pan_tilt_sim.tools.bench', '--help'),
                            cwd=tmp_path, env=env, capture_output=True, text=True,
                            timeout=60, check=False)
    assert result.returncode == 0, result.stderr
    assert 'decoy' not in result.stdout + result.stderr
    assert '--runs' in result.stdout


def test_raw_rates_that_agree_raise_no_warning():
    assert bench.raw_rates_disagree({'steps_per_s': 293748, 'wall_steps_per_s': 305937}) is None
    assert bench.raw_rates_disagree({'steps_per_s': 300000, 'wall_steps_per_s': 240000}) is None


def test_raw_rates_far_apart_say_the_ratios_are_not_to_be_trusted():
    # A busy neighbour inflates the thread-CPU reading while the wall rate stays normal.
    problem = bench.raw_rates_disagree({'steps_per_s': 176154, 'wall_steps_per_s': 290148})
    assert problem is not None
    assert '176,154' in problem and '290,148' in problem and '39% apart' in problem
    assert 'ratio_to_raw' in problem


def test_rounded_gives_integer_rates_and_four_significant_digits_at_any_depth():
    figures = bench.rounded({'raw': {'steps_per_s': 123456.7, 'step_us_cpu': 3.14159,
                                     'compiled_step': True},
                             'scaling': {'2': {'steps_per_s': 9876.4}}})
    assert figures == {'raw': {'steps_per_s': 123457, 'step_us_cpu': 3.142,
                               'compiled_step': True},
                       'scaling': {'2': {'steps_per_s': 9876}}}
    assert figures['raw']['compiled_step'] is True  # a flag stays a flag (1.0 == True)


def test_slope_fits_a_line_through_jittered_samples():
    samples = [(t * 0.02, t * 0.02 * 1.01 + (0.001 if t % 2 else -0.001)) for t in range(500)]
    assert bench.slope(samples) == pytest.approx(1.01, abs=1e-4)


def test_percentile_99_of_a_uniform_spread():
    assert bench.percentile_99([float(v) for v in range(101)]) == pytest.approx(99.0)


def test_median_of_runs_goes_into_nested_figures():
    runs = [{'a': 1.0, 'scaling': {'2': 10.0}, 'built': True},
            {'a': 3.0, 'scaling': {'2': 30.0}, 'built': True},
            {'a': 2.0, 'scaling': {'2': 20.0}, 'built': True}]
    assert bench.median_of(runs) == {'a': 2.0, 'scaling': {'2': 20.0}, 'built': True}
    runs[1]['built'] = False  # a flag is true only if it was true in every run
    assert bench.median_of(runs)['built'] is False


def test_position_targets_sit_inside_the_limits():
    low, high = bench.position_targets(-4.0, 0.0, limited=True)
    assert -4.0 < low < high < 0.0
    assert bench.position_targets(-math.inf, math.inf, limited=False) == (-1.0, 1.0)


@pytest.mark.parametrize('joints', bench.CHAIN_JOINTS)
def test_generated_chain_has_a_position_controller_per_joint(tmp_path, joints):
    urdf, controllers = bench.chain_files(joints, tmp_path)
    model = bench.load_model(urdf, controllers)
    assert model.joint_states_topic == f'/chain_{joints}/joint_states'
    assert len(model.commands) == joints
    with make_simulation(str(urdf), str(controllers), 0.001) as simulation:
        assert len(simulation.handles) == joints
        simulation.advance(100)
        # Held at zero by its controllers, the chain stays near straight.
        assert max(abs(p) for p in simulation.joint_positions().values()) < 0.05


def test_pan_tilt_model_commands_both_position_controllers(repo_root):
    model = bench.load_model(repo_root / 'urdf' / 'pan_tilt.xacro',
                             repo_root / 'config' / 'pan_tilt_control.yaml')
    assert model.joint_states_topic == '/ex_urdf_pan_tilt/joint_states'
    assert set(model.commands) == {
        '/ex_urdf_pan_tilt/joint1_position_controller/command',
        '/ex_urdf_pan_tilt/joint2_position_controller/command'}


def scene_cases(tmp_path):
    """Return every case of the driving base, the grasp and the arm, written into ``tmp_path``."""
    return {**bench_scenes.driving_base(package_share(), tmp_path),
            **bench_scenes.grasp(tmp_path), **bench_scenes.ur5e_like(tmp_path)}


def test_the_driving_base_touches_the_ground_only_when_its_base_is_free(tmp_path):
    cases = scene_cases(tmp_path)
    on_ground = bench_scenes.in_process_figures(cases['on_ground'], 0.001)
    base_fixed = bench_scenes.in_process_figures(cases['base_fixed'], 0.001)
    # Two wheels and the caster on the ground, beside the room's ball on it; then the ball alone.
    assert on_ground['contact_points'] >= 4
    assert base_fixed['contact_points'] == 1
    # Its odometry follows the base it drives within 1 % of the way driven.
    assert on_ground['odometry_error_percent'] < 1.0
    assert on_ground['raw_step_us'] > base_fixed['raw_step_us'] > 0  # the contacts' solve


def test_the_driving_base_at_10_solver_iterations_is_the_room_as_an_sdf_world(tmp_path):
    cases = scene_cases(tmp_path)
    few = world_from_parameter(cases['on_ground_10_iterations'].parameters['world'])
    room = world_from_parameter(cases['on_ground'].parameters['world'])
    assert few.physics.solver_iterations == bench_scenes.FEW_SOLVER_ITERATIONS
    assert few.scenery == room.scenery == 'ground'
    assert [entity.name for entity in few.entities] == [entity.name for entity in room.entities]
    for ours, theirs in zip(few.entities, room.entities, strict=True):
        assert ours.position == pytest.approx(theirs.position), ours.name
        assert ours.orientation == pytest.approx(theirs.orientation, abs=1e-9), ours.name
        # Static where the room's is (the ball alone rolls).
        assert ('<static>true</static>' in ours.resource_string) == (
            '<static>true</static>' in theirs.resource_string), ours.name
    figures = bench_scenes.in_process_figures(cases['on_ground_10_iterations'], 0.001)
    # Fewer iterations let the wheels slip more: its odometry drifts, but it drives its circle.
    assert figures['contact_points'] >= 4 and figures['odometry_error_percent'] < 5.0


def test_the_driving_base_is_the_shipped_rover_driven_by_a_diff_drive_controller(tmp_path):
    case = scene_cases(tmp_path)['on_ground']
    urdf = case.description_file.read_text()
    assert 'libgazebo_ros_diff_drive.so' not in urdf
    assert '<ros2_control' in urdf and 'name="lidar"' in urdf
    model = bench.load_model(case.description_file, case.controllers_file)
    assert model.joint_states_topic == case.joint_states_topic
    assert case.parameters['world'].endswith('room.yaml')
    with make_simulation(str(case.description_file), str(case.controllers_file), 0.001,
                         fixed_base=False) as simulation:
        drive = simulation.controller(bench_scenes.BASE_CONTROLLER)
        assert drive.params['wheel_separation'] == pytest.approx(0.3)
        assert drive.params['wheel_radius'] == pytest.approx(0.05)


def test_the_grasp_holds_the_box_up_and_the_open_gripper_leaves_it_on_the_ground(tmp_path):
    cases = scene_cases(tmp_path)
    holding = bench_scenes.in_process_figures(cases['holding'], 0.001)
    opened = bench_scenes.in_process_figures(cases['open'], 0.001)
    half_box = bench_scenes.BOX_SIZE / 2
    assert holding['box_height_m'] > half_box + 0.9 * bench_scenes.LIFT_M
    assert opened['box_height_m'] == pytest.approx(half_box, abs=0.001)
    # Held where the fingers took it, within a millimetre, as the lift rose.
    assert holding['box_height_error_m'] < 0.001 and opened['box_height_error_m'] < 0.001
    # Two fingers' faces on the box; the box's face on the ground.
    assert holding['contact_points'] >= 4 and opened['contact_points'] >= 1


def test_the_arm_has_the_ur5e_s_masses_lengths_and_limits(tmp_path):
    case = scene_cases(tmp_path)['follow_trajectory']
    model = load_description(case.description_file).model
    with make_simulation(str(case.description_file), str(case.controllers_file),
                         0.001) as simulation:
        assert tuple(simulation.handles) == bench_scenes.UR5E_JOINTS
        # Each link's mass as PyBullet loaded it.
        body, client = simulation.physics.body_id, simulation.physics.client_id
        for name, mass in list(bench_scenes.UR5E_MASSES.items())[1:]:  # the base is welded
            index = simulation.physics.link_index(name)
            assert pybullet.getDynamicsInfo(body, index, physicsClientId=client)[0] == mass
        # Stretched out (shoulder lift and elbow at 0), the reach is UR's: d1 up, a2 + a3 out.
        simulation.physics.reset_joints([0.0] * 6)
        wrist = simulation.link_state('wrist_1_link')[0].translation
        dh = bench_scenes.UR5E_DH
        assert abs(wrist[0]) == pytest.approx(abs(dh['a2'] + dh['a3']), abs=1e-6)
        assert wrist[2] == pytest.approx(dh['d1'], abs=1e-6)
    limits = {joint.name: (joint.effort_limit, joint.upper) for joint in model.joints
              if joint.name in bench_scenes.UR5E_JOINTS}
    assert [effort for effort, _ in limits.values()] == list(bench_scenes.UR5E_EFFORT)
    assert limits['elbow_joint'][1] == pytest.approx(math.pi, abs=1e-5)


def test_the_arm_follows_its_trajectory_goal_closely(tmp_path):
    case = scene_cases(tmp_path)['follow_trajectory']
    goal = case.goals[bench_scenes.ARM_ACTION]
    assert goal.trajectory.joint_names == list(bench_scenes.UR5E_JOINTS)
    last = goal.trajectory.points[-1].time_from_start
    assert last.sec >= bench_scenes.ARM_GOAL_S - bench_scenes.ARM_PERIOD
    figures = bench_scenes.in_process_figures(case, 0.001, settle_s=1.0, count_s=4.0)
    assert 0.0 < figures['tracking_error_rad'] < 0.01
    assert figures['raw_step_us'] > 0 and figures['contact_points'] == 0


def median_range(scan: LaserScan, bearing: float, half_width: float = math.radians(2)) -> float:
    """The median range of the beams within ``half_width`` of ``bearing`` (rad, sensor frame)."""
    ranges = [measured for index, measured in enumerate(scan.ranges)
              if abs(math.remainder(scan.angle_min + index * scan.angle_increment - bearing,
                                    math.tau)) <= half_width]
    return statistics.median(ranges)


def test_the_sandbox_robot_drives_its_circle_and_its_lidar_sees_a_pillar_and_the_wall(
        tmp_path):
    case = bench_scenes.tb3_sandbox(tmp_path)['circle']
    assert case.controllers_file is None
    assert case.watched == ('/scan', 'sensor_msgs/msg/LaserScan')
    start = yaml.safe_load(case.parameters['initial_pose'])
    with sim_node(paused=True, robot_description_file=str(case.description_file),
                  world=case.parameters['world'], initial_pose=start) as sim:
        # The world's <physics> gives the step the bench's case names.
        assert sim.node.settings.time_step == float(case.parameters['time_step'])
        scans = sim.collect(LaserScan, '/scan', PROBE_QUEUE)
        odometry = sim.collect(Odometry, '/odom', PROBE_QUEUE)
        twist = sim.probe.create_publisher(Twist, '/cmd_vel', 10)
        sim.wait_for_subscribers('/scan')
        sim.wait_for_subscribers('/odom')
        assert sim.spin_until(lambda: twist.get_subscription_count() > 0)
        sim.node.step(80)  # one lidar period (5 Hz at 3 ms) where the robot starts
        assert sim.spin_until(lambda: scans)
        scan = scans[-1]
        # The lidar sits 6 cm behind the axle, heading +x.
        lidar = (start[0] - 0.06, start[1])
        pillar = (bench_scenes.PILLAR_GRID, 0.0)  # the nearest pillar, ahead and to the right
        dx, dy = pillar[0] - lidar[0], pillar[1] - lidar[1]
        assert median_range(scan, math.atan2(dy, dx)) == pytest.approx(
            math.hypot(dx, dy) - bench_scenes.PILLAR_RADIUS, abs=0.02)
        # Straight left (+y), past the pillars' column, the hexagon's inner face.
        assert median_range(scan, math.pi / 2) == pytest.approx(
            bench_scenes.HEXAGON_APOTHEM - lidar[1], abs=0.02)
        before = sum(sim.node.commands_received.values())
        twist.publish(case.messages['/cmd_vel'])
        assert sim.spin_until(lambda: sum(sim.node.commands_received.values()) > before)
        for _ in range(30):  # 9 s of sim time: most of a lap
            sim.node.step(100)
            sim.spin_until(lambda: False, 0.01)
        assert sim.spin_until(lambda: len(odometry) > 20)
    # The odometry frame starts where the robot does; the circle's centre is to its left.
    radius = bench_scenes.SANDBOX_CIRCLE_RADIUS
    points = [(message.pose.pose.position.x, message.pose.pose.position.y)
              for message in odometry]
    assert max(y for _x, y in points) > 1.8 * radius, 'it did not go round'
    for x, y in points:
        assert math.hypot(x, y - radius) == pytest.approx(radius, abs=0.02), (x, y)


def test_fewer_than_one_run_is_a_usage_error():
    with pytest.raises(SystemExit) as exit_info:
        bench.parse_args(['--runs', '0'])
    assert exit_info.value.code == 2
