"""``tricycle_steering_controller/TricycleSteeringController``: one steered, two driven wheels.

As ros2_controllers' (jazzy): the steering library's behaviour (topics,
references, odometry: :mod:`.steering_controllers`) with tricycle kinematics
(:mod:`.steering_odometry`): one ``steering_joints_names`` entry and two
``traction_joints_names`` wheels (right, left) ``traction_track_width``
apart, of radius ``traction_wheels_radius``, ``wheelbase`` from the steered
wheel.  The deprecated ``wheel_track`` and ``front_wheels_radius`` /
``rear_wheels_radius`` win where given, with a warning, as upstream.
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


class TricycleSteeringController(SteeringController):
    """Tricycle steering: one steered joint, two driven wheels on an axle."""

    type_names = ('tricycle_steering_controller/TricycleSteeringController',)
    configuration = Configuration.TRICYCLE
    kind = 'Tricycle'
    parameters = ParameterSpec([
        *library_parameters(['joint1', 'joint3'], ['joint2']),
        Param('wheel_track', DOUBLE, 0.0, "Deprecated: use 'traction_track_width'.",
              validators=UNSET_OR_LENGTH),
        TRACTION_TRACK_WIDTH,
        Param('wheelbase', DOUBLE, REQUIRED, 'Distance between the steered wheel and the '
              'traction axle (m).', (gt(0.0),), example=0.5),
        *wheels_radius_parameters(),
    ])

    def kinematics(self) -> SteeringKinematics:
        """Return tricycle kinematics from the (deprecation-mapped) geometry parameters."""
        params = self.params
        radius, track = self.traction_radius(), params['traction_track_width']
        if params['wheel_track'] > 0.0:
            self.deprecated('wheel_track', "'traction_track_width'")
            track = params['wheel_track']
        if track <= EPSILON:
            raise self.error('traction_track_width', 'not set (or not > 0): cannot configure '
                                                     'odometry')
        if radius <= 0.0:
            raise self.error('traction_wheels_radius', 'not set (or not > 0): cannot '
                                                       'configure odometry')
        return SteeringKinematics(self.configuration, params['wheelbase'], radius,
                                  traction_track=track,
                                  window=params['velocity_rolling_window_size'])
