"""pytest plugin (entry point ``pytest11``): test your ROS 2 code against pan_tilt_sim.

Installed with the package and inert until a test asks for its fixtures:

* ``sim``: a factory; ``s = sim(robot=..., controllers=..., world=...,
  parameters={...})`` returns a :class:`~pan_tilt_sim.tools.sim_handle.SimHandle`,
  a paused sim_node in the test's process that the test steps in sim time.
  The default rclpy context is initialised for the test (unless the test
  initialised it already) and shut down after it, so ``Node('mine')`` just
  works; every node the test added is destroyed first, action clients before
  their node.
* ``sim_process``: the same helpers for sim_node started as a program
  (:mod:`pan_tilt_sim.tools.sim_process_handle`).

Design notes: docs/design/tools.md#pytest_pluginpy.
"""

from __future__ import annotations

import os
import re
import shutil
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import pytest

RECORD_FAILED = 'PAN_TILT_SIM_RECORD_FAILED'
DOMAIN_ENV = 'ROS_DOMAIN_ID'
# Fast DDS derives ports from the domain id; above 232 they leave the valid range.
MAX_DOMAIN_ID = 232
_UNSAFE = re.compile(r'[^A-Za-z0-9_.-]+')
_WORKER_NUMBER = re.compile(r'(\d+)$')
_BAGS_KEY = pytest.StashKey[list]()
FIXTURES = {'sim', 'sim_process'}


def pytest_addoption(parser: pytest.Parser) -> None:
    """Add the plugin's options."""
    group = parser.getgroup('pan_tilt_sim', 'pan_tilt_sim simulation fixtures')
    group.addoption('--sim-record-failed', metavar='FOLDER', default=None,
                    help='record every sim fixture run as a bag under FOLDER/<test id>; keep '
                         f'those of failed tests (also: {RECORD_FAILED}=FOLDER)')
    group.addoption('--ros-domain-base', metavar='ID', type=int, default=None,
                    help='under pytest-xdist, worker N uses ROS_DOMAIN_ID ID+N (default: the '
                         'ROS_DOMAIN_ID pytest was started with, else 0)')


def bag_folder_of(root: Path, nodeid: str) -> Path:
    """Return the folder of a test's bags under ``root``: its node id made a file name."""
    return root / _UNSAFE.sub('_', nodeid).strip('_')


def worker_domain(base: int, worker_id: str) -> int:
    """Return the ROS domain of xdist worker ``worker_id`` (``gw3``): ``base`` + its number."""
    match = _WORKER_NUMBER.search(worker_id)
    if match is None:
        raise pytest.UsageError(f'cannot tell the number of xdist worker {worker_id!r}')
    domain = base + int(match.group(1))
    if not 0 <= domain <= MAX_DOMAIN_ID:
        raise pytest.UsageError(
            f'xdist worker {worker_id} would use ROS_DOMAIN_ID {domain}: keep '
            f'--ros-domain-base + workers <= {MAX_DOMAIN_ID}')
    return domain


def domain_base(config: pytest.Config) -> int:
    """Return the first worker's domain: --ros-domain-base, else ROS_DOMAIN_ID, else 0."""
    given = config.getoption('ros_domain_base')
    if given is not None:
        return given
    return int(os.environ.get(DOMAIN_ENV) or 0)


class _XdistController:
    """Hands each worker the domain base chosen in the controller (xdist's hook)."""

    def __init__(self, base: int) -> None:
        self.base = base

    def pytest_configure_node(self, node: Any) -> None:
        node.workerinput['pan_tilt_sim_domain_base'] = self.base


def pytest_configure(config: pytest.Config) -> None:
    """In xdist's controller: have the workers told the domain base chosen here."""
    if getattr(config, 'workerinput', None) is None and config.pluginmanager.hasplugin('xdist'):
        config.pluginmanager.register(_XdistController(domain_base(config)),
                                      'pan_tilt_sim_xdist_domains')


def uses_the_plugin(session: pytest.Session) -> bool:
    """Whether this session asks for the plugin: a test uses its fixtures, or --ros-domain-base."""
    return session.config.getoption('ros_domain_base') is not None or any(
        FIXTURES & set(getattr(item, 'fixturenames', ())) for item in session.items)


@pytest.hookimpl(tryfirst=True)
def pytest_collection_finish(session: pytest.Session) -> None:
    """Before the first test: loopback DDS unless told otherwise, one domain per xdist worker.

    Only where the session uses the plugin: other projects' test runs stay as they were.
    """
    if not uses_the_plugin(session):
        return
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    workerinput = getattr(session.config, 'workerinput', None)
    if workerinput is not None:
        base = workerinput.get('pan_tilt_sim_domain_base')
        if base is None:
            base = domain_base(session.config)
        os.environ[DOMAIN_ENV] = str(worker_domain(base, workerinput['workerid']))


