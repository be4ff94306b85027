"""sim_node in-process: the pan/tilt example driven through its ROS interface.

The node and a probe node share one executor; the node runs at
real_time_factor 0 (as fast as possible), and every wait is a bounded spin.
"""

import math
import time

import pytest
from node_harness import PROBE_QUEUE, sim_node, stamp_s
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64

from pan_tilt_sim.ros.clock_publisher import CLOCK_BURST
from pan_tilt_sim.sim.physics import pybullet

NS = '/ex_urdf_pan_tilt'
PAN = 'joint1_position_controller'
TILT = 'joint2_position_controller'
PAN_COMMAND = f'{NS}/{PAN}/command'
TILT_COMMAND = f'{NS}/{TILT}/command'
SPEED_TOLERANCE = 0.002  # rad/s above the URDF velocity limit of 0.1
SETTLE_TOLERANCE = 0.015  # rad: friction 1 N*m against P = 100 leaves up to 0.01 rad


@pytest.fixture
def pan_tilt():
    with sim_node() as sim:
        yield sim


def test_topics_are_those_of_the_seed(pan_tilt):
    topics = pan_tilt.topics_once_seen(PAN_COMMAND, TILT_COMMAND, f'{NS}/joint_states', '/clock')
    assert topics[PAN_COMMAND] == ['std_msgs/msg/Float64']
    assert topics[TILT_COMMAND] == ['std_msgs/msg/Float64']
    assert topics[f'{NS}/joint_states'] == ['sensor_msgs/msg/JointState']
    assert topics['/clock'] == ['rosgraph_msgs/msg/Clock']


def test_pan_settles_at_its_command_no_faster_than_the_velocity_limit(pan_tilt):
    start = pan_tilt.simulation.time
    pan_tilt.command(PAN, Float64(data=1.0))
    pan_tilt.run_for(15.0)
    assert pan_tilt.position('pan_joint') == pytest.approx(1.0, abs=SETTLE_TOLERANCE)
    speeds = pan_tilt.series('pan_joint', 'velocity', since=start)
    assert max(abs(v) for v in speeds) <= 0.1 + SPEED_TOLERANCE
    # 1 rad at 0.1 rad/s: not there before 10 s of sim time.
    positions = pan_tilt.series('pan_joint', 'position')
    early = [p for m, p in zip(pan_tilt.states, positions, strict=True)
             if stamp_s(m) < start + 9.5]
    assert max(early) < 0.96


def test_tilt_starts_at_its_upper_limit_and_follows_commands_within_limits(pan_tilt):
    assert pan_tilt.spin_until(lambda: pan_tilt.states)
    assert pan_tilt.states[0].position[1] == pytest.approx(-1.570796, abs=1e-6)
    pan_tilt.command(TILT, Float64(data=0.0))  # above the upper limit: clamped there
    pan_tilt.run_for(3.0)
    assert pan_tilt.position('tilt_joint') == pytest.approx(-1.570796, abs=SETTLE_TOLERANCE)
    pan_tilt.command(TILT, Float64(data=-2.0))
    pan_tilt.run_for(8.0)
    assert pan_tilt.position('tilt_joint') == pytest.approx(-2.0, abs=SETTLE_TOLERANCE)


@pytest.mark.parametrize('bad', [math.nan, math.inf, -math.inf])
def test_non_finite_commands_change_nothing(pan_tilt, bad):
    pan_tilt.command(PAN, Float64(data=0.2))
    pan_tilt.command(PAN, Float64(data=bad))
    pan_tilt.run_for(4.0)
    assert pan_tilt.position('pan_joint') == pytest.approx(0.2, abs=SETTLE_TOLERANCE)
    assert all(math.isfinite(v) for m in pan_tilt.states for v in (*m.position, *m.velocity,
                                                                    *m.effort))


def test_joint_states_arrive_at_50_hz_of_sim_time_with_every_field(pan_tilt):
    pan_tilt.run_for(2.5)
    first_two_seconds = [m for m in pan_tilt.states if stamp_s(m) < 2.0]
    assert 99 <= len(first_two_seconds) <= 101
    stamps = [stamp_s(m) for m in first_two_seconds]
    assert stamps[0] == pytest.approx(0.0)
    assert all(b - a == pytest.approx(0.02, abs=1e-6)
               for a, b in zip(stamps, stamps[1:], strict=False))
    message = first_two_seconds[-1]
    assert list(message.name) == ['pan_joint', 'tilt_joint']
    assert len(message.position) == len(message.velocity) == len(message.effort) == 2


