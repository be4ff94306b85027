"""What PyBullet alone costs per physics step, on the physics a simulation runs.

The benchmark's denominator: the node can never be faster than the PyBullet
calls it must make.  :func:`pybullet_step_cost` replays a recorded sequence
of efforts on a fresh copy of the physics (same model, time step, friction
motors) and times, with this thread's CPU clock, ``stepSimulation`` alone
(through PyBullet's Python module, positional arguments) and the three calls
the engine makes per step (set the efforts, step, read the joint states) as
the engine makes them: from C where the package was built with its compiled
step (:mod:`pan_tilt_sim.sim.compiled_step`).  Windows alternate between the
two; either way PyBullet gets the same commands, so the replay retraces the
recorded motion exactly.

For any scene, :class:`CommandRecorder` records the commands a simulation
sends PyBullet step by step, and :func:`replay_step_cost` replays them on the
same bodies (from a saved state) and times ``stepSimulation`` alone.
"""

from __future__ import annotations

import os
import statistics
import time
from collections.abc import Callable, Sequence

from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.physics import Physics

NANOSECONDS_PER_MICROSECOND = 1e3
WINDOW_STEPS = 1000


def pybullet_step_cost(physics: Physics,
                       efforts: Sequence[Sequence[float]]) -> tuple[float, float]:
    """Replay ``efforts`` (one list per step) on ``physics``; return CPU us per step.

    Returns the median over windows of ``WINDOW_STEPS`` of (``stepSimulation``
    alone, the engine's three calls); even windows time the first, odd ones
    the second.  The clock reads around each ``stepSimulation`` are
    calibrated out.
    """
    body, client = physics.body_id, physics.client_id
    indices = [physics.joint_index(joint.name) for joint in physics.joints]
    torque = pybullet.TORQUE_CONTROL
    unused = [0.0] * len(indices)
    set_motors = pybullet.setJointMotorControlArray
    step_simulation = pybullet.stepSimulation
    get_states = pybullet.getJointStates
    engine_step = physics.effort_stepper(indices)
    if len(efforts) < 2 * WINDOW_STEPS:
        raise ValueError(
            f'replaying needs at least {2 * WINDOW_STEPS} steps, got {len(efforts)}')
    clock = time.thread_time_ns
    overhead = _clock_overhead_ns()
    step_costs, call_costs = [], []
    for number, start in enumerate(range(0, len(efforts) - WINDOW_STEPS + 1, WINDOW_STEPS)):
        window = efforts[start:start + WINDOW_STEPS]
        if number % 2:
            began = clock()
            for step_efforts in window:
                engine_step(step_efforts)
            total = clock() - began - overhead
            call_costs.append(total / len(window) / NANOSECONDS_PER_MICROSECOND)
            continue
        stepping = 0
        for step_efforts in window:
            set_motors(body, indices, torque, unused, unused, step_efforts, unused, unused,
                       client)
            before = clock()
            step_simulation(client)
            stepping += clock() - before - overhead
            get_states(body, indices, client)
        step_costs.append(stepping / len(window) / NANOSECONDS_PER_MICROSECOND)
    return statistics.median(step_costs), statistics.median(call_costs)


def _clock_overhead_ns() -> float:
    """Return what one pair of back-to-back thread-clock reads measures (the floor)."""
    clock = time.thread_time_ns
    samples = []
    for _ in range(5):
        began = clock()
        for _ in range(1000):
            before = clock()
            clock()
        samples.append((clock() - began) / 1000.0 / 2.0)
        del before
    return statistics.median(samples)


# PyBullet's calls that change what the next step does: motors, dynamics, base motion, forces.
COMMAND_CALLS = ('setJointMotorControlArray', 'setJointMotorControl2',
                 'setJointMotorControlMultiDof', 'setJointMotorControlMultiDofArray',
                 'changeDynamics', 'resetBaseVelocity', 'applyExternalForce',
                 'applyExternalTorque')


