"""A paused SimNode in the test's own process, stepped by the test: the plugin's ``sim`` handle.

:class:`SimHandle` runs sim_node (real_time_factor 0, paused) on a
SingleThreadedExecutor with a probe node and the test's own nodes, and
steps it itself: each turn runs a few physics steps, then every callback
that became ready, so the test's nodes see every message in order and
their answers reach the simulation before it moves on.  Helpers come from
:class:`~pan_tilt_sim.tools.sim_helpers.SimHelpers`.
"""

from __future__ import annotations

import pathlib
from collections.abc import Mapping
from typing import Any

from geometry_msgs.msg import Pose
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter

from pan_tilt_sim.model.resources import resolve_resource
from pan_tilt_sim.model.transforms import Transform, quaternion_from_rpy
from pan_tilt_sim.ros.sim_node import SimNode
from pan_tilt_sim.tools.sim_helpers import DEFAULT_TURN_S, SimHelpers, absolute

PROBE_NAME = 'sim_test_probe'


def resolve_file(path_or_uri: str | pathlib.Path) -> str:
    """Return a path, ``file://`` or ``package://`` URI as an absolute file path."""
    return str(resolve_resource(str(path_or_uri), pathlib.Path.cwd()))


def sim_parameters(robot: str | pathlib.Path | None = None,
                   controllers: str | pathlib.Path | None = None,
                   world: str | pathlib.Path | None = None,
                   parameters: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """sim_node's parameters for a test: paused at real_time_factor 0, plus ``parameters``.

    ``robot`` and ``controllers`` are paths or URIs (resolved here),
    ``world`` a scenery name, path or URI (sim_node resolves it).
    """
    values: dict[str, Any] = {'real_time_factor': 0.0}
    if robot is not None:
        values['robot_description_file'] = resolve_file(robot)
    if controllers is not None:
        values['controllers_file'] = resolve_file(controllers)
    if world is not None:
        values['world'] = str(world)
    values.update(parameters or {})
    values['paused'] = True  # the test steps it
    return values


class SimHandle(SimHelpers):
    """A running, paused sim_node in this process; the test advances it in sim time.

    ``context`` is an initialised rclpy Context the handle uses (and does not
    shut down); :meth:`close` destroys every node it spins.
    """

    def __init__(self, context: Context, parameters: Mapping[str, Any], *,
                 namespace: str | None = None, turn: float = DEFAULT_TURN_S) -> None:
        self.context = context
        executor = SingleThreadedExecutor(context=context)
        probe = Node(PROBE_NAME, context=context)
        executor.add_node(probe)
        try:
            node = SimNode(context=context, namespace=namespace,
                           parameter_overrides=[Parameter(name, value=value)
                                                for name, value in parameters.items()])
        except BaseException:
            probe.destroy_node()
            executor.shutdown()
            raise
        super().__init__(node, executor, probe, turn)
        for each in (node, *node.companion_nodes):
            executor.add_node(each)
        self._closed = False
        self._settle()

    @property
    def simulation(self):
        """The node's Simulation (the physics and the controllers, without ROS)."""
        return self.node.simulation

    @property
    def time(self) -> float:
        """Sim time, in seconds."""
        return self.node.simulation.time

    @property
    def time_step(self) -> float:
        """Seconds of sim time per physics step."""
        return self.node.simulation.time_step

    @property
    def robot_name(self) -> str:
        """The robot's entity name (its URDF's robot name)."""
        return self.node.features.entities.robot_name

    def _advance(self, steps: int) -> None:
        self.node.step(steps)

    # --- the robot and the world ------------------------------------------------------------

    def joint_positions(self) -> dict[str, float]:
        """Return the measured position of every movable joint of the robot, by name (rad or m)."""
        return dict(self.node.simulation.joint_positions())

    def entity_pose(self, name: str) -> Pose:
        """Return the pose of entity ``name`` (robot, world-file object, ...) in the world."""
        state = self.node.features.entities.state(name)
        pose = Pose()
        pose.position.x, pose.position.y, pose.position.z = (float(c) for c in
                                                             state.pose.translation)
        (pose.orientation.x, pose.orientation.y, pose.orientation.z,
         pose.orientation.w) = (float(c) for c in state.pose.rotation)
        return pose

    def spawn(self, uri: str = '', *, name: str = '', resource_string: str = '',
              position: tuple[float, float, float] = (0.0, 0.0, 0.0),
              rpy: tuple[float, float, float] = (0.0, 0.0, 0.0), frame: str = '',
              allow_renaming: bool = False) -> str:
        """Put a URDF object (``uri``: path or URI, or ``resource_string``) into the world.

        ``position`` (m) and ``rpy`` (rad) are in ``frame`` ('' or 'world', an
        entity's name or a link of the robot).  Returns the entity's name.
        Raises SpawnError when the request cannot be honoured.
        """
        if uri and '://' not in uri:
            uri = resolve_file(uri)
        name = self.node.features.entities.spawn(
            name, uri=uri, resource_string=resource_string,
            pose=Transform(tuple(float(c) for c in position), quaternion_from_rpy(*rpy)),
            frame=frame, allow_renaming=allow_renaming)
        self._settle()
        return name

    def reset(self) -> None:
        """Put the world back as it started: sim time 0, spawned objects gone, all at rest."""
        self.node.features.entities.restore()
        self.node.reset(reset_time=True, reset_state=True)
        self._settle()

    def _controller_joints(self, controller: str) -> list[str]:
        return list(self.node.simulation.controller(controller.strip('/')).joint_names)

    def _drive_topic(self, controller_or_topic: str) -> tuple[str, type]:
        name = controller_or_topic.strip('/')
        if name in {c.name for c in self.node.simulation.controllers}:
            found = self.node.simulation.controller(name)
            topic = self.node.topic(name, found.command_topic)
        else:
            topic = absolute(controller_or_topic)
        for node in (self.node, *self.node.companion_nodes):
            for subscription in node.subscriptions:
                if subscription.topic_name == topic:
                    return topic, subscription.msg_type
        raise ValueError(f"'{controller_or_topic}' is neither a drive controller nor a topic "
                         f'the simulation reads (looked for {topic})')

    # --- teardown ---------------------------------------------------------------------------

    def close(self) -> None:
        """Destroy the test's nodes, the probe and sim_node (action clients first); idempotent."""
        if self._closed:
            return
        self._closed = True
        try:
            for client in self._action_clients.values():
                client.destroy()
            self._destroy_nodes(reversed(self._nodes))
            self._destroy_nodes([self._probe])
            for each in self.node.companion_nodes:
                self.executor.remove_node(each)
            self.executor.remove_node(self.node)
            self.node.destroy_node()
        finally:
            self.executor.shutdown()
