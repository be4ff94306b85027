"""The small base every controller stands on (after ros2_control's ControllerInterface).

A controller is pure Python: it is built from its YAML parameters, then
:meth:`Controller.configure` hands it the :class:`JointHandle` objects of
the joints it names, and :meth:`Controller.update` runs once per physics
step.  Handles carry the measured state (written by the simulation before
each update) and the effort command (written by the controller, read by the
simulation after it).  Controllers never touch PyBullet or rclpy.
"""

from __future__ import annotations

import abc
import enum
import math
from collections.abc import Mapping
from typing import Any, ClassVar

from pan_tilt_sim.controllers.pid import Pid
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.robot import JointSpec

# The command interface a ros2_control controller package's controllers claim.
PACKAGE_INTERFACES = {'position_controllers': 'position', 'velocity_controllers': 'velocity',
                      'effort_controllers': 'effort'}
# Largest command magnitude taken on a side without a limit (rad, m, rad/s, N*m...):
# far beyond any real joint, small enough that PID arithmetic on it stays finite.
MAX_COMMAND_MAGNITUDE = 1e12


class JointHandle:
    """State and effort command of one joint, shared by simulation and controllers."""

    __slots__ = ('spec', 'position', 'velocity', 'effort')

    def __init__(self, spec: JointSpec) -> None:
        self.spec = spec
        self.position = spec.initial_position
        self.velocity = 0.0
        self.effort = 0.0

    @property
    def name(self) -> str:
        """The joint's URDF name."""
        return self.spec.name

    def reset(self) -> None:
        """Return to the joint's initial state (at rest, no effort)."""
        self.position = self.spec.initial_position
        self.velocity = 0.0
        self.effort = 0.0


class CommandKind(enum.Enum):
    """What a command controller's topic carries (the node maps kinds to message types)."""

    FLOAT64 = 'std_msgs/msg/Float64'
    FLOAT64_ARRAY = 'std_msgs/msg/Float64MultiArray'
    JOINT_TRAJECTORY = 'trajectory_msgs/msg/JointTrajectory'


class CommandResult(enum.Enum):
    """What became of one command value."""

    ACCEPTED = 'accepted'
    CLAMPED = 'clamped'
    REJECTED = 'rejected'


