"""``parallel_gripper_action_controller/GripperActionController``: ParallelGripperCommand goals.

ros2_controllers' (jazzy) successor of the gripper action controllers, for
grippers whose two fingers close on an object from opposite sides (the other
finger, and any linkage, follow the commanded ``joint`` as ``<mimic>``
joints).  It serves control_msgs' ``ParallelGripperCommand`` on
``~/gripper_cmd`` (the node does, :mod:`pan_tilt_sim.ros.gripper_action`)
and runs goals exactly as :mod:`.gripper_action_controller` describes --
tolerance, stall, preemption, cancel -- with these differences, upstream's (see the design notes).

Design notes: docs/design/controllers.md#parallel_gripper_action_controllerpy.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from pan_tilt_sim.controllers.framework.parameter_spec import (
    DOUBLE,
    STRING,
    STRING_ARRAY,
    Param,
    ParameterSpec,
    Validator,
    gt_eq,
    unique,
)
from pan_tilt_sim.controllers.grippers.gripper_action_controller import (
    GripperActionController,
    GripperRequest,
    gripper_parameters,
)

MAX_EFFORT_INTERFACE_FIELD = 'max_effort_interface'
MAX_VELOCITY_INTERFACE_FIELD = 'max_velocity_interface'
MAX_VELOCITY_FIELD = 'max_velocity'
STATE_INTERFACES_FIELD = 'state_interfaces'
NEEDED_STATES = ('position', 'velocity')


def _interface_name(value: str) -> str | None:
    """Return what is wrong with a claimed interface's name ('' is none claimed), or None."""
    if not value:
        return None
    prefix, _, interface = value.rpartition('/')
    if not prefix or not interface:
        return f"'{value}' must be '<joint>/<command interface>'"
    return None


def _has_needed_states(interfaces: Sequence[str]) -> str | None:
    missing = [name for name in NEEDED_STATES if name not in interfaces]
    return (f'Expected 1 {missing[0]} state interface (in {list(interfaces)!r})' if missing
            else None)


INTERFACE_NAME = Validator("'' or '<joint>/<command interface>'", _interface_name)
NEEDED_STATE_INTERFACES = Validator('includes position and velocity', _has_needed_states)


class ParallelGripperActionController(GripperActionController):
    """ParallelGripperCommand goals on one joint; max effort and velocity through interfaces."""

    type_names = ('parallel_gripper_action_controller/GripperActionController',)
    parameters = ParameterSpec((
        *gripper_parameters(max_effort=10.0, read_only_rate=True, max_effort_text=(
            'Effort (N or N*m) when the goal gives none, before the first goal and after a '
            'cancel (through max_effort_interface only).')),
        Param(STATE_INTERFACES_FIELD, STRING_ARRAY, ['position', 'velocity'],
              'The state interfaces read from the joint.',
              (unique(), NEEDED_STATE_INTERFACES)),
        Param(MAX_EFFORT_INTERFACE_FIELD, STRING, '', 'A command interface '
              "(<joint>/<interface>) the goal's effort, or max_effort, is written to; it "
              'bounds the force. Empty: none.', (INTERFACE_NAME,)),
        Param(MAX_VELOCITY_INTERFACE_FIELD, STRING, '', 'A command interface '
              "(<joint>/<interface>) the goal's velocity, or max_velocity, is written to; it "
              'bounds the speed. Empty: none.', (INTERFACE_NAME,)),
        Param(MAX_VELOCITY_FIELD, DOUBLE, 0.1, 'Speed (m/s or rad/s) when the goal gives none '
              '(through max_velocity_interface only).', (gt_eq(0.0),)),
    ))
    action_type = 'control_msgs/action/ParallelGripperCommand'

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._effort_interface: str = self.params[MAX_EFFORT_INTERFACE_FIELD]
        self._velocity_interface: str = self.params[MAX_VELOCITY_INTERFACE_FIELD]
        self._default_velocity: float = self.params[MAX_VELOCITY_FIELD]
        self._state_interfaces = tuple(self.params[STATE_INTERFACES_FIELD])

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return ``<joint>/position`` and the max effort and velocity interfaces named."""
        claims: dict[str, tuple[str, ...]] = {self._joint_name: ('position',)}
        for full in (self._effort_interface, self._velocity_interface):
            if full:
                prefix, _, interface = full.rpartition('/')
                claims[prefix] = claims.get(prefix, ()) + (interface,)
        return claims

    def state_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the ``state_interfaces`` listed, of the joint."""
        return {self._joint_name: self._state_interfaces}

    def hold_request(self, position: float) -> GripperRequest:
        """Return the command that holds ``position``: the parameters' effort and speed."""
        return self.request(position)

    def request(self, position: float, velocities: Sequence[float] = (),
                efforts: Sequence[float] = ()) -> GripperRequest:
        """Return what a goal of ``position`` (with its velocities and efforts) asks of the joint.

        The goal's ``velocities[0]`` / ``efforts[0]`` when the interface they
        go through is claimed and they are given, else the parameters'; an
        interface not claimed bounds nothing (effort 0, velocity None: the
        joint's own limits).
        """
        effort = efforts[0] if efforts else self._default_effort
        velocity = velocities[0] if velocities else self._default_velocity
        return GripperRequest(position, effort if self._effort_interface else 0.0,
                              velocity if self._velocity_interface else None)

    def goal_request(self, positions: Sequence[float], velocities: Sequence[float],
                     efforts: Sequence[float]) -> tuple[GripperRequest | None, str]:
        """Return the request of a goal's command, or None and upstream's reason to reject it."""
        if len(positions) != 1:
            return None, ('Received action goal with wrong number of position values, '
                          f'expects 1, got {len(positions)}')
        return self.request(positions[0], velocities, efforts), ''

    def result_effort(self) -> float:
        """Return the effort the actuator applied (upstream leaves the result's effort unset)."""
        return self._handle.effort
