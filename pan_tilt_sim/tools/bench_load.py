"""bench --load: what spawned objects and world files cost, printed as one JSON object.

``ros2 run pan_tilt_sim bench --load`` (or ``python -m pan_tilt_sim.tools.bench_load``)
measures, in this process, without ROS, on the pan/tilt example at the default
time step, the figures the limits on spawned objects and world files come from
(:mod:`pan_tilt_sim.model.entity_resource`, :mod:`pan_tilt_sim.model.world_file`).
CPU seconds of this process (its only thread does the work) (see the design notes).

Design notes: docs/design/tools.md#bench_loadpy.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import sys
import tempfile
import time
from collections.abc import Callable, Sequence

from pan_tilt_sim.model.entity_resource import EntityLimits, read_entity_resource
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.model.world_file import read_world_file
from pan_tilt_sim.share import DEFAULT_CONTROLLERS, DEFAULT_DESCRIPTION, package_share
from pan_tilt_sim.sim.bullet import pybullet, quiet_native_output
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.sim.entities import Entities, spawn_world_objects
from pan_tilt_sim.sim.stability import ObjectTrials

TIME_STEP = 0.001  # s, sim_node's default
CHAIN_LINKS = (32, 64, 128, 256, 1000, 3000)
QUICK_CHAIN_LINKS = (8, 16, 256)
STEPPED_LINKS = 128  # chains up to this many links are spawned and stepped
FIRST_STEP_LINKS = 1000  # one step of chains up to this many links is timed alone
WORLD_ENTITIES = (1000, 10_000)
QUICK_WORLD_ENTITIES = (10, 20)
STEP_WINDOW = 2000  # steps timed per case
QUICK_STEP_WINDOW = 50
GRID_M = 0.5  # spacing of the world's boxes
GRID_START_M = 1.0  # x of the first column: clear of the pan/tilt at the origin
BOX_M = 0.2
UNLIMITED = EntityLimits(max_bytes=1 << 30, max_links=1 << 30, max_joints=1 << 30)
DIGITS = 4


def chain_urdf(links: int, name: str = 'chain') -> str:
    """Return a serial chain of ``links`` links joined by revolute joints about y."""
    parts = [f'<robot name="{name}">']
    parts += [f'<link name="l{index}"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" '
              'ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial><collision><origin '
              'xyz="0 0 0.05"/><geometry><box size="0.02 0.02 0.1"/></geometry></collision>'
              '</link>' for index in range(links)]
    parts += [f'<joint name="j{index}" type="revolute"><parent link="l{index}"/>'
              f'<child link="l{index + 1}"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>'
              '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
              for index in range(links - 1)]
    return '\n'.join([*parts, '</robot>\n'])


def world_yaml(count: int) -> str:
    """Return a world file of ``count`` static boxes resting on the ground, on a square grid."""
    side = int(count ** 0.5) + 1
    lines = ['scenery: ground', 'entities:']
    lines += [f'  - {{shape: box, size: [{BOX_M}, {BOX_M}, {BOX_M}], pose: {{position: '
              f'[{GRID_START_M + (index % side) * GRID_M:.2f}, '
              f'{(index // side) * GRID_M:.2f}, {BOX_M / 2}]}}}}'
              for index in range(count)]
    return '\n'.join(lines) + '\n'


def cpu_s(work: Callable[[], object]) -> tuple[float, object]:
    """Run ``work``; return the CPU seconds it took and what it returned."""
    start = time.process_time()
    result = work()
    return time.process_time() - start, result


class World:
    """The pan/tilt example with entities, as sim_node builds it (no ROS)."""

    def __init__(self, share: pathlib.Path, entity_limits: EntityLimits = UNLIMITED) -> None:
        self.simulation = make_simulation(share / DEFAULT_DESCRIPTION,
                                          share / DEFAULT_CONTROLLERS, TIME_STEP)
        self.entities = Entities(self.simulation.physics, self.simulation.description.name,
                                 limits=entity_limits)

    def step_us(self, steps: int) -> float:
        """CPU microseconds per physics step (the node's own stepping, controllers included)."""
        self.simulation.advance(10)  # warm
        seconds, _ = cpu_s(lambda: self.simulation.advance(steps))
        return seconds / steps * 1e6

    def close(self) -> None:
        """Release the entities and the simulation."""
        self.entities.close()
        self.simulation.close()


def chain_figures(links: int, share: pathlib.Path, folder: pathlib.Path,
                  window: int) -> dict[str, float | bool]:
    """Measure the ``chains`` figures of one chain (see the module's design notes)."""
    text = chain_urdf(links)
    read_s, resource = cpu_s(lambda: read_entity_resource(resource_string=text,
                                                          limits=UNLIMITED))
    path = folder / f'chain_{links}.urdf'
    path.write_text(resource.physics_urdf, encoding='utf-8')
    with quiet_native_output():
        client = pybullet.connect(pybullet.DIRECT)
    try:
        load_s, body = cpu_s(lambda: pybullet.loadURDF(
            str(path), flags=pybullet.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client))
        try:
            pybullet.getBasePositionAndOrientation(body, physicsClientId=client)
            reported = True
        except pybullet.error:
            reported = False
        figures: dict[str, float | bool] = {'read_s': read_s, 'pybullet_load_s': load_s,
                                            'state_reported': reported}
        if links > STEPPED_LINKS and links <= FIRST_STEP_LINKS:
            figures['first_step_s'], _ = cpu_s(
                lambda: pybullet.stepSimulation(physicsClientId=client))
    finally:
        pybullet.disconnect(physicsClientId=client)
    if links > STEPPED_LINKS:
        return figures
    trials = ObjectTrials(TIME_STEP)
    try:
        figures['trial_s'], _ = cpu_s(lambda: trials.run(path, False, resource.model))
    finally:
        trials.close()
    world = World(share)
    try:
        alone = world.step_us(window)
        prepared = world.entities.prepare(resource_string=text)
        figures['add_s'], _ = cpu_s(lambda: world.entities.add(
            prepared, pose=Transform((2.0, 2.0, 0.5))))
        figures['step_us'] = world.step_us(window) - alone
    finally:
        world.close()
    return figures


def world_figures(count: int, share: pathlib.Path, folder: pathlib.Path,
                  window: int) -> dict[str, float]:
    """Measure the ``world`` figures of ``count`` static boxes (see the module's design notes)."""
    path = folder / f'world_{count}.yaml'
    path.write_text(world_yaml(count), encoding='utf-8')
    read_s, world_file = cpu_s(lambda: read_world_file(path, max_entities=count))
    world = World(share)
    try:
        alone = world.step_us(window)
        spawn_s, _ = cpu_s(lambda: spawn_world_objects(world.entities, world_file))
        step = world.step_us(window) - alone
    finally:
        world.close()
    return {'read_s': read_s, 'spawn_s': spawn_s,
            'startup_ms_per_entity': (read_s + spawn_s) / count * 1e3,
            'step_us': step, 'step_us_per_entity': step / count}


def rounded(figures: object) -> object:
    """``figures`` with every float to four significant digits, at any depth."""
    if isinstance(figures, dict):
        return {key: rounded(value) for key, value in figures.items()}
    if isinstance(figures, float):
        return float(f'{figures:.{DIGITS}g}')
    return figures


def main(argv: Sequence[str] | None = None) -> None:
    """Measure and print the JSON object."""
    parser = argparse.ArgumentParser(
        prog='bench --load', description='What spawned objects and world files cost.')
    parser.add_argument('--quick', action='store_true',
                        help='small cases only (all keys, timing meaningless)')
    parser.add_argument('--verbose', action='store_true', help='say on stderr what runs')
    args = parser.parse_args(argv)
    share = package_share()
    chains = QUICK_CHAIN_LINKS if args.quick else CHAIN_LINKS
    worlds = QUICK_WORLD_ENTITIES if args.quick else WORLD_ENTITIES
    window = QUICK_STEP_WINDOW if args.quick else STEP_WINDOW

    def log(text: str) -> None:
        if args.verbose:
            print(f'bench --load: {text}', file=sys.stderr, flush=True)

    with tempfile.TemporaryDirectory(prefix='pan_tilt_bench_load_') as name:
        folder = pathlib.Path(name)
        result: dict[str, dict] = {'chains': {}, 'world': {}}
        for links in chains:
            log(f'chain of {links} links')
            result['chains'][str(links)] = chain_figures(links, share, folder, window)
        for count in worlds:
            log(f'world of {count} boxes')
            result['world'][str(count)] = world_figures(count, share, folder, window)
    print(json.dumps(rounded(result)), flush=True)


if __name__ == '__main__':
    main()
