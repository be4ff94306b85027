"""The loaded controllers' ROS side on sim_node, and the one way to change them at run time.

A controller's ROS entities exist while it is configured (inactive or
active), as a ros2_control controller's do.  Each controller declares them
(:meth:`~pan_tilt_sim.controllers.framework.base.Controller.ros_surface`, see
:mod:`pan_tilt_sim.controllers.framework.surface`); this module creates one entity per
declared entry from tables keyed by message and action type, never by
controller type (see the design notes).

Design notes: docs/design/ros.md#controller_bindingspy.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.service import Service as ServiceEntity
from sensor_msgs.msg import Imu, JointState, Range
from std_srvs.srv import Empty, SetBool

from pan_tilt_sim.controllers import CommandResult, Controller
from pan_tilt_sim.controllers.framework.surface import (
    PRIVATE,
    ActionServer,
    CommandTopic,
    Service,
    StateTopic,
    TrajectoryStateAnswer,
)
from pan_tilt_sim.errors import ConfigurationError
from pan_tilt_sim.model.ros_arguments import RosArguments
from pan_tilt_sim.ros import optional_interfaces
from pan_tilt_sim.ros.command_reader import CommandReader
from pan_tilt_sim.ros.gain_parameters import GainParameters
from pan_tilt_sim.ros.gripper_action import GripperCommandServer, ParallelGripperCommandServer
from pan_tilt_sim.ros.robot_state import tf_message_type
from pan_tilt_sim.ros.ros_interfaces import (
    COMMAND_MESSAGES,
    GROUP_VALUES,
    optional_message,
    seconds,
)
from pan_tilt_sim.ros.state_sinks import (
    AckermannDriveSink,
    DofStateSink,
    DynamicJointStateSink,
    GroupValuesSink,
    ImuSink,
    JointStateSink,
    MecanumStateSink,
    PoseSink,
    RangeSink,
    SteeringStatusSink,
    TfMessageSink,
    TrajectoryStateSink,
    TwistSink,
    WrenchSink,
    odometry_sink,
)
from pan_tilt_sim.ros.trajectory_action import TrajectoryActionServer
from pan_tilt_sim.sim.engine import Simulation

try:
    from control_msgs.msg import (
        DynamicJointState,
        InterfaceValue,
        JointTrajectoryControllerState,
        MultiDOFStateStamped,
        SingleDOFState,
    )
    from control_msgs.srv import QueryTrajectoryState
except ImportError:  # an optional interface package (see optional_interfaces)
    DynamicJointState = InterfaceValue = MultiDOFStateStamped = SingleDOFState = None
    JointTrajectoryControllerState = QueryTrajectoryState = None
try:
    from control_msgs.msg import MecanumDriveControllerState
except ImportError:  # optional, and absent from control_msgs builds older than this project's
    MecanumDriveControllerState = None

QUEUE_DEPTH = 10
STEERING_STATUS = 'control_msgs/msg/SteeringControllerStatus'
ACKERMANN_DRIVE = 'ackermann_msgs/msg/AckermannDrive'  # not in the venv: no such topic there
WARNING_THROTTLE_S = 1.0


class ControllerBindings:
    """Topics, actions and gain parameters of the configured controllers on ``node``."""

    def __init__(self, node: Node, simulation: Simulation, topic: Callable[..., str],
                 gain_parameters: GainParameters, *, actions: bool,
                 command_topics: bool = True, reader: CommandReader | None = None,
                 namespace: str = '') -> None:
        self._node = node
        # The namespace the controllers' nodes would be in, for their remap rules.
        self._namespace = namespace
        # Each loaded controller's own node arguments (remap rules), by name.
        self._arguments: dict[str, RosArguments] = {}
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
        # The URDF's Gazebo drive plugins: bound once, always active (no manager knows them).
        self._plugins = {unit.name for unit in simulation.plugins}
        for controller in [*simulation.plugins, *self._manager.configured]:
            self._bind(controller)

    # --- the run-time changes (controller_manager's services) ----------------------------------

    def load(self, name: str, type_name: Any, params: Mapping[str, Any], source: str,
             arguments: RosArguments | None = None) -> None:
        """Load controller ``name`` (unconfigured: no ROS entities yet).

        ``arguments`` are the controller node's own (the spawner's
        ``--controller-ros-args``): their remap rules rename its topics and
        action, from configure on, until it is unloaded.
        """
        self._manager.load(name, type_name, params, source)
        if arguments is not None and arguments.remaps:
            self._arguments[name] = arguments

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
        self._arguments.pop(name, None)

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
        """Publish the samples the state topics took since the last flush."""
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

    def release(self) -> None:
        """Destroy every topic, service and action of the plugins and controllers (a robot goes)."""
        for name in list(self._entities):
            self._unbind(name)
        self.destroy()

    # --- entities ------------------------------------------------------------------------------

    def _bind(self, controller: Controller) -> None:
        name = controller.name
        entities: list[Any] = []
        self._entities[name] = entities
        self.commands_received.setdefault(name, 0)
        for warning in controller.config_warnings:
            self._logger.warning(warning)
        controller.node_namespace = self._topic()
        for endpoint in controller.ros_surface():
            if isinstance(endpoint, CommandTopic):
                if COMMAND_MESSAGES.get(endpoint.message, (None,))[0] is None:
                    self._missing(controller, endpoint.name, endpoint.message)
                elif self._command_topics:
                    entities.append(self._subscribe(controller, endpoint))
            elif isinstance(endpoint, StateTopic):
                if STATE_SINKS.get(endpoint.message, (None,))[0] is not None:
                    entities.append(self._publish(controller, endpoint))
                else:  # the controller takes no samples for it
                    endpoint.connect(None)
                    self._missing(controller, endpoint.name, endpoint.message)
            elif isinstance(endpoint, Service):
                if SERVICES.get(endpoint.service, (None,))[0] is not None:
                    entities.append(self._provide(controller, endpoint))
                else:
                    self._missing(controller, endpoint.name, endpoint.service)
            elif isinstance(endpoint, ActionServer):
                self._serve(controller, endpoint)
        self._noticing.append(controller)
        self._gains.add(controller)

    def _missing(self, controller: Controller, name: str, interface: str) -> None:
        """Say that ``controller`` has no ``name``: ``interface``'s package is not installed."""
        package = interface.split('/')[0]
        self._logger.warning(
            f'{controller.name}: no topic {self._name(controller, name)} ({interface}): '
            f'{package} is not installed ({optional_interfaces.BUILD_HINT})')

    def _name(self, controller: Controller, topic: str) -> str:
        """Resolve a declared name: ``~/x`` the controller's, ``/x`` as is, else the robot's.

        Then the controller's remap rules apply, as rcl applies a node's
        rules to the names it creates (``~/cmd_vel:=/cmd_vel``).
        """
        if topic.startswith(PRIVATE):
            resolved = self._topic(controller.name, topic[len(PRIVATE):])
        elif topic.startswith('/'):
            resolved = topic
        else:
            resolved = self._topic(topic)
        arguments = self._arguments.get(controller.name)
        if arguments is None:
            return resolved
        return arguments.remapped(resolved, self._namespace, controller.name)

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
        """Create the publisher of ``endpoint`` and hand the controller its sink."""
        message_type, make_sink = STATE_SINKS[endpoint.message]
        publisher = self._node.create_publisher(
            message_type, self._name(controller, endpoint.name), QUEUE_DEPTH)
        sink = make_sink(publisher, endpoint.fields)
        self._state_sinks.append((controller, publisher, sink))
        self._connections.append((controller.name, endpoint, publisher, sink))
        endpoint.connect(sink)
        return publisher

    def _provide(self, controller: Controller, endpoint: Service) -> Any:
        service_type, extract, answer = SERVICES[endpoint.service]
        call, inactive = endpoint.call, endpoint.inactive
        name, is_active = controller.name, self._manager.is_active

        def serve(request: Any, response: Any) -> Any:
            if inactive is not None and not is_active(name):
                answer(inactive, response)
            else:
                answer(call(extract(request)), response)
            return response
        return self._node.create_service(service_type, self._name(controller, endpoint.name),
                                         serve)

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
        for owner, endpoint, _publisher, _sink in self._connections:
            if owner == name:
                endpoint.connect(None)  # its publisher goes: no more samples for it
        for entity in entities:
            if hasattr(entity, 'publish'):
                self._node.destroy_publisher(entity)
            elif isinstance(entity, ServiceEntity):
                self._node.destroy_service(entity)
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
        manager_active = self._manager.is_active
        plugins = self._plugins

        def is_active(name: str) -> bool:
            return name in plugins or manager_active(name)
        accept, problem = endpoint.accept, endpoint.problem
        while_chained = endpoint.while_chained

        def store(message: Any) -> None:
            counts[name] += 1
            if not is_active(name):
                logger.warning(f'{name}: ignored a command: the controller is inactive',
                               throttle_duration_sec=WARNING_THROTTLE_S)
                return
            if controller.is_chained and not while_chained:
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


