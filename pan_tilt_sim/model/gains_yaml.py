"""Writing PID gains back into the user's controller YAML, changing nothing else.

The file is parsed with PyYAML's composer, which gives every key and value
its exact place in the text; each gain's value is then replaced in place
(or, for a field the file did not have, added right after its last sibling
gain, in the same flow or block style and with the same key form).  Every
other byte -- comments, order, quoting, indentation, blank lines -- stays as
the user wrote it.  Where a gain is written is where the loader
(:mod:`pan_tilt_sim.model.controller_config`) reads it from:

* ROS 1 (rosparam) style: ``<controller>: {pid: {p, i, d, i_clamp...}}``, at
  the top level or under the one namespace key;
* ros2_control style: ``<controller>: ros__parameters: pid: {...}`` (one-joint
  controllers) or ``gains: {<joint>: {...}}`` (multi-joint ones), nested or
  dotted (``gains.<joint>.p``), the controller's own node winning over
  wildcard (``/**``) nodes, a later definition over an earlier one.

Gains reached through a YAML alias or merge key (``*defaults``, ``<<:``)
would change every user of the anchor, so they are refused.
"""

from __future__ import annotations

import dataclasses
import fnmatch
import math
from collections.abc import Iterator, Mapping, Sequence
from typing import Any

import yaml

from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model import yaml_input
from pan_tilt_sim.model.controller_config import ROS2_PARAMETERS, TYPE_FIELD, WILDCARD_CHARACTERS

PID_FIELD = 'pid'
GAINS_FIELD = 'gains'
PID_VALUE_FIELDS = ('p', 'i', 'd', 'i_clamp', 'i_clamp_min', 'i_clamp_max')
NAME_SEPARATOR = '/'
PARAMETER_SEPARATOR = '.'
NUMBER_TAGS = ('tag:yaml.org,2002:int', 'tag:yaml.org,2002:float')


@dataclasses.dataclass(frozen=True)
class GainsUpdate:
    """New values for one joint's PID fields (``p``, ``i``, ``d``, clamp fields)."""

    controller: str
    joint: str
    gains_field: str  # 'pid' (one-joint controllers) or 'gains' (per joint)
    values: Mapping[str, float]

    @property
    def path(self) -> tuple[str, ...]:
        """The parameter path of this joint's gains inside the controller's parameters."""
        return (PID_FIELD,) if self.gains_field == PID_FIELD else (GAINS_FIELD, self.joint)


def yaml_float(value: float) -> str:
    """Format ``value`` so that YAML 1.1 (PyYAML, ROS) and 1.2 both read it back as this float.

    ``repr`` gives the shortest text that round-trips; YAML 1.1 needs a dot in
    the mantissa (``1e-05`` would be a string) and ``.inf`` for infinity.
    """
    if math.isinf(value):
        return '.inf' if value > 0 else '-.inf'
    if math.isnan(value):
        raise ValueError('a gain cannot be NaN')
    text = repr(float(value))
    mantissa, e, exponent = text.partition('e')
    if e and '.' not in mantissa:
        text = f'{mantissa}.0e{exponent}'
    return text


def clamp_values(i_clamp: float, existing: Sequence[str]) -> dict[str, float]:
    """Return the clamp fields to write for a symmetric clamp, in the style the file uses."""
    values = {}
    if 'i_clamp_min' in existing or 'i_clamp_max' in existing:
        values['i_clamp_min'] = -i_clamp
        values['i_clamp_max'] = i_clamp
    if 'i_clamp' in existing or not values:
        values['i_clamp'] = i_clamp
    return values


def gain_fields(text: str, source: str, controller: str, path: Sequence[str]) -> list[str]:
    """Return the PID fields the file defines for a controller's gains at ``path``."""
    definitions = _definitions(_compose(text, source), source, controller, tuple(path))
    return [field for field in PID_VALUE_FIELDS if field in definitions]


