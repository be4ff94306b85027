"""Reading controller YAML: the examples' ROS 1 layout and ros2_control's.

ROS 1 style (``rosparam load``), as in both examples::

    ex_urdf_pan_tilt:                      # optional: one key wrapping them all
      joint_state_controller:
        type: joint_state_controller/JointStateController
        publish_rate: 50
      joint1_position_controller:
        type: position_controllers/JointPositionController
        joint: pan_joint
        pid: {p: 100.0, i: 0.01, d: 10.0}

Design notes: docs/design/model.md#controller_configpy.
"""

from __future__ import annotations

import dataclasses
import fnmatch
import os
import pathlib
import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from pan_tilt_sim.errors import ConfigurationError, ControllerConfigError
from pan_tilt_sim.model import naming, yaml_input
from pan_tilt_sim.model.rates import rate_problem
from pan_tilt_sim.model.resources import resolve_resource
from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_ROBOT_NAME, package_share

if TYPE_CHECKING:
    from pan_tilt_sim.model.description import RobotDescription

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
MAPPING_SEPARATOR = ':='
CONTROLLERS_ARGS = 'controllers_args'
CONTROLLERS_FILE = 'controllers_file'
# A launch substitution: $(kind arg arg...); nested substitutions are not expanded.
SUBSTITUTION = re.compile(
    r'\$\((?P<kind>[A-Za-z][A-Za-z0-9_-]*)(?P<args>(?:[ \t]+[^()\s]+)*)[ \t]*\)')
VARIABLE_KINDS = ('var', 'arg')  # launch's LaunchConfiguration; ROS 1's roslaunch arg
EXPANDED_KINDS = (*VARIABLE_KINDS, 'env', 'optenv', 'find-pkg-share', 'find-pkg-prefix')


@dataclasses.dataclass(frozen=True)
class ControllerSpec:
    """One controller's name, YAML ``type`` string and parameters."""

    name: str
    type: str
    params: Mapping[str, Any]


@dataclasses.dataclass(frozen=True)
class ControllersConfig:
    """The controllers of one file (or several, read in order), and the namespace they share.

    ``update_rate`` is the controller_manager's (ros2_control style files
    only; None for ROS 1 files).
    """

    controllers: tuple[ControllerSpec, ...]
    source: pathlib.Path
    namespace: str | None = None
    sources: tuple[pathlib.Path, ...] = ()
    update_rate: float | None = None
    # gazebo_ros_control/pid_gains/<joint>: {p, i, d, ...} as written (ROS 1 layout).
    pid_gains: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    # One line each (naming the file): what the file holds that the reader's rules drop.
    warnings: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        """How errors name the file(s)."""
        return ' + '.join(str(path) for path in self.sources) or str(self.source)


def parse_controllers_args(items: Sequence[str], field: str = CONTROLLERS_ARGS) -> dict[str, str]:
    """Turn ``['name:=value', ...]`` into substitution values; errors name ``field``."""
    values = {}
    for item in items:
        name, separator, value = item.partition(MAPPING_SEPARATOR)
        if not separator or not name.strip():
            raise ControllerConfigError(f"{field}: '{item}' is not of the form name:=value")
        values[name.strip()] = value
    return values


def expand_substitutions(text: str, values: Mapping[str, str]) -> str:
    """Expand the launch substitutions in ``text`` that can be; leave the others as written."""
    def replace(match: re.Match) -> str:
        expanded = _expansion(match, values)
        return match.group(0) if expanded is None else expanded
    return SUBSTITUTION.sub(replace, text)


