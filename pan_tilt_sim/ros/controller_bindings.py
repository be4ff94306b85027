"""The loaded controllers' ROS side on sim_node, and the one way to change them at run time.

A controller's ROS entities exist while it is configured (inactive or
active), as a ros2_control controller's do:

* a broadcaster: ``<ns>/joint_states`` (``sensor_msgs/msg/JointState``);
* a command controller: ``<ns>/<controller>/<command topic>`` (whose commands
  are ignored while the controller is inactive, or in chained mode: then the
  controller before it in the chain writes its references);
* a joint trajectory controller, where control_msgs is installed, also
  ``<ns>/<controller>/follow_joint_trajectory`` (:mod:`.trajectory_action`);
* its PID gains as sim_node parameters (:mod:`.gain_parameters`).

Given a :class:`~pan_tilt_sim.ros.command_reader.CommandReader` (the sim_node
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

from rclpy.node import Node
from sensor_msgs.msg import JointState

from pan_tilt_sim.controllers import CommandController, CommandResult, Controller
from pan_tilt_sim.controllers.joint_state_controller import JointStateController
from pan_tilt_sim.controllers.joint_trajectory_controller import JointTrajectoryController
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.ros.command_reader import CommandReader
from pan_tilt_sim.ros.gain_parameters import GainParameters
from pan_tilt_sim.ros.ros_interfaces import COMMAND_MESSAGES, joint_state_message
from pan_tilt_sim.ros.trajectory_action import ACTION, TrajectoryActionServer
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
        self._joint_state_sinks: list[tuple[JointStateController, Any, JointStateSink]] = []
        self._trajectory_controllers: list[JointTrajectoryController] = []
        self.actions: dict[str, TrajectoryActionServer] = {}
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
        for controller in self._trajectory_controllers:
            notices = controller.notices
            while notices:
                self._logger.warning(f'{controller.name}: {notices.pop(0)}')
        for action in self.actions.values():
            if action.needs_attention():
                self._attention.trigger()
                return

    def flush_joint_states(self) -> None:
        """Publish the JointState samples the broadcasters took since the last flush."""
        for _controller, _publisher, sink in self._joint_state_sinks:
            sink.flush()

    def serve_actions(self) -> None:
        """Deliver the results of goals that ended and the feedback that is due (executor)."""
        for action in self.actions.values():
            action.poll()

    def refresh_readers(self) -> None:
        """Sample joint states only for broadcasters someone listens to."""
        for controller, publisher, sink in self._joint_state_sinks:
            controller.set_sink(sink if publisher.get_subscription_count() > 0 else None)

    def destroy(self) -> None:
        """Remove every action server (their goals end aborted)."""
        for action in self.actions.values():
            action.destroy()
        self.actions.clear()
        self._node.destroy_guard_condition(self._attention)

    # --- entities ------------------------------------------------------------------------------

    def _bind(self, controller: Controller) -> None:
        node, name = self._node, controller.name
        entities: list[Any] = []
        self._entities[name] = entities
        self.commands_received.setdefault(name, 0)
        if isinstance(controller, JointStateController):
            publisher = node.create_publisher(JointState, self._topic('joint_states'),
                                              QUEUE_DEPTH)
            sink = JointStateSink(publisher, controller.names)
            self._joint_state_sinks.append((controller, publisher, sink))
            controller.set_sink(sink)
            entities.append(publisher)
        elif isinstance(controller, CommandController) and self._command_topics:
            message_type, extract = COMMAND_MESSAGES[controller.command_kind]
            subscription = node.create_subscription(
                message_type, self._topic(name, controller.command_topic),
                self._command_callback(controller, extract), QUEUE_DEPTH,
                callback_group=self._reader.group if self._reader is not None else None)
            entities.append(subscription)
            if self._reader is not None:
                self._reader.add(subscription)
        if isinstance(controller, JointTrajectoryController):
            self._trajectory_controllers.append(controller)
        if isinstance(controller, JointTrajectoryController) and self._actions_wanted:
            self.actions[name] = TrajectoryActionServer(
                node, controller, self._topic(name, ACTION),
                now=lambda: self._simulation.time,
                is_active=lambda: self._manager.is_active(name))
        self._gains.add(controller)

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
        self._joint_state_sinks = [item for item in self._joint_state_sinks
                                   if item[0].name != name]
        self._trajectory_controllers = [controller for controller in self._trajectory_controllers
                                        if controller.name != name]
        action = self.actions.pop(name, None)
        if action is not None:
            action.destroy()
        self._gains.remove(name)

    def _command_callback(self, controller: CommandController, extract):
        logger = self._logger
        name = controller.name
        counts = self.commands_received
        is_active = self._manager.is_active

        def store(message) -> None:
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
            result = controller.set_command(value)
            if result is not CommandResult.ACCEPTED:
                logger.warning(f'{name}: {controller.command_problem(value, result)}',
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

    def __init__(self, publisher: Any, names: Iterable[str]) -> None:
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
