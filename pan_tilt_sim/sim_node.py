"""Re-export of :mod:`pan_tilt_sim.ros.sim_node`: ``from pan_tilt_sim.sim_node import SimNode``.

A documented import path, kept stable; the node lives in
:mod:`pan_tilt_sim.ros.sim_node`, and the program that runs it is
``python -m pan_tilt_sim`` (:mod:`pan_tilt_sim.__main__`).
"""

from pan_tilt_sim.ros.sim_node import SimNode

__all__ = ['SimNode']