def _expansion(match: re.Match, values: Mapping[str, str]) -> str | None:
    kind, args = match['kind'], match['args'].split()
    if not args and kind != 'optenv':
        return None
    if kind in VARIABLE_KINDS:
        name, default = args[0], args[1:]
        return values.get(name, ' '.join(default) if default else None)
    if kind in ('env', 'optenv'):
        if not args:
            return None
        default = ' '.join(args[1:]) if len(args) > 1 else ('' if kind == 'optenv' else None)
        return os.environ.get(args[0], default)
    if kind in ('find-pkg-share', 'find-pkg-prefix') and len(args) == 1:
        try:
            share = resolve_resource(f'package://{args[0]}/.', pathlib.Path.cwd())
        except ConfigurationError:
            return None
        return str(share if kind == 'find-pkg-share' else share.parent.parent)
    return None


def _unexpanded_problem(match: re.Match, args_name: str) -> str:
    kind, args = match['kind'], match['args'].split()
    text = match.group(0)
    if kind in VARIABLE_KINDS and args:
        return (f"{text} is not set: give it in {args_name} as '{args[0]}:=<value>' "
                f'(a launch file would fill it from its arguments)')
    if kind == 'env' and args:
        return f'{text}: the environment variable {args[0]} is not set'
    if kind in ('find-pkg-share', 'find-pkg-prefix') and len(args) == 1:
        return f"{text}: package '{args[0]}' is not in the ament index"
    return (f'{text} is a launch substitution sim_node does not expand (it expands '
            f"{', '.join(f'$({kind} ...)' for kind in EXPANDED_KINDS)})")


def _leftover_substitution(value: Any) -> re.Match | None:
    """Return the first substitution left in a parsed document (keys and values)."""
    if isinstance(value, str):
        return SUBSTITUTION.search(value)
    if isinstance(value, Mapping):
        items = [item for pair in value.items() for item in pair]
    elif isinstance(value, list | tuple):
        items = list(value)
    else:
        return None
    for item in items:
        found = _leftover_substitution(item)
        if found is not None:
            return found
    return None


def _line_of(text: str, needle: str) -> str:
    """Return ':<line>' of the first line outside comments holding ``needle``, or ''."""
    for number, line in enumerate(text.splitlines(), 1):
        if needle in line.split('#', 1)[0]:
            return f':{number}'
    return ''


def controllers_files_for(given: str, description: RobotDescription, *,
                          given_as: str = f"the parameter '{CONTROLLERS_FILE}'",
                          runs_by_plugins: bool = False) -> tuple[pathlib.Path, ...]:
    """Return the controller YAML file(s) to use for ``description``.

    ``given`` (the user's ``controllers_file``) wins; relative paths are
    taken from the current directory, ``package://`` works too.  Else the
    files the URDF's control plugin names in ``<parameters>`` (``$(find
    pkg)`` was expanded by xacro; ``package://`` and ``file://`` work;
    a relative path is taken from the description's folder, or from the
    current directory -- where Gazebo would look -- if only there it
    exists).  Else, for the shipped pan/tilt model, its shipped controllers.
    Else, for a URDF whose Gazebo plugins run it (``runs_by_plugins``: a diff drive, planar
    move, p3d, odometry or joint state publisher plugin, as
    :func:`pan_tilt_sim.plugins.registry.runs_by_plugins` tells), none: it runs without
    controllers, as in Gazebo.
    """
    if given:
        try:
            return (resolve_resource(given, pathlib.Path.cwd()),)
        except ConfigurationError as err:
            raise ControllerConfigError(f'{given_as}: {err}') from None
    named = plugin_controllers_files(description)
    if named:
        return named
    if description.name == DEFAULT_ROBOT_NAME:
        return (package_share() / DEFAULT_CONTROLLERS,)
    if runs_by_plugins:
        return ()
    raise ControllerConfigError(
        f'{description.source}: no controllers file: {given_as} is not set and the URDF names '
        'none (no gz_ros2_control, ign_ros2_control or gazebo_ros2_control plugin with '
        f'<parameters>); give the controller YAML with {given_as}')


