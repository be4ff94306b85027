"""A pytest plugin: with ``PAN_TILT_SIM_RECORD_FAILED=<folder>``, keep each failed test's runs.

Every SimNode that :func:`node_harness.sim_node` starts during a test then
records its run (``record:=<folder>/<test id>/sim_node_<n>``); the bags of a
test that passed are removed after it, those of a test that failed (in its
set-up or its body) stay, to open with ``ros2 bag info``/``play``, Foxglove
or PlotJuggler.  Nodes made by fixtures wider than one test are not recorded.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

# The variable and the folder layout of the installed pytest plugin's sim fixture.
from pan_tilt_sim.tools.pytest_plugin import RECORD_FAILED, bag_folder_of

__all__ = ['RECORD_FAILED', 'bag_folder_of']


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo) -> Iterator[None]:
    """Remember each phase's report on the test item (the fixture below reads them)."""
    outcome = yield
    report = outcome.get_result()
    setattr(item, f'_record_failed_{report.when}', report)


@pytest.fixture(autouse=True)
def _record_failed_tests(request: pytest.FixtureRequest) -> Iterator[None]:
    root = os.environ.get(RECORD_FAILED)
    if not root:
        yield
        return
    import node_harness

    folder = bag_folder_of(Path(root), request.node.nodeid)
    with node_harness.recording_into(folder):
        yield
    failed = any(getattr(getattr(request.node, f'_record_failed_{when}', None), 'failed', False)
                 for when in ('setup', 'call'))
    if not failed:
        shutil.rmtree(folder, ignore_errors=True)
