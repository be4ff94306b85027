"""pan_tilt_sim: a headless PyBullet stand-in for Gazebo + gazebo_ros_control.

Layers, data flowing one way (``test/test_layers.py`` enforces it):

* ``model``       -- the robot as files describe it: xacro/URDF to one robot
  model, meshes, kinematics, mimic, names, controller YAML.  No rclpy, no PyBullet.
* ``controllers`` -- pure-Python controllers built from the YAML (no rclpy,
  no PyBullet), one type per module, a registry of YAML ``type`` strings.
* ``sim``         -- the only place PyBullet is imported: one client per
  simulation, the stepping loop (``engine``), scenery, the camera renderer.
* ``ros``         -- everything that imports rclpy: the thin ``sim_node``,
  its parameters, services, publishers, pacing and the program around it.
* ``tools``       -- step_response, bench, launch-file helpers.

``errors``, ``schedule`` and ``share`` are small shared modules any layer
may use.  The documented entry points stay where they were:
``pan_tilt_sim.sim_node.SimNode`` and ``pan_tilt_sim.engine.make_simulation``.
"""
