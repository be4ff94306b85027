"""Where the robot's topics live, by the rule gazebo_ros_control users expect.

The namespace is the first of these that applies:

1. the node's own namespace, if it is not ``/`` (``--ros-args -r __ns:=/x``);
2. the ``robot_namespace`` parameter;
3. the controllers file's single top-level key, when it wraps the controllers;
4. the ``robotNamespace`` of the URDF's gazebo_ros_control plugin;
5. none (topics at the root).
"""

from __future__ import annotations

import re

from pan_tilt_sim.errors import ParameterError

ROOT = '/'
# A ROS name token: a letter or underscore, then letters, digits, underscores.
_TOKEN = re.compile(r'[A-Za-z_][A-Za-z0-9_]*')


NAMESPACE_RULE = ("tokens of letters, digits and underscores, not starting with a digit, "
                  "separated by '/'")
NAME_RULE = 'letters, digits and underscores, not starting with a digit'


def is_valid_name(name: str) -> bool:
    """Whether ``name`` is one ROS name token (a controller's name in its topic)."""
    return _TOKEN.fullmatch(name) is not None


def is_valid_namespace(namespace: str) -> bool:
    """Whether ``namespace`` is empty, ``/`` or a valid ROS namespace (no trailing ``/``)."""
    if not namespace or namespace == ROOT:
        return True
    tokens = namespace.removeprefix(ROOT).split(ROOT)
    return all(_TOKEN.fullmatch(token) for token in tokens)


def check_namespace(field: str, namespace: str) -> None:
    """Raise ParameterError unless ``namespace`` is empty or a valid ROS namespace."""
    if not is_valid_namespace(namespace):
        raise ParameterError(
            f"parameter '{field}': '{namespace}' is not a valid ROS namespace ({NAMESPACE_RULE})")


def normalize(namespace: str | None) -> str:
    """Normalize ``'ns'``, ``'/ns'``, ``'/ns/'`` -> ``'/ns'``; empty or ``/`` -> ``''``."""
    if not namespace:
        return ''
    stripped = namespace.strip(ROOT)
    return f'{ROOT}{stripped}' if stripped else ''


def resolve_robot_namespace(node_namespace: str, robot_namespace: str,
                            controllers_namespace: str | None,
                            plugin_namespace: str | None) -> str:
    """Return the namespace of the robot's topics ('' for the root), first rule that applies."""
    for candidate in (node_namespace, robot_namespace, controllers_namespace, plugin_namespace):
        namespace = normalize(candidate)
        if namespace:
            return namespace
    return ''


def join(namespace: str, *names: str) -> str:
    """Return an absolute topic name: ``join('/ns', 'ctrl', 'command')`` -> ``/ns/ctrl/command``."""
    return ROOT.join([namespace, *names]) if namespace else ROOT + ROOT.join(names)