def record_root(config: pytest.Config) -> Path | None:
    """Return where failed tests' bags go: --sim-record-failed, else the environment."""
    folder = config.getoption('sim_record_failed') or os.environ.get(RECORD_FAILED)
    return Path(folder) if folder else None


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo) -> Iterator[None]:
    """Remember each phase's report; name the bags of a failed test in its report."""
    outcome = yield
    report = outcome.get_result()
    item.stash[_phase_key(report.when)] = report
    bags = item.stash.get(_BAGS_KEY, None)
    if report.failed and bags:
        report.sections.append(('pan_tilt_sim bags', '\n'.join(
            f'kept the run of this test as a bag: {bag}' for bag in bags)))


_PHASE_KEYS: dict[str, pytest.StashKey] = {}


def _phase_key(when: str) -> pytest.StashKey:
    return _PHASE_KEYS.setdefault(when, pytest.StashKey[Any]())


def _failed(item: pytest.Item) -> bool:
    return any(getattr(item.stash.get(_phase_key(when), None), 'failed', False)
               for when in ('setup', 'call'))


class SimFactory:
    """The ``sim`` fixture: makes simulation handles and closes them after the test.

    ``in_process``: False makes the handles of ``sim_process`` (sim_node as a program).
    """

    def __init__(self, request: pytest.FixtureRequest, *, in_process: bool = True) -> None:
        import rclpy
        from rclpy.signals import SignalHandlerOptions
        from rclpy.utilities import get_default_context

        self.context = get_default_context()
        # The test's rclpy, unless it started its own: then it is the test's to shut down.
        # pytest keeps its own handling of Ctrl-C.
        self._owns_context = not self.context.ok()
        if self._owns_context:
            rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
        self._request = request
        self._in_process = in_process
        self._handles: list[Any] = []
        root = record_root(request.config)
        self._bag_folder = bag_folder_of(root, request.node.nodeid) if root else None
        self.bags: list[Path] = []
        request.node.stash[_BAGS_KEY] = self.bags

    def __call__(self, robot: str | Path | None = None, controllers: str | Path | None = None,
                 world: str | Path | None = None, parameters: Mapping[str, Any] | None = None,
                 *, namespace: str | None = None, turn: float | None = None) -> Any:
        """Start a paused simulation; with no arguments the pan/tilt example.

        ``robot``, ``controllers`` and ``world``: paths or ``package://`` URIs
        (``world`` also a scenery name); ``parameters``: more sim_node
        parameters; ``turn``: sim seconds run between two spins of the executor.
        """
        from pan_tilt_sim.tools.sim_handle import SimHandle, sim_parameters
        from pan_tilt_sim.tools.sim_helpers import DEFAULT_TURN_S
        from pan_tilt_sim.tools.sim_process_handle import SimProcessHandle

        values = sim_parameters(robot, controllers, world, parameters)
        if self._bag_folder is not None and 'record' not in values:
            bag = self._bag_folder / f'sim_{len(self._handles)}'
            self._bag_folder.mkdir(parents=True, exist_ok=True)
            values['record'] = str(bag)
            self.bags.append(bag)
        kind = SimHandle if self._in_process else SimProcessHandle
        handle = kind(self.context, values, namespace=namespace,
                           turn=DEFAULT_TURN_S if turn is None else turn)
        self._handles.append(handle)
        return handle

    def close(self) -> None:
        """Close every handle (newest first), shut rclpy down if the fixture started it."""
        import rclpy

        try:
            for handle in reversed(self._handles):
                handle.close()
        finally:
            if self._owns_context:
                # Without a context argument rclpy also puts a fresh default context in
                # place of the one shut down, for the next test's rclpy.init().
                rclpy.try_shutdown()
        if self._bag_folder is not None and not _failed(self._request.node):
            shutil.rmtree(self._bag_folder, ignore_errors=True)
            self.bags.clear()


@pytest.fixture
def sim(request: pytest.FixtureRequest) -> Iterator[SimFactory]:
    """Yield the factory of paused simulations in the test's own process."""
    factory = SimFactory(request)
    try:
        yield factory
    finally:
        factory.close()


@pytest.fixture
def sim_process(request: pytest.FixtureRequest) -> Iterator[SimFactory]:
    """Yield a factory of paused sim_node programs in child processes, helpers as ``sim``'s.

    Independent of launch_pytest: its fixtures may start the test's other nodes beside it.
    """
    factory = SimFactory(request, in_process=False)
    try:
        yield factory
    finally:
        factory.close()