def plugin_controllers_files(description: RobotDescription) -> tuple[pathlib.Path, ...]:
    """Return the files the URDF's gz_ros2_control / gazebo_ros2_control plugin names (or none).

    What Gazebo's controller_manager is started with: see
    :func:`controllers_files_for` for how each is found.
    """
    return tuple(_plugin_file(text, plugin.filename, description.source)
                 for plugin in description.model.control_plugins for text in plugin.parameters)


def _plugin_file(text: str, plugin: str, description_file: pathlib.Path) -> pathlib.Path:
    origin = f"{description_file}: the {plugin} plugin's <parameters>"
    try:
        path = resolve_resource(text, description_file.parent)
    except ConfigurationError as err:
        raise ControllerConfigError(f'{origin}: {err}') from None
    if not path.exists() and not pathlib.Path(text).is_absolute() and '://' not in text:
        from_cwd = pathlib.Path(text).resolve()
        if from_cwd.exists():
            return from_cwd
    if not path.is_file():
        raise ControllerConfigError(
            f"{origin} names '{text}' (resolved to {path}): no such file")
    return path


def read_text(path: pathlib.Path) -> str:
    """Return a controllers file's text; errors name the file.

    Within :mod:`~pan_tilt_sim.model.yaml_input`'s limits: a regular file
    (not a device or FIFO) of at most ``MAX_FILE_BYTES``.
    """
    try:
        return yaml_input.read_text(path)
    except yaml_input.YamlInputError as err:
        raise ControllerConfigError(f'controllers file {path}: {err}') from None


def parse_yaml(text: str, path: pathlib.Path) -> Any:
    """Parse YAML text within the limits; errors name the file and, where known, the line.

    Aliases are expanded with a bound on the expanded size and depth, and an
    alias holding itself is refused (:mod:`~pan_tilt_sim.model.yaml_input`).
    """
    try:
        return yaml_input.load(text)
    except yaml_input.YamlInputError as err:
        raise ControllerConfigError(f'{path}{err.where}: {err}') from None


def read_yaml(path: pathlib.Path) -> Any:
    """Parse a YAML file; errors name the file and, for syntax errors, the line."""
    return parse_yaml(read_text(path), path)


NO_CONTROLLERS_FILE = pathlib.Path('(no controllers file)')


