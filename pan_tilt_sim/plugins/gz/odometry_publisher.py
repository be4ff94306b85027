"""gz-sim's OdometryPublisher system as a unit of the simulation: true-pose odometry. No ROS.

Not a ros2_control controller: the simulation creates one per system
element (:mod:`pan_tilt_sim.plugins.registry`) and updates it every physics
step; it is always active.  As the system, every ``1 /
odom_publish_frequency`` s of sim time it publishes the model's pose in the
world (its root link frame, moved by ``xyz_offset`` and turned by
``rpy_offset``) and its twist in the base's own axes: ``gz.msgs.Odometry``
on ``odom_topic`` (``nav_msgs/msg/Odometry`` through the bridge,
``odom_frame`` -> ``robot_base_frame``) and the same transform as
``gz.msgs.Pose_V`` on ``tf_topic`` (``tf2_msgs/msg/TFMessage``).  With
``dimensions`` 2, z, roll and pitch are 0 and so are the twist's z, roll
and pitch rates.  ``gaussian_noise``: the standard deviation added to
the position and the twist.  Pure Python: the simulation hands in the
base's state (:meth:`GzOdometryPublisher.set_base_motion`).
"""

from __future__ import annotations

import dataclasses
import math
import random
from collections.abc import Callable, Mapping

from pan_tilt_sim.controllers.framework.base import Controller, JointHandle
from pan_tilt_sim.controllers.framework.surface import Endpoint, StateTopic
from pan_tilt_sim.controllers.toolbox.odometry_outputs import OdometryOutputs, TfSink
from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.transforms import (
    Transform,
    Vector,
    quaternion_from_rpy,
    quaternion_multiply,
    rotate,
)
from pan_tilt_sim.plugins.framework.elements import (
    GZ,
    Element,
    ElementReader,
    ElementSpec,
    Kind,
    check_frames,
    gz_topic,
)
from pan_tilt_sim.plugins.framework.plugin import (
    BaseMotion,
    Plugin,
    PluginWorld,
    SpatialOdometrySink,
    heading,
)
from pan_tilt_sim.schedule import DUE_EPSILON

GZ_ODOMETRY_FILES = frozenset({'gz-sim-odometry-publisher-system',
                               'ignition-gazebo-odometry-publisher-system'})
GZ_ODOMETRY_NAMES = frozenset({'gz::sim::systems::OdometryPublisher',
                               'ignition::gazebo::systems::OdometryPublisher'})
# The element spec (gz-sim's names and defaults; '': named after the model).
ELEMENTS = ElementSpec(
    Element('dimensions', 2.0),  # 2: x, y, yaw; 3: the full pose
    Element('odom_frame', '', Kind.TEXT),  # {model}/odom
    Element('robot_base_frame', '', Kind.TEXT),  # {model}/base_footprint
    Element('odom_publish_frequency', 50.0, positive=True),  # Hz
    Element('odom_topic', '', Kind.TEXT),  # /model/{model}/odometry
    Element('tf_topic', '', Kind.TEXT),  # /model/{model}/pose
    Element('xyz_offset', kind=Kind.VECTOR),  # m
    Element('rpy_offset', kind=Kind.VECTOR),  # rad
    Element('gaussian_noise', 0.0, non_negative=True),  # standard deviation
)


@dataclasses.dataclass(frozen=True)
class GzOdometryPlugin:
    """gz-sim's OdometryPublisher system: the model's true pose as odometry.

    ``dimensions`` 2: x, y and yaw only (z, roll, pitch 0); 3: the full pose.
    ``xyz_offset`` (m) and ``rpy_offset`` (rad) move the published pose,
    ``gaussian_noise`` is the standard deviation added to pose and twist.
    """

    name: str
    odom_frame: str
    robot_base_frame: str
    odom_publish_frequency: float = 50.0
    odometry_topic: str = ''
    tf_topic: str = ''
    dimensions: int = 2
    xyz_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    gaussian_noise: float = 0.0

    convention = GZ


def read_gz_odometry_publisher(element: PluginElement, model: RobotModel) -> GzOdometryPlugin:
    """Return the system's settings (the element spec), elements and defaults as gz-sim's."""
    name = model.name
    reader = ElementReader(element, name)
    values = ELEMENTS.read(reader)
    dimensions = values['dimensions']
    if dimensions not in (2.0, 3.0):
        raise reader.error('dimensions', f'must be 2 or 3, got {dimensions:g}')
    odom_frame = values['odom_frame'] or f'{name}/odom'
    base_frame = values['robot_base_frame'] or f'{name}/base_footprint'
    check_frames(reader, (('odom_frame', odom_frame), ('robot_base_frame', base_frame)))
    return GzOdometryPlugin(
        name=reader.name, odom_frame=odom_frame, robot_base_frame=base_frame,
        odom_publish_frequency=values['odom_publish_frequency'],
        odometry_topic=gz_topic(values['odom_topic'] or f'/model/{name}/odometry'),
        tf_topic=gz_topic(values['tf_topic'] or f'/model/{name}/pose'),
        dimensions=int(dimensions), xyz_offset=values['xyz_offset'],
        rpy_offset=values['rpy_offset'], gaussian_noise=values['gaussian_noise'])


