"""Declarative controller parameters, in the spirit of generate_parameter_library.

Every controller type lists its YAML parameters as :class:`Param` entries --
name, type, default, validators, read-only flag, description -- in a
:class:`ParameterSpec` kept beside its module.  :func:`load_parameters`
checks a controller's parameters against that spec before the controller
uses them:

* a value of the wrong type, or one a validator refuses, is an error of the
  form ``<file>: <controller>.<field>: <what is wrong>``;
* a missing parameter without a default (:data:`REQUIRED`) is an error;
* a key the spec does not know is kept out of the values and named in a
  warning, with the closest known name ("did you mean 'wheel_separation'?");
* the defaults of parameters not given are filled in.

Design notes: docs/design/controllers.md#parameter_specpy.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.frame_ids import FRAME_ID_RULE, frame_id_problem
from pan_tilt_sim.model.rates import rate_problem

BOOL, INT, DOUBLE, STRING = 'bool', 'int', 'double', 'string'
BOOL_ARRAY, INT_ARRAY, DOUBLE_ARRAY, STRING_ARRAY = (
    'bool_array', 'int_array', 'double_array', 'string_array')
TYPES = (BOOL, INT, DOUBLE, STRING, BOOL_ARRAY, INT_ARRAY, DOUBLE_ARRAY, STRING_ARRAY)
MAP_PREFIX = '__map_'


class _Required:
    """The default of a parameter that must be given."""

    def __repr__(self) -> str:
        return 'REQUIRED'


REQUIRED: Any = _Required()

# Keys ros2_control's controller_manager, controller_interface or rclpy accept
# for every controller; none is an error or a warning.
COMMON_KEYS = ('type', 'update_rate', 'is_async', 'thread_priority', 'use_sim_time',
               'params_file', 'fallback_controllers', 'qos_overrides')


@dataclasses.dataclass(frozen=True)
class Validator:
    """One check of a parameter's value: ``check(value)`` returns the problem or None."""

    text: str  # how the docs and the problem describe the rule
    check: Callable[[Any], str | None]

    def __call__(self, value: Any) -> str | None:
        """Return what is wrong with ``value``, or None."""
        return self.check(value)


def gt(bound: float) -> Validator:
    """Require more than ``bound`` (each element, for an array)."""
    return _each(f'> {bound:g}', lambda value: value > bound)


def gt_eq(bound: float) -> Validator:
    """Require at least ``bound`` (each element, for an array)."""
    return _each(f'>= {bound:g}', lambda value: value >= bound)


def bounds(lower: float, upper: float) -> Validator:
    """Require a value within [lower, upper] (each element, for an array)."""
    return _each(f'in [{lower:g}, {upper:g}]', lambda value: lower <= value <= upper)


def rate(*, zero_allowed: bool = False) -> Validator:
    """Require a rate (Hz) > 0 whose period is finite (``zero_allowed``: or 0)."""
    return Validator('>= 0 Hz, finite period' if zero_allowed else '> 0 Hz, finite period',
                     lambda value: rate_problem(value, zero_allowed=zero_allowed))


def one_of(*choices: Any) -> Validator:
    """Require one of ``choices`` (each element, for an array: ``subset_of``)."""
    listed = ', '.join(str(choice) for choice in choices)
    return _each(f'one of {listed}', lambda value: value in choices)


def not_empty() -> Validator:
    """Require a non-empty string or array."""
    return Validator('not empty', lambda value: None if len(value) else 'must not be empty')


def names() -> Validator:
    """Require every element of a string array to be a non-empty name."""
    return _each('a non-empty name', lambda value: bool(value))


def unique() -> Validator:
    """Require an array without repeated elements."""
    def check(value: Sequence[Any]) -> str | None:
        repeated = [item for index, item in enumerate(value) if item in value[:index]]
        return f"'{repeated[0]}' is named more than once" if repeated else None
    return Validator('unique', check)


def fixed_size(size: int) -> Validator:
    """Require an array of exactly ``size`` elements."""
    return Validator(f'{size} elements', lambda value: None if len(value) == size else
                     f'must have {size} elements, has {len(value)}')