def load_controllers_config(paths: pathlib.Path | str | Sequence[pathlib.Path | str],
                            args: Mapping[str, str] | None = None, *,
                            args_name: str = f"the parameter '{CONTROLLERS_ARGS}'",
                            manager: str = CONTROLLER_MANAGER) -> ControllersConfig:
    """Read the controllers file(s) at ``paths`` (several: read in order, later ones win).

    No paths: no controllers (a robot its Gazebo plugins run).

    ``args`` are the values of ``$(var name)`` substitutions; ``args_name``
    says in errors where they come from.  ``manager`` is the controller
    manager's node name, whose section gives ``update_rate`` (gz_ros2_control's
    ``<controller_manager_name>``).
    """
    if isinstance(paths, str | os.PathLike):
        paths = [paths]
    if not paths:  # a robot its Gazebo plugins run (see controllers_files_for)
        return ControllersConfig((), NO_CONTROLLERS_FILE)
    paths = [pathlib.Path(path).expanduser().resolve() for path in paths]
    documents = [(path, _read_document(path, args or {}, args_name)) for path in paths]
    label = ' + '.join(str(path) for path in paths)
    ros2 = [(path, _ros2_nodes(document, path)) for path, document in documents]
    if all(nodes for _path, nodes in ros2):
        config = _ros2_control_config([node for _path, nodes in ros2 for node in nodes], label,
                                      manager)
        warnings = [warning for path, document in documents
                    for warning in _ros2_dropped_blocks(document, path)]
        return dataclasses.replace(config, source=paths[0], sources=tuple(paths),
                                   warnings=tuple(warnings))
    if len(documents) > 1:
        mixed = ', '.join(str(path) for path, nodes in ros2 if not nodes)
        raise ControllerConfigError(
            f'{label}: several controller files must all be ros2_control style '
            f'(ros__parameters); not so: {mixed}')
    path, document = documents[0]
    namespace = None
    holder: Mapping[Any, Any] = document
    controllers = _controllers_in(document)
    if not controllers and isinstance(document.get(TYPE_FIELD), str):
        # ROS 1: one controller per file, named by the namespace it is loaded into.
        controllers = [ControllerSpec(name=_name_from_file(path), type=document[TYPE_FIELD],
                                      params=document)]
    if not controllers and len(document) == 1:
        (key, inner), = document.items()
        if isinstance(inner, Mapping):
            controllers = _controllers_in(inner)
            namespace = str(key) if controllers else None
            holder = inner
    blocks = _controller_blocks(document, {spec.name for spec in controllers})
    if not controllers and len(blocks) > 1:
        raise ControllerConfigError(
            f"{path}: several top-level keys hold controllers ({_quoted(blocks)}): one key "
            "may wrap a robot's controllers (its namespace), or put them all at the top level")
    if not controllers:
        raise ControllerConfigError(
            f"{path}: no controllers in it (a controller is a mapping with a '{TYPE_FIELD}')")
    _check_names(path, controllers, namespace)
    top_level = _quoted(spec.name for spec in controllers)
    warnings = [] if namespace is not None else [
        f"{path}: top-level key '{key}' holds controllers ({_quoted(names)}) that are not "
        f'loaded: beside controllers at the top level ({top_level}) a block of controllers '
        "is ignored; put every controller at the top level, or all under one key (the robot's "
        'namespace)'
        for key, names in blocks.items()]
    return ControllersConfig(controllers=tuple(controllers), source=path, namespace=namespace,
                             sources=(path,), pid_gains=_plugin_pid_gains(holder, path),
                             warnings=tuple(warnings))


def _quoted(names: Iterable[Any]) -> str:
    return ', '.join(f"'{name}'" for name in names)


def _controller_blocks(document: Mapping[Any, Any], controllers: set[str]) -> dict[str, list[str]]:
    """Return the top-level keys, other than controllers, whose mapping holds controllers."""
    blocks = {}
    for key, value in document.items():
        if str(key) in controllers or key == GAZEBO_ROS_CONTROL or not isinstance(value, Mapping):
            continue
        held = _controllers_in(value)
        if held:
            blocks[str(key)] = [spec.name for spec in held]
    return blocks


def _ros2_dropped_blocks(document: Mapping[Any, Any], path: pathlib.Path) -> list[str]:
    """Name the top-level blocks of a ros2_control file that hold a controller but are ignored.

    Only ``ros__parameters`` sections are read; a block with none under it
    (an anchor's holder, a ROS 1 style block) is dropped, whatever it holds.
    """
    return [
        f"{path}: top-level key '{key}' holds a controller (a mapping with a '{TYPE_FIELD}') "
        f"but is ignored: it has no '{ROS2_PARAMETERS}' (in a ros2_control style file only "
        f"'<node>: {ROS2_PARAMETERS}:' sections are read)"
        for key, value in document.items()
        if isinstance(value, Mapping) and not _has_parameters(value) and _holds_controller(value)]


def _has_parameters(mapping: Mapping[Any, Any]) -> bool:
    return ROS2_PARAMETERS in mapping or any(
        _has_parameters(value) for value in mapping.values() if isinstance(value, Mapping))


def _holds_controller(mapping: Mapping[Any, Any]) -> bool:
    return isinstance(mapping.get(TYPE_FIELD), str) or any(
        _holds_controller(value) for value in mapping.values() if isinstance(value, Mapping))


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


def _read_document(path: pathlib.Path, args: Mapping[str, str],
                   args_name: str) -> Mapping[Any, Any]:
    """Read one file, substitutions expanded; it must be a non-empty mapping."""
    expanded, document = _expanded_document(path, args)
    _check_expanded(document, expanded, path, args_name)
    return document


