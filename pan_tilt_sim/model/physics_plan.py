"""What the physics needs of a robot, decided once from its description. No PyBullet, no ROS.

:func:`plan_physics` reads a :class:`~pan_tilt_sim.model.description.RobotDescription`
and the start-up options into a :class:`PhysicsPlan`: the URDF text PyBullet loads and
whether the base is welded or free, the actuated joints, their mimic couplings, where
they start (followers where their leaders put them), PyBullet's speed cap, the poses at
which effective inertias are checked, the links' contact surfaces and where the base is
placed.  :class:`pan_tilt_sim.sim.physics.Physics` builds from it in one pass and makes
no decision about the model itself.  A description the physics cannot take (a mimic
of a joint that does not move) raises :class:`DescriptionError` here, before PyBullet
is touched.

Design notes: docs/design/sim.md#start-up-path.
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
from collections.abc import Sequence

from pan_tilt_sim.model.base_pose import ORIGIN, BasePose
from pan_tilt_sim.model.description import RobotDescription
from pan_tilt_sim.model.inertials import with_massive_root
from pan_tilt_sim.model.mimic import MimicCoupling, follow_leaders, mimic_couplings
from pan_tilt_sim.model.robot import JointSpec, RobotModel
from pan_tilt_sim.model.transforms import Transform, quaternion_from_rpy

# PyBullet clamps every joint's speed to this (rad/s or m/s); we raise it to
# twice the fastest URDF velocity limit, never below PyBullet's default.
DEFAULT_VELOCITY_CAP = 100.0
VELOCITY_CAP_MARGIN = 2.0
# Poses at which inertias are checked: the start, then every joint at these
# fractions of its range (0 = lower, 1 = upper), or at these angles without limits.
RANGE_FRACTIONS = (0.5, 0.25, 0.75)
FREE_POSES = (0.0, math.pi / 2.0, -math.pi / 2.0)


@dataclasses.dataclass(frozen=True)
class LinkSurface:
    """One link's contact in PyBullet: its friction, and its spring (N/m, N s/m) if any."""

    link: str
    friction: float
    spring: tuple[float, float] | None = None


@dataclasses.dataclass(frozen=True)
class BasePlacement:
    """Where the root link frame starts (world frame).

    ``frame``'s x, y and rotation place it; its z is the frame's height for a
    welded base, and for a base ``on_ground`` the height of the robot's lowest
    collision point above the ground (the physics measures where that puts the
    frame).  ``as_loaded``: a welded base at the origin stays where PyBullet
    loads it.
    """

    frame: Transform
    on_ground: bool
    as_loaded: bool


@dataclasses.dataclass(frozen=True)
class PhysicsPlan:
    """Everything the physics builds a robot from (see the module).

    ``urdf`` is the text PyBullet loads (a free base's massless root link given
    a negligible mass), ``implicit_cylinders`` whether its cylinders are exact
    shapes (a free base's wheels roll round) rather than polygon hulls;
    ``joints`` the actuated joints, the order of every array the physics takes
    or gives; ``coupled`` the joints a mimic coupling joins (leaders and
    followers); ``surfaces`` what PyBullet's links get: a welded robot only the
    URDF's ``<gazebo reference>`` frictions, a free one every link's surface
    with its contact spring (:meth:`RobotModel.surface`).
    """

    source: pathlib.Path
    urdf: str
    fixed_base: bool
    implicit_cylinders: bool
    joints: tuple[JointSpec, ...]
    mimics: tuple[MimicCoupling, ...]
    coupled: frozenset[str]
    initial_positions: tuple[float, ...]
    velocity_cap: float
    inertia_poses: tuple[tuple[float, ...], ...]
    surfaces: tuple[LinkSurface, ...]
    base: BasePlacement

    def with_mimics(self, positions: Sequence[float]) -> list[float]:
        """Return joint ``positions`` with every mimic follower put by its leader."""
        return _followed(self.joints, self.mimics, positions)


