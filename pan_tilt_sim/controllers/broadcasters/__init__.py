"""Broadcasters: joint states and the semantic sensors (IMU, force/torque, range, pose)."""
