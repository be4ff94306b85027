"""sim_node as a program beside the test, stepped over DDS: the plugin's ``sim_process`` handle.

:class:`SimProcessHandle` starts ``python -m pan_tilt_sim`` paused at
real_time_factor 0 (as ``ros2 run pan_tilt_sim sim_node`` would run) and
gives the test the helpers of the in-process handle, through ROS only:
stepping and the world through the simulation_interfaces services
(``/sim_node/step_simulation``, ``get_entity_state``, ...), sim time from
/clock, joint positions from the robot's JointStates.  The process runs in
the test's ROS domain; it is interrupted (SIGINT), and killed if it does
not end, when the handle closes.

It holds nothing of pytest's or of launch's, so it also serves a test that
brings its other nodes up with launch_pytest: make the handle in a fixture
beside launch_pytest's and close it there.  Unlike the in-process handle,
what crosses DDS between two processes is not bit-for-bit repeatable.
"""

from __future__ import annotations

import importlib
import os
import signal
import subprocess
import sys
import tempfile
from collections.abc import Mapping
from typing import Any

from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState

from pan_tilt_sim.model.transforms import quaternion_from_rpy
from pan_tilt_sim.tools.sim_helpers import (
    DEFAULT_TURN_S,
    SimHelpers,
    SimTimeoutError,
    absolute,
    interface,
)

NODE = '/sim_node'
PROBE_NAME = 'sim_process_probe'
# Wall seconds for the program to start and be found over DDS (discovery can take
# a Fast DDS announcement period of 3 s, see docs/testing.md), and to answer.
START_BUDGET_S = 60.0
CALL_BUDGET_S = 30.0
STOP_BUDGET_S = 10.0
ROBOT_CATEGORY = 1  # simulation_interfaces/msg/EntityCategory.ROBOT


def parameter_argument(name: str, value: Any) -> str:
    """``name:=value`` as ``--ros-args -p`` takes it (YAML: bools lower case, lists in [])."""
    if isinstance(value, bool):
        text = 'true' if value else 'false'
    elif isinstance(value, (list, tuple)):
        text = '[' + ', '.join(parameter_argument('', item)[2:] for item in value) + ']'
    elif isinstance(value, str) and (value == '' or value.strip() != value):
        text = f"'{value}'"
    else:
        text = str(value)
    return f'{name}:={text}'


