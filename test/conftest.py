"""Shared test set-up: DDS on loopback, one ROS domain per test process."""

import os
import pathlib
import sys

import pytest

# Keep DDS traffic on loopback and give each pytest process (an xdist worker,
# or a second test run on the same machine) its own domain, so concurrent runs
# never hear each other's sim_nodes.  Child processes inherit it.  The tests
# take 30..129, clear of the low ids people use by hand and of the bench's own
# pid-derived range (pan_tilt_sim.tools.bench.PID_DOMAIN_BASE, 150..229).
# PAN_TILT_SIM_TEST_DOMAIN pins it.
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
_DOMAIN_BASE, _DOMAIN_SPAN = 30, 100
os.environ['ROS_DOMAIN_ID'] = os.environ.get(
    'PAN_TILT_SIM_TEST_DOMAIN', str(_DOMAIN_BASE + os.getpid() % _DOMAIN_SPAN))
# Ray (tune/sweep tests) on loopback only, and no usage reports: on Linux Ray
# otherwise puts its nodes on the machine's network address.  Read by Ray at
# import, so set before any test imports it.
os.environ['RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER'] = '0'
os.environ['RAY_USAGE_STATS_ENABLED'] = '0'
# ament index look-ups find the package installed into this environment.
_prefixes = [p for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
if sys.prefix not in _prefixes:
    os.environ['AMENT_PREFIX_PATH'] = os.pathsep.join([sys.prefix, *_prefixes])

REPO_ROOT = pathlib.Path(__file__).resolve().parents[1]
# The helpers every test folder shares (harnesses, clients, URDF/YAML builders) live in
# test/support/ and are imported by their bare names (`from node_harness import sim_node`)
# from any folder; a helper that serves one folder sits beside its tests instead.
SUPPORT = REPO_ROOT / 'test' / 'support'
if str(SUPPORT) not in sys.path:
    sys.path.insert(0, str(SUPPORT))

# PAN_TILT_SIM_RECORD_FAILED=<folder> keeps the bags of failed tests (see record_failed.py).
pytest_plugins = ['record_failed']
ORIGINAL_EXAMPLES = REPO_ROOT / 'test' / 'data' / 'original_examples'


@pytest.fixture
def original_examples() -> pathlib.Path:
    """Return the folder of the examples' original files (see its README.md)."""
    return ORIGINAL_EXAMPLES


@pytest.fixture
def repo_root() -> pathlib.Path:
    """Return the source checkout's root folder."""
    return REPO_ROOT


def pytest_configure(config: pytest.Config) -> None:
    """Register the opt-in markers: minutes-long tests, off unless asked for."""
    config.addinivalue_line(
        'markers', 'soak: flood and soak tests (minutes); run only with PAN_TILT_SIM_SLOW=1')
    config.addinivalue_line(
        'markers', 'fuzz: thousands of fuzzed inputs (minutes); run only with '
        'PAN_TILT_SIM_SLOW=1')
    config.addinivalue_line(
        'markers', 'matrix: the whole consistency matrix (every drive, root link and sensor '
                   'mount; minutes); run only with PAN_TILT_SIM_MATRIX=1')


@pytest.fixture
def context():
    """Return a fresh, initialised rclpy Context, shut down after the test."""
    import rclpy
    from rclpy.context import Context

    context = Context()
    rclpy.init(context=context)
    yield context
    rclpy.try_shutdown(context=context)


@pytest.fixture
def client():
    """Yield a private PyBullet DIRECT client id; disconnect it afterwards."""
    import pybullet

    client_id = pybullet.connect(pybullet.DIRECT)
    yield client_id
    pybullet.disconnect(physicsClientId=client_id)


@pytest.fixture
def cache_dir(tmp_path):
    """Return a cache folder for converted meshes (not created yet)."""
    return tmp_path / 'cache'


@pytest.fixture
def my_robot_share(tmp_path, monkeypatch, original_examples):
    """Install the my_robot example's package into a temporary prefix; return its share folder."""
    import mesh_fixtures as mf

    prefix = mf.make_my_robot_package(tmp_path, original_examples / 'my_robot.urdf')
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(prefix))
    return prefix / 'share' / mf.MY_ROBOT_PACKAGE
