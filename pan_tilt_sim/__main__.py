"""The sim_node program: ``python -m pan_tilt_sim`` and the ``sim_node`` console script.

Both start here, so both behave the same: the signal handlers are in place
before rclpy and PyBullet are imported (about half a second), so a Ctrl-C
at any moment stops the program cleanly; a configuration error exits with
code 2 and one line (see :mod:`pan_tilt_sim.ros.runner`).
"""

from __future__ import annotations

from pan_tilt_sim.ros import runner

PROGRAM = 'sim_node'


def make_sim_node():
    """Build the SimNode (imports rclpy and PyBullet: call it once the handlers are in)."""
    from pan_tilt_sim.ros.sim_node import SimNode

    return SimNode()


def main(args: list[str] | None = None) -> None:
    """Run sim_node until SIGINT/SIGTERM (exit 0); a configuration error exits with code 2."""
    runner.main(make_sim_node, args, program=PROGRAM)


if __name__ == '__main__':
    main()