class SimProcessHandle(SimHelpers):
    """sim_node in a child process, paused; the test steps it with step_simulation."""

    def __init__(self, context: Context, parameters: Mapping[str, Any], *,
                 namespace: str | None = None, turn: float = DEFAULT_TURN_S) -> None:
        self._srv = interface('simulation_interfaces', 'srv', 'StepSimulation',
                              'the sim_process fixture')
        self._services = importlib.import_module('simulation_interfaces.srv')
        self.context = context
        executor = SingleThreadedExecutor(context=context)
        probe = Node(PROBE_NAME, context=context)
        executor.add_node(probe)
        ros_args = [item for name, value in parameters.items()
                    for item in ('-p', parameter_argument(name, value))]
        if namespace:
            ros_args += ['-r', f'__ns:={absolute(namespace)}']
        # A file, not a pipe: a pipe nobody reads would block the program once full.
        self._log = tempfile.TemporaryFile()
        self._prefix = (absolute(namespace).rstrip('/') if namespace else '') + NODE
        self.process = subprocess.Popen(
            [sys.executable, '-m', 'pan_tilt_sim', '--ros-args', *ros_args],
            env=dict(os.environ), stdout=self._log, stderr=subprocess.STDOUT)
        super().__init__(None, executor, probe, turn)
        self._clients: dict[str, Any] = {}
        self._time_step = float(parameters.get('time_step', 0.001))
        try:
            self._clock = self.messages('/clock', Clock)
            self._service('step_simulation', START_BUDGET_S)
        except BaseException:
            self.close()
            raise

    # --- primitives -------------------------------------------------------------------------

    @property
    def time(self) -> float:
        """Sim time, in seconds: the newest /clock."""
        if not self._clock:
            return 0.0
        clock = self._clock[-1].clock
        return clock.sec + clock.nanosec * 1e-9

    @property
    def time_step(self) -> float:
        """Seconds of sim time per physics step."""
        return self._time_step

    def _advance(self, steps: int) -> None:
        target = self.time + steps * self._time_step
        request = self._services.StepSimulation.Request(steps=steps)
        response = self._call('step_simulation', request)
        if response.result.result != 1:  # simulation_interfaces/msg/Result.RESULT_OK
            raise RuntimeError(f'step_simulation: {response.result.error_message}')
        # The steps' /clock reaches this process before the turn ends.
        if not self._wait_wall(lambda: self.time >= target - self._time_step / 2):
            raise SimTimeoutError(f'/clock stayed at {self.time:.3f} s after stepping to '
                             f'{target:.3f} s')

    def _service(self, name: str, budget_s: float = CALL_BUDGET_S) -> Any:
        client = self._clients.get(name)
        if client is None:
            kind = ''.join(part.title() for part in name.split('_'))
            client = self._probe.create_client(getattr(self._services, kind),
                                               f'{self._prefix}/{name}')
            self._clients[name] = client
        if not self._wait_wall(client.service_is_ready, budget_s):
            raise SimTimeoutError(f'no service {self._prefix}/{name} after {budget_s:g} s of wall '
                             f'time; sim_node said:\n{self._output()}')
        return client

    def _call(self, name: str, request: Any) -> Any:
        future = self._service(name).call_async(request)
        if not self._wait_wall(future.done, CALL_BUDGET_S):
            raise SimTimeoutError(f'{self._prefix}/{name} did not answer within '
                             f'{CALL_BUDGET_S:g} s of wall time')
        return future.result()

    def _output(self) -> str:
        self._log.seek(0)
        return self._log.read().decode(errors='replace')

    # --- the robot and the world ------------------------------------------------------------

    def joint_positions(self) -> dict[str, float]:
        """Return the newest JointState's positions, by joint name (steps until one has come)."""
        states = self.messages(self._joint_states_topic(), JointState)
        if not states:
            self.run_until(lambda: states, timeout=1.0)
        return dict(zip(states[-1].name, states[-1].position, strict=False))

    def _joint_states_topic(self) -> str:
        for topic, types in self._probe.get_topic_names_and_types():
            if 'sensor_msgs/msg/JointState' in types and topic.endswith('/joint_states'):
                return topic
        raise SimTimeoutError('no joint_states topic in the ROS graph')

    def entity_pose(self, name: str) -> Any:
        """Return the pose of entity ``name`` in the world frame (get_entity_state)."""
        response = self._call('get_entity_state',
                              self._services.GetEntityState.Request(entity=name))
        if response.result.result != 1:
            raise KeyError(f'{name}: {response.result.error_message}')
        return response.state.pose

    @property
    def robot_name(self) -> str:
        """The robot's entity name (get_entities, then the one of category ROBOT)."""
        names = self._call('get_entities', self._services.GetEntities.Request()).entities
        for name in names:
            info = self._call('get_entity_info',
                              self._services.GetEntityInfo.Request(entity=name)).info
            if info.category.category == ROBOT_CATEGORY:
                return name
        raise KeyError('no entity of category ROBOT')

    def spawn(self, uri: str = '', *, name: str = '', resource_string: str = '',
              position: tuple[float, float, float] = (0.0, 0.0, 0.0),
              rpy: tuple[float, float, float] = (0.0, 0.0, 0.0), frame: str = '',
              allow_renaming: bool = False) -> str:
        """Put a URDF object into the world (spawn_entity); return its name.

        ``position`` (m) and ``rpy`` (rad) are in ``frame``, as for the in-process handle.
        """
        request = self._services.SpawnEntity.Request(
            name=name, allow_renaming=allow_renaming, uri=uri, resource_string=resource_string)
        (request.initial_pose.pose.position.x, request.initial_pose.pose.position.y,
         request.initial_pose.pose.position.z) = (float(c) for c in position)
        orientation = request.initial_pose.pose.orientation
        orientation.x, orientation.y, orientation.z, orientation.w = quaternion_from_rpy(*rpy)
        request.initial_pose.header.frame_id = frame
        response = self._call('spawn_entity', request)
        if response.result.result != 1:
            raise RuntimeError(f'spawn_entity: {response.result.error_message}')
        return response.entity_name

    def reset(self) -> None:
        """Put the world back as it started (reset_simulation, scope ALL)."""
        response = self._call('reset_simulation', self._services.ResetSimulation.Request())
        if response.result.result != 1:
            raise RuntimeError(f'reset_simulation: {response.result.error_message}')
        self._clock.clear()

    def _controller_joints(self, controller: str) -> list[str]:
        state_type = interface('control_msgs', 'msg', 'JointTrajectoryControllerState',
                               'follow_joint_trajectory()')
        states = self.messages(f'{absolute(controller)}/controller_state', state_type)
        self.run_until(lambda: states, timeout=1.0)
        return list(states[-1].joint_names)

    def _drive_topic(self, controller_or_topic: str) -> tuple[str, type]:
        graph = dict(self._probe.get_topic_names_and_types())
        for topic in (f'{absolute(controller_or_topic)}/cmd_vel', absolute(controller_or_topic)):
            if topic in graph and self._probe.get_subscriptions_info_by_topic(topic):
                package, kind, name = graph[topic][0].split('/')
                return topic, getattr(importlib.import_module(f'{package}.{kind}'), name)
        raise ValueError(f"'{controller_or_topic}' is neither a drive controller nor a topic "
                         'sim_node reads')

    # --- teardown ---------------------------------------------------------------------------

    def close(self) -> None:
        """Destroy the test's nodes and the probe, then stop the program (SIGINT, then kill)."""
        try:
            for client in self._action_clients.values():
                client.destroy()
            self._destroy_nodes(reversed(self._nodes))
            self._destroy_nodes([self._probe])
            self.executor.shutdown()
        finally:
            if self.process.poll() is None:
                self.process.send_signal(signal.SIGINT)
                try:
                    self.process.communicate(timeout=STOP_BUDGET_S)
                except subprocess.TimeoutExpired:
                    self.process.kill()
                    self.process.communicate()
            self._log.close()
