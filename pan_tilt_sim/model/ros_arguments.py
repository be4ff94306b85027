"""ROS command-line arguments (``--ros-args ...``), read as rcl reads them, without rclpy.

Two places hand sim_node such arguments as data rather than through rcl:

* ros2_control's controller_manager passes its own ``--params-file`` and
  ``-p`` arguments on to every controller node it creates, so a controller
  finds its section of the YAML the launch file gave the controller_manager
  (``parameters=[robot_controllers]``); sim_node, standing in for it, reads
  those sections from the same files.
* the spawner's ``--controller-ros-args "-r ~/cmd_vel:=/cmd_vel"`` reaches
  the controller_manager as ``<controller>.node_options_args``, the
  arguments of the controller's own node: remaps of its topic names, ``-p``
  parameters, ``--params-file`` files.

Design notes: docs/design/model.md#ros_argumentspy.
"""

from __future__ import annotations

import dataclasses
import pathlib
from collections.abc import Sequence
from typing import Any

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model import naming, yaml_input

ROS_ARGS = '--ros-args'
END_OF_ROS_ARGS = '--'
REMAP_FLAGS = ('-r', '--remap')
PARAM_FLAGS = ('-p', '--param')
PARAMS_FILE_FLAG = '--params-file'
# rcl's other flags that take a value (skipped with it); the rest stand alone.
VALUED_FLAGS = ('-e', '--enclave', '--log-level', '--log-config-file', '--log-file-name')
SEPARATOR = ':='
PRIVATE = '~'
NODE_NAME_RULE = '__node'
NAMESPACE_RULES = ('__ns',)
SUBSTITUTIONS = ('{node}', '{ns}', '{namespace}')


@dataclasses.dataclass(frozen=True)
class Remap:
    """One ``-r [node:]from:=to`` rule."""

    source: str
    target: str
    node: str | None = None

    def applies_to(self, node: str) -> bool:
        """Whether the rule is for ``node`` (a rule without a node name is for every node)."""
        return self.node is None or self.node == node


@dataclasses.dataclass(frozen=True)
class RosArguments:
    """The arguments of one node's ``--ros-args`` sections that sim_node reads itself."""

    params_files: tuple[pathlib.Path, ...] = ()
    # (node or None, name, value as written); the value is YAML, as rcl reads it.
    parameters: tuple[tuple[str | None, str, str], ...] = ()
    remaps: tuple[Remap, ...] = ()

    def parameters_for(self, node: str) -> dict[str, Any]:
        """Return the ``-p`` values for ``node`` (later ones win), each read as YAML."""
        values: dict[str, Any] = {}
        for owner, name, text in self.parameters:
            if owner is None or owner == node:
                values[name] = parameter_value(text)
        return values

    def remapped(self, name: str, namespace: str, node: str) -> str:
        """Return the absolute topic ``name`` of ``node`` after the first rule that matches it."""
        for rule in self.remaps:
            if rule.applies_to(node) and expand(rule.source, namespace, node) == name:
                return expand(rule.target, namespace, node)
        return name


def parse_ros_arguments(argv: Sequence[str], field: str, *,
                        whole: bool = False) -> RosArguments:
    """Read the ``--ros-args`` sections of ``argv`` (all of it with ``whole``).

    ``whole``: ``argv`` holds ROS arguments only (a controller's
    ``node_options_args``, where ``--ros-args`` is optional).  Errors name
    ``field`` and the argument.
    """
    params_files: list[pathlib.Path] = []
    parameters: list[tuple[str | None, str, str]] = []
    remaps: list[Remap] = []
    inside = whole
    items = iter(argv)
    for item in items:
        if item == ROS_ARGS:
            inside = True
            continue
        if not inside:
            continue
        if item == END_OF_ROS_ARGS:
            inside = whole
            continue
        if item in (*REMAP_FLAGS, *PARAM_FLAGS, PARAMS_FILE_FLAG, *VALUED_FLAGS):
            value = next(items, None)
            if value is None:
                raise ParameterError(f"{field}: '{item}' must be followed by a value")
            if item in REMAP_FLAGS:
                remaps.append(_remap(value, field))
            elif item in PARAM_FLAGS:
                parameters.append(_parameter(value, field))
            elif item == PARAMS_FILE_FLAG:
                params_files.append(pathlib.Path(value).expanduser())
            continue
        if whole and not item.startswith('--'):
            raise ParameterError(
                f"{field}: '{item}' is not a ROS argument (expected -r from:=to, -p name:=value "
                f'or --params-file FILE)')
    return RosArguments(tuple(params_files), tuple(parameters), tuple(remaps))


def _split_rule(text: str, flag: str, field: str) -> tuple[str | None, str, str]:
    left, separator, right = text.partition(SEPARATOR)
    if not separator or not left:
        raise ParameterError(f"{field}: '{flag} {text}' is not of the form [node:]name:=value")
    node, colon, name = left.rpartition(':')
    return (node if colon else None), name, right


def _remap(text: str, field: str) -> Remap:
    node, source, target = _split_rule(text, '-r', field)
    if not target:
        raise ParameterError(f"{field}: '-r {text}' remaps to nothing")
    return Remap(source, target, node)


def _parameter(text: str, field: str) -> tuple[str | None, str, str]:
    return _split_rule(text, '-p', field)


def parameter_value(text: str) -> Any:
    """Return a ``-p name:=value`` value as rcl reads it: YAML (``1`` int, ``[a, b]`` a list)."""
    try:
        value = yaml_input.load(text)
    except yaml_input.YamlInputError:
        return text
    return text if value is None and text.strip() not in ('null', '~') else value


def expand(name: str, namespace: str, node: str) -> str:
    """Expand a topic name of ``node`` in ``namespace`` into an absolute one, as rcl does."""
    namespace = naming.normalize(namespace)
    for token in SUBSTITUTIONS:
        name = name.replace(token, node if token == '{node}' else namespace or '/')
    if name == PRIVATE or name.startswith(PRIVATE + '/'):
        rest = name[len(PRIVATE):].strip('/')
        return naming.join(namespace, node, rest) if rest else naming.join(namespace, node)
    if name.startswith('/'):
        return name
    return naming.join(namespace, name)


def node_rules(arguments: RosArguments, node: str) -> list[str]:
    """Return the ``__node``/``__ns`` rules among ``arguments`` that apply to ``node``."""
    return [f'{rule.source}:={rule.target}' for rule in arguments.remaps
            if rule.applies_to(node) and rule.source in (NODE_NAME_RULE, *NAMESPACE_RULES)]

