"""gz-sim (and Ignition Gazebo) systems."""
