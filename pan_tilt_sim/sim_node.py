"""The documented import path of the node: ``from pan_tilt_sim.sim_node import SimNode``.

The node lives in :mod:`pan_tilt_sim.ros.sim_node`; the program that runs
it is ``python -m pan_tilt_sim`` (:mod:`pan_tilt_sim.__main__`).
"""

from pan_tilt_sim.ros.sim_node import SimNode

__all__ = ['SimNode']
