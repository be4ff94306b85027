"""What a ``<ros2_control>`` ``<sensor>`` measures, and where on the robot it sits. No ROS.

A ros2_control sensor is a name and state interfaces; hardware decides what
they read.  The simulator reads them from the physics when their names are
those gz_ros2_control, mock_components and ros2_control's semantic
components give them:

* ``force.x`` ... ``torque.z`` -- the wrench on the joint above the sensor's
  link (what the link and everything beyond it load it with);
* ``orientation.x`` ... ``orientation.w``, ``angular_velocity.x`` ...,
  ``linear_acceleration.x`` ... -- an IMU on the link (REP 145: the
  orientation in the world, the specific force ``R^T (a - g)``);
* ``position.x`` ... ``position.z`` with ``orientation.*`` -- the link's
  pose (pose_broadcaster's interfaces);
* ``range`` -- the distance along the sensor frame's +x to the first thing
  hit.

Design notes: docs/design/model.md#control_sensorspy.
"""

from __future__ import annotations

import dataclasses

from pan_tilt_sim.model.robot import ControlSensor, RobotModel
from pan_tilt_sim.model.sensors import SensorSpec
from pan_tilt_sim.model.transforms import Transform

FORCE = ('force.x', 'force.y', 'force.z')
TORQUE = ('torque.x', 'torque.y', 'torque.z')
WRENCH = FORCE + TORQUE
ORIENTATION = ('orientation.x', 'orientation.y', 'orientation.z', 'orientation.w')
ANGULAR_VELOCITY = ('angular_velocity.x', 'angular_velocity.y', 'angular_velocity.z')
LINEAR_ACCELERATION = ('linear_acceleration.x', 'linear_acceleration.y',
                       'linear_acceleration.z')
IMU = ORIENTATION + ANGULAR_VELOCITY + LINEAR_ACCELERATION
POSITION = ('position.x', 'position.y', 'position.z')
POSE = POSITION + ORIENTATION
RANGE = ('range',)
SIMULATED = frozenset(WRENCH + IMU + POSITION + RANGE)
FRAME_ID = 'frame_id'  # the <sensor>'s <param name="frame_id">


@dataclasses.dataclass(frozen=True)
class Placement:
    """Where a sensor sits: ``link``, its frame at ``pose`` in the link, and how that is known.

    ``gazebo`` is the Gazebo sensor of the same name, if the URDF has one
    (its noise, rate and force-torque conventions apply).
    """

    link: str
    pose: Transform = Transform()
    gazebo: SensorSpec | None = None
    via: str = ''


def placement(model: RobotModel, sensor: ControlSensor) -> Placement | None:
    """Return where the URDF puts ``sensor``, or None if nothing in it does."""
    gazebo = next((spec for spec in model.sensors if spec.name == sensor.name), None)
    if gazebo is not None:
        return Placement(gazebo.link, gazebo.pose, gazebo,
                         f"its Gazebo <sensor name=\"{sensor.name}\"> on '{gazebo.link}'")
    links = set(model.link_names)
    frame = sensor.params.get(FRAME_ID, '').strip()
    if frame in links:
        return Placement(frame, via=f'<param name="{FRAME_ID}">{frame}</param>')
    if sensor.name in links:
        return Placement(sensor.name, via='the link of its name')
    return None


def unplaced_reason(sensor: ControlSensor) -> str:
    """Say why :func:`placement` found no place for ``sensor`` (for the start-up warning)."""
    frame = sensor.params.get(FRAME_ID, '').strip()
    given = (f"its <param name=\"{FRAME_ID}\"> '{frame}' is not a link of the robot" if frame
             else f'it has no <param name="{FRAME_ID}">')
    if measures(sensor, POSITION):  # a pose broadcaster's frame_id is the pose's reference
        return (f'no Gazebo <sensor> of its name, {given}, and no link has its name: it '
                'reads NaN')
    return (f'no Gazebo <sensor> of its name, {given}, and no link has its name: it reads '
            "NaN until a broadcaster's frame_id names a link for it")


def unsimulated(sensor: ControlSensor) -> tuple[str, ...]:
    """Return the sensor's state interfaces the simulator does not produce, in file order."""
    return tuple(name for name in sensor.state_interface_names if name not in SIMULATED)


def measures(sensor: ControlSensor, group: tuple[str, ...]) -> bool:
    """Whether the sensor has any of the state interfaces of ``group`` (WRENCH, IMU...)."""
    return any(name in group for name in sensor.state_interface_names)


def reads_imu(sensor: ControlSensor) -> bool:
    """Whether the sensor is an IMU: angular velocity or linear acceleration, not a pose.

    Its orientation is then the IMU's (in the world); a sensor with
    ``position.*`` reads its orientation as part of its pose.
    """
    return (measures(sensor, ANGULAR_VELOCITY + LINEAR_ACCELERATION)
            or (measures(sensor, ORIENTATION) and not measures(sensor, POSITION)))


def carried_mass(model: RobotModel, link: str) -> float:
    """Return the mass (kg) of ``link`` and every link beyond it: what the joint above carries."""
    children: dict[str, list[str]] = {}
    for joint in model.joints:
        children.setdefault(joint.parent, []).append(joint.child)
    total, pending, seen = 0.0, [link], set()
    while pending:
        name = pending.pop()
        if name in seen:  # a malformed URDF with a loop: stop, do not spin
            continue
        seen.add(name)
        inertial = model.link(name).inertial
        total += 0.0 if inertial is None else inertial.mass
        pending.extend(children.get(name, ()))
    return total