def _expanded_document(path: pathlib.Path,
                       args: Mapping[str, str]) -> tuple[str, Mapping[Any, Any]]:
    """Return a file's text with its substitutions expanded, and its non-empty mapping."""
    expanded = expand_substitutions(read_text(path), args)
    document = parse_yaml(expanded, path)
    if not isinstance(document, Mapping) or not document:
        raise ControllerConfigError(f'{path}: no controllers in it (expected a YAML mapping)')
    return expanded, document


def _check_expanded(value: Any, expanded: str, path: pathlib.Path, args_name: str) -> None:
    """Refuse a substitution left in ``value`` (read from ``path``), naming its line."""
    leftover = _leftover_substitution(value)
    if leftover is not None:
        raise ControllerConfigError(
            f'{path}{_line_of(expanded, leftover.group(0))}: '
            f'{_unexpanded_problem(leftover, args_name)}')


def _name_from_file(path: pathlib.Path) -> str:
    """Name a file's one controller after the file: ``head.yaml`` -> ``head``."""
    name = re.sub(r'\W', '_', path.stem) or 'controller'
    return f'_{name}' if name[0].isdigit() else name


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
    """Turn ROS 2's dotted parameter names into nested mappings.

    A list of mappings is read as the mappings merged, as rcl's YAML
    parameter parser reads it: ros2_controllers' gpio_command_controller
    documents ``command_interfaces: {gpio1: [{interfaces: [...]}]}``, which
    is the parameter ``command_interfaces.gpio1.interfaces``.
    """
    nested: dict[str, Any] = {}
    for key, value in parameters.items():
        *parents, leaf = str(key).split(PARAMETER_SEPARATOR)
        target = nested
        for parent in parents:
            inner = target.get(parent)
            if not isinstance(inner, dict):
                inner = target[parent] = {}
            target = inner
        if isinstance(value, list) and value and all(isinstance(item, Mapping)
                                                    for item in value):
            merged: dict[Any, Any] = {}
            for item in value:
                merged.update(item)
            value = merged
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


def node_parameters(paths: Sequence[pathlib.Path | str], node: str,
                    args: Mapping[str, str] | None = None, *,
                    args_name: str = f"the parameter '{CONTROLLERS_ARGS}'") -> dict[str, Any]:
    """Return the ``ros__parameters`` the ROS 2 parameter files at ``paths`` give ``node``.

    As rcl reads ``--params-file``: a key names the node (a namespace before
    it is ignored) or is a wildcard (``/**``) matching it; files are read in
    order, later ones winning, and a node's own section wins over wildcards
    of the same file.  Errors name the file; a file without any
    ``ros__parameters`` gives nothing.  A substitution left unexpanded is an
    error only in what the file gives ``node`` (other nodes' sections may
    use launch arguments ``node`` is not given).
    """
    merged: dict[str, Any] = {}
    for path in paths:
        path = pathlib.Path(path).expanduser().resolve()
        expanded, document = _expanded_document(path, args or {})
        patterns, own = _split_nodes(_ros2_nodes(document, path))
        given = _parameters_of(node, patterns, own)
        _check_expanded(given, expanded, path, args_name)
        _merge_into(merged, given)
    return merged


def _split_nodes(nodes: list[tuple[str, dict[str, Any]]]
                 ) -> tuple[list[tuple[str, dict[str, Any]]], dict[str, dict[str, Any]]]:
    """Split ``(node or pattern, parameters)`` into wildcard patterns and named nodes."""
    patterns: list[tuple[str, dict[str, Any]]] = []
    own: dict[str, dict[str, Any]] = {}
    for name, params in nodes:
        if any(character in name for character in WILDCARD_CHARACTERS):
            patterns.append((name, params))
        else:
            _merge_into(own.setdefault(name, {}), params)
    return patterns, own


