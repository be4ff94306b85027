"""runner: what a program run says about bad ROS arguments, and how it takes stop signals.

The program-level behaviour (exit codes, one stderr line, stopping on signals)
is tested end to end in test_startup_errors.py and test_signals.py; these are
the pieces, in-process.
"""

from __future__ import annotations

import gc
import os
import signal
import subprocess
import sys

import pytest
import sim_process

from pan_tilt_sim.errors import ArgumentError, ConfigurationError
from pan_tilt_sim.ros import runner
from pan_tilt_sim.ros.runner import (
    StopRequested,
    StopSignals,
    collector_held_off,
    debug_requested,
    init_ros,
    shut_down_ros,
)


def _python_call() -> None:
    """Python runs pending signal handlers at calls like this one."""


@pytest.fixture
def default_context():
    import rclpy

    yield
    rclpy.try_shutdown()


@pytest.mark.parametrize(('argv', 'debug'), [
    (['sim_node', '--ros-args', '--log-level', 'debug'], True),
    (['sim_node', '--ros-args', '--log-level', 'DEBUG'], True),
    (['sim_node', '--ros-args', '--log-level', 'sim_node:=debug'], True),
    (['sim_node', '--ros-args', '--log-level', 'info'], False),
    (['sim_node', '--ros-args', '-p', 'time_step:=0.001'], False),
    (['sim_node', 'debug'], False),
])
def test_debug_is_asked_for_with_log_level_debug(argv, debug):
    assert debug_requested(argv) is debug


@pytest.mark.parametrize(('args', 'expected'), [
    (['sim_node', '--ros-args', '--no-such-flag'],
     "ROS arguments: unknown ROS argument '--no-such-flag'"),
    (['sim_node', '--ros-args', '-p', 'time_step'],
     "ROS arguments: couldn't parse parameter override rule: '-p time_step'"),
    (['sim_node', '--ros-args', '-r', '__node:=9node'],
     "ROS arguments: couldn't parse remap rule: '-r __node:=9node' "
     "(Node name not remapped to invalid name: '9node')"),
])
def test_malformed_ros_arguments_raise_one_clean_line(args, expected, capfd, default_context):
    with pytest.raises(ArgumentError) as raised:
        init_ros(args)
    assert str(raised.value) == expected
    # rcl's own log lines were folded into the message, not printed.
    assert capfd.readouterr().err == ''


def _rcl_failure(args):
    """rclpy.init's exception for ``args`` and what rcl logged meanwhile, untouched."""
    import rclpy

    with runner._captured_native_stderr() as captured:
        with pytest.raises(Exception) as raised:  # noqa: PT011 -- rclpy's private RCLError
            rclpy.init(args=args)
    return raised.value, ''.join(captured)


def test_rcl_still_words_a_bad_argument_as_the_runner_tidies_it(default_context):
    # Fails when rcl or rclpy reword it: update runner._rcl_reason's patterns (until
    # then it passes the new text on whole, see the next test).
    err, log = _rcl_failure(['sim_node', '--ros-args', '-p', 'time_step'])
    text = str(err)
    assert text.startswith(runner._RCL_PREFIX), f'rcl no longer begins with the prefix: {text}'
    assert runner._RCL_SOURCE_LOCATION.search(text), f'no source location to drop: {text}'
    assert runner._RCL_LEXER_DETAIL.search(text), f'no lexer detail to drop: {text}'
    lines = [runner._RCL_LOG_LINE.match(line) for line in log.splitlines() if line.strip()]
    assert lines and all(lines), f'rcl logs lines of another shape: {log!r}'
    assert any(runner._RCL_GENERIC_ERROR in line['text'] for line in lines), log


def test_rclpy_still_names_unknown_ros_arguments_as_the_runner_reads_them(default_context):
    err, _ = _rcl_failure(['sim_node', '--ros-args', '--no-such-flag', '--nor-this'])
    assert runner._unknown_ros_arguments(err) == ['--no-such-flag', '--nor-this'], (
        f'rclpy reports unknown ROS arguments differently: {type(err).__name__}: {err}')


