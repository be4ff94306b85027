"""``libgazebo_ros_diff_drive.so`` as a unit of the simulation: the plugin's semantics, no ROS.

Not a ros2_control controller: the simulation creates one per plugin
element (:mod:`pan_tilt_sim.plugins.registry`) and updates it every physics
step, before the controllers; it is always active.  As the plugin, a
``geometry_msgs/Twist`` (``linear.x``, ``angular.z``; the last one holds, a
non-finite one is refused) sets each wheel pair's velocity targets every
``1 / update_rate`` s, reached by a motor of at most ``max_wheel_torque``
N m and ramped by ``max_wheel_acceleration``; odometry (``encoder``: the
first pair's wheels; ``world``: the base's true planar pose) goes to the
odometry topic and ``/tf``.  A reset drops the command and puts the
encoder odometry back at the origin.  Elements, defaults and the whole
behaviour per generation: docs/design/gazebo-plugins.md.  Pure Python.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from pan_tilt_sim.controllers.framework.base import (
    Actuator,
    ActuatorKind,
)
from pan_tilt_sim.controllers.framework.surface import (
    CommandTopic,
    Endpoint,
    StateTopic,
)
from pan_tilt_sim.controllers.toolbox.odometry import Odometry
from pan_tilt_sim.controllers.toolbox.twist_command import TwistCommand
from pan_tilt_sim.controllers.toolbox.wheel_sides import WheelSides
from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.sensors import ROS1, ROS2, Ros2Names
from pan_tilt_sim.plugins.framework.drives import ClassicTopics, WheeledDrive
from pan_tilt_sim.plugins.framework.elements import (
    Element,
    ElementReader,
    ElementSpec,
    Kind,
    check_frames,
    check_wheels,
    joints_by_name,
)
from pan_tilt_sim.plugins.framework.plugin import (
    BaseState,
    PlanarOdometrySink,
    PluginWorld,
)
from pan_tilt_sim.schedule import DUE_EPSILON

REACHED = 0.01  # m/s: a wheel this close to its speed is set to it directly (the plugin's)
ENCODER, WORLD = 'encoder', 'world'
ROS2_SOURCES = {0: ENCODER, 1: WORLD}  # gazebo_ros's odometry_source numbers
# The element spec, per generation (gazebo_ros's and gazebo_plugins' names and defaults).
# ROS 2 also reads left_joint/right_joint, wheel_separation and wheel_diameter once per
# wheel pair, and <ros>.
ROS2_ELEMENTS = ElementSpec(
    Element('num_wheel_pairs', 1.0),
    Element('odometry_source', 1.0),  # 0 encoder, 1 world
    Element('max_wheel_torque', 5.0, positive=True),  # N m
    Element('max_wheel_acceleration', 0.0, non_negative=True),  # m/s^2, 0: none
    Element('update_rate', 100.0, non_negative=True),  # Hz, 0: every step
    Element('odometry_frame', 'odom', Kind.TEXT),
    Element('robot_base_frame', 'base_footprint', Kind.TEXT),
    Element('publish_odom', False, Kind.FLAG),
    Element('publish_odom_tf', False, Kind.FLAG),
    Element('covariance_x', 1e-5),
    Element('covariance_y', 1e-5),
    Element('covariance_yaw', 1e-3),
)
# ROS 1 also reads robotNamespace.
ROS1_ELEMENTS = ElementSpec(
    Element('odometrySource', WORLD, Kind.TEXT),  # encoder or world
    Element('leftJoint', 'left_joint', Kind.TEXT),
    Element('rightJoint', 'right_joint', Kind.TEXT),
    Element('wheelSeparation', 0.34, positive=True),  # m
    Element('wheelDiameter', 0.15, positive=True),  # m
    Element('wheelTorque', 5.0, positive=True),  # N m
    Element('wheelAcceleration', 0.0, non_negative=True),  # m/s^2
    Element('updateRate', 100.0, non_negative=True),  # Hz
    Element('odometryFrame', 'odom', Kind.TEXT),
    Element('robotBaseFrame', 'base_footprint', Kind.TEXT),
    Element('publishTf', True, Kind.FLAG),  # the odometry
    Element('publishOdomTF', True, Kind.FLAG),
    Element('commandTopic', 'cmd_vel', Kind.TEXT),
    Element('odometryTopic', 'odom', Kind.TEXT),
)
# Elements only ROS 1's diff drive reads: they tell which generation a plugin is.
ROS1_DIFF_DRIVE_KEYS = {*ROS1_ELEMENTS.names, 'robotNamespace'}


@dataclasses.dataclass(frozen=True)
class DiffDrivePlugin(ClassicTopics):
    """One ``gazebo_ros_diff_drive`` plugin: wheels, geometry, limits, topics and frames.

    ``left_joints[i]`` and ``right_joints[i]`` are wheel pair i, with
    ``wheel_separation[i]`` (m) and ``wheel_diameter[i]`` (m).  Topics are
    as the plugin resolves them, before sim_node's namespace override
    (:meth:`topics`).  ``update_rate`` 0: every physics step.
    """

    name: str
    convention: str
    left_joints: tuple[str, ...]
    right_joints: tuple[str, ...]
    wheel_separation: tuple[float, ...]
    wheel_diameter: tuple[float, ...]
    max_wheel_torque: float = 5.0
    max_wheel_acceleration: float = 0.0
    update_rate: float = 100.0
    odometry_frame: str = 'odom'
    robot_base_frame: str = 'base_footprint'
    odometry_source: str = WORLD
    publish_odom: bool = False
    publish_odom_tf: bool = False
    covariance: tuple[float, float, float] = (1e-5, 1e-5, 1e-3)  # x, y, yaw
    command_topic: str = 'cmd_vel'
    odometry_topic: str = 'odom'
    namespace: str = ''
    remappings: tuple[tuple[str, str], ...] = ()

    filename = 'libgazebo_ros_diff_drive.so'

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Every wheel, left ones first."""
        return self.left_joints + self.right_joints

    def tf_topic(self, override: str = '') -> str:
        """Return where the odometry TF goes: ``/tf``, or where ``<remapping>/tf:=tf`` puts it.

        As the plugin's TransformBroadcaster does: ``/tf`` is absolute, so only a
        remapping moves it (Nav2's multi-robot robots remap it into their namespace).
        """
        if self.convention == ROS1:
            return '/tf'
        return Ros2Names(self.name, override or self.namespace, self.remappings).topic('/tf')

    @property
    def twist_covariance(self) -> tuple[float, ...]:
        """The odometry twist covariance's diagonal: ROS 2 repeats the pose's, ROS 1 has none."""
        return self.pose_covariance if self.convention == ROS2 else (0.0,) * 6


