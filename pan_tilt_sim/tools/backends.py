"""Where evaluations run: this process, local worker processes, or a Ray cluster.

Every back end has one operation, :meth:`Backend.map`: call
``function(shared, item)`` for each item and return the results *in the
order of the items*, whatever order they finish in -- so a caller that
feeds the results to an optimiser in that order gets the same answer from
every back end.  ``shared`` is what all calls of one map have in common
(the robot, loaded once): Ray stores it once in the object store; worker
processes get it pickled with each call (a few tens of kB, against
~0.2 s of simulation per call).

Design notes: docs/design/tools.md#backendspy.
"""

from __future__ import annotations

import abc
import concurrent.futures
import multiprocessing
import os
from collections.abc import Callable, Sequence
from typing import Any

RAY_HINT = ("--address needs Ray, which is not installed: pip install ray (or "
            "'ray[client]' for ray:// addresses), or leave out --address to use local worker "
            'processes')
RAY_CLIENT_HINT = ("connecting to a ray:// address needs Ray Client: pip install 'ray[client]'")


class BackendError(RuntimeError):
    """A back end cannot be started (Ray missing, cluster unreachable)."""


class Backend(abc.ABC):
    """Runs evaluations; see the module's design notes."""

    name: str = ''

    @property
    @abc.abstractmethod
    def parallelism(self) -> int:
        """How many evaluations run at once."""

    @abc.abstractmethod
    def map(self, function: Callable[[Any, Any], Any], shared: Any,
            items: Sequence[Any]) -> list[Any]:
        """Return ``[function(shared, item) for item in items]``, computed in parallel."""

    def close(self) -> None:  # noqa: B027 -- nothing to release by default
        """Release workers and connections."""

    def __enter__(self) -> Backend:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


class InProcess(Backend):
    """Evaluations one after another in this process."""

    name = 'in-process'

    @property
    def parallelism(self) -> int:
        """One at a time."""
        return 1

    def map(self, function: Callable[[Any, Any], Any], shared: Any,
            items: Sequence[Any]) -> list[Any]:
        """Call ``function`` on each item in turn."""
        return [function(shared, item) for item in items]


def _warm_up() -> None:
    """Import the simulation in a new worker before its first evaluation arrives."""
    import pan_tilt_sim.tools.evaluation  # noqa: F401


class LocalProcesses(Backend):
    """A pool of ``workers`` spawned processes on the local machine."""

    name = 'local processes'

    def __init__(self, workers: int) -> None:
        if workers < 1:
            raise BackendError(f'--workers: {workers} must be at least 1')
        self._workers = workers
        self._pool = concurrent.futures.ProcessPoolExecutor(
            max_workers=workers, mp_context=multiprocessing.get_context('spawn'),
            initializer=_warm_up)

    @property
    def parallelism(self) -> int:
        """The number of worker processes."""
        return self._workers

    def map(self, function: Callable[[Any, Any], Any], shared: Any,
            items: Sequence[Any]) -> list[Any]:
        """Submit every item, then collect the results in item order."""
        futures = [self._pool.submit(function, shared, item) for item in items]
        try:
            return [future.result() for future in futures]
        except concurrent.futures.process.BrokenProcessPool as err:
            raise BackendError(f'a worker process died: {err}') from None

    def close(self) -> None:
        """Stop the worker processes."""
        self._pool.shutdown(wait=True, cancel_futures=True)


class RayCluster(Backend):
    """Evaluations as Ray tasks; ``address``: see the module's design notes."""

    name = 'Ray'

    def __init__(self, address: str | None = None, *, ship_code: bool = True) -> None:
        try:
            import ray
        except ImportError:
            raise BackendError(RAY_HINT) from None
        self._ray = ray
        self._owned = False
        if not ray.is_initialized():
            if address is None:
                raise BackendError('no Ray address given and no Ray instance running here')
            self._connect(address, ship_code)
            self._owned = True
        self._remotes: dict[Callable[..., Any], Any] = {}

    def _connect(self, address: str, ship_code: bool) -> None:
        ray = self._ray
        runtime_env = None
        if ship_code and address != 'local':
            import pan_tilt_sim

            runtime_env = {'py_modules': [pan_tilt_sim], 'excludes': ['__pycache__']}
        try:
            ray.init(address=address, runtime_env=runtime_env, include_dashboard=False,
                     logging_level='WARNING', log_to_driver=False)
        except ImportError as err:
            raise BackendError(f'{RAY_CLIENT_HINT} ({err})') from None
        except (ConnectionError, RuntimeError, ValueError) as err:
            first_line = str(err).strip().splitlines()[0] if str(err).strip() else repr(err)
            raise BackendError(f'--address {address}: cannot connect to Ray: '
                               f'{first_line}') from None

    @property
    def parallelism(self) -> int:
        """The CPUs of the cluster (Ray runs one task per CPU)."""
        return max(1, int(self._ray.cluster_resources().get('CPU', 1)))

    def map(self, function: Callable[[Any, Any], Any], shared: Any,
            items: Sequence[Any]) -> list[Any]:
        """Submit each item as a task (``shared`` put once), then get the results in order."""
        remote = self._remotes.get(function)
        if remote is None:
            remote = self._ray.remote(num_cpus=1, max_retries=0)(function)
            self._remotes[function] = remote
        shared_ref = self._ray.put(shared)
        refs = [remote.remote(shared_ref, item) for item in items]
        return self._ray.get(refs)

    def close(self) -> None:
        """Disconnect, if this back end was the one that connected."""
        if self._owned and self._ray.is_initialized():
            self._ray.shutdown()
        self._owned = False


def default_workers() -> int:
    """Return how many CPUs this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def make_backend(workers: int | None, address: str | None) -> Backend:
    """Return the back end the command line asks for (``--workers``, ``--address``)."""
    if address is not None:
        return RayCluster(address)
    workers = default_workers() if workers is None else workers
    if workers == 0:
        return InProcess()
    return LocalProcesses(workers)
