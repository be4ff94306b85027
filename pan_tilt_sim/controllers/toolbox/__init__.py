"""Shared by controller families and plugins: PID, gains, limits, rate limiter, odometry."""