def on_grid(stamp: float, period: float) -> bool:
    return abs(stamp / period - round(stamp / period)) < 1e-6


def test_clock_stamps_are_on_the_10_ms_grid_and_the_newest_one_always_leaves(pan_tilt):
    # At factor 0 the node runs ~100x real time: /clock is capped at one
    # message per wall millisecond (bursts of 20), but every stamp is a 10 ms
    # multiple and the newest one reached leaves at the end of each batch.
    clock = pan_tilt.collect(Clock, '/clock', PROBE_QUEUE)
    pan_tilt.wait_for_subscribers('/clock')
    start, started = pan_tilt.simulation.time, time.monotonic()
    pan_tilt.run_until_sim_time(start + 2.0)
    wall_ms = (time.monotonic() - started) * 1e3
    pan_tilt.drain()
    times = [stamp_s(m) for m in clock]
    assert times and all(on_grid(t, 0.01) for t in times)
    assert times == sorted(set(times))
    newest_grid = math.floor(pan_tilt.simulation.time / 0.01 + 1e-6) * 0.01
    assert times[-1] == pytest.approx(newest_grid, abs=1e-9)
    assert len(times) <= wall_ms + 20 + wall_ms / 4  # one per wall ms, a burst, one per batch


def test_far_above_real_time_clock_averages_at_most_one_message_per_wall_ms(pan_tilt):
    # The newest stamp leaves at the end of every batch even without a token,
    # but it borrows one: over many batches the cap holds, a burst aside.
    pan_tilt.collect(Clock, '/clock', PROBE_QUEUE)
    pan_tilt.wait_for_subscribers('/clock')
    sent = record_publications(pan_tilt.node)
    start, started = pan_tilt.simulation.time, time.monotonic()
    pan_tilt.run_until_sim_time(start + 30.0)
    wall_ms = (time.monotonic() - started) * 1e3
    clocks = sum(kind == 'clock' for kind, _ in sent)
    # 30 s of sim time reaches 3000 stamps (one per 10 ms); the cap lets about one per wall
    # ms through.  On a loaded machine the run may take longer than 3000 ms: then the cap
    # binds less, and the floor is half of what was reachable instead.
    assert clocks > min(3000, wall_ms) / 2
    assert clocks <= wall_ms + CLOCK_BURST + 1


def test_with_a_3_ms_step_clock_comes_every_9_ms_and_says_so_once(capfd):
    with sim_node(time_step=0.003) as sim:
        clock = sim.collect(Clock, '/clock', PROBE_QUEUE)
        sim.run_for(0.5)
    times = [stamp_s(m) for m in clock]
    assert times and all(on_grid(t, 0.009) for t in times)
    assert capfd.readouterr().err.count('/clock every 3 steps (9 ms of sim time)') == 1


def test_an_effort_controller_meets_damping_and_friction(tmp_path):
    config = tmp_path / 'effort.yaml'
    config.write_text(
        'ex_urdf_pan_tilt:\n'
        '  joint_state_controller: {type: joint_state_controller/JointStateController,'
        ' publish_rate: 50}\n'
        '  pan_effort: {type: effort_controllers/JointEffortController, joint: pan_joint}\n')
    with sim_node(controllers_file=str(config)) as pan_tilt:
        assert pan_tilt.node.topic('pan_effort', 'command') == f'{NS}/pan_effort/command'
        pan_tilt.command('pan_effort', Float64(data=50.0))
        pan_tilt.run_for(1.0)
        # Steady speed (50 - 1) / 50 = 0.98 rad/s.
        assert pan_tilt.states[-1].velocity[0] == pytest.approx(0.98, abs=0.01)
        assert pan_tilt.states[-1].effort[0] == pytest.approx(50.0)


def test_the_original_examples_files_drive_the_same_topics(original_examples):
    with sim_node(robot_description_file=str(original_examples / 'pan_tilt.xacro'),
                  controllers_file=str(original_examples / 'pan_tilt_control.yaml')) as pan_tilt:
        topics = pan_tilt.topics_once_seen(PAN_COMMAND, f'{NS}/joint_states')
        assert topics[PAN_COMMAND] == ['std_msgs/msg/Float64']
        assert topics[f'{NS}/joint_states'] == ['sensor_msgs/msg/JointState']
        pan_tilt.command(PAN, Float64(data=-0.3))
        pan_tilt.run_for(5.0)
        assert pan_tilt.position('pan_joint') == pytest.approx(-0.3, abs=SETTLE_TOLERANCE)


