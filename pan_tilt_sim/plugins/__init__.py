"""Gazebo's model plugins as units of the simulation: one module each, one registry. No ROS.

``gazebo_classic/`` holds the gazebo_ros (ROS 2) / gazebo_plugins (ROS 1)
plugins, ``gz/`` gz-sim's systems, ``framework/`` what they share (the
element reader, the plugin interface, the sample types) and ``registry.py``
the one list of plugin types.  See docs/architecture.md.
"""
