"""The Gazebo-side stand-ins' tests: a world-only sim_node in-process, the programs as processes.

* :func:`world_only` -- a SimNode as gz_sim.launch.py starts it (``robot_from_spawn``,
  no controller active until spawned), real_time_factor 0, on a harness;
* :func:`spawn` -- one SpawnEntity call (never resent: a second call is a second spawn);
* :func:`two_rovers` -- robot1 (the world's first robot) and robot2, each a driven rover;
* :func:`start` / :func:`finish` -- a stand-in program (``python -m
  pan_tilt_sim.tools.stand_ins NAME``) and its end, the harness spun meanwhile.
"""

from __future__ import annotations

import contextlib
import math
import subprocess
import sys
from collections.abc import Iterator

import sim_process
from node_harness import NodeHarness
from rclpy.parameter import Parameter

from pan_tilt_sim.ros.sim_node import SimNode

SERVICE = '/sim_node/spawn_entity'
BUILD_BUDGET_S = 30.0
EXIT_BUDGET_S = 60.0


def srv():
    """simulation_interfaces' services."""
    from simulation_interfaces import srv as module

    return module


@contextlib.contextmanager
def world_only(namespace: str = '', **parameters) -> Iterator[tuple[NodeHarness, SimNode]]:
    """A SimNode as gz_sim.launch.py starts it, on a harness (real_time_factor 0 unless given).

    ``namespace``: the node's (its services are ``<namespace>/sim_node/...``).
    """
    parameters.setdefault('real_time_factor', 0.0)
    parameters.setdefault('autostart_controllers', False)  # the spawners activate them
    parameters['robot_from_spawn'] = True
    harness = NodeHarness()
    try:
        overrides = [Parameter(name, value=value) for name, value in parameters.items()]
        node = harness.add(SimNode(context=harness.context, namespace=namespace,
                                   parameter_overrides=overrides))
        yield harness, node
    finally:
        harness.close()


def spawn(harness: NodeHarness, *, name: str = '', resource_string: str = '', uri: str = '',
          allow_renaming: bool = False, frame: str = '', x: float = 0.0, y: float = 0.0,
          yaw: float = 0.0, namespace: str = ''):
    """Call SpawnEntity once; return its response."""
    request = srv().SpawnEntity.Request(name=name, resource_string=resource_string, uri=uri,
                                        allow_renaming=allow_renaming,
                                        entity_namespace=namespace)
    request.initial_pose.header.frame_id = frame
    request.initial_pose.pose.position.x, request.initial_pose.pose.position.y = x, y
    request.initial_pose.pose.orientation.z = math.sin(yaw / 2)
    request.initial_pose.pose.orientation.w = math.cos(yaw / 2)
    client = harness.probe.create_client(srv().SpawnEntity, SERVICE)
    try:
        assert harness.spin_until(client.service_is_ready), f'no {SERVICE}'
        future = client.call_async(request)
        assert harness.spin_until(future.done, BUILD_BUDGET_S), f'{SERVICE} did not answer'
        return future.result()
    finally:
        harness.probe.destroy_client(client)


def two_rovers(harness: NodeHarness) -> None:
    """Spawn rovers robot1 (the world's first robot, at y = 0) and robot2 (at y = 1)."""
    from mobile_fixtures import ROS2_DIFF_DRIVE, rover_urdf

    rover = rover_urdf('rover', ros2_control=False, extra=f'<gazebo>{ROS2_DIFF_DRIVE}</gazebo>')
    for name, y in (('robot1', 0.0), ('robot2', 1.0)):
        response = spawn(harness, name=name, resource_string=rover, namespace=name, y=y)
        assert response.result.result == 1, response.result.error_message


def start(name: str, *arguments: str) -> subprocess.Popen:
    """Start the stand-in ``name`` with ``arguments``; its stdout and stderr together."""
    return subprocess.Popen(
        [sys.executable, '-m', 'pan_tilt_sim.tools.stand_ins', name, *arguments],
        env=sim_process.environment(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
        text=True)


def finish(harness: NodeHarness | None, process: subprocess.Popen) -> tuple[int, str]:
    """Spin the harness until the program ends (bounded); return its exit code and output."""
    if harness is not None:
        assert harness.spin_until(lambda: process.poll() is not None, EXIT_BUDGET_S), (
            'the program did not end')
    output = process.communicate(timeout=EXIT_BUDGET_S)[0]
    return process.returncode, output
