"""What create and spawn_entity.py share: waiting on the simulation ends when they are stopped."""

from __future__ import annotations

from interrupting import interrupted_after_check


def test_a_wait_interrupted_between_its_check_and_its_spin_ends_unfulfilled():
    result = interrupted_after_check(
        'from pan_tilt_sim.tools.stand_ins.spawning import spin_for\n',
        'assert spin_for(node, 30.0, lambda: False) is False')
    assert (result.returncode, result.stdout) == (0, 'returned\n'), result.stderr
