"""Reading controller YAML: the seeds' ROS 1 layout and ros2_control's.

ROS 1 style (``rosparam load``), as in both seeds::

    ex_urdf_pan_tilt:                      # optional: one key wrapping them all
      joint_state_controller:
        type: joint_state_controller/JointStateController
        publish_rate: 50
      joint1_position_controller:
        type: position_controllers/JointPositionController
        joint: pan_joint
        pid: {p: 100.0, i: 0.01, d: 10.0}

A single top-level key whose value holds the controllers is the robot's
namespace, as ``rosparam load`` inside ``ns=...`` would make it.  Beside the
controllers, gazebo_ros_control's own PID gains for a joint's position or
velocity interface, ``gazebo_ros_control: {pid_gains: {<joint>: {p, i, d}}}``,
are kept as written (:attr:`ControllersConfig.pid_gains`).

ros2_control style (a ROS 2 parameter file), recognised by its
``ros__parameters`` keys::

    controller_manager:
      ros__parameters:
        update_rate: 100
        arm_controller:
          type: joint_trajectory_controller/JointTrajectoryController
    arm_controller:
      ros__parameters:
        joints: [shoulder_joint, elbow_joint]
        gains: {shoulder_joint: {p: 100.0, i: 0.01, d: 10.0}}

The controllers are the entries with a ``type`` under any node's
``ros__parameters`` (normally the controller_manager's); each takes the
``ros__parameters`` of the node of its name.  Node keys may carry a
namespace (``/robot/arm_controller``, or nested mappings), which is
ignored -- the last name token is the node -- and wildcard keys such as
``/**`` give parameters to every node they match, under the node's own
(the node's own win).  Dotted names (``gains.shoulder_joint.p: 100.0``)
mean the same as nested mappings, as in ROS 2.  As in ros2_control, every
controller's ``update_rate`` defaults to the controller_manager's, which
defaults to 100 Hz.  The file gives no namespace: the robot's namespace
comes from the node, the ``robot_namespace`` parameter or the URDF plugin.
"""

from __future__ import annotations

import dataclasses
import fnmatch
import math
import pathlib
from collections.abc import Mapping
from typing import Any

import yaml

from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model import naming

TYPE_FIELD = 'type'
ROS2_PARAMETERS = 'ros__parameters'
UPDATE_RATE_FIELD = 'update_rate'
CONTROLLER_MANAGER = 'controller_manager'
GAZEBO_ROS_CONTROL = 'gazebo_ros_control'
PID_GAINS = 'pid_gains'
# ros2_control's controller_manager runs at 100 Hz unless told otherwise.
DEFAULT_UPDATE_RATE = 100.0
NAME_SEPARATOR = '/'
PARAMETER_SEPARATOR = '.'
WILDCARD_CHARACTERS = '*?['


@dataclasses.dataclass(frozen=True)
class ControllerSpec:
    """One controller's name, YAML ``type`` string and parameters."""

    name: str
    type: str
    params: Mapping[str, Any]


@dataclasses.dataclass(frozen=True)
class ControllersConfig:
    """The controllers of one file, and the namespace the file wraps them in."""

    controllers: tuple[ControllerSpec, ...]
    source: pathlib.Path
    namespace: str | None = None
    # gazebo_ros_control/pid_gains/<joint>: {p, i, d, ...} as written (ROS 1 layout).
    pid_gains: Mapping[str, Any] = dataclasses.field(default_factory=dict)


def read_yaml(path: pathlib.Path) -> Any:
    """Parse a YAML file; errors name the file and, for syntax errors, the line."""
    if path.is_dir():
        raise ControllerConfigError(f'controllers file {path}: is a directory, not a file')
    if not path.is_file():
        raise ControllerConfigError(f'controllers file {path}: no such file')
    try:
        text = path.read_text(encoding='utf-8')
    except (OSError, UnicodeDecodeError) as err:
        raise ControllerConfigError(f'controllers file {path}: cannot read: {err}') from None
    try:
        return yaml.safe_load(text)
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        line = f':{mark.line + 1}' if mark is not None else ''
        problem = err.problem or err.context or 'invalid YAML'
        raise ControllerConfigError(f'{path}{line}: YAML syntax error: {problem}') from None
    except yaml.YAMLError as err:
        raise ControllerConfigError(f'{path}: YAML error: {err}') from None


