"""Reading controller YAML in the layout the seeds use.

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
namespace, as ``rosparam load`` inside ``ns=...`` would make it.
"""

from __future__ import annotations

import dataclasses
import pathlib
from collections.abc import Mapping
from typing import Any

import yaml

from pan_tilt_sim.errors import ControllerConfigError

TYPE_FIELD = 'type'


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


def read_yaml(path: pathlib.Path) -> Any:
    """Parse a YAML file; errors name the file and, for syntax errors, the line."""
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
    namespace = None
    controllers = _controllers_in(document)
    if not controllers and len(document) == 1:
        (key, inner), = document.items()
        if isinstance(inner, Mapping):
            controllers = _controllers_in(inner)
            namespace = str(key) if controllers else None
    if not controllers:
        raise ControllerConfigError(
            f"{path}: no controllers in it (a controller is a mapping with a '{TYPE_FIELD}')")
    return ControllersConfig(controllers=tuple(controllers), source=path, namespace=namespace)


def _controllers_in(mapping: Mapping[Any, Any]) -> list[ControllerSpec]:
    return [
        ControllerSpec(name=str(name), type=value[TYPE_FIELD], params=value)
        for name, value in mapping.items()
        if isinstance(value, Mapping) and TYPE_FIELD in value
    ]
