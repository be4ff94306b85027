"""The robot as its files describe it: no rclpy, no PyBullet."""
