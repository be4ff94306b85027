"""Running a node as a command-line program: start-up errors, signals, a clean exit.

* Malformed ``--ros-args`` and every :class:`~pan_tilt_sim.errors.ConfigurationError`
  raised while the node is built end the program with exit code 2 and ONE line on
  stderr (rcl's own log lines folded in; the traceback only with
  ``--ros-args --log-level debug``).
* SIGINT and SIGTERM destroy the node and exit 0, without a traceback.  The
  handlers are installed before ``rclpy.init`` and unconditionally, because a shell
  starts background jobs with SIGINT ignored and ``ros2 run`` does not forward
  signals; rclpy's own handlers are chained to them.
* With ``PAN_TILT_SIM_PARENT_PID`` set (by the launch file), the program stops as on
  SIGTERM when that process dies, so it never outlives its launch.
* The garbage collector is held off while the program starts and what start-up made
  is then frozen (``gc.freeze``), so start-up's objects are never scanned again.
* The DDS participant is made right after ``rclpy.init`` by a hidden placeholder node
  (``_<program>_starting``), so Fast DDS discovers peers while the rest loads.
* This module imports neither rclpy nor PyBullet before the handlers are in place:
  :func:`run` takes a factory that imports the node only when called.
"""

from __future__ import annotations

import ast
import contextlib
import ctypes
import gc
import os
import re
import signal
import sys
import tempfile
import threading
import time
import traceback
from collections.abc import Callable, Iterator, Sequence
from typing import TYPE_CHECKING

from pan_tilt_sim.errors import ArgumentError, ConfigurationError, one_line

if TYPE_CHECKING:
    from rclpy.context import Context
    from rclpy.executors import Executor
    from rclpy.node import Node

EXIT_OK = 0
EXIT_CONFIGURATION_ERROR = 2
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
LOG_LEVEL_FLAG = '--log-level'
DEBUG_LEVEL = 'debug'
STDERR_FD = 2
# The pid of the process whose death must stop the program (set by the launch file).
PARENT_PID_VARIABLE = 'PAN_TILT_SIM_PARENT_PID'
PR_SET_PDEATHSIG = 1  # <linux/prctl.h>
PARENT_POLL_S = 0.5  # the watcher thread's period where prctl is not available
RCLPY_SIGNAL_BUDGET_S = 0.5  # how long leaving the spin waits for rclpy's signal thread
RCLPY_SIGNAL_POLL_S = 0.001
# rcl's generic last word on any bad argument; the specific reason comes before it.
_RCL_GENERIC_ERROR = 'Failed to parse global arguments'
_RCL_LOG_LINE = re.compile(r'^\[(?:WARN|ERROR|FATAL)\] \[[^\]]*\] \[rcl[^\]]*\]: (?P<text>.*)$')
_RCL_PREFIX = 'failed to initialize rcl: '
# Source locations rcl appends to its errors (", at /project/src/rcl/arguments.c:352").
_RCL_SOURCE_LOCATION = re.compile(r',? at [^\s,]+\.c:\d+')
# rcl's lexer detail ("Expected lexeme type (22) not found ...") helps no user.
_RCL_LEXER_DETAIL = re.compile(r'\. Error: Expected lexeme.*$')


class StopRequested(KeyboardInterrupt):
    """SIGINT or SIGTERM asked the program to stop."""


class StopSignals:
    """SIGINT/SIGTERM handlers for the life of the program (a context manager).

    Every signal is recorded in :attr:`received`; the first one raises
    :class:`StopRequested` only inside :meth:`interruptible` (the node's
    start-up, and the spin's loop: see :func:`~pan_tilt_sim.ros.spinning.spin`),
    so that destroying the node is never cut short.  Previous
    handlers come back on exit.  Outside the main thread nothing is installed.
    """

    def __init__(self) -> None:
        self.received: signal.Signals | None = None
        self._interruptible = False
        self._previous: dict[signal.Signals, object] = {}

    def __enter__(self) -> StopSignals:
        if threading.current_thread() is threading.main_thread():
            for signum in STOP_SIGNALS:
                self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc_info: object) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
        self._previous.clear()

    @contextlib.contextmanager
    def interruptible(self) -> Iterator[None]:
        """Let the first signal raise :class:`StopRequested` inside this block."""
        if self.received is not None:
            raise StopRequested(self.received.name)
        self._interruptible = True
        try:
            yield
        finally:
            self._interruptible = False

    def _handle(self, signum: int, frame: object) -> None:
        first = self.received is None
        self.received = signal.Signals(signum)
        if first and self._interruptible:
            self._interruptible = False
            raise StopRequested(self.received.name)


