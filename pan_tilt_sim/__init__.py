"""pan_tilt_sim: a headless PyBullet stand-in for Gazebo + gazebo_ros_control.

Layers, data flowing one way:

* ``description``  -- xacro/URDF files to a processed URDF and joint facts;
* ``physics``      -- one PyBullet client, torque-driven joints;
* ``controllers``  -- pure-Python controllers (no rclpy), built from YAML;
* ``engine``       -- the stepping loop tying physics and controllers;
* ``sim_node``     -- the thin rclpy node: parameters, topics, timing;
  ``services`` -- its reset/pause services;
* ``runner``       -- the program around it: ROS arguments, one-line start-up
  errors (exit code 2), SIGINT/SIGTERM.
"""
