"""A small stand-in of ROS 2's launch API that runs a ros2_control or Gazebo launch file.

``launch`` and ``launch_ros`` are not on PyPI.  :func:`load` runs a launch file's
``generate_launch_description()`` against stand-in modules that record what it asks for
(the names :func:`modules` defines; importing any other is an ImportError).
:class:`StandInLaunch` carries it out as launch would: arguments declared (``choices``
checked), OpaqueFunctions called, includes of installed Python launch files followed with
their launch_arguments (one of a package not installed is refused when it would run),
GroupAction scoped as launch scopes it (launch configurations, environment,
PushRosNamespace/PushROSNamespace, SetRemap, SetParameter), ExecuteProcess run to its
end first; then the nodes as launch_ros starts them: sim_node, pan_tilt_sim's Gazebo-side
stand-ins (create, parameter_bridge, ...) and robot_state_publisher
(test/support/robot_state_publisher_stand_in.py) as processes, controller_manager's
spawner in-process (test/support/spawner_client.py), each OnProcessExit's actions after
its target ended, each OnShutdown's when it is closed (as at Ctrl-C).  An action it cannot
carry out is a ValueError naming it, never skipped.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import logging
import math
import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys
import time
import types
from collections.abc import Iterable, Iterator
from typing import Any

import sim_process
import yaml
from spawner_client import spawner_main

HERE = pathlib.Path(__file__).resolve().parent
STAND_IN_MODULES = ('launch', 'launch.actions', 'launch.conditions', 'launch.event_handlers',
                    'launch.launch_description_sources', 'launch.logging',
                    'launch.substitutions', 'launch.substitutions.command',
                    'launch.substitutions.find_executable', 'launch_ros',
                    'launch_ros.actions', 'launch_ros.parameter_descriptions',
                    'launch_ros.substitutions', 'controller_manager',
                    'controller_manager.launch_utils')
# pan_tilt_sim's executables that run as processes here (sim_node has its own start).
STAND_IN_EXECUTABLES = ('create', 'parameter_bridge', 'image_bridge', 'spawn_entity.py',
                        'ros2_control_node')
EXECUTE_PROCESS_WAIT_S = 30.0  # an ExecuteProcess (xacro -o world.sdf) runs before the nodes
PROCESS_EXIT_WAIT_S = 120.0  # for a process an OnProcessExit waits on (create: the robot in)
SUBSTITUTION = re.compile(r'\$\(var ([A-Za-z0-9_]+)\)')
# The texts launch reads as a true or false condition (any case); any other is an error.
TRUE_TEXTS, FALSE_TEXTS = ('true', '1'), ('false', '0')


class Recorded:
    """A launch action or substitution: keeps its arguments."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.args, self.kwargs = args, kwargs


class Substitution(Recorded):
    """A substitution: ``perform(context)`` gives its text, as launch's substitutions do."""

    def perform(self, context: LaunchContext) -> str:
        """Return the text this stands for with the context's launch configurations."""
        return text(self, context.launch_configurations)


class LaunchContext:
    """launch.LaunchContext: what an OpaqueFunction's function is called with."""

    def __init__(self, launch_configurations: dict[str, str]) -> None:
        self.launch_configurations = launch_configurations


class LaunchDescription(list):
    """launch.LaunchDescription: its actions, in order; ``add_action`` appends one."""

    def add_action(self, action: Any) -> None:
        """Append ``action``, as launch's does."""
        self.append(action)


class Node(Recorded):
    """launch_ros.actions.Node."""


class RegisterEventHandler(Recorded):
    """launch.actions.RegisterEventHandler."""


class OnProcessExit(Recorded):
    """launch.event_handlers.OnProcessExit."""


class OnShutdown(Recorded):
    """launch.event_handlers.OnShutdown: ``on_shutdown``, actions or ``f(event, context)``."""


@dataclasses.dataclass(frozen=True)
class ShutdownEvent:
    """launch.events.Shutdown, as an OnShutdown callable is given it."""

    reason: str = 'reason not given'
    due_to_sigint: bool = False


class AppendEnvironmentVariable(Recorded):
    """launch.actions.AppendEnvironmentVariable: name, value (prepend, separator)."""


class SetEnvironmentVariable(Recorded):
    """launch.actions.SetEnvironmentVariable: name, value."""


class ExecuteProcess(Recorded):
    """launch.actions.ExecuteProcess: ``cmd``, a list of texts or substitutions."""


class Shutdown(Recorded):
    """launch.actions.Shutdown (a Node's ``on_exit``; recorded only)."""


class Command(Substitution):
    """launch.substitutions.Command: the words, run; its stdout."""