class Controller(abc.ABC):
    """Base of every controller type; subclasses list their YAML ``type`` strings."""

    type_names: ClassVar[tuple[str, ...]] = ()
    # The YAML type this controller was created from (the registry sets it).
    type_name: str = ''
    # The YAML section the PID gains come from: 'pid' (ROS 1, one joint) or
    # 'gains' (ros2_controllers, per joint); the gain parameters follow it.
    gains_field: ClassVar[str] = 'gains'

    def __init__(self, name: str, params: Mapping[str, Any], source: str = '') -> None:
        self.name = name
        self.params = params
        self._source = source

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The joints this controller claims (commands them exclusively)."""
        return ()

    @abc.abstractmethod
    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Take the handles of the joints this controller uses."""

    @abc.abstractmethod
    def update(self, time: float, period: float) -> None:
        """Run one control step at sim ``time`` (s), ``period`` s after the previous one."""

    def command_interfaces(self) -> dict[str, tuple[str, ...]]:
        """Return the command interfaces this controller claims, by joint (ros2_control's claim).

        ``position``, ``velocity`` or ``effort``: a joint whose ``<ros2_control>``
        block lacks one of them cannot be driven by this controller.
        """
        return {}

    def reset(self) -> None:  # noqa: B027 -- stateless controllers need no reset
        """Forget commands and internal state, as after a fresh start."""

    def pids(self) -> dict[str, Pid]:
        """Return the PIDs of this controller by joint (gains may change live); none here."""
        return {}

    def error(self, field: str, problem: str) -> ControllerConfigError:
        """Return an error naming this controller's field in the controllers file."""
        where = f'{self._source}: ' if self._source else ''
        return ControllerConfigError(f'{where}{self.name}.{field}: {problem}')

    def handle(self, joints: Mapping[str, JointHandle], joint: str, field: str, *,
               commanded: bool = True) -> JointHandle:
        """Look up ``joint``; the error lists the joints that exist.

        A ``<mimic>`` joint follows its leader, so it cannot be ``commanded``.
        """
        try:
            handle = joints[joint]
        except KeyError:
            existing = ', '.join(sorted(joints)) or 'none'
            raise self.error(
                field, f"joint '{joint}' is not a movable joint of the robot "
                f'(movable joints: {existing})') from None
        mimic = handle.spec.mimic
        if commanded and mimic is not None:
            raise self.error(
                field, f"joint '{joint}' mimics '{mimic.joint}': it follows that joint "
                'and cannot be commanded')
        return handle

    def required_joint(self) -> str:
        """Return the ``joint`` parameter, which must be a non-empty string."""
        joint = self.params.get('joint')
        if joint is None or joint == '':
            raise self.error('joint', 'missing: name the joint this controller drives')
        if not isinstance(joint, str):
            raise self.error('joint', f'{joint!r} is not a joint name (expected one string)')
        return joint

    def joint_list(self, field: str = 'joints', *, required: bool = True) -> tuple[str, ...]:
        """Return the ``joints`` parameter: distinct joint names (may be empty if not required)."""
        joints = self.params.get(field)
        if joints is None and not required:
            return ()
        if not isinstance(joints, list | tuple) or not all(
                isinstance(joint, str) and joint for joint in joints):
            raise self.error(field, f'{joints!r} must be a list of joint names')
        if required and not joints:
            raise self.error(field, 'empty: name the joints this controller drives')
        repeated = sorted({joint for joint in joints if joints.count(joint) > 1})
        if repeated:
            raise self.error(field, f"joint '{repeated[0]}' is named more than once")
        return tuple(joints)


class CommandController(Controller):
    """A controller that takes commands from a topic ``<controller>/<command_topic>``."""

    command_topic: ClassVar[str] = 'command'
    command_kind: ClassVar[CommandKind] = CommandKind.FLOAT64

    @abc.abstractmethod
    def set_command(self, value: Any) -> CommandResult:
        """Store the latest command (called from subscriptions; must be cheap)."""

    @abc.abstractmethod
    def setpoints(self) -> dict[str, float]:
        """Return what each joint is driven toward now, by joint, in its interface's unit.

        For a position loop the rate-limited setpoint, for a velocity or
        effort command the (clamped) command, for a trajectory the desired
        position sampled at the present sim time.
        """

    def command_problem(self, value: Any, result: CommandResult) -> str:
        """Describe what was wrong with ``value``, which ``set_command`` rejected or clamped."""
        if result is CommandResult.REJECTED:
            return (f'ignored command {value!r}: not a finite number within '
                    f'+-{MAX_COMMAND_MAGNITUDE:g}')
        return f"command {value!r} is outside the joint's limits; clamped"


def clamp(value: float, lower: float, upper: float) -> float:
    """Limit ``value`` to [lower, upper]."""
    return lower if value < lower else upper if value > upper else value


def is_sane_number(value: Any) -> bool:
    """Whether ``value`` is a finite number within +-MAX_COMMAND_MAGNITUDE."""
    return isinstance(value, int | float) and math.isfinite(value) and (
        abs(value) <= MAX_COMMAND_MAGNITUDE)


def bounded_command(value: float, lower: float, upper: float) -> tuple[float, CommandResult]:
    """Check a scalar command: non-finite or huge is rejected, out-of-range is clamped.

    A command beyond +-MAX_COMMAND_MAGNITUDE (1e308, say) is rejected, not
    clamped: no joint means it, it is a broken sender, and on a side without
    a limit gains times such an error would overflow.
    """
    if not is_sane_number(value):
        return value, CommandResult.REJECTED
    if value < lower or value > upper:
        return clamp(value, lower, upper), CommandResult.CLAMPED
    return value, CommandResult.ACCEPTED
