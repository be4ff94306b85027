"""A fuzzing worker in a child process: one JSON request a line in, one answer a line out.

:class:`WorkerProcess` runs a worker script (test/sim/load_worker.py,
test/sim/input_worker.py) and hands it requests one after another.  A crash
(a signal, an exit) or a hang there is a failing example here -- with the
child's last output -- and the next request gets a fresh child.
"""

from __future__ import annotations

import json
import pathlib
import selectors
import signal
import subprocess
import sys
import tempfile

import pytest
import sim_process

ANSWER_BUDGET_S = 30.0  # no answer within this: the child hangs
# More for the first answer of a new child: it imports PyBullet, NumPy and the package first,
# which on a busy machine takes longer than any one answer.
STARTUP_BUDGET_S = 120.0


class WorkerProcess:
    """A worker script in a child process, started again whenever it died."""

    def __init__(self, script: pathlib.Path) -> None:
        self._script = script
        self._process: subprocess.Popen | None = None
        self._stderr = tempfile.TemporaryFile(mode='w+', encoding='utf-8', errors='replace')

    def run(self, request: dict) -> dict:
        """Return the child's answer to ``request``; fail if it crashes or falls silent."""
        fresh = self._process is None
        process = self._started()
        budget = ANSWER_BUDGET_S + (STARTUP_BUDGET_S if fresh else 0.0)
        try:
            process.stdin.write(json.dumps(request) + '\n')
            process.stdin.flush()
        except BrokenPipeError:
            pass  # it died: the read below says how
        with selectors.DefaultSelector() as selector:
            selector.register(process.stdout, selectors.EVENT_READ)
            ready = selector.select(budget)
        if not ready:
            process.kill()
            process.wait()
            self._process = None
            pytest.fail(f'the worker hung: no answer within {budget:g} s', False)
        line = process.stdout.readline()
        if not line:
            code = process.wait()
            self._process = None
            pytest.fail(f'the worker died ({_ending(code)}); its last output: '
                        f'{self._tail()!r}', False)
        return json.loads(line)

    @property
    def pid(self) -> int:
        """The child's process id (started if need be)."""
        return self._started().pid

    def close(self) -> None:
        """End the child (stdin closed: it returns) and forget its output."""
        if self._process is not None:
            self._process.stdin.close()
            try:
                self._process.wait(timeout=ANSWER_BUDGET_S)
            except subprocess.TimeoutExpired:
                self._process.kill()
                self._process.wait()
            self._process = None
        self._stderr.close()

    def _started(self) -> subprocess.Popen:
        if self._process is None:
            self._stderr.seek(0)
            self._stderr.truncate()
            self._process = subprocess.Popen(
                [sys.executable, str(self._script)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                stderr=self._stderr, text=True, env=sim_process.environment())
        return self._process

    def _tail(self) -> str:
        self._stderr.flush()
        self._stderr.seek(0)
        return self._stderr.read()[-1500:]


def _ending(code: int) -> str:
    if code < 0:
        return f'killed by {signal.Signals(-code).name}'
    return f'exit code {code}'
