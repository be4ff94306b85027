"""gz-sim's DiffDrive system as a unit of the simulation: a Twist in, wheels out, odometry back.

Not a ros2_control controller: the simulation creates one per system
element (:mod:`pan_tilt_sim.plugins.registry`) and updates it every physics
step, before the controllers; it is always active.  As the system, the
``geometry_msgs/msg/Twist`` ros_gz_bridge would carry on ``topic`` (the last
one holds; a non-finite one is refused) goes through the system's speed
limiter (jerk, acceleration, velocity, each within ``[min, max]``) and sets
every wheel's velocity target each step; odometry from the first left and
right wheels (a rolling mean of 10 updates, as gz-math's) goes to
``odom_topic`` and ``tf_topic`` every ``1 / odom_publish_frequency`` s.  A
reset drops the command and puts the odometry back at the origin.  The
whole behaviour: docs/design/gazebo-plugins.md.  Pure Python.
"""

from __future__ import annotations

import dataclasses
import math

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
from pan_tilt_sim.controllers.toolbox.rate_limiter import (
    InvalidLimitsError,
    RateLimiter,
    RateLimits,
)
from pan_tilt_sim.controllers.toolbox.twist_command import TwistCommand
from pan_tilt_sim.controllers.toolbox.wheel_sides import WheelSides
from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.plugins.framework.drives import WheeledDrive
from pan_tilt_sim.plugins.framework.elements import (
    GZ,
    Element,
    ElementReader,
    ElementSpec,
    Kind,
    check_frames,
    check_wheels,
    gz_topic,
    joints_by_name,
    root_link,
)
from pan_tilt_sim.plugins.framework.plugin import PlanarOdometrySink, PluginWorld
from pan_tilt_sim.schedule import DUE_EPSILON

ODOMETRY_WINDOW = 10  # updates in the odometry twist's rolling mean (gz-math's default)
GZ_DIFF_DRIVE_FILES = frozenset({'gz-sim-diff-drive-system', 'ignition-gazebo-diff-drive-system'})
GZ_DIFF_DRIVE_NAMES = frozenset({'gz::sim::systems::DiffDrive',
                                 'ignition::gazebo::systems::DiffDrive'})
# DiffDrive's limits: (SDF element, jazzy RateLimits field) per group; min_acceleration
# bounds every change, so it is both the deceleration and the reverse acceleration.
GZ_LIMIT_ELEMENTS = ('min_velocity', 'max_velocity', 'min_acceleration', 'max_acceleration',
                     'min_jerk', 'max_jerk')
GROUPS = ('linear', 'angular')


def _own(entry: str, group: str) -> str:
    """Return a group's own limit element: min_velocity, linear -> min_linear_velocity."""
    kind, what = entry.split('_')
    return f'{kind}_{group}_{what}'


# The element spec (gz-sim's names and defaults; '': named after the model).  The system also
# reads one or more left_joint and right_joint.
ELEMENTS = ElementSpec(
    *(Element(entry, math.nan) for entry in GZ_LIMIT_ELEMENTS),  # both groups; NaN: none
    *(Element(_own(entry, group), math.nan) for group in GROUPS for entry in GZ_LIMIT_ELEMENTS),
    Element('frame_id', '', Kind.TEXT),  # {model}/odom
    Element('child_frame_id', '', Kind.TEXT),  # {model}/{root link}
    Element('wheel_separation', 1.0, positive=True),  # m
    Element('wheel_radius', 0.2, positive=True),  # m
    Element('odom_publish_frequency', 50.0, positive=True),  # Hz
    Element('topic', '', Kind.TEXT),  # /model/{model}/cmd_vel
    Element('odom_topic', '', Kind.TEXT),  # /model/{model}/odometry
    Element('tf_topic', '', Kind.TEXT),  # /model/{model}/tf
)


