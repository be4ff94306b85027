"""What a test does with a simulation, in sim time: the helpers both test handles share.

:class:`SimHelpers` holds a probe node on the handle's executor and builds
every helper of the pytest plugin's handles on three primitives that the
in-process handle (:mod:`pan_tilt_sim.tools.sim_handle`) and the
process-level one (:mod:`pan_tilt_sim.tools.sim_process_handle`) each
provide: advance the physics by some steps (:meth:`SimHelpers._advance`),
let every ready callback run (:meth:`SimHelpers._settle`), and read the sim
time.  Waits for DDS (a subscription to match, an action server to appear)
are bounded in wall time; everything else is counted in sim time.
"""

from __future__ import annotations

import dataclasses
import importlib
import math
import time
from collections.abc import Callable, Iterable, Sequence
from typing import Any

from rclpy.action import ActionClient
from rclpy.executors import ExternalShutdownException, ShutdownException, TimeoutException
from rclpy.node import Node
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    QoSProfile,
    ReliabilityPolicy,
)

# Wall seconds a test waits for DDS to match a publisher or find a server.
DISCOVERY_BUDGET_S = 10.0
DISCOVERY_POLL_S = 0.01
# Sim seconds each turn of run_until() steps before the test's callbacks run.
DEFAULT_TURN_S = 0.01
# Messages each watched topic can hold between two turns.
READER_DEPTH = 1000
# Sim seconds a goal may run past its trajectory's last point before it times out.
GOAL_MARGIN_S = 5.0
# Callbacks one _settle() may run before it gives up: a node that answers every
# message with another on a topic it reads itself would otherwise never let go.
SETTLE_LIMIT = 100_000
# How many of a topic's latest messages a timeout report shows.
REPORTED_MESSAGE_CHARS = 300
INSTALL_HINT = (
    'in a ROS 2 install: sudo apt install ros-$ROS_DISTRO-{debian}; in a venv without ROS, '
    "build it from the ROS interface sources (pan_tilt_sim's scripts/build_interfaces.sh does)")


class CallbacksKeptComingError(RuntimeError):
    """The test's nodes kept each other busy: the executor never ran out of ready callbacks."""


class SimTimeoutError(AssertionError):
    """A condition did not hold within the sim time allowed (an assertion: the test failed)."""


class MissingInterfaceError(ImportError):
    """A helper needs a ROS interface package that is not installed."""


def interface(package: str, kind: str, name: str, helper: str) -> type:
    """Return ``package.kind.name`` (``control_msgs``, ``action``, ``FollowJointTrajectory``).

    Raises :class:`MissingInterfaceError` naming the package, the helper
    that needs it and how to install it.
    """
    try:
        module = importlib.import_module(f'{package}.{kind}')
    except ImportError:
        debian = package.replace('_', '-')
        raise MissingInterfaceError(
            f'{helper} needs the ROS interface package {package}, which is not installed: '
            + INSTALL_HINT.format(debian=debian)) from None
    return getattr(module, name)


@dataclasses.dataclass(frozen=True)
class DriveResult:
    """Where :meth:`SimHelpers.drive` left the robot: the true pose and the odometry then."""

    pose: Any  # geometry_msgs/msg/Pose, in the world frame
    odometry: Any  # nav_msgs/msg/Odometry, the newest the robot's odometry topic gave


@dataclasses.dataclass
class _Watched:
    """A topic the test reads: its type and every message since the test first asked."""

    message_type: type
    messages: list
    subscription: Any


def reader_qos(publishers: Iterable[Any]) -> QoSProfile:
    """Return a subscription QoS that matches every publisher in ``publishers`` (TopicEndpointInfo).

    Reliable and volatile unless some publisher is best effort (then best
    effort) or all of them are transient local (then transient local, so the
    latched message arrives too).
    """
    publishers = list(publishers)
    reliability = (ReliabilityPolicy.BEST_EFFORT
                   if any(p.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT
                          for p in publishers) else ReliabilityPolicy.RELIABLE)
    durability = (DurabilityPolicy.TRANSIENT_LOCAL
                  if publishers and all(p.qos_profile.durability ==
                                        DurabilityPolicy.TRANSIENT_LOCAL for p in publishers)
                  else DurabilityPolicy.VOLATILE)
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=READER_DEPTH,
                      reliability=reliability, durability=durability)