class PathJoinSubstitution(Substitution):
    """launch.substitutions.PathJoinSubstitution."""


class PathSubstitution(Substitution):
    """launch.substitutions.PathSubstitution: ``/`` joins a part on."""

    def __truediv__(self, part: Any) -> PathSubstitution:
        return PathSubstitution(PathJoinSubstitution([self, part]))


class DeclareLaunchArgument(Recorded):
    """launch.actions.DeclareLaunchArgument: a name, its default_value and its choices."""

    def declare(self, arguments: dict[str, str]) -> None:
        """Set the default (performed) unless given; refuse a value outside ``choices``."""
        name = self.args[0]
        if name not in arguments:
            arguments[name] = text(self.kwargs.get('default_value', ''), arguments)
        choices = self.kwargs.get('choices')
        if choices is not None and arguments[name] not in choices:
            raise ValueError(f'Argument "{name}" provided value "{arguments[name]}" is not '
                             f'valid. Valid options are: {choices}')


class OpaqueFunction(Recorded):
    """launch.actions.OpaqueFunction: ``function(context, *args, **kwargs)`` gives actions."""

    def run(self, arguments: dict[str, str]) -> list:
        """Call the function with a context of ``arguments``; return its actions."""
        function = self.kwargs['function']
        return function(LaunchContext(arguments), *self.kwargs.get('args') or [],
                        **self.kwargs.get('kwargs') or {}) or []


class FindExecutable(Substitution):
    """launch.substitutions.FindExecutable: the program's path (this environment's bin first)."""


class IfElseSubstitution(Substitution):
    """launch.substitutions.IfElseSubstitution: if_value when the condition holds, else_value."""

    def __init__(self, condition: Any, if_value: Any = '', else_value: Any = '') -> None:
        if if_value == else_value == '':
            raise ValueError('One of if_value and else_value must be specified')
        super().__init__(condition, if_value=if_value, else_value=else_value)


class IfCondition(Recorded):
    """launch.conditions.IfCondition: holds when its text is true (see :func:`truth`)."""


class UnlessCondition(Recorded):
    """launch.conditions.UnlessCondition: holds when its text is false (see :func:`truth`)."""


class IncludeLaunchDescription(Recorded):
    """launch.actions.IncludeLaunchDescription: another package's launch file (Gazebo's).

    The stand-in does not run other packages' launch files; :class:`StandInLaunch`
    refuses one that is left in (its condition holding), naming the file and its
    ``launch_arguments`` (name-value pairs, or a dict's items).
    """

    def path(self, arguments: dict[str, str]) -> pathlib.Path:
        """Return the included file, performed."""
        return pathlib.Path(text(self.args[0].args[0], arguments))

    def describe(self, arguments: dict[str, str]) -> str:
        """Return the included file's name and its launch arguments, performed."""
        names = [part for part in _strings(self.args[0].args[0]) if part.strip('/')]
        given = ', '.join(f'{text(name, arguments)}={text(value, arguments)!r}'
                          for name, value in self.kwargs.get('launch_arguments', []))
        return f'{os.path.basename(names[-1])}({given})'


class PythonLaunchDescriptionSource(Recorded):
    """launch.launch_description_sources.PythonLaunchDescriptionSource."""


class ParameterFile(Recorded):
    """launch_ros ParameterFile: a file; with allow_substs its $(var name) are filled in."""


class GroupAction(Recorded):
    """launch.actions.GroupAction: ``actions``; ``scoped`` (default true), ``forwarding``
    (only true is carried out), ``launch_configurations`` set for the group."""


class PushRosNamespace(Recorded):
    """launch_ros.actions.PushROSNamespace (alias PushRosNamespace): ``namespace``."""


class SetRemap(Recorded):
    """launch_ros.actions.SetRemap: ``src``, ``dst`` for every node after it in its scope."""


class SetParameter(Recorded):
    """launch_ros.actions.SetParameter: ``name``, ``value`` for every node after it."""


class LogInfo(Recorded):
    """launch.actions.LogInfo: ``msg`` (texts or substitutions), logged when carried out."""


class TextSubstitution(Substitution):
    """launch.substitutions.TextSubstitution: ``text``."""


class PythonExpression(Substitution):
    """launch.substitutions.PythonExpression: the joined texts evaluated (math's names
    available, as launch's default ``python_modules``)."""


# Actions carried out as they are reached: skipped there when their condition does not hold.
SCOPE_ACTIONS = (GroupAction, PushRosNamespace, SetRemap, SetParameter, LogInfo,
                 AppendEnvironmentVariable, SetEnvironmentVariable, OpaqueFunction)