def test_integers_are_accepted_for_double_parameters():
    with sim_node(real_time_factor=0, time_step=0.002) as sim:
        assert sim.node.settings.real_time_factor == 0.0
        assert isinstance(sim.node.settings.real_time_factor, float)
        assert sim.node.settings.time_step == 0.002


def test_paused_holds_sim_time_while_topics_stay_alive():
    with sim_node(paused=True) as pan_tilt:
        pan_tilt.command(PAN, Float64(data=0.5))  # accepted while paused
        pan_tilt.spin_for(0.3)
        assert pan_tilt.simulation.time == 0.0
        pan_tilt.node.set_paused(False)
        pan_tilt.run_for(8.0)
        assert pan_tilt.position('pan_joint') == pytest.approx(0.5, abs=SETTLE_TOLERANCE)


def test_xacro_args_reach_xacro(repo_root, tmp_path):
    source = (repo_root / 'urdf' / 'pan_tilt.xacro').read_text()
    path = tmp_path / 'pan_tilt_arg.xacro'
    path.write_text(source.replace(
        '<xacro:property name="base_link_length" value="0.01"/>',
        '<xacro:arg name="pan_limit" default="3.14"/>'
        '<xacro:property name="base_link_length" value="0.01"/>').replace(
        'lower="-3.14" upper="3.14"', 'lower="-3.14" upper="$(arg pan_limit)"'))
    with sim_node(robot_description_file=str(path), xacro_args=['pan_limit:=0.25']) as sim:
        assert sim.simulation.description.model.joint('pan_joint').upper == 0.25


def test_a_joint_starting_at_a_limit_is_logged_once_at_info(capfd):
    # Read from the console, not from /rosout: a late /rosout subscriber depends on
    # DDS keeping the node's start-up messages, which it did not always do under load.
    with sim_node() as sim:
        sim.run_until_sim_time(0.1)
    lines = [line for line in capfd.readouterr().err.splitlines() if 'starts at' in line]
    assert len(lines) == 1
    assert lines[0].startswith('[INFO]') and '[sim_node]:' in lines[0]
    assert "tilt_joint' starts at -1.5708" in lines[0]


def test_the_same_commands_from_a_reset_give_the_same_joint_states_to_the_last_bit(pan_tilt):
    runs = []
    for _ in range(2):
        pan_tilt.node.set_paused(True)
        pan_tilt.node.reset(reset_time=True)
        pan_tilt.drain()
        first = len(pan_tilt.states)
        pan_tilt.command(PAN, Float64(data=0.7))  # taken while held: acts from t = 0
        pan_tilt.command(TILT, Float64(data=-2.2))
        pan_tilt.node.set_paused(False)
        pan_tilt.run_for(3.0)
        runs.append([(stamp_s(m), tuple(m.position), tuple(m.velocity), tuple(m.effort))
                     for m in pan_tilt.states[first:] if stamp_s(m) <= 3.0])
    assert len(runs[0]) == 151  # 0 .. 3 s at 50 Hz
    assert runs[0] == runs[1]


# --- steps run in chunks that end only where something watched is due -------------------

def record_chunks(node) -> list[int]:
    """Record the size of every chunk of steps the node hands the physics."""
    chunks: list[int] = []
    advance = node.simulation.advance

    def recording(steps: int) -> None:
        chunks.append(steps)
        advance(steps)

    node.simulation.advance = recording
    return chunks


def test_with_nobody_watching_clock_tf_or_camera_a_batch_is_one_chunk():
    # joint_states is watched, but the joint-state broadcaster runs inside the
    # physics step: it needs no chunk boundary.
    with sim_node(paused=True) as pan_tilt:
        chunks = record_chunks(pan_tilt.node)
        pan_tilt.node.step(500)
        assert chunks == [500]


