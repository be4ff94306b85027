"""``<mimic>`` joints: a follower at ``multiplier * leader + offset``.

Facts about the couplings, without PyBullet: which joint follows which, in
an order where every leader comes before its followers (chains allowed),
and the follower positions that go with given leader positions.  The
physics layer enforces each coupling with a PyBullet gear constraint, which
its solver keeps exact to ~1e-4 rad (at the instant a leader hits a limit
stop, ~2e-3) while the follower's inertia loads the leader, as a rigid
linkage would; nothing runs in the step loop for it.  Followers cannot be
commanded; they appear in joint_states like every movable joint.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.robot import JointSpec


@dataclasses.dataclass(frozen=True)
class MimicCoupling:
    """``follower = multiplier * leader + offset``, between two movable joints."""

    follower: str
    leader: str
    multiplier: float
    offset: float


def mimic_couplings(joints: Sequence[JointSpec],
                    source: object = '') -> tuple[MimicCoupling, ...]:
    """Return the couplings among the movable ``joints``, leaders before their followers."""
    by_name = {joint.name: joint for joint in joints}
    ordered: list[MimicCoupling] = []
    placed: set[str] = set()

    def place(joint: JointSpec, chain: tuple[str, ...]) -> None:
        mimic = joint.mimic
        if mimic is None or joint.name in placed:
            return
        if joint.name in chain:
            cycle = ' -> '.join((*chain[chain.index(joint.name):], joint.name))
            raise DescriptionError(f'{source}: mimic joints form a cycle: {cycle}')
        leader = by_name.get(mimic.joint)
        if leader is None:
            raise DescriptionError(
                f"{source}: joint '{joint.name}' mimics '{mimic.joint}', "
                'which is not a movable joint of this robot')
        place(leader, (*chain, joint.name))
        ordered.append(MimicCoupling(joint.name, leader.name, mimic.multiplier, mimic.offset))
        placed.add(joint.name)

    for joint in joints:
        place(joint, ())
    return tuple(ordered)


def follow_leaders(names: Sequence[str], positions: Sequence[float],
                   couplings: Sequence[MimicCoupling]) -> list[float]:
    """Return ``positions`` (of the joints ``names``) with every follower put by its leader."""
    result = list(positions)
    index = {name: number for number, name in enumerate(names)}
    for coupling in couplings:
        result[index[coupling.follower]] = (
            coupling.multiplier * result[index[coupling.leader]] + coupling.offset)
    return result
