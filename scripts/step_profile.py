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

``--scene driving_base|grasp|ur5e_like`` profiles a bench scene's first case
instead (:mod:`pan_tilt_sim.tools.bench_scenes`), in this process without
ROS: PyBullet alone on its recorded commands (``raw_step_us``), the engine
per step, and the engine's Python functions that cost the most per step
(cProfile's own time, which cProfile inflates: read them as shares).

Usage: ``python scripts/step_profile.py [--seconds S] [--scene NAME]``
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


SCENE_CASES = {'driving_base': 'on_ground', 'grasp': 'holding', 'ur5e_like': 'follow_trajectory'}
PROFILE_TOP = 15


def scene_figures(scene: str) -> None:
    """Print where one step of a bench scene's first case goes, in this process."""
    import cProfile
    import pathlib
    import pstats
    import tempfile

    from pan_tilt_sim.model.world_file import world_from_parameter
    from pan_tilt_sim.share import package_share
    from pan_tilt_sim.sim.engine import make_simulation
    from pan_tilt_sim.sim.entities import Entities, spawn_world_objects
    from pan_tilt_sim.sim.world import build_world, has_ground
    from pan_tilt_sim.tools import bench_scenes

    with tempfile.TemporaryDirectory() as folder:
        makers = {'driving_base': lambda: bench_scenes.driving_base(package_share(),
                                                                    pathlib.Path(folder)),
                  'grasp': lambda: bench_scenes.grasp(pathlib.Path(folder)),
                  'ur5e_like': lambda: bench_scenes.ur5e_like(pathlib.Path(folder))}
        case = makers[scene]()[SCENE_CASES[scene]]
        raw = bench_scenes.in_process_figures(case, TIME_STEP)
        fixed = case.parameters.get('fixed_base')
        world = world_from_parameter(case.parameters.get('world', 'empty'))
        with make_simulation(str(case.description_file), str(case.controllers_file), TIME_STEP,
                             fixed_base=None if fixed is None else fixed == 'true'
                             ) as simulation:
            entities = Entities(simulation.physics, simulation.description.name,
                                targets=build_world(world.scenery, simulation.physics.client_id),
                                ground=has_ground(world.scenery))
            spawn_world_objects(entities, world)
            for topic, message in case.messages.items():
                simulation.controller(topic.rsplit('/', 2)[-2]).set_command(
                    bench_scenes._command_value(message))
            for action, goal in case.goals.items():
                from pan_tilt_sim.ros.ros_interfaces import joint_trajectory

                simulation.controller(action.rsplit('/', 2)[-2]).set_command(
                    joint_trajectory(goal.trajectory))
            engine = per_step_us(simulation.advance, ENGINE_STEPS)
            profiler = cProfile.Profile()
            profiler.runcall(simulation.advance, ENGINE_STEPS)
            entities.close()
    print(f'{scene} ({SCENE_CASES[scene]}), time_step {TIME_STEP} s: thread CPU us per step')
    print(f'  {"PyBullet alone, its commands replayed (raw_step_us)":60s} '
          f'{raw["raw_step_us"]:7.2f}')
    print(f'  {"engine: PyBullet + controllers (Simulation.advance)":60s} {engine:7.2f}')
    print(f'  {"ratio_to_raw of the engine alone":60s} {raw["raw_step_us"] / engine:7.2f}')
    print("the engine's costliest functions, own time per step (cProfile, inflated):")
    stats = pstats.Stats(profiler)
    rows = sorted(stats.stats.items(), key=lambda item: item[1][2], reverse=True)[:PROFILE_TOP]
    for (filename, line, function), (_, calls, own, _, _) in rows:
        where = f'{pathlib.Path(filename).name}:{line} {function}'
        print(f'  {where[:60]:60s} {own / ENGINE_STEPS * MICROSECONDS:7.2f}  '
              f'({calls / ENGINE_STEPS:.2f} calls)')


def main() -> None:
    """Print the per-step figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=5.0, help='node run, wall s')
    parser.add_argument('--scene', choices=sorted(SCENE_CASES), default=None,
                        help="profile a bench scene's first case instead (no ROS)")
    args = parser.parse_args()
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    if args.scene is not None:
        scene_figures(args.scene)
        return
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
