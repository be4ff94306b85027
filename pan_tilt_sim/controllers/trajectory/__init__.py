"""The joint trajectory controller, its trajectories and its FollowJointTrajectory goals."""