def frame_id() -> Validator:
    """Require a valid frame id (see :func:`frame_id_problem`)."""
    return Validator('a frame id', frame_id_problem)


def frame_id_or_empty() -> Validator:
    """Require an empty string (the parameter's fallback) or a valid frame id."""
    return Validator('empty or a frame id',
                     lambda value: frame_id_problem(value) if value else None)


def frame_id_prefix() -> Validator:
    """Require an empty prefix or a frame id, with an optional trailing '/'."""
    def check(value: str) -> str | None:
        if not value or value == '/' or frame_id_problem(value.removesuffix('/')) is None:
            return None
        return f"{value!r} is not a valid frame id prefix ({FRAME_ID_RULE}, then one '/')"
    return Validator('empty or a frame id prefix', check)


def _each(text: str, accept: Callable[[Any], bool]) -> Validator:
    def check(value: Any) -> str | None:
        items = value if isinstance(value, list | tuple) else (value,)
        for item in items:
            if not accept(item):
                return f'{item!r} must be {text}'
        return None
    return Validator(text, check)


@dataclasses.dataclass(frozen=True)
class Param:
    """One parameter of a controller type.

    ``tunable``: changeable while the controller runs (as a node parameter);
    ``read_only``: fixed once the controller is configured (the rest may be
    given anew by a reconfigure).  ``finite``: doubles must be finite.
    ``simulated`` false: an upstream parameter this simulator accepts but
    does not act on; a value that asks for something (not the default, not
    false, zero or empty) is named in a warning.
    """

    name: str
    type: str
    default: Any = None
    description: str = ''
    validators: tuple[Validator, ...] = ()
    read_only: bool = False
    tunable: bool = False
    finite: bool = True
    simulated: bool = True
    # A value for the docs' examples and the every-type test (required entries need one;
    # an optional entry has one where the type needs it or its alternative given).
    example: Any = None

    def __post_init__(self) -> None:
        if self.type not in TYPES:
            raise ValueError(f'{self.name}: unknown parameter type {self.type!r}')

    @property
    def required(self) -> bool:
        """Whether the parameter has no default and must be given."""
        return self.default is REQUIRED

    @property
    def map_list(self) -> str | None:
        """The list parameter a ``__map_<list>`` segment of the name expands over, if any."""
        for segment in self.name.split('.'):
            if segment.startswith(MAP_PREFIX):
                return segment[len(MAP_PREFIX):]
        return None

    def expand(self, entries: Sequence[str]) -> list[str]:
        """Return the concrete names of this entry for ``entries`` of its map list."""
        if self.map_list is None:
            return [self.name]
        marker = MAP_PREFIX + self.map_list
        return [self.name.replace(marker, entry) for entry in entries]

    def rule(self) -> str:
        """Describe the type and the validators in a few words (the docs' column)."""
        rules = ', '.join(validator.text for validator in self.validators)
        return f'{self.type}' + (f' ({rules})' if rules else '')


class ParameterSpec:
    """The parameters of one controller type, in declaration order."""

    def example(self) -> dict[str, Any]:
        """Return the smallest parameters this spec accepts: the entries' examples.

        Each required entry has one; an optional entry has one where the type
        needs it given (one of two alternatives, such as a force-torque
        broadcaster's ``sensor_name`` or ``interface_names``).  A ``__map_``
        entry's example is given for each example entry of its list.
        """
        chosen = [param for param in self if param.required or param.example is not None]
        values = {param.name: param.example for param in chosen if param.map_list is None}
        for param in chosen:
            if param.map_list is not None:
                entries = values.get(param.map_list) or ()
                values.update({name: param.example
                               for name in param.expand([str(entry) for entry in entries])})
        return _nest(values)

    def __init__(self, params: Iterable[Param] = ()) -> None:
        self._params: dict[str, Param] = {}
        for param in params:
            if param.name in self._params:
                raise ValueError(f'parameter {param.name!r} declared twice')
            self._params[param.name] = param

    def __iter__(self):
        """Iterate over the entries."""
        return iter(self._params.values())

    def __len__(self) -> int:
        return len(self._params)

    def __contains__(self, name: object) -> bool:
        return name in self._params

    def __getitem__(self, name: str) -> Param:
        return self._params[name]

    def extend(self, *params: Param) -> ParameterSpec:
        """Return this spec with ``params`` added (an entry of the same name is replaced)."""
        merged = dict(self._params)
        for param in params:
            merged[param.name] = param
        return ParameterSpec(merged.values())

    def without(self, *names: str) -> ParameterSpec:
        """Return this spec without the entries called ``names``."""
        return ParameterSpec(param for param in self if param.name not in names)

    def tunable(self) -> list[Param]:
        """Return the entries that may change while the controller runs."""
        return [param for param in self if param.tunable]


