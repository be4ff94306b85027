"""``libgazebo_ros_p3d.so`` as a unit of the simulation: a link's true pose and twist. No ROS.

Not a ros2_control controller: the simulation creates one per plugin
element (:mod:`pan_tilt_sim.plugins.registry`) and updates it every physics
step; it is always active.  As the plugin, every ``1 / update_rate``
s of sim time (0: every step) and only while someone listens, it publishes
``nav_msgs/Odometry``: header frame ``frame_name``, child frame the link;
the link frame's pose and the twist of its origin (m, rad, m/s, rad/s) in
the world -- or, with ``frame_name`` a link, relative to that link (the
twist rotated into its axes) -- then ``xyz_offsets`` added to the position
and ``rpy_offsets`` turning the orientation; Gaussian noise of standard
deviation ``gaussian_noise`` on every twist component, and its variance on
the covariances' diagonals.  Pure Python: the simulation hands in the link
states (:meth:`GazeboP3d.set_link_state`).
"""

from __future__ import annotations

import dataclasses
import random
from collections.abc import Callable, Mapping

from pan_tilt_sim.controllers.framework.base import Controller, JointHandle
from pan_tilt_sim.controllers.framework.surface import Endpoint, StateTopic
from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.sensors import ROS1, ROS2, Ros2Names, ros1_resolve
from pan_tilt_sim.model.transforms import (
    Transform,
    Vector,
    quaternion_from_rpy,
    quaternion_multiply,
    rotate,
)
from pan_tilt_sim.plugins.framework.elements import Element, ElementReader, ElementSpec, Kind
from pan_tilt_sim.plugins.framework.plugin import (
    LinkState,
    Plugin,
    PluginWorld,
    SpatialOdometrySink,
)
from pan_tilt_sim.schedule import DUE_EPSILON

WORLD_FRAMES = ('world', '/world', 'map', '/map')  # poses in the world
# The element spec, per generation; ROS 2 also reads <ros>, ROS 1 robotNamespace.
ROS2_ELEMENTS = ElementSpec(
    Element('body_name', '', Kind.TEXT),  # required: the link
    Element('frame_name', 'world', Kind.TEXT),  # world, map or a link
    Element('xyz_offsets', kind=Kind.VECTOR),  # m
    Element('rpy_offsets', kind=Kind.VECTOR),  # rad
    Element('gaussian_noise', 0.0, non_negative=True),  # standard deviation
    Element('update_rate', 0.0, non_negative=True),  # Hz, 0: every step
)
ROS1_ELEMENTS = ElementSpec(
    Element('bodyName', '', Kind.TEXT),
    Element('frameName', 'world', Kind.TEXT),
    Element('xyzOffsets', kind=Kind.VECTOR),
    Element('rpyOffsets', kind=Kind.VECTOR),
    Element('gaussianNoise', 0.0, non_negative=True),
    Element('updateRate', 0.0, non_negative=True),
    Element('topicName', 'odom', Kind.TEXT),
)
ROS1_P3D_KEYS = {*ROS1_ELEMENTS.names, 'robotNamespace'}


@dataclasses.dataclass(frozen=True)
class P3dPlugin:
    """One ``gazebo_ros_p3d`` plugin: which link, in which frame, offsets, noise, rate, topic.

    ``frame_name`` a link of the robot: the pose and twist relative to that
    link; ``world``/``map``: in the world.  Offsets: m and rad (roll, pitch,
    yaw); ``gaussian_noise``: the standard deviation added to each twist
    component.  ``update_rate`` 0: every physics step.
    """

    name: str
    convention: str
    body_name: str
    frame_name: str = 'world'
    xyz_offsets: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_offsets: tuple[float, float, float] = (0.0, 0.0, 0.0)
    gaussian_noise: float = 0.0
    update_rate: float = 0.0
    topic: str = 'odom'
    namespace: str = ''
    remappings: tuple[tuple[str, str], ...] = ()

    @property
    def in_world(self) -> bool:
        """Whether poses are in the world (not relative to a link)."""
        return self.frame_name in WORLD_FRAMES

    def topics(self, override: str = '') -> str:
        """Return the odometry topic (absolute), ``override`` as the namespace."""
        namespace = override or self.namespace
        if self.convention == ROS1:
            return ros1_resolve(namespace, self.topic)
        return Ros2Names(self.name, namespace, self.remappings).topic(self.topic)