# Each state message type (by its ROS name): its class (None where its interface package is
# not installed: no such topics then), and the sink that turns a controller's samples into
# messages on a publisher.
STATE_SINKS: dict[str, tuple[type | None, Callable[[Any, Mapping[str, Any]], Any]]] = {
    'sensor_msgs/msg/JointState': (JointState, JointStateSink),
    'control_msgs/msg/DynamicJointState': (DynamicJointState, DynamicJointStateSink),
    'control_msgs/msg/MultiDOFStateStamped': (MultiDOFStateStamped, DofStateSink),
    'control_msgs/msg/JointTrajectoryControllerState': (
        JointTrajectoryControllerState, TrajectoryStateSink),
    'nav_msgs/msg/Odometry': (Odometry, odometry_sink),
    'geometry_msgs/msg/TwistStamped': (TwistStamped, TwistSink),
    'geometry_msgs/msg/WrenchStamped': (WrenchStamped, WrenchSink),
    'sensor_msgs/msg/Imu': (Imu, ImuSink),
    'sensor_msgs/msg/Range': (Range, RangeSink),
    'geometry_msgs/msg/PoseStamped': (PoseStamped, PoseSink),
    GROUP_VALUES: (optional_message(GROUP_VALUES), GroupValuesSink),
    'control_msgs/msg/MecanumDriveControllerState': (MecanumDriveControllerState,
                                                     MecanumStateSink),
    STEERING_STATUS: (optional_message(STEERING_STATUS), SteeringStatusSink),
    ACKERMANN_DRIVE: (optional_message(ACKERMANN_DRIVE), AckermannDriveSink),
}
def _success_and_message(answer: tuple[bool, str], response: Any) -> None:
    """Fill a response's ``success`` and ``message`` from ``(success, message)``."""
    response.success, response.message = answer


