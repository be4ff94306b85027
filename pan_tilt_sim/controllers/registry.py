"""Maps the YAML ``type`` strings to controller classes."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.controllers.ackermann_steering_controller import AckermannSteeringController
from pan_tilt_sim.controllers.base import Controller
from pan_tilt_sim.controllers.bicycle_steering_controller import BicycleSteeringController
from pan_tilt_sim.controllers.diff_drive_controller import DiffDriveController
from pan_tilt_sim.controllers.effort_gripper_action_controller import (
    EffortGripperActionController,
)
from pan_tilt_sim.controllers.force_torque_sensor_broadcaster import (
    ForceTorqueSensorBroadcaster,
)
from pan_tilt_sim.controllers.forward_command_controller import ForwardCommandController
from pan_tilt_sim.controllers.gpio_command_controller import GpioCommandController
from pan_tilt_sim.controllers.gripper_action_controller import GripperActionController
from pan_tilt_sim.controllers.imu_sensor_broadcaster import IMUSensorBroadcaster
from pan_tilt_sim.controllers.joint_effort_controller import JointEffortController
from pan_tilt_sim.controllers.joint_group_effort_controller import JointGroupEffortController
from pan_tilt_sim.controllers.joint_group_position_controller import (
    JointGroupPositionController,
)
from pan_tilt_sim.controllers.joint_group_velocity_controller import (
    JointGroupVelocityController,
)
from pan_tilt_sim.controllers.joint_position_controller import JointPositionController
from pan_tilt_sim.controllers.joint_state_controller import JointStateController
from pan_tilt_sim.controllers.joint_trajectory_controller import JointTrajectoryController
from pan_tilt_sim.controllers.joint_velocity_controller import JointVelocityController
from pan_tilt_sim.controllers.mecanum_drive_controller import MecanumDriveController
from pan_tilt_sim.controllers.omni_wheel_drive_controller import OmniWheelDriveController
from pan_tilt_sim.controllers.parallel_gripper_action_controller import (
    ParallelGripperActionController,
)
from pan_tilt_sim.controllers.pid_controller import PidController
from pan_tilt_sim.controllers.pose_broadcaster import PoseBroadcaster
from pan_tilt_sim.controllers.range_sensor_broadcaster import RangeSensorBroadcaster
from pan_tilt_sim.controllers.tricycle_controller import TricycleController
from pan_tilt_sim.controllers.tricycle_steering_controller import TricycleSteeringController
from pan_tilt_sim.errors import ControllerConfigError

CONTROLLER_CLASSES: tuple[type[Controller], ...] = (
    JointStateController,
    JointPositionController,
    JointVelocityController,
    JointEffortController,
    ForwardCommandController,
    JointGroupPositionController,
    JointGroupVelocityController,
    JointGroupEffortController,
    JointTrajectoryController,
    PidController,
    DiffDriveController,
    MecanumDriveController,
    OmniWheelDriveController,
    AckermannSteeringController,
    BicycleSteeringController,
    TricycleSteeringController,
    TricycleController,
    GripperActionController,
    EffortGripperActionController,
    ParallelGripperActionController,
    ForceTorqueSensorBroadcaster,
    IMUSensorBroadcaster,
    RangeSensorBroadcaster,
    PoseBroadcaster,
    GpioCommandController,
)

CONTROLLER_TYPES: dict[str, type[Controller]] = {
    type_name: cls for cls in CONTROLLER_CLASSES for type_name in cls.type_names}


def supported_types() -> list[str]:
    """Return every YAML ``type`` string the simulator understands, sorted."""
    return sorted(CONTROLLER_TYPES)


def create_controller(name: str, type_name: Any, params: Mapping[str, Any],
                      source: str = '') -> Controller:
    """Build the controller ``name`` of ``type_name``; unknown types list the supported ones."""
    cls = CONTROLLER_TYPES.get(type_name) if isinstance(type_name, str) else None
    if cls is None:
        where = f'{source}: ' if source else ''
        raise ControllerConfigError(
            f"{where}{name}.type: unknown controller type '{type_name}' "
            f"(supported: {', '.join(supported_types())})")
    controller = cls(name, params, source)
    controller.type_name = type_name
    return controller


def is_known_type(type_name: Any) -> bool:
    """Whether ``type_name`` is a controller type the simulator has."""
    return isinstance(type_name, str) and type_name in CONTROLLER_TYPES


def drives_base(type_name: Any) -> bool:
    """Whether a controller of ``type_name`` moves a mobile base (False for unknown types)."""
    cls = CONTROLLER_TYPES.get(type_name) if isinstance(type_name, str) else None
    return cls is not None and cls.drives_base


def is_command_type(type_name: Any) -> bool:
    """Whether a controller of ``type_name`` commands joints (known or not).

    Unknown types are judged by name, as ros2_control names them: broadcasters
    (``*Broadcaster``, ROS 1's ``*StateController``) only read.
    """
    cls = CONTROLLER_TYPES.get(type_name) if isinstance(type_name, str) else None
    if cls is not None:
        return cls.commands_joints
    base = str(type_name).rpartition('/')[2]
    return not base.endswith(('Broadcaster', 'StateController'))
