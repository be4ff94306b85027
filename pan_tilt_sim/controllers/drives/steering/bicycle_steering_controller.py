"""``bicycle_steering_controller/BicycleSteeringController``: one steered, one driven wheel.

As ros2_controllers' (jazzy): the steering library's behaviour (topics,
references, odometry: :mod:`.steering_controllers`) with bicycle kinematics
(:mod:`.steering_odometry`): one ``steering_joints_names`` entry steered to
``atan(omega * wheelbase / v)`` and one ``traction_joints_names`` wheel of
radius ``traction_wheel_radius`` turning at ``v / radius``, ``wheelbase``
apart.  The deprecated ``front_wheel_radius`` / ``rear_wheel_radius`` win
where given, with a warning, as upstream.
"""

from __future__ import annotations

from pan_tilt_sim.controllers.drives.steering.steering_controllers import (
    SteeringController,
    library_parameters,
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


class BicycleSteeringController(SteeringController):
    """Bicycle steering: one steered joint, one driven wheel."""

    type_names = ('bicycle_steering_controller/BicycleSteeringController',)
    configuration = Configuration.BICYCLE
    kind = 'Bicycle'
    parameters = ParameterSpec([
        *library_parameters(['joint1'], ['joint2']),
        Param('wheelbase', DOUBLE, REQUIRED, 'Distance between the front and rear wheel (m).',
              (gt(0.0),), example=0.5),
        Param('traction_wheel_radius', DOUBLE, 0.0, 'Radius of the traction wheel (m).',
              example=0.05,
              validators=UNSET_OR_LENGTH),
        Param('front_wheel_radius', DOUBLE, 0.0, "Deprecated: use 'traction_wheel_radius'.",
              read_only=True,
              validators=UNSET_OR_LENGTH),
        Param('rear_wheel_radius', DOUBLE, 0.0, "Deprecated: use 'traction_wheel_radius'.",
              read_only=True,
              validators=UNSET_OR_LENGTH),
    ])

    def kinematics(self) -> SteeringKinematics:
        """Return bicycle kinematics from the (deprecation-mapped) geometry parameters."""
        params = self.params
        radius = self.traction_radius('traction_wheel_radius',
                                      ('front_wheel_radius', 'rear_wheel_radius'))
        if radius <= 0.0:
            raise self.error('traction_wheel_radius', 'not set (or not > 0): cannot configure '
                                                      'odometry')
        return SteeringKinematics(self.configuration, params['wheelbase'], radius,
                                  window=params['velocity_rolling_window_size'])
