"""``effort_controllers/GripperActionController``: grasp goals through a PID on effort.

Goals run as :mod:`.gripper_action_controller` describes; the joint is
driven by a PID on the position error, its derivative on the measured
velocity -- gains ``gains.<joint>: {p, i, d, i_clamp}`` (upstream's
adapter's names), else ``gazebo_ros_control/pid_gains/<joint>``, else the
position controller's defaults (p 100, i 0.01, d 10; upstream's are zero:
nothing would move) -- and its effort is clamped to ``|max_effort|``, as
upstream clamps it (so ``max_effort`` 0, the parameter's default, applies
no effort at all: a goal asking for it gets a notice), and to the URDF
effort limit.  The result's ``effort`` is the last effort computed.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.controllers.framework.base import Actuator, ActuatorKind, JointHandle
from pan_tilt_sim.controllers.framework.shared_parameters import pid_gains
from pan_tilt_sim.controllers.grippers.gripper_action_controller import (
    GripperActionController,
    GripperGoal,
    GripperRequest,
)
from pan_tilt_sim.controllers.toolbox.gains import (
    DEFAULT_POSITION_GAINS,
    GAINS_FIELD,
    choose_gains,
    joint_gains_from_params,
)
from pan_tilt_sim.controllers.toolbox.pid import Pid


class EffortGripperActionController(GripperActionController):
    """GripperCommand goals on one joint: a PID on effort, clamped to max_effort."""

    type_names = ('effort_controllers/GripperActionController',)
    parameters = GripperActionController.parameters.extend(*pid_gains('gains.__map_joint'))
    gains_field = GAINS_FIELD
    interface = 'effort'

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        super().__init__(name, params, source)
        self._own_gains = joint_gains_from_params(self, [self._joint_name]).get(self._joint_name)
        self._pid: Pid | None = None

    def pids(self) -> dict[str, Pid]:
        """Return the joint's PID (its gains may be changed live)."""
        return {} if self._pid is None else {self._joint_name: self._pid}

    def bind(self, handle: JointHandle) -> Actuator:
        """Return the PID that drives the joint: the YAML's gains, the plugin's, or defaults."""
        gains, source = choose_gains(self._own_gains, f'{self.name}.{GAINS_FIELD}.{handle.name}',
                                     handle, DEFAULT_POSITION_GAINS)
        self._pid = Pid(gains.with_default_clamp(handle.spec.effort_limit))
        return Actuator(ActuatorKind.POSITION_PID, self.name, self._pid, source)

    def reset(self) -> None:
        """As the base, and forget the PID's integral."""
        if self._pid is not None:
            self._pid.reset()
        super().reset()

    def start_goal(self, request: GripperRequest, now: float) -> GripperGoal:
        """As the base; a goal with max_effort 0 gets a notice: it applies no effort."""
        if request.max_effort == 0.0:
            self.notices.append(
                'a goal with max_effort 0: the effort is clamped to 0 and the joint is not '
                'driven (as ros2_controllers clamps it to |max_effort|)')
        return super().start_goal(request, now)

    def drive(self, handle: JointHandle, error: float, period: float) -> None:
        """PID on the position error, derivative on the measured velocity, clamped."""
        effort = self._pid.compute(self._command.position, handle.position, period,
                                   handle.velocity)
        limit = self._force_limit
        effort = limit if effort > limit else -limit if effort < -limit else effort
        self._computed_effort = effort
        handle.effort = effort

    def result_effort(self) -> float:
        """Return the last effort computed (upstream's computed_command_)."""
        return self._computed_effort

    def _set_command(self, request: GripperRequest) -> None:
        super()._set_command(request)
        # Upstream clamps the PID's output to |max_effort|, 0 included; the URDF limit too.
        self._force_limit = min(abs(request.max_effort), self._effort_limit)