@dataclasses.dataclass
class Scope:
    """What launch keeps in a context's launch configurations for the actions after it.

    ``arguments`` and ``environment`` are the scope's own (a scoped GroupAction's
    are copies); ``namespace`` (PushRosNamespace's, absolute), ``remaps`` and
    ``parameters`` are as they stood when an action was reached.
    """

    arguments: dict[str, str]
    environment: dict[str, str]
    namespace: str | None = None
    remaps: tuple[tuple[str, str], ...] = ()
    parameters: tuple[tuple[str, str], ...] = ()

    def snapshot(self) -> Scope:
        """This scope as an action reached now sees it (its dicts shared)."""
        return dataclasses.replace(self)


def prefix_namespace(base: str | None, namespace: str | None) -> str | None:
    """launch_ros' prefix_namespace: ``namespace`` under ``base`` unless it is absolute."""
    if base is None and namespace is None:
        return None
    if namespace is None:
        combined = base
    elif not base or namespace.startswith('/'):
        combined = namespace
    else:
        combined = ('' if base == '/' else base) + '/' + namespace
    return combined if combined == '/' else combined.rstrip('/')


def absolute_namespace(namespace: str | None) -> str | None:
    """launch_ros' make_namespace_absolute."""
    return namespace if namespace is None or namespace.startswith('/') else '/' + namespace


class FindPackageShare(Substitution):
    """launch_ros.substitutions.FindPackageShare."""


class LaunchConfiguration(Substitution):
    """launch.substitutions.LaunchConfiguration."""


def generate_controllers_spawner_launch_description(
        controller_names: list, controller_params_files: list | None = None,
        extra_spawner_args: list | None = None) -> list:
    """controller_manager.launch_utils' helper: one spawner for ``controller_names``.

    As jazzy's: the ``controller_manager_name`` launch argument (default
    ``controller_manager``) names the manager, each params file is a
    ``--param-file``, then the extra arguments.  (Its ``unload_on_kill``
    argument adds nothing unless set, and is not carried out here.)
    """
    arguments = [*controller_names, '--controller-manager',
                 LaunchConfiguration('controller_manager_name')]
    for path in controller_params_files or ():
        arguments += ['--param-file', path]
    arguments += list(extra_spawner_args or ())
    return [DeclareLaunchArgument('controller_manager_name', default_value='controller_manager'),
            Node(package='controller_manager', executable='spawner', arguments=arguments)]


def modules() -> dict[str, types.ModuleType]:
    """Return the stand-in modules, by name."""
    made = {name: types.ModuleType(name) for name in STAND_IN_MODULES}
    made['launch'].LaunchDescription = LaunchDescription
    made['launch.actions'].RegisterEventHandler = RegisterEventHandler
    made['launch.actions'].DeclareLaunchArgument = DeclareLaunchArgument
    made['launch.actions'].OpaqueFunction = OpaqueFunction
    made['launch.actions'].Shutdown = Shutdown
    made['launch.actions'].AppendEnvironmentVariable = AppendEnvironmentVariable
    made['launch.actions'].SetEnvironmentVariable = SetEnvironmentVariable
    made['launch.actions'].ExecuteProcess = ExecuteProcess
    made['launch.substitutions.command'].Command = Command
    made['launch.substitutions.find_executable'].FindExecutable = FindExecutable
    made['launch.logging'].get_logger = logging.getLogger
    made['launch'].logging = made['launch.logging']
    made['launch.conditions'].IfCondition = IfCondition
    made['launch.conditions'].UnlessCondition = UnlessCondition
    made['launch.actions'].IncludeLaunchDescription = IncludeLaunchDescription
    made['launch.launch_description_sources'].PythonLaunchDescriptionSource = (
        PythonLaunchDescriptionSource)
    made['launch.substitutions'].PathSubstitution = PathSubstitution
    made['launch_ros.parameter_descriptions'].ParameterFile = ParameterFile
    made['launch.event_handlers'].OnProcessExit = OnProcessExit
    made['launch.event_handlers'].OnShutdown = OnShutdown
    made['launch.substitutions'].Command = Command
    made['launch.substitutions'].PathJoinSubstitution = PathJoinSubstitution
    made['launch.substitutions'].LaunchConfiguration = LaunchConfiguration
    made['launch.substitutions'].FindExecutable = FindExecutable
    made['launch.substitutions'].IfElseSubstitution = IfElseSubstitution
    made['launch_ros.actions'].Node = Node
    made['launch_ros.substitutions'].FindPackageShare = FindPackageShare
    made['launch.actions'].GroupAction = GroupAction
    made['launch.actions'].LogInfo = LogInfo
    made['launch.substitutions'].TextSubstitution = TextSubstitution
    made['launch.substitutions'].PythonExpression = PythonExpression
    made['launch_ros.actions'].PushROSNamespace = PushRosNamespace
    made['launch_ros.actions'].PushRosNamespace = PushRosNamespace
    made['launch_ros.actions'].SetRemap = SetRemap
    made['launch_ros.actions'].SetParameter = SetParameter
    made['controller_manager.launch_utils'].generate_controllers_spawner_launch_description = (
        generate_controllers_spawner_launch_description)
    return made


