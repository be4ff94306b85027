"""A child process that loads robot descriptions, one per request, for the load fuzzing.

Run as ``python load_worker.py``: each line on stdin is a JSON request
``{"urdf": ..., "controllers": ..., "steps": n}``; each answer is one JSON
line on the stdout the process started with.  PyBullet's own prints (its
C-level stdout) go to stderr instead, so they never mix with the answers.

For each request the worker

* starts a simulation of the robot with its controllers, as sim_node does
  (``make_simulation``): a :class:`ConfigurationError` is the answer
  ``refused`` with its message; anything else raised is ``raised`` with the
  traceback; else it commands every controller, runs ``steps`` steps and
  answers ``loaded`` with whether every joint state stayed finite;
* spawns the same URDF as an object into a world of its own (the pan/tilt
  and a ground), as SpawnEntity does: ``refused`` (a :class:`SpawnError`),
  ``raised``, or ``spawned`` with whether the object's pose and the robot's
  joints stayed finite over ``steps`` steps; the object is deleted after.

A segmentation fault, an abort or a hang is this process dying or falling
silent: the parent sees it, which is the point of running here.
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import pathlib
import sys
import tempfile
import traceback

ENTITY = 'fuzzed'
COMMAND = 0.3  # rad or m, given to every position controller; N*m or N to effort ones


class _Quiet:
    """A logger that drops everything: the answer says what matters."""

    def info(self, message: str) -> None:
        """Drop ``message``."""

    def warning(self, message: str) -> None:
        """Drop ``message``."""


def _finite(values) -> bool:
    return all(math.isfinite(value) for value in values)


def _command_all(simulation) -> None:
    from pan_tilt_sim.controllers.framework.multi_joint import MultiJointController

    for controller in simulation.command_controllers():
        if isinstance(controller, MultiJointController):
            controller.set_command([COMMAND] * len(controller.joint_names))
        else:
            controller.set_command(COMMAND)


def load_robot(folder: pathlib.Path, request: dict) -> dict:
    """Start a simulation of the request's robot and run it; say how it went."""
    from pan_tilt_sim.errors import ConfigurationError
    from pan_tilt_sim.sim.engine import make_simulation

    urdf = folder / 'robot.urdf'
    urdf.write_text(request['urdf'], encoding='utf-8')
    controllers = folder / 'controllers.yaml'
    controllers.write_text(request['controllers'], encoding='utf-8')
    try:
        simulation = make_simulation(str(urdf), str(controllers), request.get('time_step', 0.001),
                                     logger=_Quiet())
    except ConfigurationError as err:
        return {'outcome': 'refused', 'message': str(err)}
    except BaseException:
        return {'outcome': 'raised', 'traceback': traceback.format_exc()}
    try:
        _command_all(simulation)
        simulation.advance(request['steps'])
        finite = _finite([*simulation.joint_positions().values(),
                          *simulation.joint_velocities().values()])
        return {'outcome': 'loaded', 'finite': finite}
    except BaseException:
        return {'outcome': 'raised', 'traceback': traceback.format_exc()}
    finally:
        simulation.close()


class World:
    """The pan/tilt on a ground: the world fuzzed objects are spawned into, one at a time."""

    def __init__(self) -> None:
        from pan_tilt_sim.share import DEFAULT_DESCRIPTION, package_share
        from pan_tilt_sim.sim.engine import make_simulation
        from pan_tilt_sim.sim.entities import Entities

        self.simulation = make_simulation(str(package_share() / DEFAULT_DESCRIPTION), None,
                                          0.001, logger=_Quiet())
        self.entities = Entities(self.simulation.physics, self.simulation.description.name)

    def spawn(self, request: dict) -> dict:
        """Spawn the request's URDF, run the world, delete the object; say how it went."""
        from pan_tilt_sim.model.transforms import Transform
        from pan_tilt_sim.sim.entities import SpawnError

        try:
            name = self.entities.spawn(ENTITY, resource_string=request['urdf'],
                                       pose=Transform((1.0, 0.0, 0.5)))
        except SpawnError as err:
            return {'outcome': 'refused', 'message': str(err), 'code': err.problem.name}
        except BaseException:
            return {'outcome': 'raised', 'traceback': traceback.format_exc()}
        try:
            self.simulation.advance(request['steps'])
            pose = self.entities.state(name).pose
            finite = _finite([*pose.translation, *pose.rotation,
                              *self.simulation.joint_positions().values()])
            return {'outcome': 'spawned', 'finite': finite}
        except BaseException:
            return {'outcome': 'raised', 'traceback': traceback.format_exc()}
        finally:
            with contextlib.suppress(KeyError):
                self.entities.delete(name)


def main() -> None:
    """Answer requests from stdin until it closes."""
    answers = os.fdopen(os.dup(sys.stdout.fileno()), 'w', buffering=1, encoding='utf-8')
    sys.stdout.flush()
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())  # PyBullet's prints: not in the answers
    logging.disable(logging.CRITICAL)
    world = World()
    with tempfile.TemporaryDirectory(prefix='load_worker_') as folder:
        for line in sys.stdin:
            request = json.loads(line)
            answer = {'robot': load_robot(pathlib.Path(folder), request),
                      'object': world.spawn(request)}
            answers.write(json.dumps(answer) + '\n')


if __name__ == '__main__':
    main()
