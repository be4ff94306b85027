"""Rigid transforms and quaternions: URDF rpy, composition, round trips."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from pan_tilt_sim.model.transforms import (
    Transform,
    quaternion_from_axis_angle,
    quaternion_from_matrix,
    quaternion_from_rpy,
    rotation_matrix,
)


def close_rotation(a, b, tolerance=1e-6):
    """Whether quaternions ``a`` and ``b`` are the same rotation (q and -q are)."""
    dot = abs(sum(x * y for x, y in zip(a, b, strict=True)))
    return dot == pytest.approx(1.0, abs=tolerance)


def test_rpy_is_urdf_fixed_axis_roll_then_pitch_then_yaw():
    q = quaternion_from_rpy(0.3, -0.2, 1.1)
    expected = rotation_matrix(quaternion_from_axis_angle((0, 0, 1), 1.1))
    for axis, angle in (((0, 1, 0), -0.2), ((1, 0, 0), 0.3)):
        step = rotation_matrix(quaternion_from_axis_angle(axis, angle))
        expected = tuple(tuple(sum(expected[r][k] * step[k][c] for k in range(3))
                               for c in range(3)) for r in range(3))
    for got, want in zip(rotation_matrix(q), expected, strict=True):
        assert got == pytest.approx(want, abs=1e-12)


@given(st.floats(-math.pi, math.pi), st.floats(-1.5, 1.5), st.floats(-math.pi, math.pi))
def test_a_quaternion_survives_the_round_trip_through_its_matrix(roll, pitch, yaw):
    q = quaternion_from_rpy(roll, pitch, yaw)
    rows = rotation_matrix(q)
    columns = tuple(tuple(rows[r][c] for r in range(3)) for c in range(3))
    assert close_rotation(quaternion_from_matrix(columns), q)


def test_a_transform_composes_rotation_then_translation():
    quarter_turn = Transform((1.0, 0.0, 0.0), quaternion_from_axis_angle((0, 0, 1), math.pi / 2))
    assert quarter_turn.apply((1.0, 0.0, 0.0)) == pytest.approx((1.0, 1.0, 0.0))
    twice = quarter_turn.then(quarter_turn)
    # (1,0,0) -> inner: (0,1,0) + (1,0,0) = (1,1,0) -> outer: (-1,1,0) + (1,0,0)
    assert twice.apply((1.0, 0.0, 0.0)) == pytest.approx((0.0, 1.0, 0.0), abs=1e-12)