def load(path: pathlib.Path, monkeypatch) -> list:
    """Return the actions of the launch file at ``path``, made with the stand-in modules."""
    for name, module in modules().items():
        monkeypatch.setitem(sys.modules, name, module)
    spec = importlib.util.spec_from_file_location('launch_file_under_test', path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.generate_launch_description()


def _load_file(path: pathlib.Path) -> list:
    """The actions of an included launch file (the stand-in modules are in place already)."""
    spec = importlib.util.spec_from_file_location(f'included_{path.stem.replace(".", "_")}',
                                                  path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.generate_launch_description()


def perform(value: Any, arguments: dict[str, str]) -> Any:
    """Return the text a substitution stands for (lists and dicts element by element)."""
    if isinstance(value, FindPackageShare):
        from ament_index_python.packages import get_package_share_directory

        return get_package_share_directory(perform(value.args[0], arguments))
    if isinstance(value, PathJoinSubstitution):
        return os.path.join(*[perform(part, arguments) for part in value.args[0]])
    if isinstance(value, PathSubstitution):
        return perform(value.args[0], arguments)
    if isinstance(value, IfCondition):
        return truth(text(value.args[0], arguments))
    if isinstance(value, UnlessCondition):
        return not truth(text(value.args[0], arguments))
    if isinstance(value, IfElseSubstitution):
        holds = truth(text(value.args[0], arguments))
        return text(value.kwargs['if_value' if holds else 'else_value'], arguments)
    if isinstance(value, TextSubstitution):
        return value.kwargs['text'] if 'text' in value.kwargs else value.args[0]
    if isinstance(value, PythonExpression):
        return str(eval(text(value.args[0], arguments), {},  # noqa: S307
                        {'math': math, **vars(math)}))
    if isinstance(value, LaunchConfiguration):
        if value.args[0] not in arguments and 'default' in value.kwargs:
            return text(_as_text(value.kwargs['default']), arguments)
        return arguments[value.args[0]]
    if isinstance(value, FindExecutable):
        name = text(value.kwargs['name'], arguments)
        found = (shutil.which(name, path=os.path.dirname(sys.executable))
                 or shutil.which(name))
        if found is None:
            raise ValueError(f"executable '{name}' not found on the PATH")
        return found
    if isinstance(value, Command):
        words = shlex.split(text(value.args[0], arguments))
        words[0] = shutil.which(words[0], path=os.path.dirname(sys.executable)) or words[0]
        return subprocess.run(words, capture_output=True, text=True, check=True).stdout
    if isinstance(value, list | tuple):
        return [perform(item, arguments) for item in value]
    if isinstance(value, dict):
        return {key: perform(item, arguments) for key, item in value.items()}
    return value


def _as_text(value: Any) -> Any:
    """A plain default (``True``, ``1.5``) as the text launch makes of it."""
    return str(value) if isinstance(value, bool | int | float) else value


def text(value: Any, arguments: dict[str, str]) -> str:
    """Return the text of a substitution or a list of them (joined, as launch joins them)."""
    performed = perform(value, arguments)
    return ''.join(performed) if isinstance(performed, list) else performed


def truth(condition: str) -> bool:
    """Return what a condition's text means to launch: 'true'/'1' or 'false'/'0', any case."""
    if condition.strip().lower() in TRUE_TEXTS:
        return True
    if condition.strip().lower() in FALSE_TEXTS:
        return False
    raise ValueError(f'{condition!r} is not a condition: expected true, false, 1 or 0')


def _strings(value: Any) -> Iterator[str]:
    """The plain texts inside a substitution or a list of them, in order."""
    if isinstance(value, str):
        yield value
    elif isinstance(value, list | tuple):
        for item in value:
            yield from _strings(item)
    elif isinstance(value, Recorded):
        yield from _strings(list(value.args))


class StandInLaunch:
    """Carries out a launch description's nodes; :meth:`close` stops the processes.

    ``arguments`` are the launch arguments given (``name:=value``); the
    declarations, OpaqueFunctions, includes and groups are carried out here, in
    order, so :attr:`actions` holds what they left, each with the :class:`Scope`
    it was reached in (the nodes are performed with it).
    """

    def __init__(self, actions: list, folder: pathlib.Path,
                 arguments: dict[str, str] | None = None) -> None:
        self.folder = folder
        self.arguments = dict(arguments or {})
        # What (Append|Set)EnvironmentVariable set, over this process's environment.
        self.environment: dict[str, str] = {}
        self._scope_of: dict[int, Scope] = {}  # by id() of each action left
        self.actions = self._carry_out(actions, Scope(self.arguments, self.environment))
        self.processes: dict[str, subprocess.Popen] = {}
        self._process_of: dict[int, subprocess.Popen] = {}  # by id() of the Node action
        self._logs: dict[str, pathlib.Path] = {}
        self.spawner_exits: list[tuple[list[str], int]] = []
        self._files = 0

    def nodes(self) -> Iterator[Node]:
        """The Node actions started at once (not those an event waits for) whose condition holds."""
        return (action for action in self.actions
                if isinstance(action, Node) and self._holds(action))

    def start_processes(self) -> None:
        """Start every node that runs as a process (all but the spawners).

        An include of a package not installed whose condition holds, or a node
        the stand-in cannot start, is refused (ValueError).
        """
        for action in self.actions:
            if isinstance(action, IncludeLaunchDescription) and self._holds(action):
                raise ValueError(
                    f'IncludeLaunchDescription of {action.describe(self.arguments_of(action))} '
                    'is not carried out by the launch stand-in')
        for node in self.nodes():
            package, executable = node.kwargs['package'], node.kwargs['executable']
            if package not in ('pan_tilt_sim', 'robot_state_publisher') and (
                    package, executable) != ('controller_manager', 'spawner') or (
                    package == 'pan_tilt_sim'
                    and executable not in ('sim_node', *STAND_IN_EXECUTABLES)):
                raise ValueError(f"Node(package='{package}', executable='{executable}') is not "
                                 'started by the launch stand-in')
        for action in self.actions:
            if isinstance(action, ExecuteProcess) and self._holds(action):
                self._execute(action)
        for node in self.nodes():
            package, executable = node.kwargs['package'], node.kwargs['executable']
            if (package, executable) == ('pan_tilt_sim', 'sim_node'):
                self.processes['sim_node'] = subprocess.Popen(
                    sim_process.command(*self.ros_args(node)), env=self._environment(node),
                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                self._process_of[id(node)] = self.processes['sim_node']
            elif package == 'pan_tilt_sim' and executable in STAND_IN_EXECUTABLES:
                self._start_stand_in(node)
            elif package == 'robot_state_publisher':
                command = [sys.executable, str(HERE / 'robot_state_publisher_stand_in.py'),
                           '--ros-args', *self.ros_args(node)]
                name, number = 'robot_state_publisher', 1
                while name in self.processes:  # one per robot: each is stopped at the end
                    number += 1
                    name = f'robot_state_publisher_{number}'
                self.processes[name] = subprocess.Popen(
                    command, env=self._environment(node), stdout=subprocess.DEVNULL,
                    stderr=subprocess.PIPE, text=True)

    def _start_stand_in(self, node: Node) -> None:
        """Start a pan_tilt_sim stand-in as launch_ros would: its arguments, then its ROS ones.

        Its output goes to a file in the folder (``<name>.log``): read by :meth:`output`.
        """
        executable = node.kwargs['executable']
        name = executable
        number = 1
        while name in self.processes:
            number += 1
            name = f'{executable}_{number}'
        arguments = [str(item) for item in perform(node.kwargs.get('arguments', []),
                                                  self.arguments_of(node))]
        command = [sys.executable, '-m', 'pan_tilt_sim.tools.stand_ins', executable,
                   *arguments, '--ros-args', *self.ros_args(node)]
        log = (self.folder / f'{name}.log').open('w')
        self.processes[name] = subprocess.Popen(
            command, env=self._environment(node), stdout=log, stderr=subprocess.STDOUT,
            text=True)
        self._process_of[id(node)] = self.processes[name]
        self._logs[name] = self.folder / f'{name}.log'

    def _environment(self, action: Recorded) -> dict[str, str]:
        """The environment of the action's process: the variables its scope set."""
        return {**sim_process.environment(), **self._scope(action).environment}

    def _scope(self, action: Recorded) -> Scope:
        """The scope the action was reached in (the top level's for one never reached)."""
        return self._scope_of.get(id(action)) or Scope(self.arguments, self.environment)

    def arguments_of(self, action: Recorded) -> dict[str, str]:
        """The launch configurations the action is performed with."""
        return self._scope(action).arguments

    def _execute(self, action: ExecuteProcess) -> None:
        """Run an ExecuteProcess's ``cmd`` (each item's text, as launch joins a list item).

        It runs to its end (within :data:`EXECUTE_PROCESS_WAIT_S`) before any node
        starts: a world that ``xacro -o`` writes is there when the simulation reads it.
        """
        words = [text(item, self.arguments_of(action)) for item in action.kwargs['cmd']]
        words[0] = shutil.which(words[0], path=os.path.dirname(sys.executable)) or words[0]
        done = subprocess.run(words, env=self._environment(action), capture_output=True, text=True,
                              timeout=EXECUTE_PROCESS_WAIT_S, check=False)
        if done.returncode != 0:
            raise ValueError(f'ExecuteProcess {words} exited {done.returncode}: {done.stderr}')

    def output(self, name: str) -> str:
        """What the stand-in process ``name`` wrote so far (stdout and stderr)."""
        return self._logs[name].read_text()

    def wait_for_exit(self, name: str, timeout: float = PROCESS_EXIT_WAIT_S) -> int | None:
        """Wait up to ``timeout`` s for the process ``name`` to end; its exit code or None."""
        try:
            return self.processes[name].wait(timeout)
        except subprocess.TimeoutExpired:
            return None

    def run_spawners(self, harness) -> list[int]:
        """Run the spawners in order, each OnProcessExit's spawners after its target; exits.

        A RegisterEventHandler whose condition does not hold registers nothing.
        The handlers of a stand-in process (``create``) run first, once it
        has ended (within :data:`PROCESS_EXIT_WAIT_S`; else AssertionError).
        """
        handlers = {}
        for action in self.actions:
            if isinstance(action, RegisterEventHandler) and self._holds(action):
                handler = action.kwargs.get('event_handler') or action.args[0]
                if not isinstance(handler, OnProcessExit):
                    continue
                on_exit = handler.kwargs['on_exit']
                handlers[id(handler.kwargs['target_action'])] = (
                    on_exit if isinstance(on_exit, list | tuple) else [on_exit])
        codes = []
        queue = []
        for actions in handlers.values():
            for action in actions:
                if (isinstance(action, Node) and action.kwargs['executable'] != 'spawner'
                        and self._holds(action)):
                    raise ValueError(f"OnProcessExit's Node(executable="
                                     f"'{action.kwargs['executable']}') is not started by the "
                                     'launch stand-in')
        for target, actions in handlers.items():
            process = self._process_of.get(target)
            if process is None:
                continue
            deadline = time.monotonic() + PROCESS_EXIT_WAIT_S
            while process.poll() is None and time.monotonic() < deadline:
                harness.spin_until(lambda ended=process: ended.poll() is not None)
            assert process.poll() is not None, (
                f'{process.args[4:6]} did not exit within {PROCESS_EXIT_WAIT_S} s')
            queue.extend(self._spawners(actions))
        queue.extend(self._spawners(self.nodes()))
        while queue:
            spawner = queue.pop(0)
            given = self.arguments_of(spawner)
            arguments = [str(item) for item in perform(spawner.kwargs.get('arguments', []),
                                                      given)]
            # Its own parameter files are --param-files to jazzy's spawner too.
            for parameters in perform(spawner.kwargs.get('parameters', []), given):
                arguments += ['--param-file', str(self._parameter_file(parameters, given))]
            try:
                code = spawner_main(harness, arguments, self._namespace(spawner) or '/')
            except SystemExit as refused:  # its arguments refused, as the program exits
                code = refused.code
            codes.append(code)
            self.spawner_exits.append((arguments, code))
            queue.extend(self._spawners(handlers.get(id(spawner), [])))
        return codes

    def close(self) -> dict[str, str]:
        """End the launch as Ctrl-C ends it: the OnShutdown handlers' actions, then every
        process stopped (SIGINT); return what each wrote on stderr (a stand-in: all)."""
        try:
            self._shut_down(ShutdownEvent(reason='ctrl-c (SIGINT)', due_to_sigint=True))
        finally:
            errors = {}
            for name, process in self.processes.items():
                _ended, errors[name] = sim_process.stop(process, 10.0)
                if name in self._logs:
                    errors[name] = self.output(name)
        return errors

    def _shut_down(self, event: ShutdownEvent) -> None:
        """Carry out each OnShutdown's actions whose registration's condition holds, the
        latest registered first (launch puts a new handler in front).  Their processes are
        not started: launch starts none once it is shutting down."""
        registered = [action for action in self.actions
                      if isinstance(action, RegisterEventHandler) and self._holds(action)]
        for action in reversed(registered):
            handler = action.kwargs.get('event_handler') or action.args[0]
            if not isinstance(handler, OnShutdown):
                continue
            scope = self._scope(action)
            actions = handler.kwargs['on_shutdown']
            if callable(actions):
                actions = actions(event, LaunchContext(scope.arguments))
            if actions is not None:
                self._carry_out(list(actions) if isinstance(actions, list | tuple)
                                else [actions], scope)

    def _carry_out(self, actions: list, scope: Scope) -> list:
        """Carry out the actions in ``scope`` in order; return the actions left, each scoped.

        An include of an installed Python launch file (its condition holding) is
        followed: its launch_arguments set in the scope, as launch sets them (an
        include has no scope of its own), its actions carried out in its place.
        A GroupAction's actions are carried out in a scope of their own.
        """
        left = []
        for action in actions:
            if isinstance(action, list):  # a LaunchDescription among the actions
                left += self._carry_out(action, scope)
                continue
            if not isinstance(action, Recorded):
                raise ValueError(f'{type(action).__name__} is not a launch action the launch '
                                 'stand-in carries out')
            if isinstance(action, SCOPE_ACTIONS) and not self._holds(action, scope.arguments):
                continue
            if isinstance(action, DeclareLaunchArgument | AppendEnvironmentVariable
                          | SetEnvironmentVariable):
                if isinstance(action, DeclareLaunchArgument):
                    action.declare(scope.arguments)
                else:
                    self._set_variable(action, scope)
                self._reach(action, scope)
                left.append(action)
            elif isinstance(action, IncludeLaunchDescription) and self._is_installed(
                    action, scope.arguments):
                if self._holds(action, scope.arguments):
                    for name, value in action.kwargs.get('launch_arguments', []):
                        scope.arguments[text(name, scope.arguments)] = text(value,
                                                                            scope.arguments)
                    left += self._carry_out(_load_file(action.path(scope.arguments)), scope)
            elif isinstance(action, OpaqueFunction):
                left += self._carry_out(action.run(scope.arguments), scope)
            elif isinstance(action, GroupAction):
                left += self._carry_out(*self._group(action, scope))
            elif isinstance(action, PushRosNamespace):
                pushed = text(action.kwargs.get('namespace', action.args[0] if action.args
                                                else ''), scope.arguments)
                scope.namespace = absolute_namespace(prefix_namespace(scope.namespace, pushed))
            elif isinstance(action, SetRemap):
                source, target = [text(action.kwargs.get(key, action.args[index] if len(
                    action.args) > index else ''), scope.arguments)
                    for index, key in enumerate(('src', 'dst'))]
                scope.remaps += ((source, target),)
            elif isinstance(action, SetParameter):
                name, value = [perform(action.kwargs.get(key, action.args[index] if len(
                    action.args) > index else ''), scope.arguments)
                    for index, key in enumerate(('name', 'value'))]
                scope.parameters += ((''.join(name) if isinstance(name, list) else name,
                                      ''.join(value) if isinstance(value, list) else str(value)),)
            elif isinstance(action, LogInfo):
                logging.getLogger('launch').info(text(action.kwargs.get(
                    'msg', action.args[0] if action.args else ''), scope.arguments))
            elif isinstance(action, Node | RegisterEventHandler | ExecuteProcess
                            | IncludeLaunchDescription):
                self._reach(action, scope)
                left.append(action)
            else:
                raise ValueError(f'{type(action).__name__} is not carried out by the launch '
                                 'stand-in')
        return left

    def _reach(self, action: Recorded, scope: Scope) -> None:
        """Keep the scope an action (and a handler's actions) is performed with."""
        reached = scope.snapshot()
        self._scope_of[id(action)] = reached
        if isinstance(action, RegisterEventHandler):
            handler = action.kwargs.get('event_handler') or action.args[0]
            if isinstance(handler, OnShutdown):
                return  # its actions are carried out in this scope when the launch ends
            if not isinstance(handler, OnProcessExit):
                raise ValueError(f'RegisterEventHandler of {type(handler).__name__} is not '
                                 'carried out by the launch stand-in')
            on_exit = handler.kwargs['on_exit']
            for later in on_exit if isinstance(on_exit, list | tuple) else [on_exit]:
                if not isinstance(later, Node):
                    raise ValueError(f'OnProcessExit of {type(later).__name__} is not '
                                     'carried out by the launch stand-in')
                self._scope_of[id(later)] = reached

    def _group(self, action: GroupAction, scope: Scope) -> tuple[list, Scope]:
        """A GroupAction's actions and the scope they are carried out in, as launch makes it."""
        actions = action.kwargs.get('actions', action.args[0] if action.args else [])
        if action.kwargs.get('forwarding', True) is not True:
            raise ValueError('GroupAction(forwarding=False) is not carried out by the launch '
                             'stand-in')
        inner = (dataclasses.replace(scope, arguments=dict(scope.arguments),
                                     environment=dict(scope.environment))
                 if action.kwargs.get('scoped', True) else scope)
        for name, value in (action.kwargs.get('launch_configurations') or {}).items():
            inner.arguments[text(name, scope.arguments)] = text(value, scope.arguments)
        return list(actions), inner

    def _set_variable(self, action: Recorded, scope: Scope) -> None:
        """Carry out (Append|Set)EnvironmentVariable for the processes started after it."""
        given = scope.arguments
        name = text(action.args[0] if action.args else action.kwargs['name'], given)
        value = text(action.args[1] if len(action.args) > 1 else action.kwargs['value'], given)
        old = scope.environment.get(name, os.environ.get(name, ''))
        if isinstance(action, AppendEnvironmentVariable) and old:
            separator = action.kwargs.get('separator', os.pathsep)
            value = (value + separator + old if truth(text(
                action.kwargs.get('prepend', 'false'), given)) else
                old + separator + value)
        scope.environment[name] = value

    def _is_installed(self, action: IncludeLaunchDescription,
                      arguments: dict[str, str]) -> bool:
        """Whether the include names an installed Python launch file (pan_tilt_sim's or any
        package's in the ament index): one of a package not installed (ros_gz_sim) is not."""
        from ament_index_python.packages import PackageNotFoundError

        try:
            included = action.path(arguments)
        except PackageNotFoundError:  # another package's (ros_gz_sim's, not installed here)
            return False
        return included.suffix == '.py' and included.is_file()

    def _holds(self, action: Recorded, arguments: dict[str, str] | None = None) -> bool:
        """Whether the action's condition (if any) holds (in its scope unless given one)."""
        return perform(action.kwargs.get('condition', True),
                       self.arguments_of(action) if arguments is None else arguments)

    def _spawners(self, actions: Iterable) -> list[Node]:
        """The spawner nodes among ``actions`` whose condition holds (others are not run here)."""
        return [action for action in actions if isinstance(action, Node)
                and action.kwargs['executable'] == 'spawner' and self._holds(action)]

    def _namespace(self, node: Node) -> str | None:
        """The node's namespace as launch_ros makes it: its own under its scope's pushed one."""
        own = node.kwargs.get('namespace')
        return absolute_namespace(prefix_namespace(
            self._scope(node).namespace,
            None if own is None else text(own, self.arguments_of(node))))

    def ros_args(self, node: Node) -> list[str]:
        """The node's ROS arguments, in launch_ros' order: name, namespace, the scope's
        parameters, its own, the scope's remaps, its own."""
        scope, args = self._scope(node), []
        given = scope.arguments
        name = text(node.kwargs.get('name') or '', given)
        namespace = self._namespace(node)
        if name:
            args += ['-r', f'__node:={name}']
        if namespace not in (None, '/'):
            args += ['-r', f'__ns:={namespace}']
        for parameter, value in scope.parameters:
            args += ['-p', f'{parameter}:={value}']
        for parameters in perform(node.kwargs.get('parameters', []), given):
            args += ['--params-file', str(self._parameter_file(parameters, given))]
        for source, target in [*scope.remaps, *node.kwargs.get('remappings', [])]:
            args += ['-r', f'{text(source, given)}:={text(target, given)}']
        return args + [str(item) for item in perform(node.kwargs.get('ros_arguments', []),
                                                      given)]

    def _parameter_file(self, parameters: Any, arguments: dict[str, str]) -> pathlib.Path:
        """A file name stays; a dict is written under ``/**``, as launch_ros writes it."""
        self._files += 1
        path = self.folder / f'launch_params_{self._files}.yaml'
        if isinstance(parameters, ParameterFile):
            text = pathlib.Path(perform(parameters.args[0], arguments)).read_text()
            if parameters.kwargs.get('allow_substs'):
                text = SUBSTITUTION.sub(lambda match: arguments[match[1]], text)
            path.write_text(text)
            return path
        if not isinstance(parameters, dict):
            return pathlib.Path(parameters)
        path.write_text(yaml.safe_dump({'/**': {'ros__parameters': _typed(parameters)}}))
        return path


def _typed(value: Any) -> Any:
    """A dict's text values typed as launch_ros types them: read as YAML, a bool, int or
    float is taken as such ('True' is true); any other text stays text."""
    if isinstance(value, dict):
        return {key: _typed(item) for key, item in value.items()}
    if isinstance(value, str) and value:
        try:
            read = yaml.safe_load(value)
        except yaml.YAMLError:
            return value
        return read if type(read) in (bool, int, float) else value
    return value
