"""Shared test set-up: DDS on loopback, one ROS domain per test process."""

import os
import pathlib
import sys

import pytest

# Keep DDS traffic on loopback and give each pytest process (xdist worker)
# its own domain so parallel runs never hear each other.
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
_WORKER = os.environ.get('PYTEST_XDIST_WORKER', 'gw0')
_DOMAIN_BASE = 40
os.environ.setdefault(
    'ROS_DOMAIN_ID', str(_DOMAIN_BASE + int(''.join(c for c in _WORKER if c.isdigit()) or 0)))
# ament index look-ups find the package installed into this environment.
_prefixes = [p for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
if sys.prefix not in _prefixes:
    os.environ['AMENT_PREFIX_PATH'] = os.pathsep.join([sys.prefix, *_prefixes])

REPO_ROOT = pathlib.Path(__file__).resolve().parents[1]
SEEDS_RESTORED = REPO_ROOT.parent / 'shared' / 'seeds' / 'restored'


@pytest.fixture
def seeds_dir() -> pathlib.Path:
    """Return the seeds' restored files, or skip where the folder is absent."""
    if not SEEDS_RESTORED.is_dir():
        pytest.skip(f'seed files not found: {SEEDS_RESTORED} is absent '
                    '(a user clone has no ../shared)')
    return SEEDS_RESTORED


@pytest.fixture
def repo_root() -> pathlib.Path:
    """Return the source checkout's root folder."""
    return REPO_ROOT


def pytest_configure(config: pytest.Config) -> None:
    """Register the ``soak`` marker: minutes-long flood/soak tests, off unless asked for."""
    config.addinivalue_line(
        'markers', 'soak: flood and soak tests (minutes); run only with PAN_TILT_SIM_SLOW=1')


@pytest.fixture
def context():
    """Return a fresh, initialised rclpy Context, shut down after the test."""
    import rclpy
    from rclpy.context import Context

    context = Context()
    rclpy.init(context=context)
    yield context
    rclpy.try_shutdown(context=context)
