"""``libgazebo_ros_joint_state_publisher.so`` as a unit of the simulation: joint states. No ROS.

Not a ros2_control controller: the simulation creates one per plugin the
URDF declares (:mod:`pan_tilt_sim.model.drive_plugins`) and updates it every
physics step; it is always active and commands nothing.  As the plugin,
every ``1 / update_rate`` s of sim time (0: every step) it publishes
``sensor_msgs/JointState`` with the named joints' positions (rad or m),
velocities and efforts, in the order the plugin names them -- only while
someone listens.  Pure Python.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

from pan_tilt_sim.controllers.base import Controller, JointHandle
from pan_tilt_sim.controllers.surface import Endpoint, StateTopic
from pan_tilt_sim.model.drive_plugins import JointStatePlugin
from pan_tilt_sim.schedule import DUE_EPSILON

# sink(time, names, positions, velocities, efforts)
JointStateSink = Callable[[float, Sequence[str], Sequence[float], Sequence[float],
                           Sequence[float]], None]


class GazeboJointStatePublisher(Controller):
    """One ``gazebo_ros_joint_state_publisher`` plugin: the named joints' states."""

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
