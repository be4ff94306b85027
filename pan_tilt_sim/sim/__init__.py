"""The simulation: the only layer that imports PyBullet (one client per simulation)."""