def stop_with_parent(environ: dict[str, str] | None = None) -> bool:
    """Arrange for SIGTERM when the process named by ``PAN_TILT_SIM_PARENT_PID`` dies.

    Returns whether a process is watched.  When it is this process's parent,
    Linux's parent-death signal does it; when something stands between them
    (a launch prefix such as gdb), or off Linux, a watcher thread polls.  If
    the process is already gone, SIGTERM is sent at once.
    """
    text = (os.environ if environ is None else environ).get(PARENT_PID_VARIABLE, '').strip()
    if not text.isdigit():
        return False
    parent = int(text)
    if os.getppid() == parent and _parent_death_signal(signal.SIGTERM):
        if os.getppid() != parent:  # it died before the request took effect
            os.kill(os.getpid(), signal.SIGTERM)
        return True
    if not _is_alive(parent):
        os.kill(os.getpid(), signal.SIGTERM)
        return True
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True,
                     name='parent-watch').start()
    return True


def _parent_death_signal(signum: int) -> bool:
    """Ask Linux to send ``signum`` when the parent dies; False where that is not possible."""
    if not sys.platform.startswith('linux'):
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(PR_SET_PDEATHSIG, int(signum), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _is_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process: it exists
        return True
    return True


def _watch_parent(parent: int) -> None:
    while _is_alive(parent):
        time.sleep(PARENT_POLL_S)
    os.kill(os.getpid(), signal.SIGTERM)


def debug_requested(argv: Sequence[str]) -> bool:
    """Whether ``--log-level debug`` (for any logger) is among ``argv``."""
    return any(flag == LOG_LEVEL_FLAG and value.rpartition(':=')[2].lower() == DEBUG_LEVEL
               for flag, value in zip(argv, argv[1:], strict=False))


@contextlib.contextmanager
def _captured_native_stderr() -> Iterator[list[str]]:
    """Send C-level stderr (rcl's console logging) elsewhere; the text lands in the list."""
    text: list[str] = []
    sys.stderr.flush()
    with tempfile.TemporaryFile() as captured:
        saved = os.dup(STDERR_FD)
        os.dup2(captured.fileno(), STDERR_FD)
        try:
            yield text
        finally:
            sys.stderr.flush()
            os.dup2(saved, STDERR_FD)
            os.close(saved)
            captured.seek(0)
            text.append(captured.read().decode('utf-8', errors='replace'))


def _rcl_reason(err: Exception, log: str) -> str:
    """One line from rclpy.init's exception and the lines rcl logged about it.

    rcl reports a bad argument only as text (rclpy raises its private
    RCLError or UnknownROSArgsError), so this is the one place that reads
    that text: it drops rcl's prefix, source locations, lexer detail and
    generic last word.  Text of another shape (another rcl) is kept as it is,
    folded into the line, so nothing rcl said is lost.
    """
    unknown = _unknown_ros_arguments(err)
    if unknown is not None:
        return 'unknown ROS argument ' + ', '.join(f"'{arg}'" for arg in unknown)
    reason = str(err).removeprefix(_RCL_PREFIX)
    reason = _RCL_SOURCE_LOCATION.sub('', reason)
    reason = _RCL_LEXER_DETAIL.sub('', reason).rstrip('.').replace('. Error: ', ': ')
    details = []
    for line in filter(str.strip, log.splitlines()):
        match = _RCL_LOG_LINE.match(line)
        if match is None:
            details.append(line.strip())
        elif _RCL_GENERIC_ERROR not in match['text']:
            details.append(match['text'])
    if details:
        reason += ' (' + '; '.join(details) + ')'
    reason = one_line(reason)
    return reason[:1].lower() + reason[1:]


def _unknown_ros_arguments(err: Exception) -> list[str] | None:
    """Return the arguments an UnknownROSArgsError names (its text is a list's repr), or None."""
    if type(err).__name__ != 'UnknownROSArgsError':
        return None
    try:
        unknown = ast.literal_eval(str(err))
    except (SyntaxError, ValueError):
        return None
    if isinstance(unknown, list) and unknown and all(isinstance(arg, str) for arg in unknown):
        return unknown
    return None


def init_ros(args: list[str] | None, *, debug: bool = False) -> None:
    """Initialise rclpy; malformed ROS arguments raise a one-line :class:`ArgumentError`."""
    import rclpy  # slow: only once the signal handlers are in place

    if debug:
        rclpy.init(args=args)
        return
    failure = None
    with _captured_native_stderr() as captured:
        try:
            rclpy.init(args=args)
        except Exception as err:  # rclpy raises RCLError / UnknownROSArgsError, not exported
            failure = err
    log = ''.join(captured)
    if failure is not None:
        raise ArgumentError(f'ROS arguments: {_rcl_reason(failure, log)}') from failure
    # Nothing went wrong: whatever rcl said is the user's to see.
    sys.stderr.write(log)


def report_error(program: str, err: ConfigurationError, *, debug: bool) -> None:
    """Print ``program: error: ...`` on stderr, after the traceback when debugging."""
    if debug:
        traceback.print_exception(err)
    print(f'{program}: error: {err}', file=sys.stderr)


def _ros_is_shut_down() -> bool:
    rclpy = sys.modules.get('rclpy')
    return rclpy is not None and not rclpy.ok()


def shut_down_ros() -> None:
    """Shut rclpy's default context down unless something else already did.

    rclpy's own signal handler shuts every context down from a thread of its
    own, without the lock ``try_shutdown`` takes: a signal arriving between
    that call's "still ok?" check and its shutdown makes rcl refuse the second
    shutdown ("rcl_shutdown already called").  That is the outcome we asked
    for, not an error.
    """
    rclpy = sys.modules['rclpy']
    try:
        rclpy.try_shutdown()
    except Exception:  # RCLError, which rclpy does not export
        if rclpy.ok():
            raise


@contextlib.contextmanager
def interruptible_spin(stop: StopSignals, context: Context) -> Iterator[None]:
    """Hold the spin's loop, which the first stop signal ends with :class:`StopRequested`.

    rclpy's handler passes a signal to a thread of its own, which wakes the
    executors and only then shuts the contexts down, without waking them: an
    executor woken in between went back to waiting for good, so the loop may
    not rely on that shutdown.  Leaving at once, though, would tear the
    executor down while that thread may still be triggering its guard
    condition, which can crash the process, so on the way
    out this waits -- up to RCLPY_SIGNAL_BUDGET_S, and only where rclpy
    handles that signal -- for the shutdown that thread makes after it.
    """
    try:
        with stop.interruptible():
            yield
    except StopRequested:
        if _rclpy_handles(stop.received):
            deadline = time.monotonic() + RCLPY_SIGNAL_BUDGET_S
            while context.ok() and time.monotonic() < deadline:
                time.sleep(RCLPY_SIGNAL_POLL_S)
        raise


def _rclpy_handles(signum: signal.Signals | None) -> bool:
    """Whether rclpy's own handler is installed for ``signum``."""
    from rclpy.signals import SignalHandlerOptions, get_current_signal_handlers_options

    options = get_current_signal_handlers_options()
    own = {signal.SIGINT: SignalHandlerOptions.SIGINT, signal.SIGTERM: SignalHandlerOptions.SIGTERM}
    return options == SignalHandlerOptions.ALL or options == own.get(signum)


@contextlib.contextmanager
def participant_made_first(program: str) -> Iterator[None]:
    """Make the default context's DDS participant now; keep it until the block ends.

    rmw_fastrtps makes a context's participant with its first node and
    releases it with its last: a hidden node with nothing of its own
    (``ros2 node list`` shows it only with ``--all``) holds it while the
    block builds the real node.
    """
    from rclpy.node import Node
    from rclpy.parameter import Parameter

    placeholder = Node(
        f"_{re.sub(r'[^A-Za-z0-9_]', '_', program)}_starting", use_global_arguments=False,
        enable_rosout=False, start_parameter_services=False, parameter_overrides=[
            Parameter('start_type_description_service', value=False)])
    try:
        yield
    finally:
        placeholder.destroy_node()


@contextlib.contextmanager
def collector_held_off() -> Iterator[None]:
    """Hold the cyclic garbage collector off in the block; freeze what it made if it succeeds."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
        gc.freeze()
    finally:
        if was_enabled:
            gc.enable()


def run(make_node: Callable[[], Node], args: list[str] | None = None, *,
        program: str, make_executor: Callable[[Node], Executor] | None = None) -> int:
    """Build a node with ``make_node``, spin it until stopped; return the exit code.

    ``make_executor(node)`` gives the executor to spin it on (default: rclpy's
    SingleThreadedExecutor).
    """
    debug = debug_requested(sys.argv if args is None else args)
    node: Node | None = None
    initialized = False
    failure: ConfigurationError | None = None
    with StopSignals() as stop:
        try:
            with stop.interruptible(), collector_held_off():
                stop_with_parent()
                init_ros(args, debug=debug)
                initialized = True
                with participant_made_first(program):
                    node = make_node()
            import rclpy

            from pan_tilt_sim.ros import spinning

            if stop.received is None and rclpy.ok():
                # Only while the context is alive: an executor whose construction
                # a signal cuts short complains from __del__ with a traceback.
                spinning.spin(node, on_ready=lambda: node.get_logger().debug(
                    'started; spinning until SIGINT or SIGTERM'), make_executor=(
                    spinning.single_threaded if make_executor is None
                    else lambda context: make_executor(node)),
                    interrupts=interruptible_spin(stop, node.context))
        except ConfigurationError as err:
            failure = err
        except KeyboardInterrupt:
            pass
        except Exception:
            # rclpy's signal handler shuts the context down (ending the spin with
            # ExternalShutdownException, or failing calls on it) before ours runs.
            if stop.received is None and not (initialized and _ros_is_shut_down()):
                raise
        finally:
            if node is not None:
                node.destroy_node()
            if initialized:
                shut_down_ros()
    if failure is not None:
        # Last, after rcl's shutdown chatter when debugging: the line the user reads.
        report_error(program, failure, debug=debug)
        return EXIT_CONFIGURATION_ERROR
    return EXIT_OK


def main(make_node: Callable[[], Node], args: list[str] | None = None, *,
         program: str, make_executor: Callable[[Node], Executor] | None = None) -> None:
    """Run a node program; exit 0 when stopped by a signal, 2 on a configuration error."""
    status = run(make_node, args, program=program, make_executor=make_executor)
    if status != EXIT_OK:
        sys.exit(status)
