"""PyBullet's solver settings as parameters: PyBullet's own defaults, and what each takes."""

import math

import pytest

from pan_tilt_sim.model.physics_settings import (
    DEFAULT_PHYSICS,
    MAX_SOLVER_ITERATIONS,
    NAMES,
    setting_problem,
)


def test_the_settings_are_named_as_the_parameters_and_default_to_pybullets_own():
    assert NAMES == ('solver_iterations', 'erp', 'contact_erp', 'cfm', 'contact_slop',
                     'split_impulse')
    # PyBullet 3.2.7's: 50 iterations, erp 0.2, contactERP 0.08, no CFM, slop 1e-5, split
    # impulse on (test/sim/test_physics.py checks that setting them changes nothing).
    assert [getattr(DEFAULT_PHYSICS, name) for name in NAMES] == [50, 0.2, 0.08, 0.0, 1e-5,
                                                                   True]


@pytest.mark.parametrize(('name', 'value'), [
    ('solver_iterations', 1), ('solver_iterations', MAX_SOLVER_ITERATIONS), ('erp', 0.0),
    ('erp', 1.0), ('contact_erp', 0.5), ('cfm', 0.0), ('cfm', 2), ('contact_slop', 0.01),
    ('split_impulse', False),
])
def test_values_pybullet_takes_are_accepted(name, value):
    assert setting_problem(name, value) is None


@pytest.mark.parametrize(('name', 'value', 'problem'), [
    ('solver_iterations', 0, 'must be a whole number from 1 to 10000, got 0'),
    ('solver_iterations', 10_001, 'must be a whole number from 1 to 10000, got 10001'),
    ('solver_iterations', 20.0, 'must be a whole number from 1 to 10000, got 20.0'),
    ('solver_iterations', True, 'must be a whole number from 1 to 10000, got True'),
    ('erp', 1.5, 'must be from 0 to 1 (a share of the error per step), got 1.5'),
    ('contact_erp', -0.1, 'must be from 0 to 1 (a share of the error per step), got -0.1'),
    ('cfm', -1e-9, 'must be >= 0, got -1e-09'),
    ('cfm', math.inf, 'must be a finite number, got inf'),
    ('contact_slop', math.nan, 'must be a finite number, got nan'),
    ('contact_slop', 'a', "must be a finite number, got 'a'"),
    ('split_impulse', 1, 'must be a bool, got 1'),
])
def test_values_pybullet_cannot_take_are_refused_naming_the_parameter(name, value, problem):
    assert setting_problem(name, value) == f"parameter '{name}' {problem}"
