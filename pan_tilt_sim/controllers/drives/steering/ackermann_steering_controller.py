"""``ackermann_steering_controller/AckermannSteeringController``: two steered, two driven wheels.

As ros2_controllers' (jazzy): the steering library's behaviour (topics,
references, odometry: :mod:`.steering_controllers`) with Ackermann
kinematics (:mod:`.steering_odometry`): two ``steering_joints_names`` (right,
left) on an axle ``steering_track_width`` wide, each steered to its own angle
about the common turning centre, and two ``traction_joints_names`` (right,
left) ``traction_track_width`` apart, ``wheelbase`` behind (or ahead of) them,
of radius ``traction_wheels_radius``.  ``steering_track_width`` 0 (unset) is
``traction_track_width``.  The deprecated ``front_wheels_radius`` /
``rear_wheels_radius`` (radius) and ``front_wheel_track`` /
``rear_wheel_track`` (track, mapped by ``front_steering``) win where given,
with a warning, as upstream.
"""

from __future__ import annotations

from pan_tilt_sim.controllers.drives.steering.steering_controllers import (
    EPSILON,
    TRACTION_TRACK_WIDTH,
    SteeringController,
    library_parameters,
    wheels_radius_parameters,
)
from pan_tilt_sim.controllers.drives.steering.steering_odometry import (
    Configuration,
    SteeringKinematics,
)
from pan_tilt_sim.controllers.framework.parameter_spec import (
    DOUBLE,
    REQUIRED,
    Param,
    ParameterSpec,
    gt,
)
from pan_tilt_sim.controllers.framework.shared_parameters import UNSET_OR_LENGTH


class AckermannSteeringController(SteeringController):
    """Ackermann steering: two steered wheels, two driven wheels, odometry from both."""

    type_names = ('ackermann_steering_controller/AckermannSteeringController',)
    configuration = Configuration.ACKERMANN
    kind = 'Ackermann'
    parameters = ParameterSpec([
        *library_parameters(['joint1', 'joint3'], ['joint2', 'joint4']),
        Param('front_wheel_track', DOUBLE, 0.0, "Deprecated: use 'traction_track_width' or "
              "'steering_track_width'.",
              validators=UNSET_OR_LENGTH),
        Param('steering_track_width', DOUBLE, 0.0, 'Distance between the steering joints (m); '
              '0: traction_track_width.',
              validators=UNSET_OR_LENGTH),
        Param('rear_wheel_track', DOUBLE, 0.0, "Deprecated: use 'traction_track_width' or "
              "'steering_track_width'.",
              validators=UNSET_OR_LENGTH),
        TRACTION_TRACK_WIDTH,
        Param('wheelbase', DOUBLE, REQUIRED, 'Distance between the front and rear axles (m).',
              (gt(0.0),), example=0.5),
        *wheels_radius_parameters(),
    ])

    def kinematics(self) -> SteeringKinematics:
        """Return Ackermann kinematics from the (deprecation-mapped) geometry parameters."""
        params = self.params
        radius = self.traction_radius()
        traction, steering = params['traction_track_width'], params['steering_track_width']
        front = params['front_steering']
        if params['front_wheel_track'] > 0.0:
            self.deprecated('front_wheel_track', "'traction_track_width' or "
                                                 "'steering_track_width'")
            if front:
                steering = params['front_wheel_track']
            else:
                traction = params['front_wheel_track']
        if params['rear_wheel_track'] > 0.0:
            self.deprecated('rear_wheel_track', "'traction_track_width' or "
                                                "'steering_track_width'")
            if front:
                traction = params['rear_wheel_track']
            else:
                steering = params['rear_wheel_track']
        if radius <= EPSILON:
            raise self.error('traction_wheels_radius', 'not set (or not > 0): cannot '
                                                       'configure odometry')
        if steering <= EPSILON:
            steering = traction
        return SteeringKinematics(self.configuration, params['wheelbase'], radius,
                                  traction_track=traction, steering_track=steering,
                                  window=params['velocity_rolling_window_size'])
