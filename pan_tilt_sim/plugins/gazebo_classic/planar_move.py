"""``libgazebo_ros_planar_move.so`` as a unit of the simulation: the base moved by a Twist. No ROS.

Not a ros2_control controller: the simulation creates one per plugin
element (:mod:`pan_tilt_sim.plugins.registry`) and updates it every physics
step, before the controllers; it is always active.  As the plugin, a
``geometry_msgs/Twist`` (``linear.x``, ``linear.y``, ``angular.z``; ROS 1:
until ``cmdTimeout``; a non-finite one is refused) *sets* the base's planar
velocity every ``1 / update_rate`` s: no wheel turns.  The unit computes the
velocity (:meth:`GazeboPlanarMove.take_base_velocity`); the simulation sets
it on the base before the physics step.  The base's true pose and twist go
to the odometry topic and ``/tf`` every ``1 / publish_rate`` s.  A reset
drops the command.  The whole behaviour: docs/design/gazebo-plugins.md.
Pure Python: the simulation hands in the base's state.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import ClassVar

from pan_tilt_sim.controllers.framework.base import (
    Actuator,
    CommandController,
    CommandKind,
    JointHandle,
)
from pan_tilt_sim.controllers.framework.surface import (
    CommandTopic,
    Endpoint,
    StateTopic,
)
from pan_tilt_sim.controllers.toolbox.odometry_outputs import OdometryOutputs, TfSink
from pan_tilt_sim.controllers.toolbox.twist_command import TwistCommand, TwistCommanded
from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.sensors import ROS1, ROS2
from pan_tilt_sim.model.transforms import Vector
from pan_tilt_sim.plugins.framework.drives import ClassicTopics
from pan_tilt_sim.plugins.framework.elements import (
    Element,
    ElementReader,
    ElementSpec,
    Kind,
    check_frames,
)
from pan_tilt_sim.plugins.framework.plugin import (
    BaseMotion,
    Plugin,
    PluginWorld,
    SpatialOdometrySink,
    heading,
)
from pan_tilt_sim.schedule import DUE_EPSILON

# The element spec, per generation; ROS 2 also reads <ros>, ROS 1 robotNamespace.
ROS2_ELEMENTS = ElementSpec(
    Element('update_rate', 20.0, non_negative=True),  # Hz, 0: every step
    Element('publish_rate', 20.0, non_negative=True),  # Hz, 0: every step
    Element('odometry_frame', 'odom', Kind.TEXT),
    Element('robot_base_frame', 'base_footprint', Kind.TEXT),
    Element('publish_odom', True, Kind.FLAG),
    Element('publish_odom_tf', True, Kind.FLAG),
    Element('covariance_x', 1e-5),
    Element('covariance_y', 1e-5),
    Element('covariance_yaw', 1e-3),
)
ROS1_ELEMENTS = ElementSpec(  # ROS 1 sets the velocity every step
    Element('odometryRate', 20.0, non_negative=True),  # Hz
    Element('odometryFrame', 'odom', Kind.TEXT),
    Element('robotBaseFrame', 'base_footprint', Kind.TEXT),
    Element('publishOdometryTf', True, Kind.FLAG),
    Element('cmdTimeout', -1.0),  # s, negative: none
    Element('commandTopic', 'cmd_vel', Kind.TEXT),
    Element('odometryTopic', 'odom', Kind.TEXT),
)
ROS1_PLANAR_MOVE_KEYS = {*ROS1_ELEMENTS.names, 'robotNamespace'}


@dataclasses.dataclass(frozen=True)
class PlanarMovePlugin(ClassicTopics):
    """One ``gazebo_ros_planar_move`` plugin: the base's planar velocity set from a Twist.

    ``update_rate`` (Hz, 0: every step): how often the base's velocity is
    set; ``publish_rate`` (Hz, 0: every step): odometry and TF.
    ``command_timeout`` (s, negative: none; ROS 1's ``cmdTimeout``).
    """

    name: str
    convention: str
    update_rate: float = 20.0
    publish_rate: float = 20.0
    odometry_frame: str = 'odom'
    robot_base_frame: str = 'base_footprint'
    publish_odom: bool = True
    publish_odom_tf: bool = True
    covariance: tuple[float, float, float] = (1e-5, 1e-5, 1e-3)  # x, y, yaw
    command_timeout: float = -1.0
    command_topic: str = 'cmd_vel'
    odometry_topic: str = 'odom'
    namespace: str = ''
    remappings: tuple[tuple[str, str], ...] = ()

    filename = 'libgazebo_ros_planar_move.so'

    # topics() and pose_covariance (the twist's too): ClassicTopics


def read_planar_move(element: PluginElement, model: RobotModel) -> PlanarMovePlugin:
    """Return the plugin's settings (the element spec).

    ROS 2: ``update_rate`` (20 Hz), ``publish_rate`` (20 Hz), ``publish_odom``
    / ``publish_odom_tf`` (true), ``odometry_frame``, ``robot_base_frame``,
    ``covariance_x|y|yaw``; ROS 1: ``commandTopic``, ``odometryTopic``,
    ``odometryFrame``, ``robotBaseFrame``, ``odometryRate`` (20 Hz),
    ``publishOdometryTf`` (true), ``cmdTimeout`` (-1: none).
    """
    reader = ElementReader(element, model.name)
    if reader.has_any(ROS1_PLANAR_MOVE_KEYS) and 'ros' not in reader.texts:
        values = ROS1_ELEMENTS.read(reader)
        plugin = PlanarMovePlugin(
            name=reader.name, convention=ROS1, update_rate=0.0,
            publish_rate=values['odometryRate'], odometry_frame=values['odometryFrame'],
            robot_base_frame=values['robotBaseFrame'], publish_odom=True,
            publish_odom_tf=values['publishOdometryTf'], command_timeout=values['cmdTimeout'],
            command_topic=values['commandTopic'], odometry_topic=values['odometryTopic'],
            namespace=reader.ros1_namespace())
        check_frames(reader, (('odometryFrame', plugin.odometry_frame),
                              ('robotBaseFrame', plugin.robot_base_frame)))
        return plugin
    namespace, remappings = reader.ros()
    values = ROS2_ELEMENTS.read(reader)
    plugin = PlanarMovePlugin(
        name=reader.name, convention=ROS2, update_rate=values['update_rate'],
        publish_rate=values['publish_rate'], odometry_frame=values['odometry_frame'],
        robot_base_frame=values['robot_base_frame'], publish_odom=values['publish_odom'],
        publish_odom_tf=values['publish_odom_tf'],
        covariance=(values['covariance_x'], values['covariance_y'], values['covariance_yaw']),
        namespace=namespace, remappings=remappings)
    check_frames(reader, (('odometry_frame', plugin.odometry_frame),
                          ('robot_base_frame', plugin.robot_base_frame)))
    return plugin


class GazeboPlanarMove(Plugin, OdometryOutputs, TwistCommanded, CommandController):
    """One ``gazebo_ros_planar_move`` plugin: a Twist sets the base's planar velocity."""

    filenames = frozenset({'gazebo_ros_planar_move'})
    filename = PlanarMovePlugin.filename
    sets_base_velocity = True
    drives_base: ClassVar[bool] = True
    command_kind = CommandKind.TWIST

    @classmethod
    def read(cls, element: PluginElement, model: RobotModel) -> PlanarMovePlugin:
        """Return the settings of ``element`` (:func:`read_planar_move`)."""
        return read_planar_move(element, model)

    def attach(self, world: PluginWorld) -> None:
        """Read the base's frame and velocities from the simulation."""
        self.set_base_motion(world.base_motion)

    def __init__(self, plugin: PlanarMovePlugin, source: str = '') -> None:
        super().__init__(plugin.name, {}, source)
        self.plugin = plugin
        self._update_period = 1.0 / plugin.update_rate if plugin.update_rate > 0.0 else 0.0
        self._publish_period = 1.0 / plugin.publish_rate if plugin.publish_rate > 0.0 else 0.0
        self._odometry_sink: SpatialOdometrySink | None = None
        self._tf_sink: TfSink | None = None
        self._base_motion: Callable[[], BaseMotion] | None = None
        self._command = TwistCommand('cmd_vel', sideways=True)
        self._time = 0.0
        self.reset()

    def actuators(self) -> dict[str, Actuator]:
        """None: the plugin moves the model, not its joints."""
        return {}

    def set_base_motion(self, source: Callable[[], BaseMotion]) -> None:
        """Where the unit reads the base's frame and velocities."""
        self._base_motion = source

    # --- ROS surface -----------------------------------------------------------------------

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the command topic in; odometry and ``/tf`` out, as the plugin publishes."""
        plugin = self.plugin
        command, odometry = plugin.topics(self.node_namespace.strip('/'))
        endpoints: list[Endpoint] = [
            CommandTopic(command, self.command_kind.value, self.set_command,
                         self.command_problem)]
        if plugin.publish_odom:
            endpoints.append(self.odometry_topic(
                odometry, (plugin.odometry_frame, plugin.robot_base_frame),
                plugin.pose_covariance, plugin.pose_covariance, spatial=True))
        if plugin.publish_odom_tf:
            endpoints.append(StateTopic('/tf', 'tf2_msgs/msg/TFMessage', self.set_tf_sink))
        return tuple(endpoints)

    # --- lifecycle -------------------------------------------------------------------------

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Nothing to bind: the plugin moves the model, not joints."""
        self.reset()

    def reset(self) -> None:
        """No command; both rates start again from sim time 0."""
        self._command.latest = None
        self._twist = (0.0, 0.0, 0.0)
        self._received = 0.0
        self._last_update = self._last_publish = 0.0
        self._pending: tuple[Vector, Vector] | None = None

    # --- commands (set_command, command_problem: TwistCommanded) ----------------------------

    def twist_taken(self) -> None:
        """Put the taken twist in force; ROS 1's cmdTimeout counts from now."""
        latest = self._command.latest
        self._twist = (latest.linear[0], latest.linear[1], latest.angular[2])
        self._received = self._time

    def setpoints(self) -> dict[str, float]:
        """None: no joint is commanded."""
        return {}

    @property
    def command(self) -> tuple[float, float, float]:
        """The twist in force: (linear.x, linear.y, angular.z)."""
        return self._twist

    # --- the step ---------------------------------------------------------------------------

    def update(self, time: float, period: float) -> None:
        """When due, compute the base's velocity (see :meth:`take_base_velocity`) and publish."""
        self._time = time
        plugin = self.plugin
        timeout = plugin.command_timeout
        if plugin.convention == ROS1 and timeout >= 0.0 and time - self._received > timeout:
            self._twist = (0.0, 0.0, 0.0)
        if self._base_motion is None:
            return
        if time - self._last_update + DUE_EPSILON >= self._update_period:
            frame, _linear, _angular = self._base_motion()
            yaw = heading(frame)
            x, y, angular = self._twist
            cos, sin = math.cos(yaw), math.sin(yaw)
            self._pending = ((x * cos - y * sin, y * cos + x * sin, 0.0), (0.0, 0.0, angular))
            self._last_update = time
        if self._odometry_sink is None and self._tf_sink is None:
            return
        if time - self._last_publish + DUE_EPSILON < self._publish_period:
            return
        self._last_publish = time
        self._publish(time)

    def take_base_velocity(self) -> tuple[Vector, Vector] | None:
        """Return the velocity to set on the base now (world linear, angular), once; or None."""
        pending, self._pending = self._pending, None
        return pending

    def _publish(self, time: float) -> None:
        frame, linear, angular = self._base_motion()
        yaw = heading(frame)
        cos, sin = math.cos(yaw), math.sin(yaw)
        vx, vy = linear[0], linear[1]
        twist = (cos * vx + sin * vy, cos * vy - sin * vx, 0.0)
        if self._odometry_sink is not None:
            self._odometry_sink(time, frame, twist, (0.0, 0.0, angular[2]))
        if self._tf_sink is not None:
            self._tf_sink(time, [(self.plugin.odometry_frame, self.plugin.robot_base_frame,
                                  frame)])
