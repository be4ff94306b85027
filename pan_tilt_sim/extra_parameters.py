"""Declaring the parameters of sim_node's optional features (camera, TF, world).

Like the core's parameters (:mod:`pan_tilt_sim.parameters`): declared with a
description, doubles also take integers (``-p camera.fov_deg:=90``), and a
wrong type is a :class:`~pan_tilt_sim.errors.ParameterError` naming the
parameter and the type it wants (one line and exit code 2 at start-up), not
rclpy's InvalidParameterTypeException: every parameter is declared with
dynamic typing and its type is checked here instead.
"""

from __future__ import annotations

from typing import Any

from rcl_interfaces.msg import ParameterDescriptor, ParameterType
from rclpy.node import Node

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.parameters import coerce

BOOL = ParameterType.PARAMETER_BOOL
INTEGER = ParameterType.PARAMETER_INTEGER
DOUBLE = ParameterType.PARAMETER_DOUBLE
STRING = ParameterType.PARAMETER_STRING


def declare(node: Node, name: str, wanted: int, default: Any, description: str, *,
            read_only: bool = True) -> Any:
    """Declare parameter ``name`` on ``node`` and return its value, checked for type."""
    descriptor = ParameterDescriptor(
        name=name, type=wanted, description=description, read_only=read_only,
        dynamic_typing=True)
    value = node.declare_parameter(name, default, descriptor).value
    if wanted == INTEGER:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ParameterError(f"parameter '{name}' must be an integer, got {value!r}")
        return value
    return coerce(name, wanted, value)
