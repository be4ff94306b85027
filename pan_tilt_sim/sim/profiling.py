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
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Sequence

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
