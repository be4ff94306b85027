"""A joint trajectory controller over three hand-made joints, without a simulator."""

from __future__ import annotations

from typing import Any

from pan_tilt_sim.controllers import JointHandle, create_controller
from pan_tilt_sim.controllers.trajectory.trajectory import JointTrajectory, TrajectoryPoint
from pan_tilt_sim.model.robot import JointKind, JointSpec

JTC = 'joint_trajectory_controller/JointTrajectoryController'
JOINTS = ('a', 'b')  # the controller's joints; 'c' is there but not claimed


def make_handles() -> dict[str, JointHandle]:
    """A revolute 'a' (±2), a prismatic 'b' (±0.5) and a continuous 'c'."""
    specs = [JointSpec('a', JointKind.REVOLUTE, -2.0, 2.0, effort_limit=1000.0),
             JointSpec('b', JointKind.PRISMATIC, -0.5, 0.5, effort_limit=1000.0),
             JointSpec('c', JointKind.CONTINUOUS)]
    return {spec.name: JointHandle(spec) for spec in specs}


def limited_handles() -> dict[str, JointHandle]:
    """As :func:`make_handles`, with velocity and effort limits on 'a' and 'b'.

    'a': 1 rad/s and 30 N*m; 'b': 0.2 m/s and 50 N.
    """
    specs = [JointSpec('a', JointKind.REVOLUTE, -2.0, 2.0, effort_limit=30.0,
                       velocity_limit=1.0),
             JointSpec('b', JointKind.PRISMATIC, -0.5, 0.5, effort_limit=50.0,
                       velocity_limit=0.2),
             JointSpec('c', JointKind.CONTINUOUS)]
    return {spec.name: JointHandle(spec) for spec in specs}


def controller_for(handles: dict[str, JointHandle] | None = None, **params: Any):
    """A configured JTC named 'arm' over JOINTS (unless ``joints`` is given)."""
    params.setdefault('joints', list(JOINTS))
    controller = create_controller('arm', JTC, params, 'test.yaml')
    controller.configure(handles if handles is not None else make_handles())
    return controller


def trajectory(*points: tuple, names: tuple[str, ...] = JOINTS,
               start: float | None = None) -> JointTrajectory:
    """Points as (time_from_start, positions[, velocities[, accelerations[, efforts]]])."""
    return JointTrajectory(tuple(names), tuple(TrajectoryPoint(*point) for point in points),
                           start)
