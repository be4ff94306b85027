"""mimic: which joint follows which, and where followers sit for given leader positions."""

import pytest

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.mimic import MimicCoupling, follow_leaders, mimic_couplings
from pan_tilt_sim.model.robot import JointKind, JointSpec, Mimic


def joint(name, mimic=None):
    return JointSpec(name, JointKind.REVOLUTE, -3.0, 3.0, mimic=mimic)


def test_couplings_list_leaders_before_their_followers_along_chains():
    joints = [joint('c', Mimic('b', 2.0, 0.1)), joint('b', Mimic('a', -1.0)), joint('a')]
    assert mimic_couplings(joints) == (
        MimicCoupling('b', 'a', -1.0, 0.0), MimicCoupling('c', 'b', 2.0, 0.1))


def test_follow_leaders_resolves_chains():
    joints = [joint('c', Mimic('b', 2.0, 0.1)), joint('b', Mimic('a', -1.0)), joint('a')]
    names = [j.name for j in joints]
    positions = follow_leaders(names, [9.0, 9.0, 0.5], mimic_couplings(joints))
    assert positions == pytest.approx([2.0 * -0.5 + 0.1, -0.5, 0.5])


def test_a_cycle_is_a_description_error_naming_it():
    joints = [joint('a', Mimic('b')), joint('b', Mimic('a'))]
    with pytest.raises(DescriptionError,
                       match=r'robot.urdf: mimic joints form a cycle: a -> b -> a'):
        mimic_couplings(joints, 'robot.urdf')


def test_a_leader_that_is_not_movable_is_a_description_error():
    with pytest.raises(DescriptionError, match="'a' mimics 'weld', which is not a movable"):
        mimic_couplings([joint('a', Mimic('weld'))])


def test_no_mimic_joints_no_couplings():
    assert mimic_couplings([joint('a'), joint('b')]) == ()
