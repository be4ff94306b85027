"""sim_node's fixed_base and initial_pose, parsed."""

from __future__ import annotations

import math

import pytest

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.base_pose import ORIGIN, BasePose, parse_fixed_base, parse_initial_pose


@pytest.mark.parametrize('value, expected', [
    ('auto', None), ('true', True), ('false', False), ('AUTO', None), (True, True),
    (False, False)])
def test_fixed_base_is_auto_true_or_false_as_text_or_bool(value, expected):
    assert parse_fixed_base(value) is expected


@pytest.mark.parametrize('value', ['yes', '', 1])
def test_any_other_fixed_base_names_the_parameter_and_the_choices(value):
    with pytest.raises(ParameterError, match=r"^parameter 'fixed_base' must be one of auto, "
                                             'true, false'):
        parse_fixed_base(value)


def test_an_initial_pose_is_x_y_z_yaw_and_unset_is_the_origin():
    assert parse_initial_pose([1.0, -2, 0.5, math.pi]) == BasePose(1.0, -2.0, 0.5, math.pi)
    assert parse_initial_pose(None) is ORIGIN and parse_initial_pose([]) is ORIGIN
    assert ORIGIN.is_origin and not BasePose(x=1.0).is_origin


@pytest.mark.parametrize('value', [[1.0, 2.0], [1.0, 2.0, 3.0, 4.0, 5.0],
                                   [0.0, math.nan, 0.0, 0.0], [0.0, 0.0, 0.0, True]])
def test_an_initial_pose_that_is_not_four_finite_numbers_names_the_parameter(value):
    with pytest.raises(ParameterError, match=r"^parameter 'initial_pose' must be four finite "
                                             r'numbers \[x, y, z, yaw\]'):
        parse_initial_pose(value)
