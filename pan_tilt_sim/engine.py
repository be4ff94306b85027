"""Re-export of :mod:`pan_tilt_sim.sim.engine`: ``from pan_tilt_sim.engine import make_simulation``.

A documented import path of the ROS-free simulation loop, kept stable; it
lives in :mod:`pan_tilt_sim.sim.engine`.
"""

from pan_tilt_sim.sim.engine import Simulation, make_simulation

__all__ = ['Simulation', 'make_simulation']
