"""Force-torque sensors on joints: PyBullet's joint force-torque sensor. No ROS.

``enableJointForceTorqueSensor`` makes PyBullet report, per joint, the
reaction wrench the parent applies on the child through the joint, computed
in the step just taken.  PyBullet gives it in the child's centre-of-mass
(inertial) frame, the moment taken about the centre of mass (pinned by
test/dependencies/test_pybullet_force_torque.py).  This module moves it to
what Gazebo's sensor reports:

* the moment about the joint, i.e. the child link's origin (or the sensor's
  ``<pose>`` origin for ``<frame>sensor</frame>``): ``M_o = M_c + r_co x F``
  with ``r_co`` the centre of mass seen from that point;
* expressed in the child link frame, the parent link frame or the sensor
  frame (``<frame>``);
* as the wrench the parent applies on the child (``parent_to_child``) or its
  opposite, the child's on the parent (``child_to_parent``, SDF's default).

A mass m hanging still below a joint: the parent holds it up with m g.
"""

from __future__ import annotations

import collections
import dataclasses
import weakref

import numpy

from pan_tilt_sim.model.robot import JointSpec
from pan_tilt_sim.model.sensors import CHILD, PARENT_TO_CHILD, SENSOR, SensorSpec
from pan_tilt_sim.model.transforms import Transform, rotation_matrix
from pan_tilt_sim.sim.bullet import pybullet, quiet_native_output
from pan_tilt_sim.sim.physics import Physics
from pan_tilt_sim.sim.sensors.mount import LinkReader
from pan_tilt_sim.sim.sensors.noise import NoiseModel

REACTION = 2  # index of the reaction wrench in getJointState's answer
# Per simulation, per joint index: how many readers want PyBullet's joint feedback on.
_FEEDBACK_USERS: weakref.WeakKeyDictionary[Physics, collections.Counter[int]] = (
    weakref.WeakKeyDictionary())
INERTIAL_POSITION = 2  # getLinkState: the inertial frame in the link frame
INERTIAL_ORIENTATION = 3


@dataclasses.dataclass(frozen=True)
class Wrench:
    """A force (N) and a torque (N m), as three-vectors."""

    force: numpy.ndarray
    torque: numpy.ndarray


class ForceTorque:
    """Reads the wrench on one joint of the simulation."""

    def __init__(self, physics: Physics, sensor: SensorSpec, joint: JointSpec, *,
                 frame: str = CHILD, measure_direction: str = PARENT_TO_CHILD,
                 noise: NoiseModel | None = None, enabled: bool = True) -> None:
        self.sensor = sensor
        self._physics = physics
        self._client = physics.client_id
        self._body = physics.body_id
        self._child = LinkReader(physics, joint.child)
        self._parent = LinkReader(physics, joint.parent)
        self._index = self._child.index  # a joint has its child link's index
        self._frame = frame
        self._sign = 1.0 if measure_direction == PARENT_TO_CHILD else -1.0
        self._noise = noise
        state = pybullet.getLinkState(self._body, self._index, physicsClientId=self._client)
        inertial = Transform(tuple(state[INERTIAL_POSITION]), tuple(state[INERTIAL_ORIENTATION]))
        self._inertial_rotation = numpy.array(rotation_matrix(inertial.rotation))
        # The point the moment is taken about, in the child link frame.
        point = numpy.array(sensor.pose.translation) if frame == SENSOR else numpy.zeros(3)
        self._com_from_point = numpy.array(inertial.translation) - point
        self.enabled = False
        self.enable(enabled)

    def enable(self, on: bool) -> None:
        """Switch PyBullet's joint feedback on or off (for this reader).

        It costs every physics step while on (Bullet runs a second articulated-body
        pass to compute the joint forces), so the ROS layer keeps it off while
        nobody listens; a reading is valid from the step after it was switched on.
        Several readers may share a joint (a Gazebo sensor and a ros2_control
        one of the same name): the feedback stays on while any of them wants it.
        """
        if on == self.enabled:
            return
        users = _FEEDBACK_USERS.setdefault(self._physics, collections.Counter())
        users[self._index] += 1 if on else -1
        if users[self._index] == (1 if on else 0):
            with quiet_native_output():  # a second sensor on the joint: PyBullet warns
                pybullet.enableJointForceTorqueSensor(self._body, self._index, on,
                                                      physicsClientId=self._client)
        self.enabled = on

    def read(self) -> Wrench:
        """Return the wrench of the step just taken, as the sensor reports it (if enabled)."""
        reaction = pybullet.getJointState(self._body, self._index,
                                          physicsClientId=self._client)[REACTION]
        force = self._inertial_rotation @ numpy.array(reaction[:3])  # child link axes
        torque = self._inertial_rotation @ numpy.array(reaction[3:])
        torque = torque + numpy.cross(self._com_from_point, force)
        rotation = self._rotation_into_frame()
        force, torque = self._sign * (rotation @ force), self._sign * (rotation @ torque)
        if self._noise is not None and self._noise.active:
            noisy = self._noise.apply(numpy.concatenate([force, torque]))
            force, torque = noisy[:3], noisy[3:]
        return Wrench(force, torque)

    def _rotation_into_frame(self) -> numpy.ndarray:
        """Rotation from the child link's axes into the reporting frame's axes."""
        if self._frame == CHILD:
            return numpy.eye(3)
        if self._frame == SENSOR:
            return numpy.array(rotation_matrix(self.sensor.pose.rotation)).T
        # PARENT: child axes -> world -> parent axes, as the joint stands now.
        child = numpy.array(rotation_matrix(self._child.frame().rotation))
        parent = numpy.array(rotation_matrix(self._parent.frame().rotation))
        return parent.T @ child
