"""Maps the YAML ``type`` strings to controller classes."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.controllers.broadcasters.force_torque_sensor_broadcaster import (
    ForceTorqueSensorBroadcaster,
)
from pan_tilt_sim.controllers.broadcasters.imu_sensor_broadcaster import IMUSensorBroadcaster
from pan_tilt_sim.controllers.broadcasters.joint_state_broadcaster import JointStateBroadcaster
from pan_tilt_sim.controllers.broadcasters.pose_broadcaster import PoseBroadcaster
from pan_tilt_sim.controllers.broadcasters.range_sensor_broadcaster import RangeSensorBroadcaster
from pan_tilt_sim.controllers.commands.forward_command_controller import ForwardCommandController
from pan_tilt_sim.controllers.commands.gpio_command_controller import GpioCommandController
from pan_tilt_sim.controllers.commands.joint_effort_controller import JointEffortController
from pan_tilt_sim.controllers.commands.joint_group_effort_controller import (
    JointGroupEffortController,
)
from pan_tilt_sim.controllers.commands.joint_group_position_controller import (
    JointGroupPositionController,
)
from pan_tilt_sim.controllers.commands.joint_group_velocity_controller import (
    JointGroupVelocityController,
)
from pan_tilt_sim.controllers.commands.joint_position_controller import JointPositionController
from pan_tilt_sim.controllers.commands.joint_velocity_controller import JointVelocityController
from pan_tilt_sim.controllers.commands.pid_controller import PidController
from pan_tilt_sim.controllers.drives.diff_drive_controller import DiffDriveController
from pan_tilt_sim.controllers.drives.mecanum_drive_controller import MecanumDriveController
from pan_tilt_sim.controllers.drives.omni_wheel_drive_controller import OmniWheelDriveController
from pan_tilt_sim.controllers.drives.steering.ackermann_steering_controller import (
    AckermannSteeringController,
)
from pan_tilt_sim.controllers.drives.steering.bicycle_steering_controller import (
    BicycleSteeringController,
)
from pan_tilt_sim.controllers.drives.steering.tricycle_steering_controller import (
    TricycleSteeringController,
)
from pan_tilt_sim.controllers.drives.tricycle_controller import TricycleController
from pan_tilt_sim.controllers.framework.base import Controller
from pan_tilt_sim.controllers.grippers.effort_gripper_action_controller import (
    EffortGripperActionController,
)
from pan_tilt_sim.controllers.grippers.gripper_action_controller import GripperActionController
from pan_tilt_sim.controllers.grippers.parallel_gripper_action_controller import (
    ParallelGripperActionController,
)
from pan_tilt_sim.controllers.trajectory.joint_trajectory_controller import (
    JointTrajectoryController,
)
from pan_tilt_sim.errors import ControllerConfigError

CONTROLLER_CLASSES: tuple[type[Controller], ...] = (
    JointStateBroadcaster,
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
