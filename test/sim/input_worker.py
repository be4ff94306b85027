"""A child process that starts fuzzed inputs and drives them, one per request.

Run as ``python input_worker.py``: each line on stdin is a JSON request drawn
by test/sim/input_strategies.py (``urdf``, ``controllers`` or null, ``requests``,
``steps``); each answer is one JSON line on the stdout the process started
with (PyBullet's own prints go to stderr).

For each request the worker starts a simulation as sim_node does
(``make_simulation``, the base free as sim_node's ``fixed_base:=auto``): a
:class:`ConfigurationError` is the answer ``refused`` with its message;
anything else raised is ``raised`` with the traceback.  Else it builds each
lidar and camera the URDF declares and takes one scan and one image, sends
every command controller the request's numbers shaped as its command kind
(a Float64, an array, a twist, a trajectory, a multi-DOF reference, gpio
values) and a gripper goal where the controller takes goals, runs
``steps`` steps, and answers ``ran`` with whether every joint state, the
base's pose and every range and depth stayed finite (``inf`` is a lidar's
"no return", so a range may be infinite but never NaN).

A segmentation fault, an abort or a hang is this process dying or falling
silent: the parent (test/sim/worker_process.py) sees it.
"""

from __future__ import annotations

import json
import logging
import math
import os
import pathlib
import sys
import tempfile
import traceback

WORLD = 'ground'


class _Quiet:
    """A logger that drops everything: the answer says what matters."""

    def info(self, message: str) -> None:
        """Drop ``message``."""

    def warning(self, message: str) -> None:
        """Drop ``message``."""


def _finite(values) -> bool:
    return all(math.isfinite(value) for value in values)


def _pad(numbers: list[float], count: int) -> list[float]:
    return [numbers[index % len(numbers)] if numbers else 0.0 for index in range(count)]


def _command(controller, requests: dict) -> None:
    """Send ``controller`` the request's numbers in its command kind, and a goal if it takes one."""
    from pan_tilt_sim.controllers.framework.base import CommandKind
    from pan_tilt_sim.controllers.framework.surface import StampedTwist
    from pan_tilt_sim.controllers.grippers.gripper_action_controller import (
        GripperActionController,
        GripperRequest,
    )
    from pan_tilt_sim.controllers.trajectory.trajectory import JointTrajectory, TrajectoryPoint

    numbers, stamp = requests['numbers'], requests['stamp']
    joints = tuple(getattr(controller, 'joint_names', ()) or ('joint1',))
    kind = controller.command_kind
    if isinstance(controller, GripperActionController):
        position, effort, velocity = requests['goal']
        request = GripperRequest(position, effort, velocity)
        if controller.check_goal(request) is None:
            controller.start_goal(request, 0.0)
        return
    if type(controller).__name__ == 'GpioCommandController':
        value = ([controller.name], [(['output1'], numbers[:1])])
    elif kind is CommandKind.FLOAT64:
        value = numbers[0] if numbers else math.nan
    elif kind is CommandKind.FLOAT64_ARRAY:
        value = numbers
    elif kind in (CommandKind.TWIST, CommandKind.TWIST_STAMPED):
        padded = _pad(numbers, 6)
        value = StampedTwist(stamp, tuple(padded[:3]), tuple(padded[3:]))
    elif kind is CommandKind.JOINT_TRAJECTORY:
        positions = tuple(_pad(numbers, len(joints)))
        value = JointTrajectory(joints, (TrajectoryPoint(abs(stamp) if math.isfinite(stamp)
                                                         else stamp, positions),))
    elif kind is CommandKind.MULTI_DOF_COMMAND:
        value = ((), numbers, ())
    else:
        return
    controller.set_command(value)


def run(folder: pathlib.Path, request: dict) -> dict:
    """Start the request's simulation, scan, render, command and step it; say how it went."""
    from pan_tilt_sim.errors import ConfigurationError
    from pan_tilt_sim.model.sensors import SensorKind
    from pan_tilt_sim.sim.engine import make_simulation
    from pan_tilt_sim.sim.sensors.lidar import Lidar
    from pan_tilt_sim.sim.sensors.vision import VisionSensor

    urdf = folder / 'robot.urdf'
    urdf.write_text(request['urdf'], encoding='utf-8')
    controllers = None
    if request['controllers'] is not None:
        controllers = folder / 'controllers.yaml'
        controllers.write_text(request['controllers'], encoding='utf-8')
    try:
        simulation = make_simulation(str(urdf), str(controllers) if controllers else None,
                                     0.001, logger=_Quiet(), fixed_base=None)
    except ConfigurationError as err:
        return {'outcome': 'refused', 'message': str(err)}
    except BaseException:
        return {'outcome': 'raised', 'traceback': traceback.format_exc()}
    try:
        readings: list[float] = []
        for sensor in simulation.description.model.sensors:
            if sensor.kind is SensorKind.LIDAR:
                ranges = Lidar(simulation.physics, sensor, WORLD).scan()
                readings += [value for value in ranges.ravel().tolist() if math.isnan(value)]
            elif sensor.kind in (SensorKind.CAMERA, SensorKind.DEPTH):
                frame = VisionSensor(simulation.physics, sensor, WORLD).render()
                readings += [value for value in frame.depth.ravel().tolist()
                             if math.isnan(value)]
        for controller in simulation.command_controllers():
            _command(controller, request['requests'])
        simulation.advance(request['steps'])
        (x, y, heading), (forward, sideways, turn) = simulation.base_state()
        finite = _finite([*simulation.joint_positions().values(),
                          *simulation.joint_velocities().values(),
                          x, y, heading, forward, sideways, turn])
        return {'outcome': 'ran', 'finite': finite and not readings}
    except BaseException:
        return {'outcome': 'raised', 'traceback': traceback.format_exc()}
    finally:
        simulation.close()


def main() -> None:
    """Answer requests from stdin until it closes."""
    answers = os.fdopen(os.dup(sys.stdout.fileno()), 'w', buffering=1, encoding='utf-8')
    sys.stdout.flush()
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())  # PyBullet's prints: not in the answers
    logging.disable(logging.CRITICAL)
    with tempfile.TemporaryDirectory(prefix='input_worker_') as folder:
        for line in sys.stdin:
            answers.write(json.dumps(run(pathlib.Path(folder), json.loads(line))) + '\n')


if __name__ == '__main__':
    main()
