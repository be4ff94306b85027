"""A gripper action controller on a hand-moved finger, without a simulator.

:class:`HandMovedGripper` loads, configures and activates a gripper
controller on :data:`FINGER` (a mimic :data:`FOLLOWER` beside it) and moves
the finger by hand: each step it goes where the ideal actuator's velocity
target takes it, or stays blocked by an object between the fingers.
"""

from __future__ import annotations

from controller_fixtures import DT, loaded

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.controllers.grippers.gripper_action_controller import (
    GripperActionController,
    GripperGoal,
    GripperRequest,
)
from pan_tilt_sim.model.robot import JointKind, JointSpec, Mimic

POSITION_TYPE = 'position_controllers/GripperActionController'
EFFORT_TYPE = 'effort_controllers/GripperActionController'
EFFORT_LIMIT = 40.0  # N
VELOCITY_LIMIT = 0.2  # m/s
FINGER = JointSpec('finger', JointKind.PRISMATIC, 0.0, 0.05, effort_limit=EFFORT_LIMIT,
                   velocity_limit=VELOCITY_LIMIT)
FOLLOWER = JointSpec('follower', JointKind.PRISMATIC, 0.0, 0.05, mimic=Mimic('finger'))


class HandMovedGripper:
    """An active gripper controller on FINGER, its handle, and the sim time of its updates."""

    def __init__(self, type_name: str = POSITION_TYPE, start: float = 0.03, **params) -> None:
        self.handle = JointHandle(FINGER, initial_position=start)
        handles = {'finger': self.handle, 'follower': JointHandle(FOLLOWER)}
        self.manager = loaded('gripper', type_name, {'joint': 'finger', **params}, handles)
        self.controller: GripperActionController = self.manager.configure('gripper')
        self.manager.switch(activate=['gripper'])
        self.time = 0.0

    def goal(self, position: float, max_effort: float = 0.0) -> GripperGoal:
        """Start a goal of ``position`` with ``max_effort`` now."""
        return self.controller.start_goal(GripperRequest(position, max_effort), self.time)

    def run(self, seconds: float, *, blocked_at: float | None = None) -> None:
        """Update for ``seconds``; the joint follows its velocity target unless it is blocked.

        ``blocked_at``: an object there stops a closing finger (it rests on it, at 0 m/s).
        """
        for _ in range(round(seconds / DT)):
            self.controller.update(self.time, DT)
            handle = self.handle
            handle.velocity = handle.velocity_target
            handle.position += handle.velocity * DT
            if blocked_at is not None and handle.position <= blocked_at:
                handle.position, handle.velocity = blocked_at, 0.0
            self.time += DT