def test_a_clock_reader_ends_chunks_at_the_stamps_while_tokens_last():
    with sim_node(paused=True) as pan_tilt:
        pan_tilt.collect(Clock, '/clock', PROBE_QUEUE)
        pan_tilt.wait_for_subscribers('/clock')
        chunks = record_chunks(pan_tilt.node)
        pan_tilt.node.step(100)  # a burst of 20 tokens covers these 10 stamps
        assert chunks == [10] * 10


def test_a_tf_reader_ends_chunks_at_the_tf_period():
    tf2_msgs = pytest.importorskip('tf2_msgs.msg')
    with sim_node(paused=True) as pan_tilt:
        pan_tilt.collect(tf2_msgs.TFMessage, '/tf')
        pan_tilt.wait_for_subscribers('/tf')
        chunks = record_chunks(pan_tilt.node)
        pan_tilt.node.step(101)  # /tf was due at step 0 (published at start)
        assert chunks == [20, 20, 20, 20, 20, 1]


def record_publications(node) -> list[tuple[str, float]]:
    """Record (topic kind, stamp) of every /clock and JointState the node publishes."""
    sent: list[tuple[str, float]] = []
    clock = node.clock_publisher.publisher

    class Recording:
        def __init__(self, kind, publisher) -> None:
            self._kind, self._publisher = kind, publisher

        def publish(self, message) -> None:
            sent.append((self._kind, round(stamp_s(message), 9)))
            self._publisher.publish(message)

        def __getattr__(self, name):
            return getattr(self._publisher, name)

    node.clock_publisher.publisher = Recording('clock', clock)
    for _controller, _publisher, sink in node.controllers._state_sinks:
        sink._publisher = Recording('joint_states', sink._publisher)
    return sent


def test_paced_a_batch_is_one_chunk_and_its_stamps_leave_after_it_before_its_joint_states():
    # At real_time_factor 1 a 20 ms batch runs in well under a wall
    # millisecond: cutting it at the 10 ms stamps buys nothing, and the
    # messages leave back to back, /clock first.
    with sim_node(paused=True, real_time_factor=1.0) as pan_tilt:
        pan_tilt.collect(Clock, '/clock', PROBE_QUEUE)
        pan_tilt.wait_for_subscribers('/clock')
        start = pan_tilt.node.simulation.steps
        assert start % 20 == 0
        chunks = record_chunks(pan_tilt.node)
        sent = record_publications(pan_tilt.node)
        pan_tilt.node.step(20)
        assert chunks == [20]
        t = start * 0.001
        # The broadcaster (50 Hz) samples the state at the batch's first step.
        assert sent == [('clock', round(t + 0.01, 9)), ('clock', round(t + 0.02, 9)),
                        ('joint_states', round(t, 9))]


@pytest.mark.parametrize('factor', [1e308, 1001.0, math.inf, -1.0])
def test_a_real_time_factor_pacing_cannot_follow_is_refused_and_the_node_runs_on(factor):
    with sim_node(real_time_factor=0.0) as harness:
        result, = harness.set_parameters(real_time_factor=factor)
        assert not result.successful
        assert "'real_time_factor'" in result.reason
        assert harness.node.real_time_factor == 0.0
        before = harness.simulation.time
        assert harness.spin_until(lambda: harness.simulation.time > before + 0.05), \
            'the node stopped stepping'
        accepted, = harness.set_parameters(real_time_factor=1000.0)
        assert accepted.successful, accepted.reason
        paced = harness.simulation.time
        assert harness.spin_until(lambda: harness.simulation.time > paced + 0.05)


def test_the_solver_settings_are_parameters_checked_when_set_and_applied_from_the_next_step():
    with sim_node(real_time_factor=0.0, solver_iterations=20, contact_slop=0) as harness:
        physics = harness.simulation.physics
        assert (physics.settings.solver_iterations, physics.settings.contact_slop) == (20, 0.0)
        assert physics.settings.erp == 0.2 and physics.settings.split_impulse is True
        refused, = harness.set_parameters(contact_erp=2.0)
        assert not refused.successful
        assert refused.reason == "parameter 'contact_erp' must be from 0 to 1 (a share of " \
                                 'the error per step), got 2.0'
        assert physics.settings.contact_erp == 0.08
        accepted, = harness.set_parameters(solver_iterations=8)
        assert accepted.successful, accepted.reason
        assert physics.settings.solver_iterations == 8
        assert pybullet.getPhysicsEngineParameters(
            physicsClientId=physics._client)['numSolverIterations'] == 8
