"""Joint limits as joint_limits_interface applies them: clamp and saturate."""

import math

import pytest

from pan_tilt_sim.controllers.framework.base import CommandResult
from pan_tilt_sim.controllers.toolbox.limits import (
    PositionLimits,
    check_effort,
    check_velocity,
    clamp_effort,
)
from pan_tilt_sim.model.robot import JointKind, JointSpec

PAN = JointSpec('pan_joint', JointKind.REVOLUTE, lower=-3.14, upper=3.14,
                effort_limit=300.0, velocity_limit=0.1, damping=50.0, friction=1.0)
TILT = JointSpec('tilt_joint', JointKind.REVOLUTE, lower=-4.71239, upper=-1.570796,
                 effort_limit=300.0, velocity_limit=0.1)
WHEEL = JointSpec('wheel', JointKind.CONTINUOUS, velocity_limit=2.0, effort_limit=5.0)


def test_position_commands_in_range_are_accepted():
    assert PositionLimits(PAN).check(1.0) == (1.0, CommandResult.ACCEPTED)


def test_position_commands_out_of_range_are_clamped_to_the_urdf_limits():
    assert PositionLimits(TILT).check(0.0) == (-1.570796, CommandResult.CLAMPED)
    assert PositionLimits(TILT).check(-9.0) == (-4.71239, CommandResult.CLAMPED)


@pytest.mark.parametrize('value', [math.nan, math.inf, -math.inf])
def test_non_finite_commands_are_rejected(value):
    assert PositionLimits(PAN).check(value)[1] is CommandResult.REJECTED
    assert check_velocity(PAN, value)[1] is CommandResult.REJECTED
    assert check_effort(PAN, value)[1] is CommandResult.REJECTED


def test_continuous_joints_have_no_position_clamp_and_are_not_wrapped():
    assert PositionLimits(WHEEL).check(12.5) == (12.5, CommandResult.ACCEPTED)


def test_velocity_and_effort_commands_saturate_at_their_limits():
    assert check_velocity(PAN, 0.5) == (0.1, CommandResult.CLAMPED)
    assert check_effort(PAN, -1000.0) == (-300.0, CommandResult.CLAMPED)
    assert check_effort(PAN, 50.0) == (50.0, CommandResult.ACCEPTED)
    assert clamp_effort(301.0, 300.0) == 300.0