def read_diff_drive(element: PluginElement, model: RobotModel) -> DiffDrivePlugin:
    """Return the plugin's settings, ROS 1's or ROS 2's elements (the element spec)."""
    reader = ElementReader(element, model.name)
    ros1 = reader.has_any(ROS1_DIFF_DRIVE_KEYS) and 'ros' not in reader.texts
    plugin = _ros1_diff_drive(reader) if ros1 else _ros2_diff_drive(reader)
    keys = ('leftJoint', 'rightJoint') if ros1 else ('left_joint', 'right_joint')
    check_wheels(reader, ((keys[0], plugin.left_joints), (keys[1], plugin.right_joints)),
                 joints_by_name(model))
    frames = ('odometryFrame', 'robotBaseFrame') if ros1 else (
        'odometry_frame', 'robot_base_frame')
    check_frames(reader, ((frames[0], plugin.odometry_frame),
                          (frames[1], plugin.robot_base_frame)))
    return plugin


def _ros2_diff_drive(reader: ElementReader) -> DiffDrivePlugin:
    values = ROS2_ELEMENTS.read(reader)
    pairs = values['num_wheel_pairs']
    if pairs < 1 or pairs != int(pairs):
        raise reader.error('num_wheel_pairs', f'must be a whole number >= 1, got {pairs:g}')
    count = int(pairs)
    left, right = reader.all('left_joint'), reader.all('right_joint')
    if len(left) != count or len(right) != count:
        raise reader.error('left_joint', f'{len(left)} left and {len(right)} right wheels for '
                           f'num_wheel_pairs {count}: each pair needs one of each')
    separations = [reader.check('wheel_separation', text, 0.34, positive=True)
                   for text in reader.all('wheel_separation')[:count]]
    diameters = [reader.check('wheel_diameter', text, 0.15, positive=True)
                 for text in reader.all('wheel_diameter')[:count]]
    source = values['odometry_source']
    if source not in ROS2_SOURCES:
        raise reader.error('odometry_source', f'must be 0 (encoder) or 1 (world), got {source:g}')
    namespace, remappings = reader.ros()
    return DiffDrivePlugin(
        name=reader.name, convention=ROS2, left_joints=tuple(left), right_joints=tuple(right),
        wheel_separation=tuple(separations + [0.34] * (count - len(separations))),
        wheel_diameter=tuple(diameters + [0.15] * (count - len(diameters))),
        max_wheel_torque=values['max_wheel_torque'],
        max_wheel_acceleration=values['max_wheel_acceleration'],
        update_rate=values['update_rate'], odometry_frame=values['odometry_frame'],
        robot_base_frame=values['robot_base_frame'], odometry_source=ROS2_SOURCES[int(source)],
        publish_odom=values['publish_odom'], publish_odom_tf=values['publish_odom_tf'],
        covariance=(values['covariance_x'], values['covariance_y'], values['covariance_yaw']),
        namespace=namespace, remappings=remappings)