def test_rcl_text_of_another_shape_is_passed_on_whole_in_one_line():
    class UnknownROSArgsError(Exception):
        pass

    assert runner._rcl_reason(RuntimeError('Something new:\n  at line 3'),
                              'a log line of another shape\n\n') == (
        'something new: at line 3 (a log line of another shape)')
    assert runner._rcl_reason(UnknownROSArgsError('--flag is unknown'), '') == (
        '--flag is unknown')


def test_the_first_signal_interrupts_only_an_interruptible_block():
    with StopSignals() as stop:
        os.kill(os.getpid(), signal.SIGTERM)  # outside the block: noted only
        _python_call()
        assert stop.received is signal.SIGTERM
    with StopSignals() as stop:
        with pytest.raises(StopRequested), stop.interruptible():
            os.kill(os.getpid(), signal.SIGINT)
            _python_call()
        os.kill(os.getpid(), signal.SIGINT)  # later ones: noted, never raised
        _python_call()
    assert stop.received is signal.SIGINT


def test_a_stop_noted_before_the_block_ends_it_at_once():
    with StopSignals() as stop:
        os.kill(os.getpid(), signal.SIGTERM)
        _python_call()
        with pytest.raises(StopRequested), stop.interruptible():
            pytest.fail('the block should not run after a stop was asked for')


def test_the_previous_handlers_come_back():
    before = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM)}
    with StopSignals():
        assert signal.getsignal(signal.SIGTERM) is not before[signal.SIGTERM]
    assert {signum: signal.getsignal(signum) for signum in before} == before


class RacingRclpy:
    """rclpy whose try_shutdown fails as when its signal handler shut the context first."""

    def __init__(self, shut_down_by_other: bool) -> None:
        self._shut_down_by_other = shut_down_by_other

    def try_shutdown(self) -> None:
        raise RuntimeError('failed to shutdown: rcl_shutdown already called on the given context')

    def ok(self) -> bool:
        return not self._shut_down_by_other


def test_a_shutdown_that_rclpys_signal_handler_won_is_not_an_error(monkeypatch):
    monkeypatch.setitem(sys.modules, 'rclpy', RacingRclpy(shut_down_by_other=True))
    shut_down_ros()  # the context is down, as asked: no exception


def test_a_shutdown_that_failed_with_the_context_still_up_is_raised(monkeypatch):
    monkeypatch.setitem(sys.modules, 'rclpy', RacingRclpy(shut_down_by_other=False))
    with pytest.raises(RuntimeError, match='rcl_shutdown'):
        shut_down_ros()


# --- the garbage collector while the program starts ----------------------------------------

@pytest.fixture
def collector():
    """Leave the test process's collector as it was found: on, nothing frozen."""
    yield
    gc.unfreeze()
    gc.enable()


def test_the_collector_is_held_off_in_the_block_then_runs_with_what_it_made_frozen(collector):
    frozen = gc.get_freeze_count()
    with collector_held_off():
        assert not gc.isenabled()
        made = [[] for _ in range(1000)]
    assert gc.isenabled()
    assert gc.get_freeze_count() >= frozen + len(made)


def test_a_failed_start_freezes_nothing_and_turns_the_collector_back_on(collector):
    frozen = gc.get_freeze_count()
    with pytest.raises(ConfigurationError), collector_held_off():
        raise ConfigurationError('bad file')
    assert gc.isenabled() and gc.get_freeze_count() == frozen


def test_a_collector_that_was_off_stays_off(collector):
    gc.disable()
    with collector_held_off():
        pass
    assert not gc.isenabled()


RUN_PROBE = """
import gc
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.ros import runner

def make_node():
    print('building, collector on:', gc.isenabled())
    raise ConfigurationError('stop here')

code = runner.run(make_node, ['probe'], program='probe')
print('after, collector on:', gc.isenabled(), 'exit code', code)
"""


