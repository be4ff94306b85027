"""What each URDF sensor costs per message, printed as one JSON object.

``python -m pan_tilt_sim.tools.sensor_cost`` runs sim_node in this process at
real_time_factor 0 with the pan/tilt of ``urdf/pan_tilt_sensors.xacro`` (a
320x240 depth camera, a 360-beam lidar, a 100 Hz IMU, a force-torque sensor),
subscribes to every sensor topic, lets ``--sim-seconds`` of sim time pass and
prints, per sensor, the wall microseconds sim_node spent per message --
measuring the world, building the messages and publishing them (the
publishers time themselves, see :mod:`pan_tilt_sim.ros.sensor_publishers`) --
and how many messages it published.  The benchmark (``bench``) prints the
same figures under ``sensor_us_per_message``.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import time
from collections.abc import Collection, Sequence

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile

from pan_tilt_sim.ros.sim_node import SimNode
from pan_tilt_sim.share import DEFAULT_CONTROLLERS, package_share

SENSOR_DESCRIPTION = pathlib.Path('urdf', 'pan_tilt_sensors.xacro')
MICROSECONDS_PER_SECOND = 1e6
SPIN_TIMEOUT_S = 0.01
DISCOVERY_TIMEOUT_S = 20.0
RUN_TIMEOUT_S = 120.0
QUEUE_DEPTH = 1  # the probe keeps only the latest message: it measures the sender


class SensorCostError(RuntimeError):
    """The measurement could not run (no subscriber matched, sim time stood still...)."""


def sensor_costs(description_file: pathlib.Path | None = None,
                 controllers_file: pathlib.Path | str | None = None, sim_seconds: float = 1.0,
                 domain_id: int | None = None, parameters: dict[str, object] | None = None,
                 watch: Collection[str] | None = None) -> dict[str, dict[str, float]]:
    """Return ``{sensor: {'us_per_message': ..., 'messages': ...}}`` with every topic watched.

    ``parameters``: further sim_node parameters (a world, an initial pose, a
    time step), name -> value.  ``controllers_file`` ``''``: the robot has none.
    ``watch``: the topics to subscribe to (default: every sensor topic).
    """
    share = package_share()
    description = description_file or share / SENSOR_DESCRIPTION
    controllers = share / DEFAULT_CONTROLLERS if controllers_file is None else controllers_file
    context = Context()
    rclpy.init(args=[], context=context, domain_id=domain_id)
    executor = SingleThreadedExecutor(context=context)
    node = probe = None
    try:
        node = SimNode(context=context, parameter_overrides=[
            Parameter('robot_description_file', value=str(description)),
            Parameter('controllers_file', value=str(controllers)),
            Parameter('real_time_factor', value=0.0),
            Parameter('sensors.noise_seed', value=0),
            *(Parameter(name, value=value) for name, value in (parameters or {}).items())])
        probe = rclpy.create_node('sensor_cost_probe', context=context)
        executor.add_node(node)
        executor.add_node(probe)
        publishers = node.features.sensors.publishers
        topics = []
        for publisher in publishers:
            for topic, message_type in publisher.topic_types():
                if watch is not None and topic not in watch:
                    continue
                probe.create_subscription(message_type, topic, lambda _message: None,
                                          QoSProfile(depth=QUEUE_DEPTH))
                topics.append(topic)
        _spin_until(executor, lambda: all(node.count_subscribers(topic) > 0 for topic in topics),
                    DISCOVERY_TIMEOUT_S, 'the probe never matched every sensor topic')
        for publisher in publishers:
            publisher.cost_s, publisher.messages = 0.0, 0
        target = node.simulation.time + sim_seconds
        _spin_until(executor, lambda: node.simulation.time >= target, RUN_TIMEOUT_S,
                    f'sim time did not reach {target} s')
        return {publisher.sensor.name: {
            'us_per_message': publisher.cost_per_message * MICROSECONDS_PER_SECOND,
            'messages': publisher.messages} for publisher in publishers}
    finally:
        executor.shutdown()
        for created in (probe, node):
            if created is not None:
                created.destroy_node()
        rclpy.try_shutdown(context=context)


def _spin_until(executor: SingleThreadedExecutor, condition, budget_s: float,
                failure: str) -> None:
    deadline = time.monotonic() + budget_s
    while not condition():
        if time.monotonic() > deadline:
            raise SensorCostError(failure)
        executor.spin_once(timeout_sec=SPIN_TIMEOUT_S)


def main(argv: Sequence[str] | None = None) -> None:
    """Measure and print the per-sensor cost as JSON."""
    parser = argparse.ArgumentParser(prog='sensor_cost', description=__doc__.splitlines()[0])
    parser.add_argument('--sim-seconds', type=float, default=2.0,
                        help='sim time to run with every topic watched (default 2)')
    parser.add_argument('--description', type=pathlib.Path, default=None,
                        help='robot description (default: urdf/pan_tilt_sensors.xacro)')
    parser.add_argument('--controllers', type=pathlib.Path, default=None,
                        help='controllers YAML (default: the pan/tilt controllers)')
    args = parser.parse_args(argv)
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    costs = sensor_costs(args.description, args.controllers, args.sim_seconds)
    print(json.dumps({name: {'us_per_message': round(figures['us_per_message']),
                             'messages': figures['messages']}
                      for name, figures in costs.items()}), flush=True)


if __name__ == '__main__':
    main()
