"""Steps asked for while paused (StepSimulation, SimulateSteps), run without blocking the node.

sim_node spins one single-threaded executor, so a request for a million
steps must not hold it for the seconds they take: a cancel, a QUITTING
request or Ctrl-C would wait for them.  A :class:`StepRunner` therefore runs
the steps of one :class:`StepJob` in slices of about :data:`SLICE_WALL_S` of
wall time, one slice per executor callback (a zero-period timer, on only
while a job runs), and whatever else is due runs between slices.  Each slice
goes through the node's own stepping (``step(n)``): controllers, /clock and
JointState as at any other time.  Requested steps run as fast as the machine
allows, whatever ``real_time_factor`` says (as Isaac Sim does).

A job completes its :attr:`StepJob.future` when its steps are done, when it
is cancelled (after the slice in progress), or when it fails -- the physics
was set playing (it must stay paused while stepping) or the node stopped.
"""

from __future__ import annotations

import enum
import time
from collections.abc import Callable

from rclpy.node import Node
from rclpy.task import Future

SLICE_WALL_S = 0.005  # wall time of physics per executor callback while a job runs
CHUNK_STEPS = 100  # steps between two looks at the wall clock within a slice


class JobEnd(enum.Enum):
    """How a step job ended."""

    DONE = 'done'
    CANCELED = 'canceled'
    FAILED = 'failed'


class StepJob:
    """``total`` physics steps asked for; :attr:`future` gets the :class:`JobEnd`."""

    def __init__(self, total: int, on_progress: Callable[[StepJob], None] | None = None) -> None:
        self.total = total
        self.completed = 0
        self.future = Future()
        self.reason = ''  # why it failed
        self.cancel_requested = False
        self._on_progress = on_progress

    @property
    def remaining(self) -> int:
        """Steps still to run."""
        return self.total - self.completed

    def progress(self) -> None:
        """Tell whoever asked for the steps how far they got."""
        if self._on_progress is not None:
            self._on_progress(self)

    def end(self, how: JobEnd, reason: str = '') -> None:
        """Complete the future (once)."""
        if not self.future.done():
            self.reason = reason
            self.future.set_result(how)


class StepRunner:
    """Runs one step job at a time on ``node``'s executor, in slices (see the module)."""

    def __init__(self, node: Node, step: Callable[[int], None],
                 is_paused: Callable[[], bool]) -> None:
        self._step = step
        self._is_paused = is_paused
        self._job: StepJob | None = None
        self._timer = node.create_timer(0.0, self._run_slice)
        self._timer.cancel()

    @property
    def job(self) -> StepJob | None:
        """The job in progress, if any."""
        return self._job

    def start(self, job: StepJob) -> None:
        """Start running ``job`` (the caller checked that none runs and the physics is held)."""
        assert self._job is None, 'one step job at a time'
        if job.total == 0:
            job.end(JobEnd.DONE)
            return
        self._job = job
        self._timer.reset()

    def fail(self, reason: str) -> None:
        """End the job in progress, if any, as failed (steps already run stay run)."""
        if self._job is not None:
            self._finish(JobEnd.FAILED, reason)

    def close(self) -> None:
        """Stop: the job in progress fails."""
        self.fail('the simulator is shutting down')
        self._timer.cancel()

    def _run_slice(self) -> None:
        job = self._job
        if job is None:
            self._timer.cancel()
            return
        if job.cancel_requested:
            self._finish(JobEnd.CANCELED)
            return
        if not self._is_paused():
            self._finish(JobEnd.FAILED, 'the simulation was set playing while stepping')
            return
        deadline = time.perf_counter() + SLICE_WALL_S
        while job.remaining:
            chunk = min(job.remaining, CHUNK_STEPS)
            self._step(chunk)
            job.completed += chunk
            if time.perf_counter() >= deadline:
                break
        job.progress()
        if not job.remaining:
            self._finish(JobEnd.DONE)

    def _finish(self, how: JobEnd, reason: str = '') -> None:
        job, self._job = self._job, None
        self._timer.cancel()
        if job is not None:
            job.end(how, reason)