def _ros1_diff_drive(reader: ElementReader) -> DiffDrivePlugin:
    values = ROS1_ELEMENTS.read(reader)
    source = values['odometrySource'].lower()
    if source not in (ENCODER, WORLD):
        raise reader.error('odometrySource', f"must be '{ENCODER}' or '{WORLD}', got '{source}'")
    return DiffDrivePlugin(
        name=reader.name, convention=ROS1, left_joints=(values['leftJoint'],),
        right_joints=(values['rightJoint'],), wheel_separation=(values['wheelSeparation'],),
        wheel_diameter=(values['wheelDiameter'],), max_wheel_torque=values['wheelTorque'],
        max_wheel_acceleration=values['wheelAcceleration'], update_rate=values['updateRate'],
        odometry_frame=values['odometryFrame'], robot_base_frame=values['robotBaseFrame'],
        odometry_source=source, publish_odom=values['publishTf'],
        publish_odom_tf=values['publishOdomTF'], covariance=(1e-5, 1e-5, 1e-3),
        command_topic=values['commandTopic'], odometry_topic=values['odometryTopic'],
        namespace=reader.ros1_namespace())


class GazeboDiffDrive(WheeledDrive):
    """One ``gazebo_ros_diff_drive`` plugin: a Twist in, wheel velocities out, odometry back."""

    filenames = frozenset({'gazebo_ros_diff_drive'})
    filename = DiffDrivePlugin.filename

    @classmethod
    def read(cls, element: PluginElement, model: RobotModel) -> DiffDrivePlugin:
        """Return the settings of ``element`` (:func:`read_diff_drive`)."""
        return read_diff_drive(element, model)

    def attach(self, world: PluginWorld) -> None:
        """Bind the wheels; the ``world`` odometry reads the base's state."""
        self.configure(world.handles)
        self.set_base_state(world.base_state)

    def __init__(self, plugin: DiffDrivePlugin, source: str = '') -> None:
        super().__init__(plugin.name, {}, source)
        self.plugin = plugin
        self._period = 1.0 / plugin.update_rate if plugin.update_rate > 0.0 else 0.0
        self._odometry = Odometry(plugin.wheel_separation[0], plugin.wheel_diameter[0] / 2.0,
                                  plugin.wheel_diameter[0] / 2.0, window=1)
        self._wheels = WheelSides(plugin.left_joints, plugin.right_joints)
        self._command = TwistCommand('cmd_vel')
        self._odometry_sink: PlanarOdometrySink | None = None
        self._base_state: Callable[[], BaseState] | None = None
        self.reset()

    def actuators(self) -> dict[str, Actuator]:
        """Return the ideal velocity actuator, its force limit the wheel torque, per wheel."""
        plugin = self.plugin
        element = 'wheelTorque' if plugin.convention == 'ros1' else 'max_wheel_torque'
        text = f"at most {plugin.max_wheel_torque:g} N*m (the plugin's {element})"
        return {wheel: Actuator(ActuatorKind.IDEAL_VELOCITY, self.name,
                                force_from_controller=True, force_text=text)
                for wheel in self.joint_names}

    def set_base_state(self, source: Callable[[], BaseState]) -> None:
        """Where the ``world`` odometry reads the base's true pose and twist."""
        self._base_state = source

    # --- ROS surface -----------------------------------------------------------------------

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the command topic in; odometry and ``/tf`` out, as the plugin publishes."""
        plugin = self.plugin
        override = self.node_namespace.strip('/')
        command, odometry = plugin.topics(override)
        endpoints: list[Endpoint] = [
            CommandTopic(command, self.command_kind.value, self.set_command,
                         self.command_problem)]
        if plugin.publish_odom:
            endpoints.append(self.odometry_topic(
                odometry, (plugin.odometry_frame, plugin.robot_base_frame),
                plugin.pose_covariance, plugin.twist_covariance))
        if plugin.publish_odom_tf:
            endpoints.append(StateTopic(plugin.tf_topic(override), 'tf2_msgs/msg/TFMessage',
                                        self.set_tf_sink))
        return tuple(endpoints)

    # --- lifecycle -------------------------------------------------------------------------

    def reset(self) -> None:
        """No command, the encoder odometry at the origin, the wheels asked to stand."""
        self._command.latest = None
        self._last_update = 0.0
        self._odometry.reset(0.0)
        self._instructed = [0.0] * len(self._wheels.all)
        for handle in self._wheels.all:
            handle.velocity_target = 0.0
            handle.force_limit = self.plugin.max_wheel_torque

    # --- commands, setpoints, odometry (the encoder's): WheeledDrive ------------------------

    # --- the step ---------------------------------------------------------------------------

    def update(self, time: float, period: float) -> None:
        """Integrate the encoders; at the update rate publish and set the wheels' targets."""
        plugin = self.plugin
        radius = plugin.wheel_diameter[0] / 2.0
        wheels = self._wheels
        if plugin.odometry_source == ENCODER and wheels.left:
            self._odometry.update_from_travel(wheels.left[0].velocity * radius * period,
                                              wheels.right[0].velocity * radius * period, time)
        for handle in wheels.all:
            handle.force_limit = plugin.max_wheel_torque
        since = time - self._last_update
        if since + DUE_EPSILON < self._period:
            return
        self._publish(time)
        self._drive(since)
        self._last_update = time

    def _drive(self, since: float) -> None:
        """Set each wheel's velocity target as the plugin does, its ramp included."""
        plugin = self.plugin
        accel = plugin.max_wheel_acceleration
        linear, angular = self._command.planar()
        wheels = self._wheels
        for pair, (left, right) in enumerate(zip(wheels.left, wheels.right, strict=True)):
            radius = plugin.wheel_diameter[pair] / 2.0
            half = angular * plugin.wheel_separation[pair] / 2.0
            desired = (linear - half, linear + half)
            current = (left.velocity * radius, right.velocity * radius)
            reached = all(abs(want - have) < REACHED
                          for want, have in zip(desired, current, strict=True))
            for side, handle in enumerate((left, right)):
                slot = 2 * pair + side
                if accel == 0.0 or reached:
                    self._instructed[slot] = desired[side]
                else:
                    step = desired[side] - current[side]
                    self._instructed[slot] += max(-accel * since, min(accel * since, step))
                handle.velocity_target = self._instructed[slot] / radius

    def _pose_and_twist(self) -> tuple[float, float, float, float, float]:
        """Return (x, y, heading, forward speed, yaw rate) from the odometry source."""
        if self.plugin.odometry_source == ENCODER or self._base_state is None:
            odometry = self._odometry
            return odometry.x, odometry.y, odometry.heading, odometry.linear, odometry.angular
        (x, y, heading), (forward, _sideways, yaw_rate) = self._base_state()
        return x, y, heading, forward, yaw_rate

    def _publish(self, time: float) -> None:
        if self._odometry_sink is None and self._tf_sink is None:
            return
        self.publish_planar(time, *self._pose_and_twist(),
                            (self.plugin.odometry_frame, self.plugin.robot_base_frame))
