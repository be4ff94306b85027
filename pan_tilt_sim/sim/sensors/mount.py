"""Where a link, and a sensor on it, is in the world: PyBullet's link states. No ROS.

PyBullet reports a link's centre-of-mass frame and its URDF link frame; a
body's base is reported by its centre of mass only, so the base's URDF frame
is recovered through its local inertial frame.  Velocities are those of the
centre of mass, and a point rigidly on the link moves at
``v_com + omega x (point - com)``.
"""

from __future__ import annotations

import dataclasses

import numpy

from pan_tilt_sim.model.transforms import Transform, rotate
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.physics import BASE_LINK_INDEX, Physics


@dataclasses.dataclass(frozen=True)
class LinkState:
    """A link's URDF frame in the world, and its centre of mass's position and velocity."""

    frame: Transform
    com: numpy.ndarray
    linear_velocity: numpy.ndarray  # of the centre of mass, world frame
    angular_velocity: numpy.ndarray  # world frame

    def point_velocity(self, point: numpy.ndarray) -> numpy.ndarray:
        """Velocity (world) of a world ``point`` fixed to the link."""
        wx, wy, wz = self.angular_velocity
        rx, ry, rz = point - self.com
        # omega x r, written out: numpy.cross's call overhead dwarfs three products.
        return self.linear_velocity + numpy.array((wy * rz - wz * ry, wz * rx - wx * rz,
                                                   wx * ry - wy * rx))


def inverse(transform: Transform) -> Transform:
    """Return the inverse of a rigid transform."""
    x, y, z, w = transform.rotation
    conjugate = (-x, -y, -z, w)
    tx, ty, tz = rotate(conjugate, transform.translation)
    return Transform((-tx, -ty, -tz), conjugate)


class LinkReader:
    """Reads one link's state from the simulation's PyBullet client."""

    def __init__(self, physics: Physics, link: str) -> None:
        self._client = physics.client_id
        self._body = physics.body_id
        self.index = physics.link_index(link)
        if self.index == BASE_LINK_INDEX:
            info = pybullet.getDynamicsInfo(self._body, BASE_LINK_INDEX,
                                            physicsClientId=self._client)
            self._base_inertial = inverse(Transform(tuple(info[3]), tuple(info[4])))

    def frame(self) -> Transform:
        """Return the link's URDF frame in the world."""
        return self.state(velocity=False).frame

    def state(self, velocity: bool = True) -> LinkState:
        """Return the link's frame, centre of mass and (if asked) velocities."""
        client, body = self._client, self._body
        if self.index == BASE_LINK_INDEX:
            position, orientation = pybullet.getBasePositionAndOrientation(
                body, physicsClientId=client)
            frame = Transform(tuple(position), tuple(orientation)).then(self._base_inertial)
            linear, angular = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
            if velocity:
                linear, angular = pybullet.getBaseVelocity(body, physicsClientId=client)
            return LinkState(frame, numpy.array(position), numpy.array(linear),
                             numpy.array(angular))
        state = pybullet.getLinkState(body, self.index, computeLinkVelocity=int(velocity),
                                      computeForwardKinematics=True, physicsClientId=client)
        frame = Transform(tuple(state[4]), tuple(state[5]))
        if velocity:
            return LinkState(frame, numpy.array(state[0]), numpy.array(state[6]),
                             numpy.array(state[7]))
        zero = numpy.zeros(3)
        return LinkState(frame, numpy.array(state[0]), zero, zero)