def absolute(topic: str) -> str:
    """``topic`` as an absolute name (the probe node lives in the root namespace)."""
    return topic if topic.startswith('/') else '/' + topic


def trajectory_point(point: Any) -> Any:
    """Return a JointTrajectoryPoint from one, or from ``(seconds, positions)``."""
    from trajectory_msgs.msg import JointTrajectoryPoint

    if isinstance(point, JointTrajectoryPoint):
        return point
    seconds, positions = point
    whole = math.floor(seconds)
    message = JointTrajectoryPoint(positions=[float(p) for p in positions])
    message.time_from_start.sec = int(whole)
    message.time_from_start.nanosec = round((seconds - whole) * 1e9)
    return message


def _seconds(duration: Any) -> float:
    return duration.sec + duration.nanosec * 1e-9


class SimHelpers:
    """Topics, actions and sim-time waits for a test, on a probe node of ``executor``."""

    def __init__(self, node: Node, executor: Any, probe: Node, turn: float) -> None:
        self.node = node
        self.executor = executor
        self._probe = probe
        self._turn = turn
        self._watched: dict[str, _Watched] = {}
        self._publishers: dict[str, Any] = {}
        self._action_clients: dict[str, ActionClient] = {}
        self._nodes: list[Node] = []

    # --- what a handle provides ------------------------------------------------------------

    @property
    def time(self) -> float:
        """Sim time, in seconds."""
        raise NotImplementedError

    @property
    def time_step(self) -> float:
        """Seconds of sim time per physics step."""
        raise NotImplementedError

    def _advance(self, steps: int) -> None:
        """Run ``steps`` physics steps (the physics stays paused otherwise)."""
        raise NotImplementedError

    def _settle(self) -> None:
        """Run every callback that is ready on the executor, and those they make ready."""
        executor = self.executor
        for _ in range(SETTLE_LIMIT):
            try:
                handler, _entity, _node = executor.wait_for_ready_callbacks(timeout_sec=0.0)
            except (TimeoutException, ShutdownException, ExternalShutdownException):
                return
            handler()
            if handler.exception() is not None:
                raise handler.exception()
        raise CallbacksKeptComingError(
            f'{SETTLE_LIMIT} callbacks in one turn: do two nodes answer each other forever?')


    def _publisher_endpoints(self, topic: str) -> list:
        """Return the publishers of ``topic`` known now (TopicEndpointInfo)."""
        return self._probe.get_publishers_info_by_topic(topic)

    # --- the test's own nodes ---------------------------------------------------------------

    def add_node(self, node: Node) -> Node:
        """Spin ``node`` on the simulation's executor; it is destroyed with the handle."""
        self.executor.add_node(node)
        self._nodes.append(node)
        return node

    # --- time -------------------------------------------------------------------------------

    def step(self, seconds: float) -> None:
        """Run ``seconds`` of sim time (in whole steps); the test's nodes take every message."""
        steps = self._steps(seconds)
        turn = self._steps(self._turn)
        self._settle()
        while steps > 0:
            chunk = min(turn, steps)
            self._advance(chunk)
            self._settle()
            steps -= chunk

    def run_until(self, predicate: Callable[[], object], timeout: float) -> None:
        """Step the physics and spin the executor in turns until ``predicate()`` holds.

        ``timeout`` is in sim seconds.  Each turn runs DEFAULT_TURN_S of physics,
        then every callback that became ready (so each node sees every message,
        in order, before the physics moves on).  Raises :class:`SimTimeoutError` with
        the sim time and the newest message of every topic the test read.
        """
        self._settle()
        deadline = self.time + timeout
        turn = self._steps(self._turn)
        while not predicate():
            left = self._steps(deadline - self.time)
            if left <= 0:
                raise SimTimeoutError(self._timeout_report(predicate, timeout))
            self._advance(min(turn, left))
            self._settle()

    def _steps(self, seconds: float) -> int:
        return max(0, round(seconds / self.time_step))

    def _timeout_report(self, predicate: Callable[[], object], timeout: float) -> str:
        name = getattr(predicate, '__name__', repr(predicate))
        lines = [f'{name} did not hold within {timeout:g} s of sim time '
                 f'(sim time now {self.time:.3f} s)']
        for topic, watched in sorted(self._watched.items()):
            latest = repr(watched.messages[-1]) if watched.messages else 'nothing received'
            if len(latest) > REPORTED_MESSAGE_CHARS:
                latest = latest[:REPORTED_MESSAGE_CHARS] + '...'
            lines.append(f'  {topic} ({len(watched.messages)} messages): {latest}')
        return '\n'.join(lines)

    # --- topics -----------------------------------------------------------------------------

    def publish(self, topic: str, message: Any, *, qos: Any = 10) -> None:
        """Publish ``message`` on ``topic`` once a subscription has matched, and deliver it.

        The first message is never lost to discovery: the publisher waits
        (bounded, DISCOVERY_BUDGET_S of wall time) until a subscription matched.
        """
        topic = absolute(topic)
        publisher = self._publishers.get(topic)
        if publisher is None:
            publisher = self._probe.create_publisher(type(message), topic, qos)
            self._publishers[topic] = publisher
            if not self._wait_wall(lambda: publisher.get_subscription_count() > 0):
                raise SimTimeoutError(f'nobody subscribes to {topic} (waited '
                                 f'{DISCOVERY_BUDGET_S:g} s of wall time for a subscription)')
        publisher.publish(message)
        self._settle()

    def messages(self, topic: str, message_type: type) -> list:
        """Every message on ``topic`` since the test first read it: a list that keeps growing."""
        return self._watch(absolute(topic), message_type).messages

    def latest(self, topic: str, message_type: type) -> Any:
        """Return the newest message on ``topic`` (None before the first); starts reading it."""
        received = self.messages(topic, message_type)
        return received[-1] if received else None

    def _watch(self, topic: str, message_type: type) -> _Watched:
        watched = self._watched.get(topic)
        if watched is not None:
            if watched.message_type is not message_type:
                raise TypeError(f'{topic} is read as {watched.message_type.__name__}, '
                                f'not {message_type.__name__}')
            return watched
        received: list = []
        publishers = self._publisher_endpoints(topic)
        subscription = self._probe.create_subscription(
            message_type, topic, received.append, reader_qos(publishers))
        watched = self._watched[topic] = _Watched(message_type, received, subscription)
        # A publisher there now is matched before the physics moves on, so nothing
        # it publishes from the next step on is missed.
        if publishers and not self._wait_wall(
                lambda: subscription.get_publisher_count() >= len(publishers)):
            raise SimTimeoutError(f'the subscription to {topic} did not match its publishers '
                             f'within {DISCOVERY_BUDGET_S:g} s of wall time')
        self._settle()
        return watched

    def _wait_wall(self, condition: Callable[[], bool],
                   budget_s: float = DISCOVERY_BUDGET_S) -> bool:
        """Spin (without stepping) until ``condition()``; False once ``budget_s`` wall s passed."""
        deadline = time.monotonic() + budget_s
        while not condition():
            if time.monotonic() > deadline:
                return False
            self.executor.spin_once(timeout_sec=DISCOVERY_POLL_S)
        return True

    # --- actions ----------------------------------------------------------------------------

    def follow_joint_trajectory(self, controller: str, points: Sequence[Any], *,
                                joint_names: Sequence[str] | None = None,
                                timeout: float | None = None) -> Any:
        """Run a trajectory on ``controller``'s follow_joint_trajectory action; return the result.

        ``points``: JointTrajectoryPoints or ``(seconds, positions)`` pairs;
        ``joint_names`` default to the controller's joints.  Waits in sim
        time (the last point's time plus GOAL_MARGIN_S unless ``timeout``).
        Returns control_msgs/action/FollowJointTrajectory's Result.
        """
        action = interface('control_msgs', 'action', 'FollowJointTrajectory',
                           'follow_joint_trajectory()')
        goal = action.Goal()
        goal.trajectory.joint_names = list(joint_names or self._controller_joints(controller))
        goal.trajectory.points = [trajectory_point(point) for point in points]
        if timeout is None:
            last = max((_seconds(p.time_from_start) for p in goal.trajectory.points), default=0)
            timeout = last + GOAL_MARGIN_S
        return self._run_goal(action, f'{absolute(controller)}/follow_joint_trajectory',
                              goal, timeout)

    def gripper(self, controller: str, position: float, max_effort: float, *,
                timeout: float = GOAL_MARGIN_S) -> Any:
        """Send a GripperCommand goal to ``controller``'s gripper_cmd action; return its result."""
        action = interface('control_msgs', 'action', 'GripperCommand', 'gripper()')
        goal = action.Goal()
        goal.command.position = float(position)
        goal.command.max_effort = float(max_effort)
        return self._run_goal(action, f'{absolute(controller)}/gripper_cmd', goal, timeout)

    def _controller_joints(self, controller: str) -> list[str]:
        raise NotImplementedError

    def _run_goal(self, action: type, name: str, goal: Any, timeout: float) -> Any:
        client = self._action_clients.get(name)
        if client is None:
            client = self._action_clients[name] = ActionClient(self._probe, action, name)
        if not self._wait_wall(client.server_is_ready):
            raise SimTimeoutError(f'no action server {name} (waited {DISCOVERY_BUDGET_S:g} s of '
                             'wall time)')
        sent = client.send_goal_async(goal)
        if not self._wait_wall(sent.done):
            raise SimTimeoutError(f'{name} did not answer the goal')
        handle = sent.result()
        if not handle.accepted:
            raise AssertionError(f'{name} rejected the goal')
        result = handle.get_result_async()
        self.run_until(result.done, timeout=timeout)
        return result.result().result

    # --- driving ----------------------------------------------------------------------------

    def drive(self, controller_or_topic: str, v: float, w: float, seconds: float) -> DriveResult:
        """Command ``v`` (m/s) and ``w`` (rad/s) for ``seconds`` of sim time, then a stop.

        ``controller_or_topic``: a drive controller's name (its ``cmd_vel``)
        or a Twist/TwistStamped topic.  The command is sent again every turn,
        as a teleop node would, so no command timeout stops the robot.
        Returns the true pose and the odometry (the ``odom`` topic beside the
        command topic) at the end, before the stop takes effect.
        """
        from nav_msgs.msg import Odometry

        topic, message_type = self._drive_topic(controller_or_topic)
        odometry_topic = topic.rsplit('/', 1)[0] + '/odom'
        odometry = self.messages(odometry_topic, Odometry)
        end = self.time + seconds
        turn = self._steps(self._turn)
        while True:
            self.publish(topic, self._twist(message_type, v, w))
            left = self._steps(end - self.time)
            if left <= 0:
                break
            self._advance(min(turn, left))
            self._settle()
        result = DriveResult(self.entity_pose(self.robot_name),
                             odometry[-1] if odometry else None)
        self.publish(topic, self._twist(message_type, 0.0, 0.0))
        return result

    def _twist(self, message_type: type, v: float, w: float) -> Any:
        message = message_type()
        twist = message.twist if hasattr(message, 'twist') else message
        if hasattr(message, 'header'):
            whole = math.floor(self.time)
            message.header.stamp.sec = int(whole)
            message.header.stamp.nanosec = round((self.time - whole) * 1e9)
        twist.linear.x = float(v)
        twist.angular.z = float(w)
        return message

    def _drive_topic(self, controller_or_topic: str) -> tuple[str, type]:
        raise NotImplementedError

    @property
    def robot_name(self) -> str:
        """The robot's entity name (its URDF's robot name)."""
        raise NotImplementedError

    def entity_pose(self, name: str) -> Any:
        """Return the pose of entity ``name`` in the world frame (geometry_msgs/msg/Pose)."""
        raise NotImplementedError

    # --- teardown ---------------------------------------------------------------------------

    def _destroy_nodes(self, nodes: Iterable[Node]) -> None:
        """Destroy ``nodes`` and their action clients (rclpy's destroy_node spares those).

        An action client left alive keeps its node's DDS participant, and its
        topics, in the graph until garbage collection: the next test would meet it.
        """
        for node in nodes:
            self.executor.remove_node(node)
            for waitable in list(node.waitables):
                if isinstance(waitable, ActionClient):
                    waitable.destroy()
            node.destroy_node()