@dataclasses.dataclass
class LoadedParameters:
    """A controller's checked parameters: nested as in the YAML, with defaults filled in.

    ``values`` keeps the YAML's nesting (``values['gains']['joint1']['p']``);
    :meth:`get` reads a dotted name.  ``warnings``: one line per key the
    spec does not know (it is not in ``values``).
    """

    values: dict[str, Any]
    warnings: list[str]

    def get(self, name: str, default: Any = None) -> Any:
        """Return the value at dotted ``name``, or ``default`` where it is absent."""
        node: Any = self.values
        for segment in name.split('.'):
            if not isinstance(node, Mapping) or segment not in node:
                return default
            node = node[segment]
        return node


def load_parameters(spec: ParameterSpec, params: Mapping[str, Any], controller: str,
                    source: str = '') -> LoadedParameters:
    """Check ``params`` of ``controller`` against ``spec``; fill in the defaults.

    Raises :class:`ControllerConfigError` naming ``<source>: <controller>.<field>``
    for the first wrong value; unknown keys become warnings.
    """
    where = f'{source}: ' if source else ''

    def fail(field: str, problem: str) -> ControllerConfigError:
        return ControllerConfigError(f'{where}{controller}.{field}: {problem}')

    flat = _flatten(params)
    sections = {name.split('.')[0] for param in spec for name in [param.name] if '.' in name}
    for key in sections:
        if params.get(key) is not None and not isinstance(params[key], Mapping):
            raise fail(key, f'expected a mapping, got {params[key]!r}')
    values: dict[str, Any] = {}
    known: dict[str, Param] = {}
    plain = [param for param in spec if param.map_list is None]
    mapped = [param for param in spec if param.map_list is not None]
    warnings = []
    for param in plain:
        known[param.name] = param
        _take(param, param.name, flat, values, fail)
    for param in mapped:
        for name in param.expand(_map_entries(values, param.map_list)):
            known[name] = param
            _take(param, name, flat, values, fail)
    for name, param in known.items():
        if not param.simulated and name in values and values[name] != param.default and (
                values[name] not in (False, 0, '', [])):
            warnings.append(f'{where}{controller}.{name}: {values[name]!r} is accepted but '
                            'not simulated; it has no effect here')
    _check_map_keys(mapped, values, {key: value for key, value in flat.items()
                                     if key not in known}, fail)
    for key, value in flat.items():
        if key in known or key.split('.', 1)[0] in COMMON_KEYS:
            continue
        if value == {} and any(name.startswith(key + '.') for name in known):
            continue  # an empty section the spec has (``gains: {}``)
        warnings.append(_unknown_key_warning(where, controller, key, known))
    return LoadedParameters(_nest(values), warnings)


def _take(param: Param, name: str, flat: Mapping[str, Any], values: dict[str, Any],
          fail: Callable[[str, str], ControllerConfigError]) -> None:
    if name not in flat or flat[name] is None:
        if param.required:
            raise fail(name, f'missing: {param.description or "a required parameter"}'
                       .rstrip('.'))
        if param.default is not None:
            values[name] = list(param.default) if isinstance(param.default, tuple) else (
                param.default)
        return
    value = _coerce(param, flat[name])
    if value is None:
        raise fail(name, f'{flat[name]!r} {_type_text(param)}')
    # Validators see the value as written (an integer stays one in the message).
    written = flat[name] if isinstance(flat[name], int | float) else value
    for validator in param.validators:
        problem = validator(written)
        if problem is not None:
            raise fail(name, problem)
    values[name] = value


