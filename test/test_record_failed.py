"""PAN_TILT_SIM_RECORD_FAILED: a failed test's runs stay as bags; a passed test's go.

An inner pytest session (a child process) runs one passing and one failing
test that each start a SimNode through the harness; afterwards only the
failing test's folder is left, holding a complete bag of its run.
"""

from __future__ import annotations

import os
import pathlib
import subprocess
import sys

import yaml
from record_failed import RECORD_FAILED, bag_folder_of

SUPPORT = pathlib.Path(__file__).resolve().parent / 'support'
INNER_TESTS = '''
from node_harness import sim_node


def test_passes():
    with sim_node() as sim:
        sim.run_until_sim_time(0.1)


def test_fails():
    with sim_node() as sim:
        sim.run_until_sim_time(0.1)
    assert False, 'fails on purpose'
'''


def test_only_the_failed_tests_bag_is_kept(tmp_path):
    inner = tmp_path / 'inner'
    inner.mkdir()
    (inner / 'conftest.py').write_text("pytest_plugins = ['record_failed']\n")
    (inner / 'test_inner.py').write_text(INNER_TESTS)
    bags = tmp_path / 'bags'
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        filter(None, [str(SUPPORT), os.environ.get('PYTHONPATH')])))
    env[RECORD_FAILED] = str(bags)
    result = subprocess.run(
        [sys.executable, '-m', 'pytest', '-q', '-p', 'no:cacheprovider', '-p', 'no:xdist',
         str(inner / 'test_inner.py')],
        cwd=inner, env=env, capture_output=True, text=True, timeout=240, check=False)
    assert result.returncode == 1, result.stdout + result.stderr
    assert '1 failed, 1 passed' in result.stdout
    failed = bag_folder_of(bags, 'test_inner.py::test_fails')
    assert [path.name for path in bags.iterdir()] == [failed.name]
    (bag,) = failed.iterdir()
    assert bag.name == 'sim_node_0'
    info = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    counts = {entry['topic_metadata']['name']: entry['message_count']
              for entry in info['topics_with_message_count']}
    assert counts['/ex_urdf_pan_tilt/joint_states'] >= 5
