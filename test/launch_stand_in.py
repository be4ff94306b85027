"""A small stand-in of ROS 2's launch API that runs a ros2_control launch file's shape.

``launch`` and ``launch_ros`` are not on PyPI.  :func:`load` runs a launch
file's ``generate_launch_description()`` against stand-in modules that record
what it asks for (Node, RegisterEventHandler + OnProcessExit, Command,
PathJoinSubstitution, PathSubstitution, FindPackageShare, LaunchConfiguration,
DeclareLaunchArgument, IfCondition, UnlessCondition, ParameterFile; IncludeLaunchDescription
is recorded and refused when it would run), and
:class:`StandInLaunch` carries the nodes out, as launch_ros would start them:

* ``pan_tilt_sim``'s ``sim_node`` as a process, ``--ros-args -r
  __node:=<name>`` and its parameters as ``--params-file`` arguments (a dict
  written to a file under ``/**``, as launch_ros writes one);
* ``robot_state_publisher`` as the stand-in program of
  test/robot_state_publisher_stand_in.py, with its parameters so;
* ``controller_manager``'s ``spawner`` in-process, playing jazzy's spawner
  (test/spawner_client.py), and each OnProcessExit's actions once it ended.
"""

from __future__ import annotations

import importlib.util
import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys
import types
from collections.abc import Iterator
from typing import Any

import sim_process
import yaml
from spawner_client import spawner_main

HERE = pathlib.Path(__file__).resolve().parent
STAND_IN_MODULES = ('launch', 'launch.actions', 'launch.conditions', 'launch.event_handlers',
                    'launch.launch_description_sources', 'launch.substitutions', 'launch_ros',
                    'launch_ros.actions', 'launch_ros.parameter_descriptions',
                    'launch_ros.substitutions')
SUBSTITUTION = re.compile(r'\$\(var ([A-Za-z0-9_]+)\)')


