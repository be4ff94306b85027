"""bench: how fast sim_node runs, printed as one JSON object.

``ros2 run pan_tilt_sim bench`` (or ``python -m pan_tilt_sim.tools.bench``)
runs the pan/tilt example and prints, measured in one run so that
ratios hold on a noisy machine (CPU figures come from the processes' and
threads' own CPU clocks, which other work on the machine distorts far less
than wall time) (see the design notes).

Design notes: docs/design/tools.md#benchpy.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import importlib.util
import itertools
import json
import math
import os
import pathlib
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence

import rclpy
import yaml
from control_msgs.action import FollowJointTrajectory
from rclpy.action import ActionClient
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from pan_tilt_sim.controllers import create_controller
from pan_tilt_sim.controllers.commands.joint_position_controller import JointPositionController
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.controller_config import load_controllers_config
from pan_tilt_sim.model.description import load_description
from pan_tilt_sim.ros.ros_interfaces import seconds
from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.sim.engine import Simulation, make_simulation
from pan_tilt_sim.sim.physics import Physics
from pan_tilt_sim.sim.profiling import pybullet_step_cost
from pan_tilt_sim.tools import bench_scenes
from pan_tilt_sim.tools.sensor_cost import sensor_costs

DEFAULT_TIME_STEP = 0.001  # s, sim_node's default time_step
CHAIN_JOINTS = (2, 8, 32)
STARTUP_RUNS = 5
EXIT_FAILURE = 1
EXIT_USAGE = 2
MILLISECONDS_PER_SECOND = 1e3
PERCENT = 100.0
P99 = 98  # index of the 99th percentile among statistics.quantiles(n=100)

RATE_WINDOW_S = 0.5  # the bare stepSimulation rate is a median over windows this long
RAW_SIM_S = 20.0  # sim seconds of the node's controllers replayed for the raw figure
QUICK_RAW_SIM_S = 3.0
CLOCK_TOPIC = '/clock'
CLOCK_TYPE = 'rosgraph_msgs/msg/Clock'
JOINT_STATE_TYPE = 'sensor_msgs/msg/JointState'
SUBSCRIBER_CASES = ('no_subscriber', 'clock_subscriber', 'joint_state_subscriber')
RECORDING_CASE = 'recording'  # factor 0, no subscriber, record:=<folder>
BAG_METADATA = 'metadata.yaml'
COMMAND_PERIOD_S = 0.25  # wall seconds between alternating position commands
COMMAND_SPAN = 0.25  # targets sit this fraction of the range inside each limit
UNLIMITED_TARGET = 1.0  # rad, +- target of a joint without position limits
FIRST_MESSAGE_TIMEOUT_S = 30.0
STOP_TIMEOUT_S = 10.0
SPIN_TIMEOUT_S = 0.01
RAW_CALIBRATION_STEPS = 1000
LOG_TAIL_CHARS = 2000
# The raw rate from thread CPU and the bare wall rate normally agree within ~5 %;
# further apart than this, the run's ratios are not to be trusted (a warning says so).
RAW_AGREEMENT = 0.25
# A domain derived from the process id, when neither option nor environment gives one:
# 150..229 keeps DDS ports valid and away from the low ids people use by hand.
PID_DOMAIN_BASE = 150
PID_DOMAIN_COUNT = 80
SERVICE_CALLERS = 20  # concurrent service callers, one call in flight each
SERVICE_MAX_CALLS = 20_000  # calls at most in the service window, whatever its length
SERVICE_CALL_TIMEOUT_S = 5.0  # a call unanswered this long counts as unanswered
SIM_NODE_NAME = 'sim_node'


@dataclasses.dataclass(frozen=True)
class Plan:
    """How long each part of a run lasts (wall seconds) and how often it repeats."""

    raw_s: float
    raw_sim_s: float
    warmup_s: float
    fast_s: float
    paced_s: float
    startup_runs: int
    chain_s: float
    sensor_sim_s: float = 2.0  # sim seconds with every sensor watched
    services_s: float = 5.0  # wall seconds of service calls
    scene_s: float = 5.0  # wall seconds each case of a contact scene is measured
    scene_settle_s: float = 2.0  # sim seconds a case runs in this process before it is recorded
    scene_contact_s: float = 5.0  # sim seconds recorded: contacts, accuracy, replayed raw
    scene_lidar_s: float = 20.0  # sim seconds over which the sandbox's lidar is timed


FULL_PLAN = Plan(raw_s=3.0, raw_sim_s=RAW_SIM_S, warmup_s=1.0, fast_s=5.0, paced_s=10.0,
                 startup_runs=STARTUP_RUNS, chain_s=3.0)
QUICK_PLAN = Plan(raw_s=0.3, raw_sim_s=QUICK_RAW_SIM_S, warmup_s=0.2, fast_s=0.6, paced_s=0.6,
                  startup_runs=1, chain_s=0.4, sensor_sim_s=0.3, services_s=0.5,
                  scene_s=0.4, scene_settle_s=0.3, scene_contact_s=0.2, scene_lidar_s=0.6)


class BenchError(RuntimeError):
    """The benchmark could not run (sim_node died, no JointState arrived...)."""


@dataclasses.dataclass(frozen=True)
class Model:
    """The files of one robot, and the topics the bench talks to."""

    description_file: pathlib.Path
    controllers_file: pathlib.Path | None  # None: the robot has no controller YAML
    joint_states_topic: str
    # Command topic -> the two position targets it alternates between.
    commands: dict[str, tuple[float, float]]
    robot: str = ''  # the robot's entity name (its URDF name)
    # sim_node parameters beyond the two files (name -> value as on the command line).
    parameters: dict[str, str] = dataclasses.field(default_factory=dict)
    # Topic -> a message sent unchanged every COMMAND_PERIOD_S.
    messages: dict[str, object] = dataclasses.field(default_factory=dict)
    # Action name -> a FollowJointTrajectory goal, sent once the node runs.
    goals: dict[str, object] = dataclasses.field(default_factory=dict)


def load_model(description_file: pathlib.Path, controllers_file: pathlib.Path) -> Model:
    """Find the JointState and position command topics of a description + controllers pair."""
    description = load_description(description_file)
    config = load_controllers_config(controllers_file)
    namespace = naming.resolve_robot_namespace(
        naming.ROOT, '', config.namespace, description.plugin_namespace)
    commands = {}
    for spec in config.controllers:
        controller = create_controller(spec.name, spec.type, spec.params, str(config.source))
        if isinstance(controller, JointPositionController):
            joint = description.model.joint(controller.joint_names[0])
            topic = naming.join(namespace, controller.name, controller.command_topic)
            commands[topic] = position_targets(joint.lower, joint.upper,
                                               joint.has_position_limits)
    return Model(description_file, controllers_file,
                 naming.join(namespace, 'joint_states'), commands, description.name)


def position_targets(lower: float, upper: float, limited: bool) -> tuple[float, float]:
    """Return two targets well inside [lower, upper], so that the joint keeps moving."""
    if not limited or not (math.isfinite(lower) and math.isfinite(upper)):
        return (-UNLIMITED_TARGET, UNLIMITED_TARGET)
    margin = COMMAND_SPAN * (upper - lower)
    return (lower + margin, upper - margin)


def chain_files(joints: int, folder: pathlib.Path) -> tuple[pathlib.Path, pathlib.Path]:
    """Write a serial chain of ``joints`` revolute joints and its controllers into ``folder``.

    Links are 5 cm cylinders of 1 kg (inertia 0.1 kg m^2, as stiff to simulate as
    the pan/tilt example's links); axes alternate between z and y; every joint has a
    position controller, and a JointState controller publishes at 50 Hz.
    """
    links = ['<link name="link_0">' + _CHAIN_LINK_BODY + '</link>']
    for index in range(1, joints + 1):
        axis = '0 0 1' if index % 2 else '0 1 0'
        links.append(
            f'<joint name="joint_{index}" type="revolute">'
            f'<parent link="link_{index - 1}"/><child link="link_{index}"/>'
            f'<origin xyz="0 0 0.05"/><axis xyz="{axis}"/>'
            '<limit effort="100" velocity="1.0" lower="-3.14" upper="3.14"/>'
            '<dynamics damping="1.0" friction="0.0"/></joint>'
            f'<link name="link_{index}">{_CHAIN_LINK_BODY}</link>')
    urdf = folder / f'chain_{joints}.urdf'
    urdf.write_text(f'<?xml version="1.0"?><robot name="chain_{joints}">'
                    + ''.join(links) + '</robot>\n', encoding='utf-8')
    lines = [f'chain_{joints}:',
             '  joint_state_controller:',
             '    type: joint_state_controller/JointStateController',
             '    publish_rate: 50']
    for index in range(1, joints + 1):
        lines += [f'  joint_{index}_position_controller:',
                  '    type: position_controllers/JointPositionController',
                  f'    joint: joint_{index}',
                  '    pid: {p: 100.0, i: 0.01, d: 10.0}']
    controllers = folder / f'chain_{joints}.yaml'
    controllers.write_text('\n'.join(lines) + '\n', encoding='utf-8')
    return urdf, controllers


_CHAIN_LINK_BODY = (
    '<visual><geometry><cylinder length="0.05" radius="0.01"/></geometry></visual>'
    '<collision><geometry><cylinder length="0.05" radius="0.01"/></geometry></collision>'
    '<inertial><mass value="1.0"/>'
    '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>')


def slope(samples: Sequence[tuple[float, float]]) -> float:
    """Least-squares slope of y against x."""
    if len(samples) < 2:
        raise BenchError('too few samples to fit a slope')
    mean_x = statistics.fmean(x for x, _ in samples)
    mean_y = statistics.fmean(y for _, y in samples)
    num = sum((x - mean_x) * (y - mean_y) for x, y in samples)
    den = sum((x - mean_x) ** 2 for x, _ in samples)
    if den <= 0.0:
        raise BenchError('samples span no time')
    return num / den


def bare_steps_per_s(description_file: pathlib.Path, time_step: float,
                     duration: float) -> float:
    """Time bare ``stepSimulation()`` calls in wall time; median over windows of RATE_WINDOW_S."""
    with Physics(load_description(description_file), time_step) as physics:
        step = physics.bare_stepper()
        started = time.perf_counter()
        for _ in range(RAW_CALIBRATION_STEPS):
            step()
        per_window = max(1, round(
            RAW_CALIBRATION_STEPS * RATE_WINDOW_S / (time.perf_counter() - started)))
        rates = []
        deadline = time.perf_counter() + duration
        while not rates or time.perf_counter() < deadline:
            started = time.perf_counter()
            for _ in range(per_window):
                step()
            rates.append(per_window / (time.perf_counter() - started))
    return statistics.median(rates)


def recorded_efforts(simulation: Simulation, model: Model, sim_seconds: float) -> list:
    """Run the engine with the bench's alternating commands; return the efforts of each step."""
    controllers = {controller.name: controller for controller in simulation.command_controllers()}
    targets = [(controllers[topic.rsplit('/', 2)[-2]], pair)
               for topic, pair in model.commands.items()]
    handles = list(simulation.handles.values())
    steps_per_command = max(1, round(COMMAND_PERIOD_S / simulation.time_step))
    efforts = []
    for step in range(round(sim_seconds / simulation.time_step)):
        if step % steps_per_command == 0:
            which = (step // steps_per_command) % 2
            for controller, pair in targets:
                controller.set_command(pair[which])
        simulation.advance(1)
        efforts.append([handle.effort for handle in handles])
    return efforts


def raw_figures(model: Model, time_step: float, sim_seconds: float,
                wall_seconds: float) -> dict[str, float | bool]:
    """PyBullet alone on the node's physics: stepSimulation's CPU cost, the calls', bare wall."""
    with make_simulation(model.description_file, model.controllers_file,
                         time_step) as simulation:
        efforts = recorded_efforts(simulation, model, sim_seconds)
        with Physics(simulation.description, time_step) as replay:
            step_us, calls_us = pybullet_step_cost(replay, efforts)
            compiled = replay.compiled_step
    return {
        'step_us_cpu': step_us,
        'steps_per_s': 1e6 / step_us,
        'calls_us_cpu': calls_us,
        'compiled_step': compiled,
        'wall_steps_per_s': bare_steps_per_s(model.description_file, time_step, wall_seconds),
    }


def raw_rates_disagree(raw: dict[str, float]) -> str | None:
    """Say so if the raw rates from thread CPU and from wall time are more than RAW_AGREEMENT apart.

    Both time the same ``stepSimulation``, one after the other; on a shared machine
    a burst of neighbours' load (or the hypervisor's CPU accounting) can
    inflate one of them, and every ``ratio_to_raw`` of the run with it.
    """
    cpu, wall = raw['steps_per_s'], raw['wall_steps_per_s']
    gap = abs(cpu - wall) / max(cpu, wall)
    if gap <= RAW_AGREEMENT:
        return None
    return (f'raw steps/s from thread CPU ({cpu:,.0f}) and from wall time ({wall:,.0f}) are '
            f'{gap:.0%} apart: the machine was busy or its CPU accounting drifted, so this '
            "run's ratio_to_raw figures are not to be trusted")


def process_cpu_clock(pid: int) -> int:
    """Return the clock id of process ``pid``'s CPU-time clock on Linux (``clock_getcpuclockid``).

    The kernel's encoding, ``MAKE_PROCESS_CPUCLOCK(pid, CPUCLOCK_SCHED)``:
    Python has no ``clock_getcpuclockid``.
    """
    return (~pid << 3) | 2


def cpu_seconds(pid: int) -> float:
    """CPU time (user + system, all threads, ended ones too) a process has used so far.

    From the process's CPU-time clock, to the nanosecond, where the system
    gives it (Linux); else from psutil or ``/proc``, which count whole clock
    ticks (a tick is a sizeable share of the bench's 10 s factor-1 window).
    """
    with contextlib.suppress(OSError):
        return time.clock_gettime(process_cpu_clock(pid))
    try:
        import psutil
    except ImportError:
        fields = pathlib.Path(f'/proc/{pid}/stat').read_text().rpartition(')')[2].split()
        # utime and stime are fields 14 and 15 of proc(5); the split starts at field 3.
        return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')
    times = psutil.Process(pid).cpu_times()
    return times.user + times.system


def thread_cpu_seconds(pid: int) -> dict[int, float]:
    """CPU time (user + system) each of the process's threads has used so far, by thread id."""
    try:
        import psutil
    except ImportError:
        times = {}
        for task in pathlib.Path(f'/proc/{pid}/task').iterdir():
            fields = (task / 'stat').read_text().rpartition(')')[2].split()
            times[int(task.name)] = (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')
        return times
    return {thread.id: thread.user_time + thread.system_time
            for thread in psutil.Process(pid).threads()}


def busiest_thread_delta(before: dict[int, float], after: dict[int, float]) -> float:
    """Return the most CPU seconds one thread used between two ``thread_cpu_seconds`` readings.

    Per thread, not the busiest thread's total at each end: the thread with
    the most CPU so far may be the one that did the start-up, not the physics.
    """
    return max(seconds - before.get(thread, 0.0) for thread, seconds in after.items())


def interrupt(process: subprocess.Popen) -> None:
    """Ctrl-C ``process`` and wait for it; kill it if it does not stop in time."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


class ChildProcess:
    """A program of the bench's in a child process; its output goes to a log file."""

    def __init__(self, name: str, command: list[str], env: dict[str, str],
                 log_file: pathlib.Path) -> None:
        self.name = name
        self._log_file = log_file
        with open(log_file, 'wb') as log:
            self.started = time.monotonic()
            self.process = subprocess.Popen(
                command, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                env=env)

    def check_alive(self) -> None:
        """Raise BenchError, with the end of its log, if the program has exited."""
        code = self.process.poll()
        if code is not None:
            log = self._log_file.read_text(errors='replace')[-LOG_TAIL_CHARS:]
            raise BenchError(f'{self.name} exited with code {code}:\n{log}')

    def cpu_seconds(self) -> float:
        """CPU seconds the program has used so far."""
        return cpu_seconds(self.process.pid)

    def stop(self) -> None:
        """Ctrl-C the program and wait for it; kill it if it does not stop."""
        interrupt(self.process)


def module_command(module: str, *args: str) -> list[str]:
    """Return the command that runs ``python -m module args`` on the installed package.

    ``-P`` keeps the working directory off ``sys.path``: run from a source
    checkout, ``-m`` would otherwise import ``./pan_tilt_sim`` -- not the code
    that ``ros2 run`` starts, and, where bytecode is not written
    (``PYTHONDONTWRITEBYTECODE``), compiled afresh at every start: ~0.1 s on
    every start-up measured.
    """
    return [sys.executable, '-P', '-m', module, *args]


class Listener(ChildProcess):
    """A subscriber in its own process (``pan_tilt_sim.tools.listener``)."""

    def __init__(self, topic: str, type_name: str, env: dict[str, str],
                 log_file: pathlib.Path) -> None:
        super().__init__('listener', module_command('pan_tilt_sim.tools.listener', topic,
                                                    type_name), env, log_file)


class BarePublisher(ChildProcess):
    """A bare rclpy JointState publisher (``pan_tilt_sim.tools.bare_publisher``)."""

    def __init__(self, topic: str, env: dict[str, str], log_file: pathlib.Path) -> None:
        super().__init__('bare_publisher', module_command(
            'pan_tilt_sim.tools.bare_publisher', topic), env, log_file)


class NodeProcess(ChildProcess):
    """sim_node in a child process."""

    def __init__(self, model: Model, parameters: dict[str, str], env: dict[str, str],
                 log_file: pathlib.Path) -> None:
        arguments = {'robot_description_file': str(model.description_file),
                     **({} if model.controllers_file is None
                        else {'controllers_file': str(model.controllers_file)}),
                     **model.parameters, **parameters}
        command = module_command('pan_tilt_sim', '--ros-args')
        for name, value in arguments.items():
            command += ['-p', f'{name}:={value}']
        super().__init__('sim_node', command, env, log_file)

    def thread_cpu_seconds(self) -> dict[int, float]:
        """CPU seconds each of the node's threads has used so far."""
        return thread_cpu_seconds(self.process.pid)


class Probe:
    """The bench's own ROS node: listens to JointState and sends position commands."""

    # Probes come and go within one process (a fresh one per start-up run);
    # distinct names keep rcl from warning about a second /rosout publisher.
    _created = itertools.count()

    def __init__(self, domain_id: int) -> None:
        self._context = Context()
        rclpy.init(args=[], context=self._context, domain_id=domain_id)
        self.node = rclpy.create_node(f'sim_bench_probe_{next(Probe._created)}',
                                      context=self._context)
        self.executor = SingleThreadedExecutor(context=self._context)
        self.executor.add_node(self.node)
        self._publishers: dict[str, object] = {}

    def close(self) -> None:
        """Destroy the node and shut the context down."""
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self._context)

    @contextlib.contextmanager
    def joint_states(self, topic: str, depth: int,
                     on_message: Callable[[float, float], None]) -> Iterator[None]:
        """Call ``on_message(arrival monotonic s, stamp s)`` for JointStates while open."""
        def callback(message: JointState) -> None:
            on_message(time.monotonic(), seconds(message.header.stamp))

        subscription = self.node.create_subscription(
            JointState, topic, callback, QoSProfile(depth=depth))
        try:
            yield
        finally:
            self.node.destroy_subscription(subscription)

    def spin_once(self, timeout: float) -> None:
        """Run at most one callback, waiting up to ``timeout`` s for one."""
        self.executor.spin_once(timeout_sec=timeout)

    def command(self, topic: str, value: float) -> None:
        """Publish a position command."""
        self.publish(topic, Float64(data=value))

    def publish(self, topic: str, message: object) -> None:
        """Publish ``message`` on ``topic`` (a publisher of its type, made on first use)."""
        publisher = self._publishers.get(topic)
        if publisher is None:
            publisher = self.node.create_publisher(type(message), topic, QoSProfile(depth=1))
            self._publishers[topic] = publisher
        publisher.publish(message)


class Bench:
    """One run of every measurement, sharing a probe, a ROS domain and a log folder."""

    def __init__(self, probe: Probe, domain_id: int, env: dict[str, str],
                 folder: pathlib.Path, time_step: float, plan: Plan,
                 log: Callable[[str], None]) -> None:
        self.probe = probe
        self.domain_id = domain_id
        self.env = env
        self.folder = folder
        self.time_step = time_step
        self.plan = plan
        self.log = log
        self._node_count = 0

    @contextlib.contextmanager
    def node(self, model: Model, real_time_factor: float | None,
             record: bool = False) -> Iterator[NodeProcess]:
        """Run sim_node on ``model`` for the duration of the block (recording, if asked).

        A recording node must leave a finished bag: BenchError otherwise.
        """
        parameters = {'time_step': repr(self.step_of(model))}
        if real_time_factor is not None:
            parameters['real_time_factor'] = repr(float(real_time_factor))
        self._node_count += 1
        bag = self.folder / f'bag_{self._node_count}'
        if record:
            parameters['record'] = str(bag)
        process = NodeProcess(model, parameters, self.env,
                              self.folder / f'sim_node_{self._node_count}.log')
        try:
            yield process
        finally:
            process.stop()
        if record and not (bag / BAG_METADATA).is_file():
            raise BenchError(f'the recording node left no {bag / BAG_METADATA}')

    def step_of(self, model: Model) -> float:
        """Return the time step ``model`` runs at: its own ``time_step``, else the bench's."""
        return float(model.parameters.get('time_step', self.time_step))

    def spin_until(self, node: ChildProcess, done: Callable[[], bool], timeout: float,
                   what: str, probe: Probe | None = None) -> None:
        """Spin the probe until ``done()``; BenchError if the node dies or time runs out."""
        probe = probe or self.probe
        deadline = time.monotonic() + timeout
        while not done():
            node.check_alive()
            if time.monotonic() > deadline:
                raise BenchError(f'no {what} within {timeout} s')
            probe.spin_once(SPIN_TIMEOUT_S)

    @contextlib.contextmanager
    def bare_publisher(self, topic: str) -> Iterator[BarePublisher]:
        """Run a bare rclpy JointState publisher on ``topic`` for the duration of the block."""
        self._node_count += 1
        publisher = BarePublisher(topic, self.env,
                                  self.folder / f'bare_publisher_{self._node_count}.log')
        try:
            yield publisher
        finally:
            publisher.stop()

    @contextlib.contextmanager
    def listener(self, topic: str, type_name: str) -> Iterator[Listener]:
        """Run a subscriber process on ``topic`` for the duration of the block."""
        self._node_count += 1
        listener = Listener(topic, type_name, self.env,
                            self.folder / f'listener_{self._node_count}.log')
        try:
            yield listener
        finally:
            listener.stop()

    def joint_state_sample(self, node: NodeProcess, model: Model) -> tuple[float, float]:
        """Subscribe just long enough for one JointState; return (arrival s, sim stamp s)."""
        got: list[tuple[float, float]] = []
        with self.probe.joint_states(model.joint_states_topic, 1,
                                     lambda wall, sim: got.append((wall, sim))):
            self.spin_until(node, lambda: bool(got), FIRST_MESSAGE_TIMEOUT_S,
                            f'JointState on {model.joint_states_topic}')
        return got[0]

    def fast(self, model: Model, duration: float, case: str = SUBSCRIBER_CASES[0],
             watched: tuple[str, str] | None = None) -> dict[str, float]:
        """Measure sim_node at factor 0 with the subscriber of ``case`` in its own process.

        ``watched``: (topic, type) read by a subscriber process instead.
        """
        with contextlib.ExitStack() as running:
            node = running.enter_context(self.node(model, 0.0, record=case == RECORDING_CASE))
            listener = None
            if watched is not None:
                listener = running.enter_context(self.listener(*watched))
            elif case == 'clock_subscriber':
                listener = running.enter_context(self.listener(CLOCK_TOPIC, CLOCK_TYPE))
            elif case == 'joint_state_subscriber':
                listener = running.enter_context(
                    self.listener(model.joint_states_topic, JOINT_STATE_TYPE))
            commander = Commander(self.probe, model)
            self.joint_state_sample(node, model)  # it runs
            for client in self._send_goals(node, model.goals):
                running.callback(client.destroy)
            self._wait(node, commander, self.plan.warmup_s)
            wall_start, sim_start = self.joint_state_sample(node, model)
            node_threads = node.thread_cpu_seconds()
            listener_cpu = listener.cpu_seconds() if listener else 0.0
            self._wait(node, commander, duration)
            wall_end, sim_end = self.joint_state_sample(node, model)
            node_cpu = busiest_thread_delta(node_threads, node.thread_cpu_seconds())
            listener_cpu = (listener.cpu_seconds() - listener_cpu) if listener else 0.0
        steps = (sim_end - sim_start) / self.step_of(model)
        if steps <= 0 or wall_end <= wall_start:
            raise BenchError(f'sim time did not advance at real_time_factor 0 ({case})')
        figures = {'steps_per_s': steps / (wall_end - wall_start),
                   'node_cpu_us_per_step': node_cpu / steps * 1e6}
        if listener is not None:
            figures['subscriber_cpu_percent'] = listener_cpu / (wall_end - wall_start) * PERCENT
        return figures

    def _send_goals(self, node: NodeProcess, goals: dict[str, object]) -> list[ActionClient]:
        """Send each FollowJointTrajectory goal; return the clients once all are accepted."""
        clients = []
        for action, goal in goals.items():
            client = ActionClient(self.probe.node, FollowJointTrajectory, action)
            clients.append(client)
            self.spin_until(node, client.server_is_ready, FIRST_MESSAGE_TIMEOUT_S,
                            f'action server {action}')
            sent = client.send_goal_async(goal)
            self.spin_until(node, sent.done, FIRST_MESSAGE_TIMEOUT_S,
                            f'answer to the goal on {action}')
            if not sent.result().accepted:
                raise BenchError(f'the goal on {action} was rejected')
        return clients

    def _wait(self, node: NodeProcess, commander: Commander, seconds: float) -> None:
        """Let the node run for ``seconds`` of wall time, sending the commands when due."""
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            node.check_alive()
            commander.send_when_due()
            time.sleep(min(COMMAND_PERIOD_S / 5, max(0.0, deadline - time.monotonic())))

    def paced(self, model: Model) -> dict[str, float]:
        """Measure CPU shares, rtf error and JointState inter-arrival at real_time_factor 1.

        Two windows on one node: first with only the /clock subscriber (the
        probe takes a JointState to know the node runs, then leaves the
        topic), then with the probe's JointState subscription as well.
        """
        samples: list[tuple[float, float]] = []

        def on_joint_state(wall: float, sim: float) -> None:
            samples.append((wall, sim))

        topic = model.joint_states_topic
        with self.node(model, 1.0) as node, self.listener(CLOCK_TOPIC, CLOCK_TYPE) as clock:
            commander = Commander(self.probe, model)
            with self.probe.joint_states(topic, 10, on_joint_state):
                self.spin_until(node, lambda: bool(samples), FIRST_MESSAGE_TIMEOUT_S,
                                f'JointState on {topic}')
            cpu, clock_cpu = self._paced_cpu(node, clock, commander)
            with self.probe.joint_states(topic, 10, on_joint_state):
                cpu_with_joint_states, _ = self._paced_cpu(node, clock, commander, samples)
        if len(samples) < 3:
            raise BenchError('too few JointState messages at real_time_factor 1')
        gaps = [later[0] - earlier[0] for earlier, later in zip(samples, samples[1:], strict=False)]
        return {
            'rtf_error': abs(slope(samples) - 1.0),
            'joint_states_p50_ms': statistics.median(gaps) * MILLISECONDS_PER_SECOND,
            'joint_states_p99_ms': percentile_99(gaps) * MILLISECONDS_PER_SECOND,
            'cpu_percent': cpu * PERCENT,
            'cpu_percent_with_joint_states': cpu_with_joint_states * PERCENT,
            'clock_subscriber_cpu_percent': clock_cpu * PERCENT,
        }

    def paced_recording(self, model: Model) -> float:
        """Return the node's CPU share at real_time_factor 1 while it records the run.

        As ``cpu_percent`` of :meth:`paced`: a /clock subscriber, nobody reading JointState.
        """
        samples: list[tuple[float, float]] = []
        topic = model.joint_states_topic
        with (self.node(model, 1.0, record=True) as node,
              self.listener(CLOCK_TOPIC, CLOCK_TYPE) as clock):
            commander = Commander(self.probe, model)
            with self.probe.joint_states(topic, 10, lambda wall, sim: samples.append(sim)):
                self.spin_until(node, lambda: bool(samples), FIRST_MESSAGE_TIMEOUT_S,
                                f'JointState on {topic}')
            cpu, _ = self._paced_cpu(node, clock, commander)
        return cpu * PERCENT

    def _paced_cpu(self, node: NodeProcess, clock: Listener, commander: Commander,
                   samples: list | None = None) -> tuple[float, float]:
        """Warm up, then return the node's and the /clock listener's CPU share over a window.

        ``samples`` (JointStates being taken) is emptied at the start of each
        part, so it ends with the window's messages only.
        """
        for duration in (self.plan.warmup_s, self.plan.paced_s):
            if samples is not None:
                samples.clear()
            cpu_start, wall_start = node.cpu_seconds(), time.monotonic()
            clock_start = clock.cpu_seconds()
            while time.monotonic() < wall_start + duration:
                node.check_alive()
                commander.send_when_due()
                self.probe.spin_once(SPIN_TIMEOUT_S)
            wall = time.monotonic() - wall_start
            cpu = (node.cpu_seconds() - cpu_start) / wall
            clock_cpu = (clock.cpu_seconds() - clock_start) / wall
        return cpu, clock_cpu

    def service_round_trips(self, model: Model) -> dict[str, float] | None:
        """Round trips of SERVICE_CALLERS concurrent service callers (see the module).

        None where simulation_interfaces is not installed.
        """
        try:
            from simulation_interfaces.srv import GetEntityState, GetSimulationState
        except ImportError:
            return None
        node_probe = self.probe.node
        calls = [(GetEntityState, 'get_entity_state', GetEntityState.Request(entity=model.robot)),
                 (GetSimulationState, 'get_simulation_state', GetSimulationState.Request())]
        clients = [(node_probe.create_client(kind, f'/{SIM_NODE_NAME}/{leaf}'), request)
                   for kind, leaf, request in (calls[index % 2]
                                               for index in range(SERVICE_CALLERS))]
        try:
            with self.node(model, 1.0) as node:
                self.spin_until(node, lambda: all(c.service_is_ready() for c, _ in clients),
                                FIRST_MESSAGE_TIMEOUT_S, 'simulation_interfaces services')
                return self._call_in_a_loop(node, clients)
        finally:
            for client, _request in clients:
                node_probe.destroy_client(client)

    def _call_in_a_loop(self, node: NodeProcess, clients: list) -> dict[str, float]:
        round_trips: list[float] = []
        unanswered = 0
        in_flight: dict[int, tuple[object, float]] = {}
        started = time.monotonic()
        stop_calling = started + self.plan.services_s
        sent = 0

        def call(index: int) -> None:
            nonlocal sent
            client, request = clients[index]
            in_flight[index] = (client.call_async(request), time.monotonic())
            sent += 1

        for index in range(len(clients)):
            call(index)
        while in_flight:
            node.check_alive()
            self.probe.spin_once(SPIN_TIMEOUT_S)
            now = time.monotonic()
            for index, (future, sent_at) in list(in_flight.items()):
                if future.done():
                    round_trips.append(now - sent_at)
                elif now - sent_at > SERVICE_CALL_TIMEOUT_S:
                    unanswered += 1
                    clients[index][0].remove_pending_request(future)
                else:
                    continue
                del in_flight[index]
                if now < stop_calling and sent < SERVICE_MAX_CALLS:
                    call(index)
        wall = time.monotonic() - started
        if not round_trips:
            raise BenchError('no service call was answered')
        return {
            'p50_ms': statistics.median(round_trips) * MILLISECONDS_PER_SECOND,
            'p99_ms': percentile_99(round_trips) * MILLISECONDS_PER_SECOND,
            'answers_per_s': len(round_trips) / wall,
            'unanswered': float(unanswered),
        }

    def startup_times(self, model: Model) -> tuple[float, float]:
        """Median wall times from a process start to its first JointState here.

        Returns (sim_node, bare rclpy publisher): the second is the floor,
        what Python, rclpy and DDS discovery alone take on the machine.  The
        two alternate, run by run, so both see the same machine.  Each run
        listens with a fresh probe.  Fast DDS announces a new participant
        before it listens, so the answer to its first announcement can be
        lost; the two then meet at the older one's next announcement, every
        0.1 s in a participant's first half second and every 3 s after that
        (docs/testing.md).  A probe older than
        half a second would time that 3 s wait in some runs, not start-up;
        a fresh one bounds it to ~0.1 s steps, hence the steps in the figures.
        """
        times: dict[bool, list[float]] = {False: [], True: []}
        for _ in range(self.plan.startup_runs):
            for bare in (False, True):
                probe = Probe(self.domain_id)
                try:
                    times[bare].append(self._first_joint_state_after_start(probe, model, bare))
                finally:
                    probe.close()
        return statistics.median(times[False]), statistics.median(times[True])

    def _first_joint_state_after_start(self, probe: Probe, model: Model, bare: bool) -> float:
        first: list[float] = []
        topic = model.joint_states_topic
        with probe.joint_states(topic, 1, lambda wall, sim: first.append(wall)):
            with self.bare_publisher(topic) if bare else self.node(model, None) as process:
                self.spin_until(process, lambda: bool(first), FIRST_MESSAGE_TIMEOUT_S,
                                f'JointState on {topic}', probe)
                return first[0] - process.started


class Commander:
    """Alternates every position controller between its two targets; resends the messages."""

    def __init__(self, probe: Probe, model: Model) -> None:
        self._probe = probe
        self._commands = model.commands
        self._messages = model.messages
        self._next = time.monotonic()
        self._which = 0

    def send_when_due(self) -> None:
        """Send the next targets if COMMAND_PERIOD_S has passed since the last ones."""
        now = time.monotonic()
        if now < self._next:
            return
        for topic, targets in self._commands.items():
            self._probe.command(topic, targets[self._which])
        for topic, message in self._messages.items():
            self._probe.publish(topic, message)
        self._which = 1 - self._which
        self._next = now + COMMAND_PERIOD_S


def percentile_99(values: Sequence[float]) -> float:
    """Return the 99th percentile of ``values`` (inclusive method)."""
    if len(values) < 2:
        return values[0]
    return statistics.quantiles(values, n=100, method='inclusive')[P99]


def run_once(bench: Bench, model: Model) -> dict:
    """Measure every figure once; return them as the JSON object's fields."""
    plan = bench.plan
    bench.log("PyBullet alone on the node's physics")
    raw = raw_figures(model, bench.time_step, plan.raw_sim_s, plan.raw_s)
    problem = raw_rates_disagree(raw)
    if problem is not None:
        print(f'bench: warning: {problem}', file=sys.stderr, flush=True)
    recording = importlib.util.find_spec('mcap') is not None
    if not recording:
        bench.log('no recording figures: the mcap package is not installed (pip install mcap)')
    factor_0 = {}
    for case in SUBSCRIBER_CASES + (RECORDING_CASE,) * recording:
        bench.log(f'sim_node at real_time_factor 0, {case.replace("_", " ")}')
        figures = bench.fast(model, plan.fast_s, case)
        factor_0[case] = {**figures, 'ratio_to_raw': figures['steps_per_s'] / raw['steps_per_s']}
    bench.log('sim_node at real_time_factor 1 with a /clock subscriber')
    paced = bench.paced(model)
    if recording:
        bench.log('sim_node at real_time_factor 1 recording the run, with a /clock subscriber')
        paced['cpu_percent_recording'] = bench.paced_recording(model)
    bench.log(f'{SERVICE_CALLERS} service callers at real_time_factor 1')
    service_round_trip = bench.service_round_trips(model)
    bench.log('start-up')
    startup, startup_floor = bench.startup_times(model)
    scaling = {}
    for joints in CHAIN_JOINTS:
        bench.log(f'chain of {joints} joints at real_time_factor 0')
        urdf, controllers = chain_files(joints, bench.folder)
        chain = load_model(urdf, controllers)
        fast = bench.fast(chain, plan.chain_s)
        case = bench_scenes.SceneCase(urdf, controllers, {}, {
            topic: Float64(data=targets[1]) for topic, targets in chain.commands.items()})
        raw_step = bench_scenes.in_process_figures(
            case, bench.time_step, plan.scene_settle_s, plan.scene_contact_s)['raw_step_us']
        scaling[str(joints)] = {**fast, 'raw_step_us': raw_step,
                                'ratio_to_raw': raw_step / fast['node_cpu_us_per_step']}
    scenes = scene_figures(bench)
    bench.log('sensors, every topic watched')
    sensors = {name: figures['us_per_message'] for name, figures in sensor_costs(
        sim_seconds=plan.sensor_sim_s, domain_id=bench.domain_id).items()}
    figures = {
        'raw': raw,
        'factor_0': factor_0,
        'factor_1': paced,
        'startup_s': startup,
        'startup_floor_s': startup_floor,
        'scaling': scaling,
        'scenes': scenes,
        'sensor_us_per_message': sensors,
    }
    if service_round_trip is not None:
        figures['service_round_trip'] = service_round_trip
    return figures


def scene_figures(bench: Bench) -> dict[str, dict[str, dict[str, float]]]:
    """Measure each case of the scenes (:mod:`pan_tilt_sim.tools.bench_scenes`).

    Per case: sim_node's ``steps_per_s`` and ``node_cpu_us_per_step`` at
    real_time_factor 0 (as :meth:`Bench.fast`, nobody subscribed to anything
    but the probe's JointState samples and the case's watched topic),
    ``real_time_multiple`` (sim seconds per wall second), and, from the same
    case run in this process, ``contact_points`` per step (and
    ``box_height_m``, the grasp's box) or, for the sandbox, its lidar's
    ``lidar_us_per_scan`` and ``lidar_us_per_step`` (the scans' wall time
    spread over every step).
    """
    scenes = {'driving_base': bench_scenes.driving_base(package_share(), bench.folder),
              'grasp': bench_scenes.grasp(bench.folder),
              'ur5e_like': bench_scenes.ur5e_like(bench.folder),
              'tb3_sandbox': bench_scenes.tb3_sandbox(bench.folder)}
    figures: dict[str, dict[str, dict[str, float]]] = {}
    for scene, cases in scenes.items():
        figures[scene] = {}
        for case_name, case in cases.items():
            bench.log(f'{scene.replace("_", " ")}, {case_name.replace("_", " ")}, '
                      'at real_time_factor 0')
            model = Model(case.description_file, case.controllers_file,
                          case.joint_states_topic, {}, parameters=case.parameters,
                          messages=case.messages, goals=case.goals)
            fast = bench.fast(model, bench.plan.scene_s, watched=case.watched)
            time_step = bench.step_of(model)
            extra = bench_scenes.in_process_figures(case, time_step, bench.plan.scene_settle_s,
                                                    bench.plan.scene_contact_s)
            extra['ratio_to_raw'] = extra['raw_step_us'] / fast['node_cpu_us_per_step']
            if case.watched is not None:
                extra.update(lidar_figures(bench, case, time_step))
            figures[scene][case_name] = {
                **fast, 'real_time_multiple': fast['steps_per_s'] * time_step, **extra}
    return figures


def lidar_figures(bench: Bench, case: bench_scenes.SceneCase,
                  time_step: float) -> dict[str, float]:
    """Time ``case``'s one sensor, a lidar, in this process, its watched topic read.

    Returns ``lidar_us_per_scan`` (wall µs per LaserScan: the rays, the
    message, the publish) and ``lidar_us_per_step`` (the same spread over the
    steps of the run).
    """
    bench.log(f'its lidar, over {bench.plan.scene_lidar_s} sim s in this process')
    parameters = {name: yaml.safe_load(value) for name, value in case.parameters.items()}
    costs = sensor_costs(case.description_file, case.controllers_file or '',
                         sim_seconds=bench.plan.scene_lidar_s, domain_id=bench.domain_id,
                         parameters=parameters, watch=(case.watched[0],))
    (lidar,) = costs.values()
    steps = bench.plan.scene_lidar_s / time_step
    return {'lidar_us_per_scan': lidar['us_per_message'],
            'lidar_us_per_step': lidar['us_per_message'] * lidar['messages'] / steps}


def median_of(results: Sequence[dict]) -> dict:
    """Return the median of every figure over several runs (nested dicts key by key)."""
    merged = {}
    for key, value in results[0].items():
        if isinstance(value, dict):
            merged[key] = median_of([result[key] for result in results])
        elif isinstance(value, bool):  # a fact of the build, not a figure: true if always
            merged[key] = all(result[key] for result in results)
        else:
            merged[key] = statistics.median(result[key] for result in results)
    return merged


def rounded(figures: dict) -> dict:
    """Round figures for printing: rates (``*steps_per_s``) as integers, else 4 digits."""
    out = {}
    for key, value in figures.items():
        if isinstance(value, dict):
            out[key] = rounded(value)
        elif isinstance(value, bool):
            out[key] = value
        elif key.endswith('steps_per_s'):
            out[key] = round(value)
        else:
            out[key] = float(f'{value:.4g}')
    return out


def default_domain_id() -> int:
    """ROS_DOMAIN_ID from the environment, else one derived from this process's id."""
    value = os.environ.get('ROS_DOMAIN_ID', '')
    if value.isdigit():
        return int(value)
    return PID_DOMAIN_BASE + os.getpid() % PID_DOMAIN_COUNT


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    """Read the command line."""
    parser = argparse.ArgumentParser(
        prog='bench', description='Measure how fast sim_node runs; print one JSON object.')
    parser.add_argument('--quick', action='store_true',
                        help='a smoke run of a few seconds (all keys, timing meaningless)')
    parser.add_argument('--runs', type=int, default=1,
                        help='repeat everything N times and print the medians (default 1)')
    parser.add_argument('--time-step', type=float, default=DEFAULT_TIME_STEP,
                        help=f'physics step in s (default {DEFAULT_TIME_STEP})')
    parser.add_argument('--domain-id', type=int, default=None,
                        help='ROS domain of the nodes (default: $ROS_DOMAIN_ID, else from '
                        'the process id)')
    parser.add_argument('--description', type=pathlib.Path, default=None,
                        help='robot description (default: the pan/tilt xacro)')
    parser.add_argument('--controllers', type=pathlib.Path, default=None,
                        help='controllers YAML (default: the pan/tilt controllers)')
    parser.add_argument('--keep-logs', type=pathlib.Path, default=None,
                        help="folder for the nodes' logs and generated chains (default: "
                        'a temporary folder, removed afterwards)')
    parser.add_argument('--verbose', action='store_true',
                        help="say on stderr what runs, and each run's figures")
    parser.add_argument('--test-session', action='store_true',
                        help='measure a pytest session instead: go-to-goal tests of a user '
                        'package, each on a fresh sim fixture, in one process and under -n 2 '
                        '(see bench_test_session)')
    parser.add_argument('--tune', action='store_true',
                        help='measure tune/sweep evaluations per second on each back end '
                        'instead (local processes, a two-node Ray cluster; see tune_bench)')
    parser.add_argument('--load', action='store_true',
                        help='measure what spawned objects and world files cost to read, load '
                        'and step instead (in this process; see bench_load)')
    args = parser.parse_args(argv)
    if args.runs < 1:
        parser.error('--runs must be at least 1')
    if not 0.0 < args.time_step <= 0.1:
        parser.error('--time-step must be > 0 and <= 0.1')
    return args


def main(argv: Sequence[str] | None = None) -> None:
    """Run the benchmark and print its JSON object on stdout."""
    args = parse_args(argv)
    if args.tune:
        from pan_tilt_sim.tools import tune_bench

        tune_bench.main(['--runs', str(args.runs)] + ['--quick'] * args.quick
                        + ['--verbose'] * args.verbose)
        return
    if args.load:
        from pan_tilt_sim.tools import bench_load

        bench_load.main(['--quick'] * args.quick + ['--verbose'] * args.verbose)
        return
    domain_id = args.domain_id if args.domain_id is not None else default_domain_id()
    if args.test_session:
        from pan_tilt_sim.tools import bench_test_session

        try:
            figures = bench_test_session.measure(args.quick, domain_id)
        except RuntimeError as err:
            print(f'bench: error: {err}', file=sys.stderr)
            sys.exit(EXIT_FAILURE)
        print(json.dumps(rounded(figures)), flush=True)
        return
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    # The probe lives in this process: the same discovery range as the nodes.
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    share = package_share()

    def log(text: str) -> None:
        if args.verbose:
            print(f'bench: {text}', file=sys.stderr, flush=True)

    try:
        model = load_model(args.description or share / DEFAULT_DESCRIPTION,
                           args.controllers or share / DEFAULT_CONTROLLERS)
    except ConfigurationError as err:
        print(f'bench: error: {err}', file=sys.stderr)
        sys.exit(EXIT_USAGE)
    plan = QUICK_PLAN if args.quick else FULL_PLAN
    probe = Probe(domain_id)
    try:
        with contextlib.ExitStack() as stack:
            if args.keep_logs is not None:
                args.keep_logs.mkdir(parents=True, exist_ok=True)
                folder = args.keep_logs
            else:
                folder = pathlib.Path(stack.enter_context(
                    tempfile.TemporaryDirectory(prefix='pan_tilt_bench_')))
            bench = Bench(probe, domain_id, env, folder, args.time_step, plan, log)
            results = []
            for run in range(args.runs):
                log(f'run {run + 1} of {args.runs} (ROS domain {domain_id})')
                results.append(run_once(bench, model))
                log(f'run {run + 1}: {json.dumps(rounded(results[-1]))}')
    except BenchError as err:
        print(f'bench: error: {err}', file=sys.stderr)
        sys.exit(EXIT_FAILURE)
    finally:
        probe.close()
    print(json.dumps(rounded(median_of(results))), flush=True)


if __name__ == '__main__':
    main()
