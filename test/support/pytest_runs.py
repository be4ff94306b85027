"""pytest run as a child process in a folder of its own: only the installed plugin at work.

For the plugin's tests: the child has its own rootdir (no conftest of this
suite), no cache, and this folder on PYTHONPATH for shared scenarios.
"""

from __future__ import annotations

import os
import pathlib
import subprocess
import sys
import textwrap

from pan_tilt_sim.tools import pytest_plugin

PYTEST = pathlib.Path(sys.executable).parent / 'pytest'
TEST_DIR = pathlib.Path(__file__).resolve().parent
RUN_BUDGET_S = 300.0
# Child runs under -n 2 take two domains from 130..149, clear of this suite's
# 30..129 and of the benchmark's 150..229.
SPARE_DOMAIN_BASE, SPARE_DOMAIN_PAIRS = 130, 10


def spare_domain_base() -> int:
    """The first of two ROS domains for a child pytest run's workers."""
    return SPARE_DOMAIN_BASE + 2 * (os.getpid() % SPARE_DOMAIN_PAIRS)


def run_pytest(folder: pathlib.Path, *args: str, env: dict[str, str] | None = None,
               unset: tuple[str, ...] = ()) -> subprocess.CompletedProcess:
    """Run pytest in ``folder`` (its own rootdir, no cache) and return what it did."""
    environment = {name: value for name, value in os.environ.items() if name not in unset}
    environment['PYTHONPATH'] = os.pathsep.join(
        [str(TEST_DIR), *filter(None, environment.get('PYTHONPATH', '').split(os.pathsep))])
    environment.pop(pytest_plugin.RECORD_FAILED, None)
    environment.update(env or {})
    return subprocess.run(
        [str(PYTEST), '-p', 'no:cacheprovider', '--rootdir', str(folder), *args],
        cwd=folder, env=environment, capture_output=True, text=True, timeout=RUN_BUDGET_S,
        check=False)


def write_tests(folder: pathlib.Path, name: str, text: str) -> pathlib.Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / 'pytest.ini').write_text('[pytest]\n')
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return path
