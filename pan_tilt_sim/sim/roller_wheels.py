"""Wheels with free rollers (mecanum, omni) on the ground: friction only across the rollers.

A mecanum or omni wheel touches the ground with one of the small rollers
round its rim.  The roller spins freely about its own axle, so at the
contact the wheel slides without resistance along one direction in the
ground plane -- the *free* direction -- and grips like an ordinary wheel
only along the perpendicular one -- the *traction* direction.  With ``d``
the wheel's rolling direction (its axis crossed with the contact normal)
and ``a`` its axis, both in the ground plane, and the rollers' angle
``gamma`` (:meth:`pan_tilt_sim.controllers.framework.base.Controller.roller_wheels`:
pi / 2 for an omni wheel, +-pi / 4 for a mecanum wheel)::

    free     f = cos(gamma) d + sin(gamma) a
    traction u = sin(gamma) d - cos(gamma) a

Design notes: docs/design/sim.md#roller_wheelspy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

from pan_tilt_sim.sim.bullet import pybullet

if TYPE_CHECKING:
    from pan_tilt_sim.sim.physics import Physics

# The share of the critical gain mass / time_step each wheel's slip damper gets.
GAIN_SHARE = 0.25
LATERAL_FRICTION = 1  # pybullet.getDynamicsInfo: the lateral friction coefficient
MASS = 0  # pybullet.getDynamicsInfo: the link's mass
JOINT_AXIS = 13  # pybullet.getJointInfo: the axis in the child link's frame
# pybullet.getContactPoints entries.
LINK_A, BODY_B, LINK_B, POSITION_ON_A, NORMAL_ON_B, NORMAL_FORCE = 3, 2, 4, 5, 7, 9
# pybullet.getLinkStates entries (with velocities).
COM_POSITION, FRAME_ORIENTATION, LINEAR_VELOCITY, ANGULAR_VELOCITY = 0, 5, 6, 7
SMALLEST_AXIS = 1e-6  # an axis this close to the contact normal: the wheel lies flat


def _rotate(q: tuple[float, float, float, float],
            v: tuple[float, float, float]) -> tuple[float, float, float]:
    """Rotate ``v`` by the unit quaternion ``q`` (x, y, z, w)."""
    x, y, z, w = q
    vx, vy, vz = v
    # t = 2 q_vec x v; v' = v + w t + q_vec x t
    tx, ty, tz = 2.0 * (y * vz - z * vy), 2.0 * (z * vx - x * vz), 2.0 * (x * vy - y * vx)
    return (vx + w * tx + y * tz - z * ty, vy + w * ty + z * tx - x * tz,
            vz + w * tz + x * ty - y * tx)


class RollerWheels:
    """The roller friction of some wheels of ``physics``' robot (see the module's design notes).

    ``angles``: the roller angle (rad) of each wheel, by the name of the
    joint whose child link is the wheel.  Building it sets those links'
    PyBullet friction to 0; :meth:`release` gives it back.
    """

    def __init__(self, physics: Physics, angles: Mapping[str, float]) -> None:
        self._client = client = physics.client_id
        self._body = body = physics.body_id
        self._links: list[int] = []
        self._wheels: list[tuple[tuple[float, float, float], float, float, float]] = []
        self._frictions: dict[int, float] = {}
        for joint, angle in angles.items():
            link = physics.joint_index(joint)
            axis = tuple(pybullet.getJointInfo(body, link, physicsClientId=client)[JOINT_AXIS])
            friction = pybullet.getDynamicsInfo(body, link, physicsClientId=client)[
                LATERAL_FRICTION]
            self._frictions[link] = friction
            self._links.append(link)
            self._wheels.append((axis, math.cos(angle), math.sin(angle), friction))
            pybullet.changeDynamics(body, link, lateralFriction=0.0, physicsClientId=client)
        mass = sum(pybullet.getDynamicsInfo(body, link, physicsClientId=client)[MASS]
                   for link in range(-1, pybullet.getNumJoints(body, physicsClientId=client)))
        self.gain = GAIN_SHARE * mass / max(1, len(self._links)) / physics.time_step
        self._slot = {link: slot for slot, link in enumerate(self._links)}
        self._other_friction: dict[tuple[int, int], float] = {}

    @property
    def links(self) -> tuple[int, ...]:
        """PyBullet's indices of the roller wheels' links."""
        return tuple(self._links)

    def release(self) -> None:
        """Give the wheels their PyBullet friction back (ordinary wheels again)."""
        for link, friction in self._frictions.items():
            pybullet.changeDynamics(self._body, link, lateralFriction=friction,
                                    physicsClientId=self._client)

    def _friction_of(self, body: int, link: int) -> float:
        key = (body, link)
        friction = self._other_friction.get(key)
        if friction is None:
            friction = self._other_friction[key] = pybullet.getDynamicsInfo(
                body, link, physicsClientId=self._client)[LATERAL_FRICTION]
        return friction

    def apply(self) -> None:
        """Add the roller friction of the last step's contacts (call it before each step)."""
        client, body, slot_of = self._client, self._body, self._slot
        # Per wheel: the summed normal force, and the force-weighted sums of the points,
        # the normals and the other surfaces' friction.
        gathered: dict[int, list] = {}
        for contact in pybullet.getContactPoints(bodyA=body, physicsClientId=client):
            slot = slot_of.get(contact[LINK_A])
            force = contact[NORMAL_FORCE]
            if slot is None or force <= 0.0:
                continue
            entry = gathered.get(slot)
            if entry is None:
                entry = gathered[slot] = [0.0, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 0.0]
            entry[0] += force
            point, normal = contact[POSITION_ON_A], contact[NORMAL_ON_B]
            for k in range(3):
                entry[1][k] += force * point[k]
                entry[2][k] += force * normal[k]
            entry[3] += force * self._friction_of(contact[BODY_B], contact[LINK_B])
        if not gathered:
            return
        links = [self._links[slot] for slot in gathered]
        states = pybullet.getLinkStates(body, links, computeLinkVelocity=1,
                                        computeForwardKinematics=1, physicsClientId=client)
        gain = self.gain
        for (slot, (total, point_sum, normal_sum, friction_sum)), state in zip(
                gathered.items(), states, strict=True):
            axis, cos_angle, sin_angle, own_friction = self._wheels[slot]
            point = (point_sum[0] / total, point_sum[1] / total, point_sum[2] / total)
            nx, ny, nz = normal_sum
            length = math.sqrt(nx * nx + ny * ny + nz * nz)
            nx, ny, nz = nx / length, ny / length, nz / length
            ax, ay, az = _rotate(state[FRAME_ORIENTATION], axis)
            along = ax * nx + ay * ny + az * nz
            ax, ay, az = ax - along * nx, ay - along * ny, az - along * nz
            length = math.sqrt(ax * ax + ay * ay + az * az)
            if length < SMALLEST_AXIS:
                continue
            ax, ay, az = ax / length, ay / length, az / length
            # Rolling direction d = a x n; traction u = sin(gamma) d - cos(gamma) a.
            dx, dy, dz = ay * nz - az * ny, az * nx - ax * nz, ax * ny - ay * nx
            ux = sin_angle * dx - cos_angle * ax
            uy = sin_angle * dy - cos_angle * ay
            uz = sin_angle * dz - cos_angle * az
            com, velocity, spin = state[COM_POSITION], state[LINEAR_VELOCITY], state[
                ANGULAR_VELOCITY]
            rx, ry, rz = point[0] - com[0], point[1] - com[1], point[2] - com[2]
            vx = velocity[0] + spin[1] * rz - spin[2] * ry
            vy = velocity[1] + spin[2] * rx - spin[0] * rz
            vz = velocity[2] + spin[0] * ry - spin[1] * rx
            slip = vx * ux + vy * uy + vz * uz
            bound = own_friction * friction_sum  # mu N, mu = own * the others' weighted mean
            push = -gain * slip
            push = bound if push > bound else -bound if push < -bound else push
            pybullet.applyExternalForce(body, self._links[slot], (push * ux, push * uy, push * uz),
                                        point, pybullet.WORLD_FRAME, physicsClientId=client)
