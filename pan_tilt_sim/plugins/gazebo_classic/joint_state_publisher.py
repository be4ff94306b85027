"""``libgazebo_ros_joint_state_publisher.so`` as a unit of the simulation: joint states. No ROS.

Also gz-sim's JointStatePublisher system, which publishes the same.  Not a
ros2_control controller: the simulation creates one per plugin element
(:mod:`pan_tilt_sim.plugins.registry`) and updates it every physics step;
it is always active and commands nothing.  As the plugin,
every ``1 / update_rate`` s of sim time (0: every step) it publishes
``sensor_msgs/JointState`` with the named joints' positions (rad or m),
velocities and efforts, in the order the plugin names them -- only while
someone listens.  Pure Python.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence

from pan_tilt_sim.controllers.framework.base import Controller, JointHandle
from pan_tilt_sim.controllers.framework.surface import Endpoint, StateTopic
from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.sensors import GZ_WORLD, ROS1, ROS2, Ros2Names, ros1_resolve
from pan_tilt_sim.plugins.framework.elements import (
    GZ,
    Element,
    ElementReader,
    ElementSpec,
    Kind,
    gz_topic,
    movable_joints,
)
from pan_tilt_sim.plugins.framework.plugin import Plugin, PluginWorld
from pan_tilt_sim.schedule import DUE_EPSILON

# sink(time, names, positions, velocities, efforts)
JointStateSink = Callable[[float, Sequence[str], Sequence[float], Sequence[float],
                           Sequence[float]], None]


GZ_FILES = frozenset({'gz-sim-joint-state-publisher-system',
                      'ignition-gazebo-joint-state-publisher-system'})
GZ_NAMES = frozenset({'gz::sim::systems::JointStatePublisher',
                      'ignition::gazebo::systems::JointStatePublisher'})
# The element spec, per generation.  Each also reads its joints: ROS 2 and gz-sim one
# joint_name each (gz-sim: none, every movable joint), ROS 1 jointName (comma-separated);
# ROS 2 reads <ros>, ROS 1 robotNamespace.
ROS2_ELEMENTS = ElementSpec(Element('update_rate', 100.0, non_negative=True))  # Hz, 0: every step
ROS1_ELEMENTS = ElementSpec(Element('updateRate', 100.0, non_negative=True))
GZ_ELEMENTS = ElementSpec(Element('topic', '', Kind.TEXT))  # '': the world's model joint_state


@dataclasses.dataclass(frozen=True)
class JointStatePlugin:
    """One joint state publisher: which joints, how often (Hz; 0: every step)."""

    name: str
    convention: str
    joints: tuple[str, ...]
    update_rate: float = 100.0
    namespace: str = ''
    remappings: tuple[tuple[str, str], ...] = ()
    topic: str = ''  # gz-sim's: the topic as the bridge carries it (no namespace applies)

    def topics(self, override: str = '') -> str:
        """Return the joint states topic (absolute), ``override`` as the namespace."""
        if self.convention == GZ:
            return self.topic
        namespace = override or self.namespace
        if self.convention == ROS1:
            return ros1_resolve(namespace, 'joint_states')
        return Ros2Names(self.name, namespace, self.remappings).topic('joint_states')


def read_joint_state_publisher(element: PluginElement, model: RobotModel) -> JointStatePlugin:
    """Return the plugin's settings (the element spec).

    ROS 2: ``joint_name`` (one element per joint, required), ``update_rate``
    (100 Hz), topic ``joint_states`` of its node; ROS 1: ``jointName``
    (comma-separated), ``updateRate`` (100 Hz) in ``robotNamespace``.
    gz-sim: ``joint_name`` (none: every movable joint), every step, on
    ``topic`` (``/world/default/model/{model}/joint_state``).  A name that
    is no movable joint of the robot ends start-up.
    """
    movable = movable_joints(model)
    reader = ElementReader(element, model.name)
    if element.stem in GZ_FILES or element.name.strip() in GZ_NAMES:
        names = reader.all('joint_name')
        for name in names:
            if name not in movable:
                raise reader.error('joint_name', f"'{name}' is not a movable joint of this robot")
        topic = GZ_ELEMENTS.read(reader)['topic'] or (
            f'/world/{GZ_WORLD}/model/{model.name}/joint_state')
        return JointStatePlugin(name=reader.name, convention=GZ,
                                joints=tuple(names or movable), update_rate=0.0,
                                topic=gz_topic(topic))
    ros1 = reader.has_any({'jointName', *ROS1_ELEMENTS.names, 'robotNamespace'})
    key = 'jointName' if ros1 else 'joint_name'
    names = [name.strip() for text in reader.all(key) for name in (
        text.split(',') if ros1 else [text]) if name.strip()]
    if not names:
        raise reader.error(key, 'is missing: name the joints to publish')
    for name in names:
        if name not in movable:
            raise reader.error(key, f"'{name}' is not a movable joint of this robot")
    namespace, remappings = ('', ()) if ros1 else reader.ros()
    rate = (ROS1_ELEMENTS if ros1 else ROS2_ELEMENTS).read(reader)
    return JointStatePlugin(
        name=reader.name, convention=ROS1 if ros1 else ROS2, joints=tuple(names),
        update_rate=rate['updateRate' if ros1 else 'update_rate'],
        namespace=reader.ros1_namespace() if ros1 else namespace,
        remappings=remappings)


class GazeboJointStatePublisher(Plugin, Controller):
    """One joint state publisher plugin (gazebo_ros's or gz-sim's): the named joints' states."""

    filenames = frozenset({'gazebo_ros_joint_state_publisher'}) | GZ_FILES
    system_names = GZ_NAMES
    filename = 'libgazebo_ros_joint_state_publisher.so'
    publishes_joint_states = True

    @classmethod
    def read(cls, element: PluginElement, model: RobotModel) -> JointStatePlugin:
        """Return the settings of ``element`` (:func:`read_joint_state_publisher`)."""
        return read_joint_state_publisher(element, model)

    def attach(self, world: PluginWorld) -> None:
        """Bind the named joints' handles."""
        self.configure(world.handles)

    def __init__(self, plugin: JointStatePlugin, source: str = '') -> None:
        super().__init__(plugin.name, {}, source)
        self.plugin = plugin
        self._period = 1.0 / plugin.update_rate if plugin.update_rate > 0.0 else 0.0
        self._handles: list[JointHandle] = []
        self._sink: JointStateSink | None = None
        self.reset()

    def ros_surface(self) -> tuple[Endpoint, ...]:
        """Return the joint states topic, as the plugin names it."""
        return (StateTopic(self.plugin.topics(self.node_namespace.strip('/')),
                           'sensor_msgs/msg/JointState', self.set_joint_state_sink,
                           {'names': self.plugin.joints}),)

    def set_joint_state_sink(self, sink: JointStateSink | None) -> None:
        """Where samples go (None: nobody listens, none are taken)."""
        self._sink = sink

    def configure(self, joints: Mapping[str, JointHandle]) -> None:
        """Bind the named joints' handles (a joint the robot lacks names the element)."""
        element = 'jointName' if self.plugin.convention == 'ros1' else 'joint_name'
        self._handles = [self.handle(joints, joint, element) for joint in self.plugin.joints]
        self.reset()

    def reset(self) -> None:
        """Start the rate again from sim time 0."""
        self._last = 0.0

    def update(self, time: float, period: float) -> None:
        """Publish the joints' states when due and watched."""
        if time - self._last + DUE_EPSILON < self._period:
            return
        self._last = time
        if self._sink is None:
            return
        handles = self._handles
        self._sink(time, self.plugin.joints, [handle.position for handle in handles],
                   [handle.velocity for handle in handles], [handle.effort for handle in handles])