def run_probe(code: str, *args: str) -> list[str]:
    """Run ``code`` as a program of its own; return the lines it printed."""
    result = subprocess.run([sys.executable, '-c', code, *args], env=sim_process.environment(),
                            capture_output=True, text=True, timeout=60, check=True)
    return result.stdout.splitlines()


def test_a_program_builds_its_node_with_the_collector_held_off():
    assert run_probe(RUN_PROBE) == [
        'building, collector on: False', 'after, collector on: True exit code 2']


GRAPH_PROBE = """
import rclpy

from pan_tilt_sim.ros import runner


def names(node):
    return sorted(name for name, _ in node.get_node_names_and_namespaces())


class OneSpin:
    def add_node(self, node):
        self.node = node

    def remove_node(self, node):
        pass

    def shutdown(self):
        pass

    def spin_once(self):
        print('spinning:', names(self.node))
        rclpy.try_shutdown()


def make_node():
    node = rclpy.create_node('probe')
    print('building:', names(node))
    return node


runner.run(make_node, ['probe', '--ros-args', '-r', '__node:=renamed'], program='my-probe',
           make_executor=lambda node: OneSpin())
"""


def test_a_program_has_its_dds_participant_before_it_builds_its_node():
    # A hidden node holds it, untouched by the program's remappings, until the
    # node is built: discovery runs while the node's imports load.
    assert run_probe(GRAPH_PROBE) == [
        "building: ['_my_probe_starting', 'renamed']", "spinning: ['renamed']"]


SPIN_PROBE = """
import os
import signal
import sys

import rclpy
from rclpy.signals import SignalHandlerGuardCondition, uninstall_signal_handlers

from pan_tilt_sim.ros import runner

BOUND = 20
SLOWING_GUARDS = 2000
RCLPY_HANDLES_SIGNALS = sys.argv[1] == 'rclpy-handlers'


class WokenExecutor:
    '''Wakes as on a signal, before anything has shut the context down.'''

    def __init__(self):
        self.spins_after_signal = -1
        self.context_up_at_shutdown = None

    def add_node(self, node):
        pass

    remove_node = add_node

    def shutdown(self):
        self.context_up_at_shutdown = rclpy.ok()

    def spin_once(self):
        self.spins_after_signal += 1
        if self.spins_after_signal == 0:
            os.kill(os.getpid(), signal.SIGINT)
        elif self.spins_after_signal == BOUND:
            rclpy.try_shutdown()  # the stop was missed: end the test's spin here


def make_node():
    if not RCLPY_HANDLES_SIGNALS:
        uninstall_signal_handlers()  # the program's own handler alone takes the signal
    node = rclpy.create_node('probe')
    # Guard conditions that rclpy's signal thread triggers before it shuts the
    # context down: they make that thread slower than this one.
    node.slowing = [SignalHandlerGuardCondition() for _ in range(SLOWING_GUARDS)]
    return node


executor = WokenExecutor()
code = runner.run(make_node, ['probe'], program='probe', make_executor=lambda node: executor)
print('spins after the signal:', executor.spins_after_signal, 'exit code', code)
print('context up when the executor shut down:', executor.context_up_at_shutdown)
"""


def test_a_program_stops_on_a_signal_even_if_its_executor_wakes_before_the_shutdown():
    # rclpy's signal thread wakes the executor, then shuts the context down
    # without waking it: the program must not depend on seeing that shutdown.
    assert run_probe(SPIN_PROBE, 'own-handler-only')[0] == 'spins after the signal: 0 exit code 0'


def test_leaving_the_spin_on_a_signal_lets_rclpys_signal_thread_finish_first():
    # That thread still works on the executor's guard condition until it has
    # shut the context down: the executor is torn down only after that.
    assert run_probe(SPIN_PROBE, 'rclpy-handlers') == [
        'spins after the signal: 0 exit code 0',
        'context up when the executor shut down: False']
