"""The drive kinds of the physics, each alone: which joints they take and what they send.

:class:`~pan_tilt_sim.sim.physics.Physics` composes them; test_damping.py and
the bit-identity tests check the whole in PyBullet.  These need no PyBullet.
"""

import pytest

from pan_tilt_sim.model.robot import JointKind, JointSpec
from pan_tilt_sim.sim.physics import (
    UNLIMITED_FORCE,
    GainDamping,
    ImplicitDamping,
    MotorRows,
    split_drives,
    static_rows,
)

DT = 0.01  # s
INERTIA = 0.1  # kg m^2, every joint's smallest effective inertia


def joint(name: str, damping: float = 0.0, friction: float = 0.0,
          effort_limit: float = float('inf')) -> JointSpec:
    return JointSpec(name, JointKind.REVOLUTE, damping=damping, friction=friction,
                     effort_limit=effort_limit)


JOINTS = [
    joint('motor', damping=5.0, friction=1.0, effort_limit=20.0),  # velocity-driven
    joint('light', damping=0.001, friction=0.3),  # 0.001 * 0.01 <= 0.1 * 0.1: explicit
    joint('heavy', damping=5.0),  # 5 * 0.01 > 0.1 * 0.1: implicit, damping alone
    joint('sticky', damping=5.0, friction=0.5),  # implicit, with friction
    joint('leader', damping=5.0),  # implicit: a mimic couples it
    joint('free'),  # neither
    joint('rough', friction=0.2),  # friction alone
]
DRIVEN = [True] + [False] * 6


def split(coupled=('leader',)):
    return split_drives(JOINTS, DRIVEN, DT, lambda: [INERTIA] * len(JOINTS), coupled)


def test_each_joint_takes_the_drive_its_damping_and_friction_need():
    drives = split()
    assert drives.velocity == [0]
    assert drives.effort == [1, 2, 3, 4, 5, 6]
    assert drives.explicit == [1]
    assert drives.damped == [2]
    assert drives.implicit == [3, 4]
    assert drives.frictional == [1, 6]
    assert drives.plain == [5]


def test_a_joint_no_mimic_couples_takes_the_velocity_gain():
    assert split(coupled=()).damped == [2, 4]


def test_inertias_are_computed_only_when_an_effort_joint_has_damping():
    def never():
        raise AssertionError('inertias computed without damping')
    drives = split_drives([joint('a', friction=0.1), joint('b', damping=1.0)], [False, True],
                          DT, never, ())
    assert drives.frictional == [0] and drives.velocity == [1]


def test_one_drive_per_joint_is_required():
    with pytest.raises(ValueError, match='1 drives for 7 joints'):
        split_drives(JOINTS, [True], DT, lambda: [1.0] * 7, ())


def test_rows_sent_once_hold_with_friction_or_not_at_all():
    assert static_rows(JOINTS, split()) == [(1, 0.3), (6, 0.2), (5, 0.0), (0, 0.0)]


def implicit_drive(inertia=2.0, damping=1.0, friction=0.5):
    drive = ImplicitDamping([joint('a', damping=damping, friction=friction)], [0], [0], 1)
    drive.refresh([inertia], DT)
    return drive


def state(velocity, torque=0.0):
    return (0.0, velocity, (0.0,) * 6, torque)


def test_the_motor_resists_with_friction_plus_damping_at_the_implicit_end_speed():
    inertia, damping, friction = 2.0, 1.0, 0.5
    drive = implicit_drive(inertia, damping, friction)
    forces = [99.0, 0.0]
    drive.resist([state(0.1)], [30.0], forces)
    # J (v_end - v) / dt = tau - d v_end - f
    end_speed = (inertia * 0.1 / DT + 30.0 - friction) / (inertia / DT + damping)
    assert forces == [99.0, pytest.approx(friction + damping * end_speed, rel=1e-12)]


def test_below_its_friction_the_joint_is_held_by_the_friction_alone():
    drive = implicit_drive(friction=0.5)
    forces = [0.0, 0.0]
    drive.resist([state(0.0)], [-0.4], forces)
    assert forces[1] == 0.5


def test_at_rest_the_passive_torque_is_what_gravity_pulls_with():
    drive = implicit_drive(inertia=2.0, damping=1.0, friction=0.5)
    drive.rest([-3.0])  # holding takes -3: gravity pulls with +3
    forces = [0.0, 0.0]
    drive.resist([state(0.0)], [5.0], forces)
    end_speed = (5.0 + 3.0 - 0.5) / (2.0 / DT + 1.0)
    assert forces[1] == pytest.approx(0.5 + end_speed, rel=1e-12)


def test_the_passive_torque_is_read_back_from_the_step():
    drive = implicit_drive(inertia=2.0)
    drive.feel([state(0.0)], [state(0.01, torque=-0.5)], [1.0])
    # J dv / dt = 2 = effort 1 + motor -0.5 + passive
    forces = [0.0, 0.0]
    drive.resist([state(0.0)], [0.0], forces)
    gain = 1.0 * DT / (2.0 + 1.0 * DT)
    assert forces[1] == pytest.approx(0.5 + gain * (1.5 - 0.5), rel=1e-12)


def test_damping_alone_is_a_velocity_gain_from_the_effective_inertia():
    drive = GainDamping(JOINTS, [2])
    assert drive.gains([0.0, 0.0, 0.45], DT) == [pytest.approx(0.05 / 0.5)]
    assert not GainDamping(JOINTS, [])


def test_motor_rows_put_velocity_joints_first_and_keep_forces_until_told():
    implicit = ImplicitDamping(JOINTS, [3], [1, 2, 3], 2)
    rows = MotorRows(JOINTS, [0, 5], implicit, [10, 11, 12, 13, 14, 15, 16])
    assert rows.indices == [10, 15, 13]
    assert rows.forces == [20.0, UNLIMITED_FORCE, 0.5]
    rows.command([1.0, 2.0], None)
    assert rows.targets == [1.0, 2.0, 0.0] and rows.forces == [20.0, UNLIMITED_FORCE, 0.5]
    rows.command([3.0, 4.0], [5.0, 6.0])
    assert rows.targets == [3.0, 4.0, 0.0] and rows.forces == [5.0, 6.0, 0.5]
    assert not MotorRows(JOINTS, [], ImplicitDamping(JOINTS, [], [], 0), [])
