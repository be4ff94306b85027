"""How a stand-in runs: rclpy up, one node under its upstream name, its body, all down again.

:func:`run_node` is the part every ROS-side stand-in (``create``,
``parameter_bridge``, ``image_bridge``, ``spawn_entity.py``) shares; each
keeps its own arguments, usage text and exit codes.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

# body(node, words): the stand-in's work; words are the command line without the program
# name and the ROS arguments.  It returns the exit code.
Body = Callable[[Any, list[str]], int]


def exit_with(run: Callable[[list[str]], int], argv: list[str] | None) -> None:
    """Exit with ``run(argv)``'s code; ``argv`` None: the process's command line."""
    sys.exit(run(sys.argv if argv is None else argv))


def run_node(argv: list[str], node_name: str, body: Body) -> int:
    """Start rclpy with ``argv``, run ``body`` on a node ``node_name``; return its code.

    Ctrl-C or a shutdown from outside returns 0; the node is destroyed and
    rclpy shut down whatever happens.
    """
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.utilities import remove_ros_args

    rclpy.init(args=argv)
    try:
        node = rclpy.create_node(node_name)
        try:
            return body(node, remove_ros_args(argv)[1:])
        finally:
            node.destroy_node()
    except (KeyboardInterrupt, ExternalShutdownException):
        return 0
    finally:
        if rclpy.ok():
            rclpy.shutdown()
