"""gazebo_ros (ROS 2) and gazebo_plugins (ROS 1) model plugins."""
