#!/usr/bin/env python3
"""Spawn an object into a running sim_node, step it and print where it lands: simulation_interfaces.

    python examples/spawn_and_step.py                  # the shipped box, 1.2 m ahead of the camera
    python examples/spawn_and_step.py --uri package://pan_tilt_sim/urdf/objects/cylinder.urdf \
        --name can --x -1.0 --y 0.3 --z 0.5 --steps 1500

does what ``ros2 service call /sim_node/spawn_entity simulation_interfaces/srv/SpawnEntity ...``
then ``/sim_node/step_simulation`` and ``/sim_node/get_entity_state`` do, for machines where
only the rclpy wheels (and the venv's simulation_interfaces) are installed.  sim_node must be
paused to step (start it with ``-p paused:=true``, or the example pauses it first with
``set_simulation_state``).  Exit code 0 when every call succeeded.
"""

import argparse
import os
import sys
import time

import rclpy
from rclpy.node import Node
from simulation_interfaces.msg import Result, SimulationState
from simulation_interfaces.srv import (
    GetEntityState,
    GetSimulationState,
    SetSimulationState,
    SpawnEntity,
    StepSimulation,
)

BOX = 'package://pan_tilt_sim/urdf/objects/box.urdf'
STATE_NAMES = {0: 'STOPPED', 1: 'PLAYING', 2: 'PAUSED', 3: 'QUITTING'}


def call(node: Node, kind, name: str, request, timeout: float):
    """Call a service once it is there; return the response (None on timeout)."""
    client = node.create_client(kind, name)
    deadline = time.monotonic() + timeout
    while not client.service_is_ready():
        if time.monotonic() > deadline:
            return None
        rclpy.spin_once(node, timeout_sec=0.1)
    future = client.call_async(request)
    while not future.done():
        if time.monotonic() > deadline:
            return None
        rclpy.spin_once(node, timeout_sec=0.1)
    return future.result()


def main(argv: list[str] | None = None) -> int:
    """Spawn, step, print the object's pose; 0 on success, 1 on a refusal or timeout."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--uri', default=BOX, help=f'a URDF to spawn (default {BOX})')
    parser.add_argument('--name', default='box')
    parser.add_argument('--x', type=float, default=-1.2)
    parser.add_argument('--y', type=float, default=0.0)
    parser.add_argument('--z', type=float, default=0.3)
    parser.add_argument('--steps', type=int, default=1000, help='physics steps to run')
    parser.add_argument('--services', default='/sim_node',
                        help="where the services are (default /sim_node; '' for Isaac's root)")
    parser.add_argument('--timeout', type=float, default=30.0, help='wall seconds per call')
    args = parser.parse_args(argv)
    prefix = args.services.rstrip('/')

    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    rclpy.init()
    node = Node('spawn_and_step')
    try:
        state = call(node, GetSimulationState, f'{prefix}/get_simulation_state',
                     GetSimulationState.Request(), args.timeout)
        if state is None:
            print(f'no {prefix}/get_simulation_state: is sim_node running?', file=sys.stderr)
            return 1
        print(f'simulation {STATE_NAMES.get(state.state.state, state.state.state)}')
        if state.state.state == SimulationState.STATE_PLAYING:
            paused = call(node, SetSimulationState, f'{prefix}/set_simulation_state',
                          SetSimulationState.Request(
                              state=SimulationState(state=SimulationState.STATE_PAUSED)),
                          args.timeout)
            print(f'paused: {paused.result.error_message or "ok"}')
        request = SpawnEntity.Request(name=args.name, uri=args.uri, allow_renaming=True)
        position = request.initial_pose.pose.position
        position.x, position.y, position.z = args.x, args.y, args.z
        spawned = call(node, SpawnEntity, f'{prefix}/spawn_entity', request, args.timeout)
        if spawned is None or spawned.result.result != Result.RESULT_OK:
            print(f'spawn refused: {spawned and spawned.result.error_message}', file=sys.stderr)
            return 1
        print(f"spawned '{spawned.entity_name}' at ({args.x}, {args.y}, {args.z})")
        stepped = call(node, StepSimulation, f'{prefix}/step_simulation',
                       StepSimulation.Request(steps=args.steps), args.timeout)
        if stepped is None or stepped.result.result != Result.RESULT_OK:
            print(f'step refused: {stepped and stepped.result.error_message}', file=sys.stderr)
            return 1
        got = call(node, GetEntityState, f'{prefix}/get_entity_state',
                   GetEntityState.Request(entity=spawned.entity_name), args.timeout)
        if got is None or got.result.result != Result.RESULT_OK:
            print(f'no state: {got and got.result.error_message}', file=sys.stderr)
            return 1
        p, stamp = got.state.pose.position, got.state.header.stamp
        print(f"after {args.steps} steps (sim time {stamp.sec + stamp.nanosec * 1e-9:.3f} s): "
              f"'{spawned.entity_name}' at ({p.x:.3f}, {p.y:.3f}, {p.z:.3f})")
        return 0
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    sys.exit(main())
