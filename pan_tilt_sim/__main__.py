"""The sim_node program: ``python -m pan_tilt_sim`` and the ``sim_node`` console script.

Both start here, so both behave the same: the signal handlers are in place
before rclpy and PyBullet are imported (about half a second), so a Ctrl-C
at any moment stops the program cleanly; a configuration error exits with
code 2 and one line (see :mod:`pan_tilt_sim.ros.runner`).

OpenBLAS runs single-threaded here unless the environment says otherwise:
numpy (which rclpy's message packages import) otherwise starts a worker per
core that spins as it loads, CPU taken from start-up, and sim_node's matrices
are 3x3 and 4x4, far too small for threads to help.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence

# Before anything imports numpy; a user's own setting wins.
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

from pan_tilt_sim.ros import runner  # noqa: E402 (after the line above, on purpose)

PROGRAM = 'sim_node'


def make_sim_node(args: Sequence[str] | None = None):
    """Build the SimNode (imports rclpy and PyBullet: call it once the handlers are in).

    Its physics runs in a paced thread of its own (see
    :mod:`pan_tilt_sim.ros.physics_thread`).  ``args`` (default: the
    program's command line) are the ROS arguments rcl was given; the node
    reads their ``--params-file`` for its controllers as ros2_control_node does.
    """
    from pan_tilt_sim.ros.sim_node import SimNode

    return SimNode(physics_thread=True, ros_arguments=sys.argv if args is None else args)


def make_executor(node):
    """Return the executor that takes turns with the node's physics thread."""
    from pan_tilt_sim.ros.physics_thread import TurnTakingExecutor

    return TurnTakingExecutor(node.turns, context=node.context)


def main(args: list[str] | None = None) -> None:
    """Run sim_node until SIGINT/SIGTERM (exit 0); a configuration error exits with code 2."""
    runner.main(lambda: make_sim_node(args), args, program=PROGRAM, make_executor=make_executor)


if __name__ == '__main__':
    main()
