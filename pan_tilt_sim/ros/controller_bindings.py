"""The loaded controllers' ROS side on sim_node, and the one way to change them at run time.

A controller's ROS entities exist while it is configured (inactive or
active), as a ros2_control controller's do.  Each controller declares them
(:meth:`~pan_tilt_sim.controllers.base.Controller.ros_surface`, see
:mod:`pan_tilt_sim.controllers.surface`); this module creates one entity per
declared entry from tables keyed by message and action type, never by
controller type:

* a :class:`~pan_tilt_sim.controllers.surface.CommandTopic`: a subscription
  whose messages' values go to the controller (:data:`COMMAND_MESSAGES`);
* a :class:`~pan_tilt_sim.controllers.surface.StateTopic`: a publisher and
  the sink the controller hands its samples to (:data:`STATE_SINKS`);
* an :class:`~pan_tilt_sim.controllers.surface.ActionServer`, where its
  interface package is installed (:data:`ACTION_SERVERS`);

plus its tunable PID gains as sim_node parameters (:mod:`.gain_parameters`).
A topic whose message type's interface package is not installed (control_msgs
for the gpio controller, where the venv lacks it) is left out with one warning;
the controller still runs.
A command controller's commands are ignored while it is inactive, or in
chained mode (then the controller before it in the chain writes its
references).  Given a :class:`~pan_tilt_sim.ros.command_reader.CommandReader` (the sim_node
program), the command subscriptions are read by it rather than by the
executor.

:class:`ControllerBindings` creates them for the controllers configured at
start-up, and :meth:`~ControllerBindings.load`,
:meth:`~ControllerBindings.configure`, :meth:`~ControllerBindings.cleanup`,
:meth:`~ControllerBindings.unload` and :meth:`~ControllerBindings.switch`
change the simulation's controllers (the controller_manager services call
these, and nothing else touches the simulation's controllers) and keep the
entities in step.  Each is one short call, made between physics steps.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

from geometry_msgs.msg import PoseStamped, WrenchStamped
from rclpy.node import Node
from sensor_msgs.msg import Imu, JointState, Range

from pan_tilt_sim.controllers import CommandResult, Controller
from pan_tilt_sim.controllers.surface import PRIVATE, ActionServer, CommandTopic, StateTopic
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.ros import optional_interfaces
from pan_tilt_sim.ros.command_reader import CommandReader
from pan_tilt_sim.ros.gain_parameters import GainParameters
from pan_tilt_sim.ros.ros_interfaces import (
    COMMAND_MESSAGES,
    GROUP_VALUES,
    joint_state_message,
    optional_message,
)
from pan_tilt_sim.ros.state_sinks import (
    GroupValuesSink,
    ImuSink,
    PoseSink,
    RangeSink,
    TransformSink,
    WrenchSink,
)
from pan_tilt_sim.ros.trajectory_action import TrajectoryActionServer
from pan_tilt_sim.sim.engine import Simulation

QUEUE_DEPTH = 10
WARNING_THROTTLE_S = 1.0


class ControllerBindings:
    """Topics, actions and gain parameters of the configured controllers on ``node``."""

    def __init__(self, node: Node, simulation: Simulation, topic: Callable[..., str],
                 gain_parameters: GainParameters, *, actions: bool,
                 command_topics: bool = True, reader: CommandReader | None = None) -> None:
        self._node = node
        self._reader = reader
        # False: command controllers take no topic (topic-based hardware feeds them).
        self._command_topics = command_topics
        self._simulation = simulation
        self._manager = simulation.manager
        self._topic = topic
        self._gains = gain_parameters
        self._actions_wanted = actions
        self._logger = node.get_logger()
        # Commands taken per controller (ignored ones included): a cheap health figure.
        self.commands_received: dict[str, int] = {}
        self._entities: dict[str, list[Any]] = {}
        # (controller, publisher, sink) of every declared state topic.
        self._state_sinks: list[tuple[Controller, Any, Any]] = []
        self._connections: list[tuple[str, StateTopic, Any, Any]] = []
        self._noticing: list[Controller] = []
        self.actions: dict[str, Any] = {}
        # Wakes the executor when a goal ended or feedback is due (see after_steps).
        self._attention = node.create_guard_condition(self.serve_actions)
        for controller in self._manager.configured:
            self._bind(controller)

    # --- the run-time changes (controller_manager's services) ----------------------------------

    def load(self, name: str, type_name: Any, params: Mapping[str, Any], source: str) -> None:
        """Load controller ``name`` (unconfigured: no ROS entities yet)."""
        self._manager.load(name, type_name, params, source)

    def configure(self, name: str) -> None:
        """Configure ``name`` (afresh if inactive) and create its ROS entities."""
        self._unbind(name)
        controller = self._manager.configure(name)
        try:
            self._bind(controller)
        except ConfigurationError:
            self._unbind(name)
            self._manager.cleanup(name)
            raise

    def cleanup(self, name: str) -> None:
        """Return an inactive ``name`` to unconfigured; its ROS entities go."""
        self._manager.cleanup(name)
        self._unbind(name)

    def unload(self, name: str) -> None:
        """Unload a controller that is not active; its ROS entities go."""
        self._manager.unload(name)
        self._unbind(name)

    def switch(self, activate: Iterable[str], deactivate: Iterable[str], *,
               strict: bool) -> list[str]:
        """Switch controllers (see ControllerManager.switch); goals they ran end now."""
        try:
            return self._manager.switch(activate, deactivate, strict=strict)
        finally:
            self.serve_actions()  # the goals of deactivated controllers end now

    # --- called by the node --------------------------------------------------------------------

    def after_steps(self) -> None:
        """After a batch of steps: log what controllers noticed; wake the executor for goals.

        Runs wherever the physics runs (sim_node's physics thread, or a timer
        on the executor); the goals' rclpy side is served on the executor, by
        :meth:`serve_actions`, through a guard condition.
        """
        for controller in self._noticing:
            notices = controller.notices
            while notices:
                self._logger.warning(f'{controller.name}: {notices.pop(0)}')
        for action in self.actions.values():
            if action.needs_attention():
                self._attention.trigger()
                return

    def flush_joint_states(self) -> None:
        """Publish the samples the broadcasters took since the last flush (JointStates...)."""
        for _controller, _publisher, sink in self._state_sinks:
            sink.flush()

    def serve_actions(self) -> None:
        """Deliver the results of goals that ended and the feedback that is due (executor)."""
        for action in self.actions.values():
            action.poll()

    def refresh_readers(self) -> None:
        """Let controllers take samples only for state topics someone listens to."""
        for _name, endpoint, publisher, sink in self._connections:
            endpoint.connect(sink if publisher.get_subscription_count() > 0 else None)

    def destroy(self) -> None:
        """Remove every action server (their goals end aborted)."""
        for action in self.actions.values():
            action.destroy()
        self.actions.clear()
        self._node.destroy_guard_condition(self._attention)

    # --- entities ------------------------------------------------------------------------------

    def _bind(self, controller: Controller) -> None:
        name = controller.name
        entities: list[Any] = []
        self._entities[name] = entities
        self.commands_received.setdefault(name, 0)
        for warning in controller.config_warnings:
            self._logger.warning(warning)
        for endpoint in controller.ros_surface():
            if isinstance(endpoint, CommandTopic | StateTopic) and (
                    endpoint.message not in (COMMAND_MESSAGES if isinstance(
                        endpoint, CommandTopic) else STATE_SINKS)):
                package = endpoint.message.split('/')[0]
                self._logger.warning(
                    f'{name}: no topic {endpoint.name} ({endpoint.message}): {package} is not '
                    f'installed ({optional_interfaces.BUILD_HINT})')
            elif isinstance(endpoint, CommandTopic):
                if self._command_topics:
                    entities.append(self._subscribe(controller, endpoint))
            elif isinstance(endpoint, StateTopic):
                entities.append(self._publish(controller, endpoint))
            elif isinstance(endpoint, ActionServer):
                self._serve(controller, endpoint)
        self._noticing.append(controller)
        self._gains.add(controller)

    def _name(self, controller: Controller, topic: str) -> str:
        """Resolve a declared name: ``~/x`` in the controller's namespace, ``/x`` as it is.

        Anything else is in the robot's namespace.
        """
        if topic.startswith(PRIVATE):
            return self._topic(controller.name, topic[len(PRIVATE):])
        if topic.startswith('/'):
            return topic
        return self._topic(topic)

    def _subscribe(self, controller: Controller, endpoint: CommandTopic) -> Any:
        message_type, extract = COMMAND_MESSAGES[endpoint.message]
        subscription = self._node.create_subscription(
            message_type, self._name(controller, endpoint.name),
            self._command_callback(controller, endpoint, extract), QUEUE_DEPTH,
            callback_group=self._reader.group if self._reader is not None else None)
        if self._reader is not None:
            self._reader.add(subscription)
        return subscription

    def _publish(self, controller: Controller, endpoint: StateTopic) -> Any:
        message_type, make_sink = STATE_SINKS[endpoint.message]
        publisher = self._node.create_publisher(
            message_type, self._name(controller, endpoint.name), QUEUE_DEPTH)
        sink = make_sink(publisher, endpoint.fields)
        self._state_sinks.append((controller, publisher, sink))
        self._connections.append((controller.name, endpoint, publisher, sink))
        endpoint.connect(sink)
        return publisher

    def _serve(self, controller: Controller, endpoint: ActionServer) -> None:
        if not self._actions_wanted or endpoint.action not in ACTION_SERVERS:
            return
        name = controller.name
        self.actions[name] = ACTION_SERVERS[endpoint.action](
            self._node, controller, self._name(controller, endpoint.name),
            now=lambda: self._simulation.time,
            is_active=lambda: self._manager.is_active(name))

    def _unbind(self, name: str) -> None:
        entities = self._entities.pop(name, None)
        if entities is None:
            return
        for entity in entities:
            if hasattr(entity, 'publish'):
                self._node.destroy_publisher(entity)
            else:
                if self._reader is not None:
                    self._reader.remove(entity)
                self._node.destroy_subscription(entity)
        self._state_sinks = [item for item in self._state_sinks if item[0].name != name]
        for owner, endpoint, _publisher, _sink in self._connections:
            if owner == name:  # its publisher is gone: the controller takes no more samples
                endpoint.connect(None)
        self._connections = [item for item in self._connections if item[0] != name]
        self._noticing = [controller for controller in self._noticing
                          if controller.name != name]
        action = self.actions.pop(name, None)
        if action is not None:
            action.destroy()
        self._gains.remove(name)

    def _command_callback(self, controller: Controller, endpoint: CommandTopic,
                          extract: Callable[[Any], Any]) -> Callable[[Any], None]:
        name = controller.name
        logger = self._logger
        counts = self.commands_received
        is_active = self._manager.is_active
        accept, problem = endpoint.accept, endpoint.problem

        def store(message: Any) -> None:
            counts[name] += 1
            if not is_active(name):
                logger.warning(f'{name}: ignored a command: the controller is inactive',
                               throttle_duration_sec=WARNING_THROTTLE_S)
                return
            if controller.is_chained:
                logger.warning(f'{name}: ignored a command: the controller is in chained mode, '
                               'its references come from the controller before it',
                               throttle_duration_sec=WARNING_THROTTLE_S)
                return
            value = extract(message)
            result = accept(value)
            if result is not CommandResult.ACCEPTED:
                logger.warning(f'{name}: {problem(value, result)}',
                               throttle_duration_sec=WARNING_THROTTLE_S)
        return store


class JointStateSink:
    """A broadcaster's samples as JointState messages, held until :meth:`flush`.

    A sample is written into one reused message when the broadcaster takes
    it (mid-batch), and leaves when the node flushes -- after the batch, or
    where a chunk of it ends -- or when the next sample comes first.  Every
    sample leaves, in order, with the state of the step it was taken at;
    only the moment changes, by at most a batch (at real_time_factor 1 a
    fraction of a millisecond).  Published with the node's other messages,
    while DDS's code is warm: right after a 20 ms sleep the first publish
    costs ~150-250 us of CPU on these VMs and the next ~10-35 us.
    """

    def __init__(self, publisher: Any, fields: Mapping[str, Any]) -> None:
        names: Iterable[str] = fields['names']
        self._publisher = publisher
        self._message = JointState()
        self._message.name = list(names)  # once: the names never change
        self._pending = False

    def __call__(self, time: float, names: Any, positions: Any, velocities: Any,
                 efforts: Any) -> None:
        """Take a sample (the broadcaster's lists are copied into the message)."""
        if self._pending:
            self._publisher.publish(self._message)
        joint_state_message(time, positions, velocities, efforts, self._message)
        self._pending = True

    def flush(self) -> None:
        """Publish the sample taken since the last flush, if any."""
        if self._pending:
            self._pending = False
            self._publisher.publish(self._message)


# Each state message type (by its ROS name): its class, and the sink that
# turns a controller's samples into messages on a publisher.  A type whose
# interface package is not installed is left out: no topic is made for it.
STATE_SINKS: dict[str, tuple[type, Callable[[Any, Mapping[str, Any]], Any]]] = {
    'sensor_msgs/msg/JointState': (JointState, JointStateSink),
    'geometry_msgs/msg/WrenchStamped': (WrenchStamped, WrenchSink),
    'sensor_msgs/msg/Imu': (Imu, ImuSink),
    'sensor_msgs/msg/Range': (Range, RangeSink),
    'geometry_msgs/msg/PoseStamped': (PoseStamped, PoseSink),
}
for _name, _sink in (('tf2_msgs/msg/TFMessage', TransformSink),
                     (GROUP_VALUES, GroupValuesSink)):
    if (_message := optional_message(_name)) is not None:
        STATE_SINKS[_name] = (_message, _sink)
# Each action type: the server that runs a controller's goals.
ACTION_SERVERS: dict[str, Callable[..., Any]] = {
    'control_msgs/action/FollowJointTrajectory': TrajectoryActionServer,
}
