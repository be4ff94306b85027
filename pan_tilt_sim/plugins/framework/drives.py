"""What the Gazebo plugins that drive the base share: topics, covariance, a wheeled unit.

:class:`ClassicTopics` gives a classic plugin's settings (ROS 1's or
ROS 2's ``gazebo_ros``) its command and odometry topics and its planar
odometry covariance.  :class:`WheeledDrive` is the unit classic's
``gazebo_ros_diff_drive`` and gz-sim's DiffDrive system both are: always
active, a twist in (:class:`~pan_tilt_sim.controllers.toolbox.twist_command.TwistCommanded`),
wheels by side (:class:`~pan_tilt_sim.controllers.toolbox.wheel_sides.WheelSides`),
planar wheel odometry out.  Pure Python.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from pan_tilt_sim.controllers.framework.base import CommandController, CommandKind, JointHandle
from pan_tilt_sim.controllers.toolbox.odometry import Odometry
from pan_tilt_sim.controllers.toolbox.odometry_outputs import OdometryOutputs
from pan_tilt_sim.controllers.toolbox.twist_command import TwistCommanded
from pan_tilt_sim.controllers.toolbox.wheel_sides import WheelSides
from pan_tilt_sim.model.sensors import ROS1, Ros2Names, ros1_resolve
from pan_tilt_sim.plugins.framework.elements import UNPLANAR_COVARIANCE
from pan_tilt_sim.plugins.framework.plugin import Plugin


class ClassicTopics:
    """Mixin of a classic drive plugin's settings: the fields it reads are the dataclass's."""

    name: str
    convention: str
    command_topic: str
    odometry_topic: str
    namespace: str
    remappings: tuple[tuple[str, str], ...]
    covariance: tuple[float, float, float]  # x, y, yaw

    def topics(self, override: str = '') -> tuple[str, str]:
        """Return the command and odometry topics (absolute), ``override`` as the namespace.

        ``override`` (sim_node's namespace or ``robot_namespace``) replaces the
        plugin's, as spawn's ``-robot_namespace`` does in Gazebo.
        """
        namespace = override or self.namespace
        if self.convention == ROS1:
            return (ros1_resolve(namespace, self.command_topic),
                    ros1_resolve(namespace, self.odometry_topic))
        names = Ros2Names(self.name, namespace, self.remappings)
        return names.topic(self.command_topic), names.topic(self.odometry_topic)

    @property
    def pose_covariance(self) -> tuple[float, ...]:
        """The odometry pose covariance's diagonal (x, y, z, roll, pitch, yaw)."""
        x, y, yaw = self.covariance
        return (x, y, UNPLANAR_COVARIANCE, UNPLANAR_COVARIANCE, UNPLANAR_COVARIANCE, yaw)


class WheeledDrive(Plugin, OdometryOutputs, TwistCommanded, CommandController):
    """A plugin unit driving wheels by side from a twist; subclasses step and publish.

    A subclass sets ``plugin`` (its settings, with ``joint_names``),
    ``_wheels``, ``_command`` and ``_odometry`` before its first reset.
    """

    drives_base: ClassVar[bool] = True
    command_kind = CommandKind.TWIST
    plugin: Any
    _wheels: WheelSides
    _odometry: Odometry

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The wheels, left then right."""
        return self.plugin.joint_names

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the wheels' handles, then reset."""
        self._wheels.bind(joints, self.handle)
        self.reset()

    def setpoints(self) -> dict[str, float]:
        """Return each wheel's velocity target (rad/s)."""
        return self._wheels.setpoints()

    @property
    def odometry(self) -> Odometry:
        """The wheel odometry (pose and twist in the odometry frame)."""
        return self._odometry