def _trajectory_state(answer: TrajectoryStateAnswer, response: Any) -> None:
    """Fill a ``control_msgs/srv/QueryTrajectoryState`` response."""
    response.success, response.message = answer.success, answer.message
    response.name = list(answer.names)
    response.position = list(answer.positions)
    response.velocity = list(answer.velocities)
    response.acceleration = list(answer.accelerations)


# Each service type: its class (None where its interface package is not installed: no such
# services then), how to get the value out of a request, and how the controller's answer
# fills the response.
SERVICES: dict[str, tuple[type | None, Callable[[Any], Any], Callable[[Any, Any], None]]] = {
    'std_srvs/srv/SetBool': (SetBool, lambda request: request.data, _success_and_message),
    'std_srvs/srv/Empty': (Empty, lambda request: None, lambda answer, response: None),
    'control_msgs/srv/QueryTrajectoryState': (
        QueryTrajectoryState, lambda request: seconds(request.time), _trajectory_state),
}
if tf_message_type() is not None:  # tf2_msgs is optional (see optional_interfaces)
    STATE_SINKS['tf2_msgs/msg/TFMessage'] = (tf_message_type(), TfMessageSink)
# Each action type: the server that runs a controller's goals.
ACTION_SERVERS: dict[str, Callable[..., Any]] = {
    'control_msgs/action/FollowJointTrajectory': TrajectoryActionServer,
    'control_msgs/action/GripperCommand': GripperCommandServer,
    'control_msgs/action/ParallelGripperCommand': ParallelGripperCommandServer,
}