def _followed(joints: Sequence[JointSpec], mimics: Sequence[MimicCoupling],
              positions: Sequence[float]) -> list[float]:
    if not mimics:
        return list(positions)
    return follow_leaders([joint.name for joint in joints], positions, mimics)


def velocity_cap(joints: Sequence[JointSpec]) -> float:
    """Return the speed cap to give PyBullet: twice the fastest finite limit, at least 100."""
    limits = [joint.velocity_limit for joint in joints if math.isfinite(joint.velocity_limit)]
    return max([DEFAULT_VELOCITY_CAP] + [VELOCITY_CAP_MARGIN * limit for limit in limits])


def check_poses(joints: Sequence[JointSpec], start: Sequence[float]) -> list[list[float]]:
    """Return the poses to check inertias at: the start, then each of RANGE_FRACTIONS."""
    poses = [list(start)]
    for number, fraction in enumerate(RANGE_FRACTIONS):
        pose = []
        for joint in joints:
            if joint.has_position_limits and math.isfinite(joint.lower) and math.isfinite(
                    joint.upper):
                pose.append(joint.lower + fraction * (joint.upper - joint.lower))
            else:
                pose.append(FREE_POSES[number % len(FREE_POSES)])
        poses.append(pose)
    return poses


def link_surfaces(model: RobotModel, fixed_base: bool) -> tuple[LinkSurface, ...]:
    """Return what PyBullet's links get for their contacts (see :class:`PhysicsPlan`)."""
    if fixed_base:
        return tuple(LinkSurface(name, surface.friction)
                     for name, surface in model.link_frictions.items())
    surfaces = [model.surface(link.name) for link in model.links]
    return tuple(LinkSurface(surface.link, surface.friction, surface.spring)
                 for surface in surfaces)


def base_placement(pose: BasePose, fixed_base: bool) -> BasePlacement:
    """Return where the base starts for ``pose`` (see :mod:`pan_tilt_sim.model.base_pose`)."""
    frame = Transform((pose.x, pose.y, pose.z),
                      quaternion_from_rpy(pose.roll, pose.pitch, pose.yaw))
    return BasePlacement(frame, on_ground=not fixed_base,
                         as_loaded=fixed_base and pose.is_origin)


def plan_physics(description: RobotDescription, *, fixed_base: bool = True,
                 initial_positions: Sequence[float] | None = None,
                 initial_pose: BasePose = ORIGIN) -> PhysicsPlan:
    """Decide what the physics builds of ``description`` (see :class:`PhysicsPlan`).

    ``initial_positions``: one per actuated joint (default: each joint's
    :attr:`~pan_tilt_sim.model.robot.JointSpec.initial_position`); a wrong
    count is a ValueError.  A mimic the physics cannot couple is a
    :class:`DescriptionError` naming the file.
    """
    model = description.model
    joints = description.actuated_joints
    mimics = mimic_couplings(joints, description.source)
    if initial_positions is None:
        initial_positions = [joint.initial_position for joint in joints]
    elif len(initial_positions) != len(joints):
        raise ValueError(f'{len(initial_positions)} initial positions for {len(joints)} joints')
    # A free base must have a mass, or PyBullet welds it (see model.inertials).
    urdf = (description.physics_urdf if fixed_base
            else with_massive_root(description.physics_urdf, model))
    start = tuple(_followed(joints, mimics, initial_positions))
    return PhysicsPlan(
        source=description.source, urdf=urdf, fixed_base=fixed_base,
        implicit_cylinders=not fixed_base, joints=joints, mimics=mimics,
        coupled=frozenset(name for coupling in mimics
                          for name in (coupling.leader, coupling.follower)),
        initial_positions=start, velocity_cap=velocity_cap(joints),
        inertia_poses=tuple(tuple(pose) for pose in check_poses(joints, start)),
        surfaces=link_surfaces(model, fixed_base),
        base=base_placement(initial_pose, fixed_base))
