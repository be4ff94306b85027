"""TwistCommand: the twist a drive takes from its topic, refused when not finite or stale."""

from __future__ import annotations

import math

import pytest

from pan_tilt_sim.controllers.framework.base import CommandResult, Reference
from pan_tilt_sim.controllers.framework.surface import StampedTwist
from pan_tilt_sim.controllers.toolbox.twist_command import TwistCommand, twist_references

ACCEPTED, REJECTED = CommandResult.ACCEPTED, CommandResult.REJECTED


def twist(vx: float, vy: float, wz: float, stamp: float = 0.0) -> StampedTwist:
    """Return a twist with every part set, the parts no drive counts too."""
    return StampedTwist(stamp, (vx, vy, 5.0), (6.0, 7.0, wz))


def test_an_accepted_twist_is_kept_planar_with_its_stamp():
    command = TwistCommand('cmd_vel', sideways=True)
    assert command.take(twist(1.0, 2.0, 3.0, stamp=4.0), now=4.5) is ACCEPTED
    assert command.latest == StampedTwist(4.0, (1.0, 2.0, 0.0), (0.0, 0.0, 3.0))


def test_without_sideways_linear_y_is_dropped_and_not_checked():
    command = TwistCommand('cmd_vel')
    assert command.take(twist(1.0, math.nan, 3.0)) is ACCEPTED
    assert command.latest == StampedTwist(0.0, (1.0, 0.0, 0.0), (0.0, 0.0, 3.0))


def test_an_unstamped_twist_is_stamped_now():
    command = TwistCommand('reference', sideways=True)
    command.take(twist(1.0, 0.0, 0.0), now=2.5)
    assert command.latest.stamp == 2.5


@pytest.mark.parametrize('sideways, bad, text', [
    (False, twist(math.inf, 0.0, 0.0), 'ignored cmd_vel (linear.x inf, angular.z 0.0): '
                                       'not finite numbers'),
    (False, twist(0.0, 0.0, math.nan), 'ignored cmd_vel (linear.x 0.0, angular.z nan): '
                                       'not finite numbers'),
    (True, twist(0.0, -math.inf, 0.0), 'ignored cmd_vel (linear.x 0.0, linear.y -inf, '
                                       'angular.z 0.0): not finite numbers'),
])
def test_a_twist_with_a_counted_part_not_finite_is_refused_and_named(sideways, bad, text):
    command = TwistCommand('cmd_vel', sideways=sideways)
    command.take(twist(1.0, 0.0, 0.0))
    assert command.take(bad) is REJECTED
    assert command.problem(bad, REJECTED) == text
    assert command.latest.linear[0] == 1.0  # the last accepted twist stays


@pytest.mark.parametrize('stale_at_timeout, age, result', [
    (False, 0.5, ACCEPTED), (False, 0.75, REJECTED),
    (True, 0.25, ACCEPTED), (True, 0.5, REJECTED),
])
def test_a_twist_older_than_the_timeout_is_refused(stale_at_timeout, age, result):
    command = TwistCommand('reference', sideways=True, timeout_field='reference_timeout',
                           stale_at_timeout=stale_at_timeout)
    value = twist(1.0, 0.0, 0.0, stamp=2.0)
    assert command.take(value, now=2.0 + age, timeout=0.5) is result
    if result is REJECTED:
        assert command.problem(value, result) == (
            f'ignored reference stamped 2.0000 s: {age:.4f} s old at sim time '
            f'{2.0 + age:.4f} s, more than reference_timeout (0.5 s)')
        assert command.latest is None


def test_a_zero_timeout_refuses_no_old_twist():
    command = TwistCommand('cmd_vel', stale_at_timeout=True)
    assert command.take(twist(1.0, 0.0, 0.0, stamp=1.0), now=100.0, timeout=0.0) is ACCEPTED


def test_twist_references_are_the_three_velocity_interfaces_in_upstreams_order():
    references = twist_references('base')
    assert list(references) == ['base/linear/x/velocity', 'base/linear/y/velocity',
                                'base/angular/z/velocity']
    assert all(isinstance(ref, Reference) and ref.name == name
               for name, ref in references.items())


def test_the_planar_command_is_the_latest_twists_or_standing_still():
    command = TwistCommand('cmd_vel')
    assert command.planar() == (0.0, 0.0)
    command.take(twist(1.0, 2.0, 3.0))
    assert command.planar() == (1.0, 3.0)
    command.take(twist(math.inf, 0.0, 0.0))  # refused: the last one holds
    assert command.planar() == (1.0, 3.0)
    command.latest = None
    assert command.planar() == (0.0, 0.0)
