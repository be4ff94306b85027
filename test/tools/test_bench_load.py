"""bench --load: what spawned objects and world files cost, as one JSON object."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from pan_tilt_sim.model.entity_resource import MAX_ENTITY_LINKS, read_entity_resource
from pan_tilt_sim.model.world_file import MAX_WORLD_ENTITIES
from pan_tilt_sim.tools import bench_load


@pytest.fixture(scope='module')
def quick_run() -> dict:
    done = subprocess.run([sys.executable, '-m', 'pan_tilt_sim.tools.bench', '--load',
                           '--quick'], capture_output=True, text=True, timeout=300, check=True)
    return json.loads(done.stdout)


def test_quick_reports_each_chain_and_world_with_every_figure(quick_run):
    assert set(quick_run) == {'chains', 'world'}
    for links in bench_load.QUICK_CHAIN_LINKS:
        figures = quick_run['chains'][str(links)]
        expected = {'read_s', 'pybullet_load_s', 'state_reported'}
        if links <= bench_load.STEPPED_LINKS:
            expected |= {'trial_s', 'add_s', 'step_us'}
        else:
            expected |= {'first_step_s'}
        assert set(figures) == expected, links
        assert all(value >= 0 for value in figures.values() if value is not True)
    for count in bench_load.QUICK_WORLD_ENTITIES:
        assert set(quick_run['world'][str(count)]) == {
            'read_s', 'spawn_s', 'startup_ms_per_entity', 'step_us', 'step_us_per_entity'}


def test_pybullet_reports_the_state_of_a_chain_at_the_link_limit_and_not_past_it(quick_run):
    assert quick_run['chains']['16']['state_reported'] is True
    assert quick_run['chains']['256']['state_reported'] is False
    assert bench_load.STEPPED_LINKS == MAX_ENTITY_LINKS


def test_the_generated_chain_and_world_are_what_they_say():
    chain = read_entity_resource(resource_string=bench_load.chain_urdf(5))
    assert len(chain.model.links) == 5 and len(chain.model.actuated_joints) == 4
    assert bench_load.world_yaml(3).count('shape: box') == 3
    assert max(bench_load.WORLD_ENTITIES) > MAX_WORLD_ENTITIES  # past the limit: measured