def _check_map_keys(mapped: Sequence[Param], values: Mapping[str, Any],
                    flat: Mapping[str, Any],
                    fail: Callable[[str, str], ControllerConfigError]) -> None:
    """Refuse a ``gains.<x>`` entry whose ``<x>`` is not in the map's list."""
    for param in mapped:
        marker = MAP_PREFIX + param.map_list
        head = param.name.split(marker, 1)[0]
        entries = _map_entries(values, param.map_list)
        for key in flat:
            if not head or not key.startswith(head):
                continue
            entry = key[len(head):].split('.', 1)[0]
            if entry not in entries:
                raise fail(f'{head}{entry}', f"'{entry}' is not one of this controller's "
                           f"{param.map_list} ({', '.join(entries) or 'none'})")


def _map_entries(values: Mapping[str, Any], name: str) -> list[str]:
    """Return the entries a ``__map_<name>`` segment expands over: a list's, or one string."""
    entries = values.get(name)
    if isinstance(entries, str):
        return [entries] if entries else []
    if not isinstance(entries, list | tuple):
        return []
    return [str(entry) for entry in entries]


def _coerce(param: Param, value: Any) -> Any:
    """Return ``value`` as the parameter's type, or None if it is not of that type."""
    if param.type.endswith('_array'):
        if not isinstance(value, list | tuple):
            return None
        element = dataclasses.replace(param, type=param.type[:-len('_array')], validators=())
        items = [_coerce(element, item) for item in value]
        return None if any(item is None for item in items) else items
    if param.type == BOOL:
        return value if isinstance(value, bool) else None
    if isinstance(value, bool):
        return None
    if param.type == INT:
        return value if isinstance(value, int) else None
    if param.type == DOUBLE:
        if not isinstance(value, int | float):
            return None
        value = float(value)
        return value if math.isfinite(value) or not param.finite else None
    return value if isinstance(value, str) else None


_TYPE_TEXTS = {
    BOOL: 'must be true or false', INT: 'must be an integer', DOUBLE: 'must be a finite number',
    STRING: 'must be a string', BOOL_ARRAY: 'must be a list of true/false values',
    INT_ARRAY: 'must be a list of integers', DOUBLE_ARRAY: 'must be a list of finite numbers',
    STRING_ARRAY: 'must be a list of strings'}


def _type_text(param: Param) -> str:
    if param.type == DOUBLE and not param.finite:
        return 'must be a number'
    return _TYPE_TEXTS[param.type]


def _unknown_key_warning(where: str, controller: str, key: str,
                         known: Mapping[str, Param]) -> str:
    line = f'{where}{controller}.{key}: unknown parameter, ignored'
    candidates = list(known) + list(COMMON_KEYS)
    close = difflib.get_close_matches(key, candidates, n=1, cutoff=0.6)
    if not close:
        leaf = key.rsplit('.', 1)[-1]
        leaves = {name.rsplit('.', 1)[-1]: name for name in candidates}
        match = difflib.get_close_matches(leaf, list(leaves), n=1, cutoff=0.6)
        close = [leaves[match[0]]] if match else []
    return line + (f" (did you mean '{close[0]}'?)" if close else '')


def _flatten(params: Mapping[str, Any], prefix: str = '') -> dict[str, Any]:
    """Return the leaves of nested ``params`` by dotted name (a mapping is never a leaf)."""
    flat: dict[str, Any] = {}
    for key, value in params.items():
        name = f'{prefix}{key}'
        if isinstance(value, Mapping) and value:
            flat.update(_flatten(value, name + '.'))
        else:
            flat[name] = value
    return flat


def _nest(values: Mapping[str, Any]) -> dict[str, Any]:
    nested: dict[str, Any] = {}
    for name, value in values.items():
        node = nested
        *parents, leaf = name.split('.')
        for parent in parents:
            node = node.setdefault(parent, {})
        node[leaf] = value
    return nested