@dataclasses.dataclass(frozen=True)
class GzDiffDrivePlugin:
    """gz-sim's DiffDrive system: wheels, geometry, limits, topics, frames.

    ``limits`` per group (``linear``, ``angular``): the SDF's
    ``min_/max_velocity``, ``_acceleration``, ``_jerk`` (NaN: not given; a
    group's own element overrides the shared one).  Topics are gz-transport
    names, as ros_gz_bridge carries them under the same name.
    """

    name: str
    left_joints: tuple[str, ...]
    right_joints: tuple[str, ...]
    wheel_separation: float = 1.0
    wheel_radius: float = 0.2
    odom_publish_frequency: float = 50.0
    command_topic: str = ''
    odometry_topic: str = ''
    tf_topic: str = ''
    frame_id: str = ''
    child_frame_id: str = ''
    linear_limits: tuple[float, ...] = (math.nan,) * 6
    angular_limits: tuple[float, ...] = (math.nan,) * 6

    convention = GZ
    filename = 'gz-sim-diff-drive-system'

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Every wheel, left ones first."""
        return self.left_joints + self.right_joints


def read_gz_diff_drive(element: PluginElement, model: RobotModel) -> GzDiffDrivePlugin:
    """Return the system's settings (the element spec), elements and defaults as gz-sim's.

    The model's name is the URDF robot's.  A wheel the robot does not have, a
    number that is not one, a separation, radius or frequency that is not
    positive, or a limit's min above its max ends start-up.
    """
    name = model.name
    reader = ElementReader(element, name)
    left, right = tuple(reader.all('left_joint')), tuple(reader.all('right_joint'))
    for key, wheels in (('left_joint', left), ('right_joint', right)):
        if not wheels:
            raise reader.error(key, 'is missing: the system needs at least one on each side')
    check_wheels(reader, (('left_joint', left), ('right_joint', right)), joints_by_name(model))
    values = ELEMENTS.read(reader)
    limits = {}
    for group in GROUPS:
        own = {_own(entry, group): values[entry] if math.isnan(values[_own(entry, group)])
               else values[_own(entry, group)] for entry in GZ_LIMIT_ELEMENTS}
        for what in ('velocity', 'acceleration', 'jerk'):
            low, high = own[f'min_{group}_{what}'], own[f'max_{group}_{what}']
            if low > high:
                raise reader.error(f'min_{group}_{what}', f'{low:g} is above max_{group}_'
                                   f'{what} {high:g}')
        limits[group] = tuple(own.values())
    frame = values['frame_id'] or f'{name}/odom'
    child = values['child_frame_id'] or f'{name}/{root_link(model)}'
    check_frames(reader, (('frame_id', frame), ('child_frame_id', child)))
    return GzDiffDrivePlugin(
        name=reader.name, left_joints=left, right_joints=right,
        wheel_separation=values['wheel_separation'], wheel_radius=values['wheel_radius'],
        odom_publish_frequency=values['odom_publish_frequency'],
        command_topic=gz_topic(values['topic'] or f'/model/{name}/cmd_vel'),
        odometry_topic=gz_topic(values['odom_topic'] or f'/model/{name}/odometry'),
        tf_topic=gz_topic(values['tf_topic'] or f'/model/{name}/tf'),
        frame_id=frame, child_frame_id=child,
        linear_limits=limits['linear'], angular_limits=limits['angular'])


def gz_limiter(limits: tuple[float, ...], name: str, group: str) -> RateLimiter:
    """Return a limiter for one group's (min/max velocity, acceleration, jerk; NaN: absent).

    gz's speed limiter bounds each quantity to ``[min, max]`` whichever way
    the robot moves, an absent bound being unbounded.
    """
    def pair(low: float, high: float) -> tuple[float, float]:
        if math.isnan(low) and math.isnan(high):
            return math.nan, math.nan
        return (-math.inf if math.isnan(low) else low), (math.inf if math.isnan(high) else high)

    min_v, max_v, min_a, max_a, min_j, max_j = limits
    min_v, max_v = pair(min_v, max_v)
    min_a, max_a = pair(min_a, max_a)
    min_j, max_j = pair(min_j, max_j)
    try:
        return RateLimiter(RateLimits(
            min_velocity=min_v, max_velocity=max_v, max_acceleration=max_a,
            max_deceleration=min_a, max_acceleration_reverse=min_a,
            max_deceleration_reverse=max_a, min_jerk=min_j, max_jerk=max_j))
    except InvalidLimitsError as err:
        raise ValueError(f"system '{name}': {group} limits: {err}") from None


class GzDiffDrive(WheeledDrive):
    """One gz-sim DiffDrive system: a Twist in, wheel velocities out, odometry back."""

    filenames = GZ_DIFF_DRIVE_FILES
    system_names = GZ_DIFF_DRIVE_NAMES
    filename = GzDiffDrivePlugin.filename

    @classmethod
    def read(cls, element: PluginElement, model: RobotModel) -> GzDiffDrivePlugin:
        """Return the settings of ``element`` (:func:`read_gz_diff_drive`)."""
        return read_gz_diff_drive(element, model)

    def attach(self, world: PluginWorld) -> None:
        """Bind the wheels."""
        self.configure(world.handles)

    def __init__(self, plugin: GzDiffDrivePlugin, source: str = '') -> None:
        super().__init__(plugin.name, {}, source)
        self.plugin = plugin
        self._period = 1.0 / plugin.odom_publish_frequency
        self._limiters = (gz_limiter(plugin.linear_limits, plugin.name, 'linear'),
                          gz_limiter(plugin.angular_limits, plugin.name, 'angular'))
        self._odometry = Odometry(plugin.wheel_separation, plugin.wheel_radius,
                                  plugin.wheel_radius, ODOMETRY_WINDOW)
        self._wheels = WheelSides(plugin.left_joints, plugin.right_joints)
        self._command = TwistCommand('cmd_vel')
        self._odometry_sink: PlanarOdometrySink | None = None
        self.reset()

    def actuators(self) -> dict[str, Actuator]:
        """Return the ideal velocity actuator per wheel (within the joint's effort limit)."""
        return {wheel: Actuator(ActuatorKind.IDEAL_VELOCITY, self.name)
                for wheel in self.joint_names}

    # --- ROS surface -----------------------------------------------------------------------

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the command topic in; odometry and its transform out, bridged names."""
        plugin = self.plugin
        return (
            CommandTopic(plugin.command_topic, self.command_kind.value, self.set_command,
                         self.command_problem),
            self.odometry_topic(plugin.odometry_topic, (plugin.frame_id, plugin.child_frame_id),
                                (0.0,) * 6, (0.0,) * 6),
            StateTopic(plugin.tf_topic, 'tf2_msgs/msg/TFMessage', self.set_tf_sink))

    # --- lifecycle -------------------------------------------------------------------------

    def reset(self) -> None:
        """No command, the odometry at the origin of the wheels' present positions."""
        self._command.latest = None
        self._last = [(0.0, 0.0), (0.0, 0.0)]  # the limited (linear, angular) of two steps
        self._last_publish = 0.0
        wheels = self._wheels
        left = wheels.left[0].position if wheels.left else 0.0
        right = wheels.right[0].position if wheels.right else 0.0
        self._odometry.reset(0.0, left, right)
        for handle in wheels.all:
            handle.velocity_target = 0.0

    # --- commands, setpoints, odometry (in frame_id): WheeledDrive ---------------------------

    # --- the step ---------------------------------------------------------------------------

    def update(self, time: float, period: float) -> None:
        """Limit the command and set the wheels; when due, update and publish the odometry."""
        plugin = self.plugin
        (previous_linear, previous_angular), (before_linear, before_angular) = self._last
        linear_limiter, angular_limiter = self._limiters
        linear, angular = self._command.planar()
        if period > 0.0:
            linear = linear_limiter.limit(linear, previous_linear, before_linear, period)
            angular = angular_limiter.limit(angular, previous_angular, before_angular, period)
        self._last = [(linear, angular), (previous_linear, previous_angular)]
        half = angular * plugin.wheel_separation / 2.0
        wheels = self._wheels
        for handle in wheels.left:
            handle.velocity_target = (linear - half) / plugin.wheel_radius
        for handle in wheels.right:
            handle.velocity_target = (linear + half) / plugin.wheel_radius
        if time - self._last_publish + DUE_EPSILON < self._period:
            return
        self._last_publish = time
        if wheels.left and wheels.right:
            self._odometry.update(wheels.left[0].position, wheels.right[0].position, time)
        odometry = self._odometry
        self.publish_planar(time, odometry.x, odometry.y, odometry.heading, odometry.linear,
                            odometry.angular, (plugin.frame_id, plugin.child_frame_id))