def read_p3d(element: PluginElement, model: RobotModel) -> P3dPlugin:
    """Return the plugin's settings: ROS 2 ``body_name`` (required), ``frame_name``, ... .

    ROS 1: ``bodyName``, ``frameName``, ``xyzOffsets``, ``rpyOffsets``,
    ``gaussianNoise``, ``updateRate``, ``topicName`` in ``robotNamespace``.
    A body or frame that is no link of the robot ends start-up.
    """
    links = set(model.link_names)
    reader = ElementReader(element, model.name)
    ros1 = reader.has_any(ROS1_P3D_KEYS) and 'ros' not in reader.texts
    spec = ROS1_ELEMENTS if ros1 else ROS2_ELEMENTS
    body, frame, xyz, rpy, noise, rate = spec.names[:6]
    values = spec.read(reader)
    link = values[body]
    if link not in links:
        raise reader.error(body, f"'{link}' is not a link of this robot" if link
                           else 'is missing (the plugin needs the link to track)')
    frame_name = values[frame]
    if frame_name not in WORLD_FRAMES and frame_name not in links:
        raise reader.error(frame, f"'{frame_name}' is neither world, map nor a link of "
                           'this robot')
    namespace, remappings = ('', ()) if ros1 else reader.ros()
    return P3dPlugin(
        name=reader.name, convention=ROS1 if ros1 else ROS2, body_name=link,
        frame_name=frame_name, xyz_offsets=values[xyz], rpy_offsets=values[rpy],
        gaussian_noise=values[noise], update_rate=values[rate],
        topic=values['topicName'] if ros1 else 'odom',
        namespace=reader.ros1_namespace() if ros1 else namespace,
        remappings=remappings)


def _inverse(transform: Transform) -> Transform:
    x, y, z, w = transform.rotation
    conjugate = (-x, -y, -z, w)
    tx, ty, tz = rotate(conjugate, transform.translation)
    return Transform((-tx, -ty, -tz), conjugate)


class GazeboP3d(Plugin, Controller):
    """One ``gazebo_ros_p3d`` plugin: ground-truth odometry of one link."""

    filenames = frozenset({'gazebo_ros_p3d'})
    filename = 'libgazebo_ros_p3d.so'

    @classmethod
    def read(cls, element: PluginElement, model: RobotModel) -> P3dPlugin:
        """Return the settings of ``element`` (:func:`read_p3d`)."""
        return read_p3d(element, model)

    def attach(self, world: PluginWorld) -> None:
        """Read link states from the simulation."""
        self.set_link_state(world.link_state)

    def __init__(self, plugin: P3dPlugin, source: str = '', *,
                 rng: random.Random | None = None) -> None:
        super().__init__(plugin.name, {}, source)
        self.plugin = plugin
        self._period = 1.0 / plugin.update_rate if plugin.update_rate > 0.0 else 0.0
        self._offset = quaternion_from_rpy(*plugin.rpy_offsets)
        self._rng = rng or random.Random()
        self._sink: SpatialOdometrySink | None = None
        self._link_state: Callable[[str], LinkState] | None = None
        self.reset()

    def set_link_state(self, source: Callable[[str], LinkState]) -> None:
        """Where the unit reads a link's state (by link name)."""
        self._link_state = source

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the odometry topic, as the plugin names it."""
        plugin = self.plugin
        variance = plugin.gaussian_noise ** 2
        return (StateTopic(plugin.topics(self.node_namespace.strip('/')),
                           'nav_msgs/msg/Odometry', self.set_odometry_sink,
                           {'frame_id': plugin.frame_name, 'child_frame_id': plugin.body_name,
                            'pose_covariance_diagonal': (variance,) * 6,
                            'twist_covariance_diagonal': (variance,) * 6, 'spatial': True}),)

    def set_odometry_sink(self, sink: SpatialOdometrySink | None) -> None:
        """Where samples go (None: nobody listens, none are taken)."""
        self._sink = sink

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Nothing to bind: the plugin reads a link, not joints."""
        self.reset()

    def reset(self) -> None:
        """Start the rate again from sim time 0."""
        self._last = 0.0

    def update(self, time: float, period: float) -> None:
        """Publish the link's state when due and watched."""
        if self._sink is None or self._link_state is None:
            return
        # As the plugin: not before the period is up, and never twice at one time.
        if time <= self._last or time - self._last + DUE_EPSILON < self._period:
            return
        self._last = time
        self._sink(time, *self.measure())

    def measure(self) -> tuple[Transform, Vector, Vector]:
        """Return the pose, linear and angular velocity the plugin would publish now."""
        plugin = self.plugin
        frame, linear, angular = self._link_state(plugin.body_name)
        if not plugin.in_world:
            reference, reference_linear, reference_angular = self._link_state(plugin.frame_name)
            inverse = _inverse(reference)
            frame = inverse.then(frame)
            linear = rotate(inverse.rotation, [a - b for a, b in zip(
                linear, reference_linear, strict=True)])
            angular = rotate(inverse.rotation, [a - b for a, b in zip(
                angular, reference_angular, strict=True)])
        x, y, z = frame.translation
        dx, dy, dz = plugin.xyz_offsets
        pose = Transform((x + dx, y + dy, z + dz),
                         quaternion_multiply(self._offset, frame.rotation))
        noise = plugin.gaussian_noise
        if noise > 0.0:
            gauss = self._rng.gauss
            linear = tuple(value + gauss(0.0, noise) for value in linear)
            angular = tuple(value + gauss(0.0, noise) for value in angular)
        return pose, tuple(linear), tuple(angular)  # type: ignore[return-value]