class CommandRecorder:
    """Records, step by step, the commands a simulation sends PyBullet (a context manager).

    While open, PyBullet's command calls (:data:`COMMAND_CALLS`) and
    ``stepSimulation`` pass through the recorder, and the compiled step is
    switched off, so that a simulation built inside the block makes every call
    through PyBullet's Python module (the compiled step sends the same
    commands, to the last bit).  Between :meth:`start` and :meth:`stop`,
    :attr:`steps` gets one list per ``stepSimulation``: the calls made before
    it, with copies of their list arguments.  :func:`replay_step_cost` plays
    them back.
    """

    def __init__(self) -> None:
        self.steps: list[list[tuple]] = []
        self._pending: list[tuple] = []
        self._recording = False
        self._originals: dict[str, object] = {}
        self._switch: str | None = None

    def __enter__(self) -> CommandRecorder:
        from pan_tilt_sim.sim import compiled_step

        self._switch = os.environ.get(compiled_step.ENVIRONMENT_SWITCH)
        os.environ[compiled_step.ENVIRONMENT_SWITCH] = '0'
        for name in (*COMMAND_CALLS, 'stepSimulation'):
            original = getattr(pybullet, name)
            self._originals[name] = original
            setattr(pybullet, name, self._stepping(original) if name == 'stepSimulation'
                    else self._command(original))
        return self

    def __exit__(self, *exc_info: object) -> None:
        from pan_tilt_sim.sim import compiled_step

        for name, original in self._originals.items():
            setattr(pybullet, name, original)
        self._originals.clear()
        if self._switch is None:
            os.environ.pop(compiled_step.ENVIRONMENT_SWITCH, None)
        else:
            os.environ[compiled_step.ENVIRONMENT_SWITCH] = self._switch

    def start(self) -> None:
        """Forget what was recorded; record every step from now on."""
        self.steps, self._pending, self._recording = [], [], True

    def stop(self) -> None:
        """Stop recording (the calls made since the last step are dropped)."""
        self._recording = False

    def _command(self, original: Callable) -> Callable:
        def record(*args: object, **kwargs: object) -> object:
            if self._recording:
                self._pending.append((original, tuple(
                    list(arg) if isinstance(arg, list) else arg for arg in args), {
                    key: list(value) if isinstance(value, list) else value
                    for key, value in kwargs.items()}))
            return original(*args, **kwargs)
        return record

    def _stepping(self, original: Callable) -> Callable:
        def step(*args: object, **kwargs: object) -> object:
            if self._recording:
                self.steps.append(self._pending)
                self._pending = []
            return original(*args, **kwargs)
        return step


def replay_step_cost(client: int, steps: Sequence[Sequence[tuple]]) -> float:
    """Replay recorded steps (:class:`CommandRecorder`) on ``client``; return CPU us per step.

    Each step's commands are sent as recorded, then one ``stepSimulation``
    is timed with this thread's CPU clock; the figure is the median over
    whole windows of ``WINDOW_STEPS`` steps, or of all of them where there
    are fewer (the clock reads calibrated out).  Restore the state the
    recording started from first, and the replay retraces the recorded motion.
    """
    if not steps:
        raise ValueError('no steps to replay')
    step_simulation = pybullet.stepSimulation
    clock = time.thread_time_ns
    overhead = _clock_overhead_ns()
    window = min(WINDOW_STEPS, len(steps))
    costs = []
    # Every step is replayed; a last window shorter than the others is not timed.
    for start in range(0, len(steps), window):
        stepping = 0
        part = steps[start:start + window]
        for calls in part:
            for function, args, kwargs in calls:
                function(*args, **kwargs)
            before = clock()
            step_simulation(client)
            stepping += clock() - before - overhead
        if len(part) == window:
            costs.append(stepping / window / NANOSECONDS_PER_MICROSECOND)
    return statistics.median(costs)