class Recorded:
    """A launch action or substitution: keeps its arguments."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.args, self.kwargs = args, kwargs


class Node(Recorded):
    """launch_ros.actions.Node."""


class RegisterEventHandler(Recorded):
    """launch.actions.RegisterEventHandler."""


class OnProcessExit(Recorded):
    """launch.event_handlers.OnProcessExit."""


class Command(Recorded):
    """launch.substitutions.Command: the words, run; its stdout."""


class PathJoinSubstitution(Recorded):
    """launch.substitutions.PathJoinSubstitution."""


class PathSubstitution(Recorded):
    """launch.substitutions.PathSubstitution: ``/`` joins a part on."""

    def __truediv__(self, part: Any) -> PathSubstitution:
        return PathSubstitution(PathJoinSubstitution([self, part]))


class DeclareLaunchArgument(Recorded):
    """launch.actions.DeclareLaunchArgument: a name and its default_value."""


class IfCondition(Recorded):
    """launch.conditions.IfCondition: true when its text is 'true' (any case) or '1'."""


class UnlessCondition(Recorded):
    """launch.conditions.UnlessCondition: false when its text is 'true' (any case) or '1'."""


class IncludeLaunchDescription(Recorded):
    """launch.actions.IncludeLaunchDescription: another package's launch file (Gazebo's).

    The stand-in does not run other packages' launch files; :class:`StandInLaunch`
    refuses one that is left in (its condition holding).
    """


class PythonLaunchDescriptionSource(Recorded):
    """launch.launch_description_sources.PythonLaunchDescriptionSource."""


class ParameterFile(Recorded):
    """launch_ros ParameterFile: a file; with allow_substs its $(var name) are filled in."""


class FindPackageShare(Recorded):
    """launch_ros.substitutions.FindPackageShare."""


class LaunchConfiguration(Recorded):
    """launch.substitutions.LaunchConfiguration."""


def modules() -> dict[str, types.ModuleType]:
    """Return the stand-in modules, by name."""
    made = {name: types.ModuleType(name) for name in STAND_IN_MODULES}
    made['launch'].LaunchDescription = list
    made['launch.actions'].RegisterEventHandler = RegisterEventHandler
    made['launch.actions'].DeclareLaunchArgument = DeclareLaunchArgument
    made['launch.conditions'].IfCondition = IfCondition
    made['launch.conditions'].UnlessCondition = UnlessCondition
    made['launch.actions'].IncludeLaunchDescription = IncludeLaunchDescription
    made['launch.launch_description_sources'].PythonLaunchDescriptionSource = (
        PythonLaunchDescriptionSource)
    made['launch.substitutions'].PathSubstitution = PathSubstitution
    made['launch_ros.parameter_descriptions'].ParameterFile = ParameterFile
    made['launch.event_handlers'].OnProcessExit = OnProcessExit
    made['launch.substitutions'].Command = Command
    made['launch.substitutions'].PathJoinSubstitution = PathJoinSubstitution
    made['launch.substitutions'].LaunchConfiguration = LaunchConfiguration
    made['launch_ros.actions'].Node = Node
    made['launch_ros.substitutions'].FindPackageShare = FindPackageShare
    return made


def load(path: pathlib.Path, monkeypatch) -> list:
    """Return the actions of the launch file at ``path``, made with the stand-in modules."""
    for name, module in modules().items():
        monkeypatch.setitem(sys.modules, name, module)
    spec = importlib.util.spec_from_file_location('launch_file_under_test', path)
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
        return perform(value.args[0], arguments).strip().lower() in ('true', '1')
    if isinstance(value, UnlessCondition):
        return perform(value.args[0], arguments).strip().lower() not in ('true', '1')
    if isinstance(value, LaunchConfiguration):
        return arguments[value.args[0]]
    if isinstance(value, Command):
        words = shlex.split(''.join(perform(part, arguments) for part in value.args[0]))
        words[0] = shutil.which(words[0], path=os.path.dirname(sys.executable)) or words[0]
        return subprocess.run(words, capture_output=True, text=True, check=True).stdout
    if isinstance(value, list | tuple):
        return [perform(item, arguments) for item in value]
    if isinstance(value, dict):
        return {key: perform(item, arguments) for key, item in value.items()}
    return value


class StandInLaunch:
    """Carries out a launch description's nodes; :meth:`close` stops the processes."""

    def __init__(self, actions: list, folder: pathlib.Path,
                 arguments: dict[str, str] | None = None) -> None:
        self.actions = actions
        self.folder = folder
        self.arguments = {action.args[0]: action.kwargs.get('default_value', '')
                          for action in actions if isinstance(action, DeclareLaunchArgument)}
        self.arguments.update(arguments or {})
        self.processes: dict[str, subprocess.Popen] = {}
        self.spawner_exits: list[tuple[list[str], int]] = []
        self._files = 0

    def nodes(self) -> Iterator[Node]:
        """The Node actions started at once (not those an event waits for) whose condition holds."""
        return (action for action in self.actions if isinstance(action, Node) and perform(
            action.kwargs.get('condition', True), self.arguments))

    def start_processes(self) -> None:
        """Start every node that runs as a process (all but the spawners).

        An included launch file whose condition holds is refused (ValueError):
        the stand-in runs only this file's nodes.
        """
        for action in self.actions:
            if isinstance(action, IncludeLaunchDescription) and perform(
                    action.kwargs.get('condition', True), self.arguments):
                raise ValueError(f'IncludeLaunchDescription({action.args[0].args[0]!r}) is '
                                 'not carried out by the launch stand-in')
        for node in self.nodes():
            package, executable = node.kwargs['package'], node.kwargs['executable']
            if (package, executable) == ('pan_tilt_sim', 'sim_node'):
                self.processes['sim_node'] = sim_process.start(*self._ros_args(node))
            elif package == 'robot_state_publisher':
                command = [sys.executable, str(HERE / 'robot_state_publisher_stand_in.py'),
                           '--ros-args', *self._ros_args(node)]
                self.processes['robot_state_publisher'] = subprocess.Popen(
                    command, env=sim_process.environment(), stdout=subprocess.DEVNULL,
                    stderr=subprocess.PIPE, text=True)

    def run_spawners(self, harness) -> list[int]:
        """Run the spawners in order, each OnProcessExit's actions after its target; exits."""
        handlers = {id(action.args[0].kwargs['target_action']): action.args[0].kwargs['on_exit']
                    for action in self.actions if isinstance(action, RegisterEventHandler)}
        codes = []
        queue = [node for node in self.nodes() if node.kwargs['executable'] == 'spawner']
        while queue:
            spawner = queue.pop(0)
            arguments = [str(item) for item in perform(spawner.kwargs.get('arguments', []),
                                                      self.arguments)]
            # Its own parameter files are --param-files to jazzy's spawner too.
            for parameters in perform(spawner.kwargs.get('parameters', []), self.arguments):
                arguments += ['--param-file', str(self._parameter_file(parameters))]
            code = spawner_main(harness, arguments, spawner.kwargs.get('namespace') or '/')
            codes.append(code)
            self.spawner_exits.append((arguments, code))
            queue.extend(handlers.get(id(spawner), []))
        return codes

    def close(self) -> dict[str, str]:
        """Stop every process (SIGINT); return what each wrote on stderr."""
        errors = {}
        for name, process in self.processes.items():
            _ended, errors[name] = sim_process.stop(process, 10.0)
        return errors

    def _ros_args(self, node: Node) -> list[str]:
        args = []
        if node.kwargs.get('name'):
            args += ['-r', f"__node:={node.kwargs['name']}"]
        if node.kwargs.get('namespace'):
            args += ['-r', f"__ns:={node.kwargs['namespace']}"]
        for parameters in perform(node.kwargs.get('parameters', []), self.arguments):
            args += ['--params-file', str(self._parameter_file(parameters))]
        for source, target in node.kwargs.get('remappings', []):
            args += ['-r', f'{source}:={target}']
        return args

    def _parameter_file(self, parameters: Any) -> pathlib.Path:
        """A file name stays; a dict is written under ``/**``, as launch_ros writes it."""
        self._files += 1
        path = self.folder / f'launch_params_{self._files}.yaml'
        if isinstance(parameters, ParameterFile):
            text = pathlib.Path(perform(parameters.args[0], self.arguments)).read_text()
            if parameters.kwargs.get('allow_substs'):
                text = SUBSTITUTION.sub(lambda match: self.arguments[match[1]], text)
            path.write_text(text)
            return path
        if not isinstance(parameters, dict):
            return pathlib.Path(parameters)
        path.write_text(yaml.safe_dump({'/**': {'ros__parameters': parameters}}))
        return path