class GzOdometryPublisher(Plugin, OdometryOutputs, Controller):
    """One gz-sim OdometryPublisher system: the model's true pose and twist as odometry."""

    filenames = GZ_ODOMETRY_FILES
    system_names = GZ_ODOMETRY_NAMES
    filename = 'gz-sim-odometry-publisher-system'

    @classmethod
    def read(cls, element: PluginElement, model: RobotModel) -> GzOdometryPlugin:
        """Return the settings of ``element`` (:func:`read_gz_odometry_publisher`)."""
        return read_gz_odometry_publisher(element, model)

    def attach(self, world: PluginWorld) -> None:
        """Read the base's frame and velocities from the simulation."""
        self.set_base_motion(world.base_motion)

    def __init__(self, plugin: GzOdometryPlugin, source: str = '', *,
                 rng: random.Random | None = None) -> None:
        super().__init__(plugin.name, {}, source)
        self.plugin = plugin
        self._period = 1.0 / plugin.odom_publish_frequency
        self._offset = quaternion_from_rpy(*plugin.rpy_offset)
        self._rng = rng or random.Random()
        self._odometry_sink: SpatialOdometrySink | None = None
        self._tf_sink: TfSink | None = None
        self._base_motion: Callable[[], BaseMotion] | None = None
        self.reset()

    def set_base_motion(self, source: Callable[[], BaseMotion]) -> None:
        """Where the unit reads the base's frame and velocities (world axes)."""
        self._base_motion = source

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the odometry and pose topics, by the names the bridge would give them."""
        plugin = self.plugin
        return (StateTopic(plugin.odometry_topic, 'nav_msgs/msg/Odometry',
                           self.set_odometry_sink,
                           {'frame_id': plugin.odom_frame,
                            'child_frame_id': plugin.robot_base_frame,
                            'pose_covariance_diagonal': (0.0,) * 6,
                            'twist_covariance_diagonal': (0.0,) * 6, 'spatial': True}),
                StateTopic(plugin.tf_topic, 'tf2_msgs/msg/TFMessage', self.set_tf_sink))

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Nothing to bind: the system reads the model's pose."""
        self.reset()

    def reset(self) -> None:
        """Start the rate again from sim time 0."""
        self._last = 0.0

    def update(self, time: float, period: float) -> None:
        """Publish when due and watched."""
        if self._base_motion is None or (self._odometry_sink is None and self._tf_sink is None):
            return
        if time - self._last + DUE_EPSILON < self._period:
            return
        self._last = time
        pose, linear, angular = self.measure()
        if self._odometry_sink is not None:
            self._odometry_sink(time, pose, linear, angular)
        if self._tf_sink is not None:
            self._tf_sink(time, [(self.plugin.odom_frame, self.plugin.robot_base_frame, pose)])

    def measure(self) -> tuple[Transform, Vector, Vector]:
        """Return the pose (world), linear and angular velocity (base axes) published now."""
        plugin = self.plugin
        frame, linear, angular = self._base_motion()
        x, y, z = frame.translation
        dx, dy, dz = rotate(frame.rotation, plugin.xyz_offset)
        rotation = quaternion_multiply(frame.rotation, self._offset)
        x, y, z = x + dx, y + dy, z + dz
        qx, qy, qz, qw = rotation
        conjugate = (-qx, -qy, -qz, qw)
        body_linear = rotate(conjugate, linear)
        body_angular = rotate(conjugate, angular)
        if plugin.dimensions == 2:
            yaw = heading(Transform((x, y, z), rotation))
            z = 0.0
            rotation = (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))
            body_linear = (body_linear[0], body_linear[1], 0.0)
            body_angular = (0.0, 0.0, body_angular[2])
        noise = plugin.gaussian_noise
        if noise > 0.0:
            gauss = self._rng.gauss
            x, y = x + gauss(0.0, noise), y + gauss(0.0, noise)
            if plugin.dimensions == 3:
                z += gauss(0.0, noise)
            body_linear = tuple(value + gauss(0.0, noise) for value in body_linear)
            body_angular = tuple(value + gauss(0.0, noise) for value in body_angular)
        return (Transform((x, y, z), rotation), tuple(body_linear),  # type: ignore[return-value]
                tuple(body_angular))
