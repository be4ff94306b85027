"""The ROS adapter: everything that imports rclpy."""
