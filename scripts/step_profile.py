#!/usr/bin/env python3
"""Where one physics step's time goes: PyBullet, controllers, ROS, executor.

Runs everything in this process and times it with this thread's CPU clock
(so other processes on a busy machine distort it less than wall time), in
microseconds per physics step:

* PyBullet alone: ``stepSimulation``, then with ``getJointStates`` and
  ``setJointMotorControlArray`` as the engine calls them;
* the engine (``Simulation.advance``: PyBullet + controllers, no ROS);
* sim_node at real_time_factor 0 on an executor, split into the engine,
  /clock and JointState publishing, and the rest (executor, pacing).
  Nobody subscribes here, so nothing is published (0.00): ``bench`` measures
  the node with a /clock or JointState subscriber in another process.

Usage: ``python scripts/step_profile.py [--seconds S]``
(sets ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST; use your own ROS_DOMAIN_ID).
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

MICROSECONDS = 1e6
ENGINE_STEPS = 20000
WARMUP_STEPS = 2000
TIME_STEP = 0.001
PAN_TARGET = 1.0
TILT_TARGET = -3.0


def per_step_us(run: Callable[[int], None], steps: int) -> float:
    """Return this thread's CPU microseconds per step of ``run(steps)``."""
    run(WARMUP_STEPS)
    started = time.thread_time()
    run(steps)
    return (time.thread_time() - started) / steps * MICROSECONDS


def pybullet_figures(simulation) -> dict[str, float]:
    """Time the PyBullet calls alone on the simulation's own client."""
    from pan_tilt_sim.sim.bullet import pybullet

    client = simulation.physics.client_id
    stepper = simulation.physics.stepper()
    efforts = [0.0] * len(simulation.handles)

    def raw(steps: int) -> None:
        for _ in range(steps):
            pybullet.stepSimulation(client)

    def calls(steps: int) -> None:
        for _ in range(steps):
            stepper(efforts)

    return {'stepSimulation alone': per_step_us(raw, ENGINE_STEPS),
            '+ getJointStates + setJointMotorControlArray': per_step_us(calls, ENGINE_STEPS)}


def node_figures(seconds: float) -> dict[str, float]:
    """Run sim_node at factor 0 on an executor; split its CPU time per step."""
    import rclpy
    from rclpy.parameter import Parameter

    from pan_tilt_sim.ros import spinning
    from pan_tilt_sim.ros.sim_node import SimNode

    rclpy.init()
    node = SimNode(parameter_overrides=[Parameter('real_time_factor', value=0.0)])
    executor = spinning.single_threaded(node.context)
    executor.add_node(node)
    simulation = node.simulation
    for controller in simulation.command_controllers():
        controller.set_command(TILT_TARGET if 'joint2' in controller.name else PAN_TARGET)
    spent = {'engine (incl. JointState)': 0.0, '/clock publishing': 0.0,
             'JointState publishing': 0.0}

    def timed(function: Callable, key: str) -> Callable:
        def wrapper(*args):
            started = time.thread_time()
            result = function(*args)
            spent[key] += time.thread_time() - started
            return result
        return wrapper

    simulation.advance = timed(simulation.advance, 'engine (incl. JointState)')
    node._publish_clock = timed(node._publish_clock, '/clock publishing')
    sink = simulation.controller('joint_state_controller')
    sink.set_sink(timed(sink._sink, 'JointState publishing'))
    try:
        wall_end = time.monotonic() + seconds
        first_steps, started = simulation.steps, time.thread_time()
        while time.monotonic() < wall_end:
            executor.spin_once(timeout_sec=0.1)
        total = time.thread_time() - started
        steps = simulation.steps - first_steps
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    figures = {key: value / steps * MICROSECONDS for key, value in spent.items()}
    figures['engine (incl. JointState)'] -= figures['JointState publishing']
    figures['engine'] = figures.pop('engine (incl. JointState)')
    figures['executor, pacing, rest'] = (total / steps * MICROSECONDS) - sum(figures.values())
    figures['node total'] = total / steps * MICROSECONDS
    return figures


def main() -> None:
    """Print the per-step figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=5.0, help='node run, wall s')
    args = parser.parse_args()
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_DESCRIPTION, package_share
    from pan_tilt_sim.sim.engine import make_simulation

    share = package_share()
    with make_simulation(str(share / DEFAULT_DESCRIPTION), str(share / DEFAULT_CONTROLLERS),
                         TIME_STEP) as simulation:
        simulation.controller('joint1_position_controller').set_command(PAN_TARGET)
        simulation.controller('joint2_position_controller').set_command(TILT_TARGET)
        figures = pybullet_figures(simulation)
        figures['engine: PyBullet + controllers'] = per_step_us(simulation.advance,
                                                                  ENGINE_STEPS)
    print('pan/tilt, time_step 0.001 s: thread CPU us per physics step')
    for key, value in figures.items():
        print(f'  {key:48s} {value:6.2f}')
    print('sim_node at real_time_factor 0:')
    for key, value in node_figures(args.seconds).items():
        print(f'  {key:48s} {value:6.2f}')


if __name__ == '__main__':
    main()