def load_controllers_config(path: pathlib.Path | str) -> ControllersConfig:
    """Read the controllers file at ``path``."""
    path = pathlib.Path(path).expanduser().resolve()
    document = read_yaml(path)
    if not isinstance(document, Mapping) or not document:
        raise ControllerConfigError(f'{path}: no controllers in it (expected a YAML mapping)')
    nodes = _ros2_nodes(document, path)
    if nodes:
        return _ros2_control_config(nodes, path)
    namespace = None
    holder: Mapping[Any, Any] = document
    controllers = _controllers_in(document)
    if not controllers and len(document) == 1:
        (key, inner), = document.items()
        if isinstance(inner, Mapping):
            controllers = _controllers_in(inner)
            namespace = str(key) if controllers else None
            holder = inner
    if not controllers:
        raise ControllerConfigError(
            f"{path}: no controllers in it (a controller is a mapping with a '{TYPE_FIELD}')")
    _check_names(path, controllers, namespace)
    return ControllersConfig(controllers=tuple(controllers), source=path, namespace=namespace,
                             pid_gains=_plugin_pid_gains(holder, path))


def _plugin_pid_gains(holder: Mapping[Any, Any], path: pathlib.Path) -> dict[str, Any]:
    """Return ``gazebo_ros_control: pid_gains:`` beside the controllers, by joint ({} if none)."""
    plugin = holder.get(GAZEBO_ROS_CONTROL)
    if plugin is None:
        return {}
    gains = plugin.get(PID_GAINS) if isinstance(plugin, Mapping) else None
    if gains is None and isinstance(plugin, Mapping):
        return {}
    if not isinstance(gains, Mapping):
        raise ControllerConfigError(
            f'{path}: {GAZEBO_ROS_CONTROL}.{PID_GAINS}: expected a mapping of joint names '
            'to {p, i, d}')
    return {str(joint): entry for joint, entry in gains.items()}


def _check_names(path: pathlib.Path, controllers: list[ControllerSpec],
                 namespace: str | None) -> None:
    """Names end up in topic names: refuse what rclpy would refuse later, with a traceback."""
    if namespace is not None and not naming.is_valid_namespace(naming.normalize(namespace)):
        raise ControllerConfigError(
            f"{path}: top-level key '{namespace}' (the robot's namespace) is not a valid ROS "
            f'namespace ({naming.NAMESPACE_RULE})')
    for spec in controllers:
        if not naming.is_valid_name(spec.name):
            raise ControllerConfigError(
                f"{path}: controller name '{spec.name}' is not a valid ROS name "
                f'({naming.NAME_RULE}); it becomes part of its topic names')


def _controllers_in(mapping: Mapping[Any, Any]) -> list[ControllerSpec]:
    return [
        ControllerSpec(name=str(name), type=value[TYPE_FIELD], params=value)
        for name, value in mapping.items()
        if isinstance(value, Mapping) and TYPE_FIELD in value
    ]


def _ros2_nodes(document: Mapping[Any, Any],
                path: pathlib.Path) -> list[tuple[str, dict[str, Any]]]:
    """Return ``(node name or pattern, parameters)`` for every ``ros__parameters`` key."""
    nodes = []

    def visit(mapping: Mapping[Any, Any], prefix: str) -> None:
        for key, value in mapping.items():
            if not isinstance(value, Mapping):
                continue
            key_path = f'{prefix}{NAME_SEPARATOR}{key}'
            if ROS2_PARAMETERS in value:
                parameters = value[ROS2_PARAMETERS]
                if parameters is None:
                    parameters = {}
                if not isinstance(parameters, Mapping):
                    raise ControllerConfigError(
                        f'{path}: {key_path.lstrip(NAME_SEPARATOR)}.{ROS2_PARAMETERS}: '
                        'expected a mapping of parameters')
                node = key_path.rstrip(NAME_SEPARATOR).rsplit(NAME_SEPARATOR, 1)[-1]
                nodes.append((node, _unflatten(parameters)))
            else:
                visit(value, key_path)

    visit(document, '')
    return nodes


