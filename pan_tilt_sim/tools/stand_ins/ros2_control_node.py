"""controller_manager's ``ros2_control_node``: sim_node named ``controller_manager``.

A ros2_control launch file that changes only the control node's package to
``pan_tilt_sim`` starts this: sim_node as the controller manager (see
:mod:`pan_tilt_sim.ros.drop_in`), named ``controller_manager`` unless the command
line renames the node (launch's ``name=``), as ros2_control_node is.
"""

from __future__ import annotations

import os
import sys

NODE_NAME = 'controller_manager'
NODE_REMAP_TARGETS = ('__node:=', '__name:=')


def arguments(argv: list[str]) -> list[str]:
    """Return ``argv`` with ``-r __node:=controller_manager`` added unless a node name is given."""
    named = any(target in word for word in argv for target in NODE_REMAP_TARGETS)
    return list(argv) if named else [*argv, '--ros-args', '-r', f'__node:={NODE_NAME}']


def main(argv: list[str] | None = None) -> None:
    """Become sim_node (``python -m pan_tilt_sim``, same PID) named as ros2_control_node is."""
    args = arguments(sys.argv if argv is None else argv)
    os.execv(sys.executable, [sys.executable, '-m', 'pan_tilt_sim', *args[1:]])
