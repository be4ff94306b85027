"""Gripper action controllers: position, parallel and effort grippers."""
