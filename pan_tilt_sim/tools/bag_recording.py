"""A tool's run of a :class:`~pan_tilt_sim.sim.engine.Simulation` recorded as sim_node records one.

The tools that step a simulation in their own process (``step_response
--record <folder>``) have no node and no DDS, but their bag holds what
sim_node's would, on the same topics: ``/clock`` every 10 ms of sim time,
the state topics of the active controllers (``joint_states``,
``dynamic_joint_states``, controller states) built by the same sinks
sim_node publishes through, ``/tf`` at 50 Hz and ``/tf_static`` (where
tf2_msgs is installed), ``robot_description``, and the commands the tool
gave, on the controllers' command topics.  No ROS graph is made: rclpy only
serializes the messages.
"""

from __future__ import annotations

from typing import Any

from builtin_interfaces.msg import Duration
from rclpy.qos import QoSProfile
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64, Float64MultiArray, String
from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMessage
from trajectory_msgs.msg import JointTrajectoryPoint

from pan_tilt_sim.controllers import CommandController
from pan_tilt_sim.controllers.framework.base import CommandKind
from pan_tilt_sim.controllers.framework.surface import PRIVATE, StateTopic
from pan_tilt_sim.controllers.trajectory.trajectory import JointTrajectory
from pan_tilt_sim.model import naming
from pan_tilt_sim.ros.clock_publisher import CLOCK_PERIOD_S, clock_period_steps
from pan_tilt_sim.ros.controller_bindings import STATE_SINKS
from pan_tilt_sim.ros.recording import Recorder
from pan_tilt_sim.ros.robot_state import (
    LATCHED,
    TF_PERIOD_S,
    TF_STATIC_TOPIC,
    TF_TOPIC,
    moving_transforms,
    static_transforms,
    tf_message_type,
    transform_message,
)
from pan_tilt_sim.ros.ros_interfaces import clock_message, stamp
from pan_tilt_sim.ros.sim_node import QUEUE_DEPTH
from pan_tilt_sim.sim.engine import Simulation

DEFAULT_QOS = QoSProfile(depth=QUEUE_DEPTH)


def command_message(kind: CommandKind, command: Any) -> Any:
    """Return the ROS message that carries ``command`` (what ``set_command`` took) on a topic."""
    if kind is CommandKind.FLOAT64:
        return Float64(data=float(command))
    if kind is CommandKind.FLOAT64_ARRAY:
        return Float64MultiArray(data=[float(value) for value in command])
    if kind is CommandKind.JOINT_TRAJECTORY and isinstance(command, JointTrajectory):
        return JointTrajectoryMessage(joint_names=list(command.joint_names), points=[
            JointTrajectoryPoint(positions=list(point.positions),
                                 velocities=list(point.velocities),
                                 time_from_start=_duration(point.time_from_start))
            for point in command.points])
    raise ValueError(f'no message for a {kind.value} command {command!r}')


def _duration(seconds: float) -> Duration:
    time = stamp(seconds)
    return Duration(sec=time.sec, nanosec=time.nanosec)


class SimulationRecording:
    """Records ``simulation``'s run into the new bag folder ``folder``, topics under ``namespace``.

    Call :meth:`after_steps` after each advance of the simulation, and
    :meth:`command` for each command given; :meth:`close` finishes the bag.
    ``field`` names the option in errors; ``warn`` takes the one line said
    when a write error stops the recording.
    """

    def __init__(self, folder: str, simulation: Simulation, namespace: str, *,
                 field: str, warn: Any) -> None:
        self._simulation = simulation
        self._namespace = namespace
        self.recorder = Recorder(folder, clock=lambda: simulation.time, sensors=False,
                                 warn=warn, field=field)
        self._clock = self.recorder.publisher(Clock, '/clock', DEFAULT_QOS)
        self._clock_every = clock_period_steps(simulation.time_step)
        self._tf_every = clock_period_steps(simulation.time_step) * round(
            TF_PERIOD_S / CLOCK_PERIOD_S)
        self._sinks = []
        self._connected: list[StateTopic] = []
        for controller in simulation.manager.active:
            for endpoint in controller.ros_surface():
                if not isinstance(endpoint, StateTopic):
                    continue
                message_type, make_sink = STATE_SINKS.get(endpoint.message, (None, None))
                if message_type is None:
                    continue
                publisher = self.recorder.publisher(
                    message_type, self._name(controller.name, endpoint.name), DEFAULT_QOS)
                sink = make_sink(publisher, endpoint.fields)
                endpoint.connect(sink)
                self._sinks.append(sink)
                self._connected.append(endpoint)
        description = simulation.description
        self.recorder.publisher(
            String, naming.join(namespace, 'robot_description'), LATCHED).publish(
            String(data=description.urdf_xml))
        self._tf_type = tf_message_type()
        self._tf = None
        if self._tf_type is not None:
            self._tf = self.recorder.publisher(self._tf_type, TF_TOPIC, DEFAULT_QOS)
            fixed = static_transforms(description.model)
            if fixed:
                self.recorder.publisher(self._tf_type, TF_STATIC_TOPIC, LATCHED).publish(
                    self._tf_type(transforms=[transform_message(parent, child, transform, 0.0)
                                              for parent, child, transform in fixed]))
        self._last_step = -1
        self.after_steps()

    def _name(self, controller: str, topic: str) -> str:
        if topic.startswith(PRIVATE):
            return naming.join(self._namespace, controller, topic[len(PRIVATE):])
        return naming.join(self._namespace, topic)

    def command(self, controller: CommandController, command: Any) -> None:
        """Record ``command`` (what ``controller.set_command`` took) as received on its topic."""
        message = command_message(controller.command_kind, command)
        topic = self._name(controller.name, f'{PRIVATE}{controller.command_topic}')
        self.recorder.publisher(type(message), topic, DEFAULT_QOS).publish(message)

    def after_steps(self) -> None:
        """Record what is due at the present step: the state samples, /clock, /tf."""
        for sink in self._sinks:
            sink.flush()
        step = self._simulation.steps
        if step == self._last_step:
            return
        self._last_step = step
        time = self._simulation.time
        if step % self._clock_every == 0:
            self._clock.publish(clock_message(time))
        if self._tf is not None and step % self._tf_every == 0:
            model = self._simulation.description.model
            self._tf.publish(self._tf_type(transforms=[
                transform_message(parent, child, transform, time) for parent, child, transform
                in moving_transforms(model, self._simulation.joint_positions())]))

    def close(self) -> None:
        """Disconnect the state topics and finish the bag."""
        for endpoint in self._connected:
            endpoint.connect(None)
        self.recorder.close()