def _unflatten(parameters: Mapping[Any, Any]) -> dict[str, Any]:
    """Turn ROS 2's dotted parameter names into nested mappings."""
    nested: dict[str, Any] = {}
    for key, value in parameters.items():
        *parents, leaf = str(key).split(PARAMETER_SEPARATOR)
        target = nested
        for parent in parents:
            inner = target.get(parent)
            if not isinstance(inner, dict):
                inner = target[parent] = {}
            target = inner
        value = _unflatten(value) if isinstance(value, Mapping) else value
        _merge_into(target, {leaf: value})
    return nested


def _merge_into(target: dict[str, Any], overrides: Mapping[str, Any]) -> None:
    """Deep-merge ``overrides`` into ``target``; overrides win, mappings merge."""
    for key, value in overrides.items():
        if isinstance(value, Mapping) and isinstance(target.get(key), dict):
            _merge_into(target[key], value)
        else:
            target[key] = dict(value) if isinstance(value, Mapping) else value


def _ros2_control_config(nodes: list[tuple[str, dict[str, Any]]],
                         path: pathlib.Path) -> ControllersConfig:
    patterns: list[tuple[str, dict[str, Any]]] = []
    own: dict[str, dict[str, Any]] = {}
    for name, params in nodes:
        if any(character in name for character in WILDCARD_CHARACTERS):
            patterns.append((name, params))
        else:
            _merge_into(own.setdefault(name, {}), params)

    def parameters_of(node: str) -> dict[str, Any]:
        merged: dict[str, Any] = {}
        for pattern, params in patterns:
            if fnmatch.fnmatchcase(node, pattern):
                _merge_into(merged, params)
        _merge_into(merged, own.get(node, {}))
        return merged

    update_rate = _update_rate(parameters_of(CONTROLLER_MANAGER), path)
    # Controllers are declared as `<name>: {type: ...}` entries (normally the
    # controller_manager's), or, since Jazzy, by a `type` among their own parameters.
    declared: dict[str, Any] = {}
    for node in [CONTROLLER_MANAGER, *own]:
        for name, entry in parameters_of(node).items():
            if isinstance(entry, Mapping) and TYPE_FIELD in entry:
                declared.setdefault(str(name), entry[TYPE_FIELD])
    for node, params in own.items():
        if isinstance(params.get(TYPE_FIELD), str):
            declared.setdefault(node, params[TYPE_FIELD])
    controllers = []
    for name, type_name in declared.items():
        params: dict[str, Any] = {UPDATE_RATE_FIELD: update_rate}
        _merge_into(params, parameters_of(name))
        params[TYPE_FIELD] = type_name
        controllers.append(ControllerSpec(name=name, type=type_name, params=params))
    if not controllers:
        raise ControllerConfigError(
            f'{path}: no controllers in it (ros2_control style: expected '
            f'{CONTROLLER_MANAGER}: {ROS2_PARAMETERS}: <name>: {{{TYPE_FIELD}: ...}})')
    return ControllersConfig(controllers=tuple(controllers), source=path)


def _update_rate(manager: Mapping[str, Any], path: pathlib.Path) -> float:
    rate = manager.get(UPDATE_RATE_FIELD, DEFAULT_UPDATE_RATE)
    if isinstance(rate, bool) or not isinstance(rate, int | float) or not (
            math.isfinite(rate) and rate > 0):
        raise ControllerConfigError(
            f'{path}: {CONTROLLER_MANAGER}.{ROS2_PARAMETERS}.{UPDATE_RATE_FIELD}: '
            f'{rate!r} must be a number of Hz > 0')
    return float(rate)
