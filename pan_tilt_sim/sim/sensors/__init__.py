"""Sensors declared in the URDF, measured in the simulation's own PyBullet client. No ROS.

One module per kind: :mod:`.vision` (camera and depth camera, TinyRenderer),
:mod:`.lidar` (batched ray casts), :mod:`.imu` (link states) and
:mod:`.force_torque` (PyBullet's joint force-torque sensor); :mod:`.mount`
finds where a sensor is, :mod:`.noise` adds the declared Gaussian noise.
Every sensor only reads the world, between batches of physics steps.
"""