def rewrite_gains(text: str, source: str, updates: Sequence[GainsUpdate]) -> str:
    """Return ``text`` with each update's gain values written where the loader reads them."""
    root = _compose(text, source)
    edits: list[tuple[int, int, str]] = []
    for update in updates:
        definitions = _definitions(root, source, update.controller, update.path)
        where = f"{source}: {update.controller}: {'.'.join(update.path)}"
        if not definitions:
            raise ControllerConfigError(
                f'{where}: no gains in the file to rewrite (add a {update.path[0]} entry)')
        last_sibling = max(definitions.values(), key=lambda d: d.value.end_mark.index)
        for field, value in update.values.items():
            if field not in PID_VALUE_FIELDS:
                raise ValueError(f'{field} is not a PID field')
            written = yaml_float(value)
            if field in definitions:
                node = definitions[field].value
                if node.tag not in NUMBER_TAGS:
                    raise ControllerConfigError(
                        f'{where}.{field}: {node.value!r} is not a number in the file (a '
                        'substitution?); tune writes numbers only, so edit it by hand')
                edits.append((node.start_mark.index, node.end_mark.index, written))
            else:
                edits.append(_addition(text, last_sibling, field, written))
    # From the end backwards, so earlier offsets stay valid; additions at one
    # place go in the order they were asked for.
    ordered = sorted(enumerate(edits), key=lambda item: (item[1][0], item[0]), reverse=True)
    for _, (start, end, replacement) in ordered:
        text = text[:start] + replacement + text[end:]
    return text


@dataclasses.dataclass(frozen=True)
class _Definition:
    """Where one field is defined: its container mapping, key node, value node, key prefix."""

    container: yaml.MappingNode
    key: yaml.ScalarNode
    value: yaml.Node
    prefix: str  # what goes before the field name in a new key ('gains.arm_joint.' or '')


def _compose(text: str, source: str) -> yaml.Node:
    try:
        root = yaml_input.compose(text)
    except yaml_input.YamlInputError as err:
        raise ControllerConfigError(f'{source}{err.where}: {err}') from None
    if not isinstance(root, yaml.MappingNode):
        raise ControllerConfigError(f'{source}: not a YAML mapping of controllers')
    return root


def _pairs(node: yaml.MappingNode) -> Iterator[tuple[yaml.ScalarNode, yaml.Node]]:
    for key, value in node.value:
        if isinstance(key, yaml.ScalarNode) and key.tag != 'tag:yaml.org,2002:merge':
            yield key, value


def _get(node: yaml.Node, key: str) -> yaml.Node | None:
    if not isinstance(node, yaml.MappingNode):
        return None
    found = None
    for key_node, value in _pairs(node):
        if key_node.value == key:
            found = value
    return found


def _parameter_mappings(root: yaml.MappingNode, source: str,
                        controller: str) -> list[yaml.MappingNode]:
    """Return the mappings holding ``controller``'s parameters, in the loader's merge order."""
    nodes = list(_ros2_nodes(root, ''))
    if nodes:
        patterns = [params for name, params in nodes
                    if any(c in name for c in WILDCARD_CHARACTERS)
                    and fnmatch.fnmatchcase(controller, name)]
        own = [params for name, params in nodes if name == controller]
        return patterns + own
    entry = _get(root, controller)
    if isinstance(entry, yaml.MappingNode) and _get(entry, TYPE_FIELD) is not None:
        return [entry]
    if _get(root, TYPE_FIELD) is not None:
        return [root]  # ROS 1: one controller per file, named after the file
    pairs = list(_pairs(root))
    if len(pairs) == 1 and isinstance(pairs[0][1], yaml.MappingNode):
        entry = _get(pairs[0][1], controller)
        if isinstance(entry, yaml.MappingNode):
            return [entry]
    raise ControllerConfigError(f"{source}: no controller '{controller}' in the file")


