"""Steering controllers (ackermann, bicycle, tricycle steering) and their kinematics."""