def _parameters_of(node: str, patterns: list[tuple[str, dict[str, Any]]],
                   own: Mapping[str, dict[str, Any]]) -> dict[str, Any]:
    merged: dict[str, Any] = {}
    for pattern, params in patterns:
        if fnmatch.fnmatchcase(node, pattern):
            _merge_into(merged, params)
    _merge_into(merged, own.get(node, {}))
    return merged


def _ros2_control_config(nodes: list[tuple[str, dict[str, Any]]], path: str,
                         manager: str = CONTROLLER_MANAGER) -> ControllersConfig:
    patterns, own = _split_nodes(nodes)

    def parameters_of(node: str) -> dict[str, Any]:
        return _parameters_of(node, patterns, own)

    update_rate = _update_rate(parameters_of(manager), path, manager)
    # Controllers are declared as `<name>: {type: ...}` entries (normally the
    # controller_manager's), or, since Jazzy, by a `type` among their own parameters.
    declared: dict[str, Any] = {}
    for node in [manager, *own]:
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
    return ControllersConfig(controllers=tuple(controllers), source=pathlib.Path(path),
                             update_rate=update_rate)


def _update_rate(manager: Mapping[str, Any], path: str, name: str = CONTROLLER_MANAGER) -> float:
    rate = manager.get(UPDATE_RATE_FIELD, DEFAULT_UPDATE_RATE)
    if isinstance(rate, bool) or not isinstance(rate, int | float) or rate_problem(rate):
        raise ControllerConfigError(
            f'{path}: {name}.{ROS2_PARAMETERS}.{UPDATE_RATE_FIELD}: '
            f'{rate!r} must be a number of Hz > 0 whose period 1 / rate is finite')
    return float(rate)


def controller_manager_config(manager_parameters: Mapping[str, Any],
                              shared: Callable[[str], Mapping[str, Any]], *,
                              update_rate: float, source: str) -> ControllersConfig:
    """Return the controllers a controller_manager node's own parameters declare.

    As ros2_control_node reads them: ``manager_parameters`` are the node's
    parameters by name (``arm_controller.type``; dotted or nested), and a
    controller is a ``<name>.type`` among them.  Each controller's
    parameters are ``shared(name)`` -- what the controller_manager's own
    arguments give the controller's node (ros2_control passes them on to
    every controller node): its section of the ``--params-file`` files --
    over ``update_rate`` (the controller_manager's).  ``source`` names the
    node in errors.  None declared is fine: spawners then give the types.
    """
    nested = _unflatten(manager_parameters)
    controllers = []
    for name, entry in nested.items():
        if not (isinstance(entry, Mapping) and TYPE_FIELD in entry):
            continue
        type_name = entry[TYPE_FIELD]
        if not isinstance(type_name, str):
            raise ControllerConfigError(
                f"{source}: parameter '{name}.{TYPE_FIELD}' must be a string, got {type_name!r}")
        if not naming.is_valid_name(name):
            raise ControllerConfigError(
                f"{source}: controller name '{name}' is not a valid ROS name "
                f'({naming.NAME_RULE}); it becomes part of its topic names')
        params: dict[str, Any] = {UPDATE_RATE_FIELD: update_rate}
        _merge_into(params, shared(name))
        params[TYPE_FIELD] = type_name
        controllers.append(ControllerSpec(name=name, type=type_name, params=params))
    return ControllersConfig(controllers=tuple(controllers), source=pathlib.Path(source),
                             update_rate=update_rate)


def unflatten(parameters: Mapping[str, Any]) -> dict[str, Any]:
    """Turn ROS 2's dotted parameter names (``gains.joint1.p``) into nested mappings."""
    return _unflatten(parameters)


def merge_parameters(target: dict[str, Any], overrides: Mapping[str, Any]) -> None:
    """Deep-merge ``overrides`` into ``target`` (overrides win, mappings merge), in place."""
    _merge_into(target, overrides)