def _ros2_nodes(node: yaml.MappingNode, prefix: str) -> Iterator[tuple[str, yaml.MappingNode]]:
    for key, value in _pairs(node):
        if not isinstance(value, yaml.MappingNode):
            continue
        key_path = f'{prefix}{NAME_SEPARATOR}{key.value}'
        parameters = _get(value, ROS2_PARAMETERS)
        if parameters is not None:
            if isinstance(parameters, yaml.MappingNode):
                name = key_path.rstrip(NAME_SEPARATOR).rsplit(NAME_SEPARATOR, 1)[-1]
                yield name, parameters
        else:
            yield from _ros2_nodes(value, key_path)


def _definitions(root: yaml.MappingNode, source: str, controller: str,
                 path: tuple[str, ...]) -> dict[str, _Definition]:
    """Return, per PID field, the definition the loader would use (the last one)."""
    found: dict[str, _Definition] = {}
    for mapping in _parameter_mappings(root, source, controller):
        for definition in _find(mapping, path):
            if isinstance(definition.value, yaml.MappingNode):
                continue
            if definition.value.start_mark.index < definition.key.end_mark.index:
                raise ControllerConfigError(
                    f"{source}: {controller}: {'.'.join(path)}.{definition.key.value}: the "
                    'value is a YAML alias; tune would change every user of its anchor, so '
                    'edit the anchor by hand')
            found[definition.key.value.rsplit(PARAMETER_SEPARATOR, 1)[-1]] = definition
    return {field: found[field] for field in PID_VALUE_FIELDS if field in found}


def _find(mapping: yaml.MappingNode, path: tuple[str, ...]) -> Iterator[_Definition]:
    """Yield the PID-field definitions under ``path`` in ``mapping`` (nested or dotted keys)."""
    for key, value in _pairs(mapping):
        parts = str(key.value).split(PARAMETER_SEPARATOR)
        if parts[:len(path)] == list(path[:len(parts)]):
            if len(parts) <= len(path):
                rest = path[len(parts):]
                if isinstance(value, yaml.MappingNode):
                    if value.start_mark.index < key.end_mark.index:
                        raise ControllerConfigError(
                            f'{key.start_mark.name}:{key.start_mark.line + 1}: '
                            f"'{key.value}' is a YAML alias; tune would change every user of "
                            'its anchor, so edit the anchor by hand')
                    yield from _find(value, rest) if rest else _fields(value)
            elif len(parts) == len(path) + 1 and parts[-1] in PID_VALUE_FIELDS:
                yield _Definition(mapping, key, value,
                                  PARAMETER_SEPARATOR.join(parts[:-1]) + PARAMETER_SEPARATOR)


def _fields(mapping: yaml.MappingNode) -> Iterator[_Definition]:
    for key, value in _pairs(mapping):
        if key.value in PID_VALUE_FIELDS:
            yield _Definition(mapping, key, value, '')


def _addition(text: str, sibling: _Definition, field: str,
              written: str) -> tuple[int, int, str]:
    """Return the edit that adds ``field`` right after ``sibling``, in its style."""
    key = f'{sibling.prefix}{field}'
    end = sibling.value.end_mark.index
    if sibling.container.flow_style:
        return end, end, f', {key}: {written}'
    line_end = text.find('\n', end)
    line_end = len(text) if line_end < 0 else line_end
    indent = ' ' * sibling.key.start_mark.column
    return line_end, line_end, f'\n{indent}{key}: {written}'


def loaded_gains(params: Mapping[str, Any], gains_field: str,
                 joint: str) -> Mapping[str, Any] | None:
    """Return the gains mapping a loaded controller's parameters hold for ``joint``, if any."""
    if gains_field == PID_FIELD:
        section = params.get(PID_FIELD)
    else:
        section = params.get(GAINS_FIELD)
        section = section.get(joint) if isinstance(section, Mapping) else None
    return section if isinstance(section, Mapping) else None
