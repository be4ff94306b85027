#!/usr/bin/env python3
"""Measure what the camera costs: per-frame render time, physics steps/s, rtf error, CPU.

Run from a checkout (ROS domain and discovery range from the environment)::

    ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST PYTHONPATH=. python scripts/camera_benchmark.py

Prints one JSON object.  ``node_rtf1_*`` run sim_node in this process at
real_time_factor 1 for ``--seconds`` of wall time, camera off and on, and
report sim/wall - 1 (rtf error) and the process's CPU share (user + system
time over wall time, 100 % = one core); ``node_rtf0_*`` run at
real_time_factor 0 for half that and report the real-time factor achieved.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import time

from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.sim.camera import CameraSettings, Renderer
from pan_tilt_sim.sim.engine import make_simulation

FRAMES = 50
ENGINE_STEPS = 50_000
DISCOVERY_TIMEOUT_S = 5.0
TIME_STEP = 0.001


def frame_cost_ms(description, frames: int) -> dict[str, float]:
    """Render ``frames`` frames at changing poses; return median and max ms per frame."""
    renderer = Renderer(description, CameraSettings())
    try:
        costs = []
        for index in range(frames):
            pan = math.sin(index * 0.1)
            start = time.perf_counter()
            renderer.render([pan, -math.pi / 2])
            costs.append((time.perf_counter() - start) * 1000.0)
    finally:
        renderer.close()
    return {'median_ms': round(statistics.median(costs), 2), 'max_ms': round(max(costs), 2)}


def engine_steps_per_second(share, with_renderer: bool) -> float:
    """Return engine steps/s, with a camera scene (robot copy + world) alive or not."""
    simulation = make_simulation(share / DEFAULT_DESCRIPTION, share / DEFAULT_CONTROLLERS,
                                 TIME_STEP)
    renderer = Renderer(simulation.description, CameraSettings()) if with_renderer else None
    try:
        simulation.advance(1000)  # warm up
        start = time.perf_counter()
        simulation.advance(ENGINE_STEPS)
        return ENGINE_STEPS / (time.perf_counter() - start)
    finally:
        if renderer is not None:
            renderer.close()
        simulation.close()


def node_run(camera: bool, seconds: float, factor: float = 1.0,
             watched: bool = True) -> dict[str, float]:
    """Run sim_node at ``factor``; return rtf error (or achieved rtf), CPU share, frames.

    With ``watched``, a second node in the process subscribes to the image
    (its callback only counts), so the camera renders.
    """
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from sensor_msgs.msg import Image

    from pan_tilt_sim.ros.sim_node import SimNode

    rclpy.init()
    node = SimNode(parameter_overrides=[Parameter('camera.enabled', value=camera),
                                        Parameter('real_time_factor', value=factor)])
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    viewer = rclpy.create_node('camera_benchmark_viewer')
    received = []
    if watched:
        viewer.create_subscription(Image, node.topic('camera', 'image_raw'),
                                   lambda message: received.append(None), 1)
        executor.add_node(viewer)
    try:
        deadline = time.monotonic() + DISCOVERY_TIMEOUT_S
        while watched and camera and time.monotonic() < deadline and (
                node.count_subscribers(node.topic('camera', 'image_raw')) == 0):
            executor.spin_once(timeout_sec=0.01)
        executor.spin_once(timeout_sec=0.1)  # first tick starts the pacer
        sim_start = node.simulation.time
        cpu_start = os.times()
        wall_start = time.monotonic()
        while time.monotonic() - wall_start < seconds:
            executor.spin_once(timeout_sec=0.1)
        wall = time.monotonic() - wall_start
        cpu_end = os.times()
        sim = node.simulation.time - sim_start
        cpu = (cpu_end.user - cpu_start.user) + (cpu_end.system - cpu_start.system)
        frames = node.features.camera.frames if node.features.camera else 0
    finally:
        executor.shutdown()
        viewer.destroy_node()
        node.destroy_node()
        rclpy.try_shutdown()
    result = {'cpu_percent': round(cpu / wall * 100.0, 1), 'frames': frames,
              'sim_s': round(sim, 3), 'wall_s': round(wall, 3)}
    if factor == 0.0:
        result['achieved_rtf'] = round(sim / wall, 1)
    else:
        result['rtf_error_percent'] = round((sim / wall / factor - 1.0) * 100.0, 3)
    return result


def main() -> None:
    """Run every measurement and print them as JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=10.0,
                        help='wall seconds per node run (default 10)')
    args = parser.parse_args()
    share = package_share()
    from pan_tilt_sim.model.description import load_description

    description = load_description(share / DEFAULT_DESCRIPTION)
    result = {
        'frame_320x240': frame_cost_ms(description, FRAMES),
        'engine_steps_per_s': {
            'no_camera_scene': round(engine_steps_per_second(share, False)),
            'camera_scene_alive': round(engine_steps_per_second(share, True)),
        },
        'node_rtf1_camera_off': node_run(False, args.seconds),
        'node_rtf1_camera_on': node_run(True, args.seconds),
        'node_rtf0_camera_off': node_run(False, args.seconds / 2, 0.0),
        'node_rtf0_camera_on_watched': node_run(True, args.seconds / 2, 0.0),
        'node_rtf0_camera_on_unwatched': node_run(True, args.seconds / 2, 0.0, watched=False),
    }
    print(json.dumps(result, indent=2))


if __name__ == '__main__':
    main()
