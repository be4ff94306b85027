"""The controller framework: base classes, parameter specs, ROS surfaces, registry, manager."""
