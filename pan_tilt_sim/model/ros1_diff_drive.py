"""ROS 1's ``diff_drive_controller/DiffDriveController`` parameters, read as jazzy's. No ROS.

A gazebo_ros_control YAML (ROS 1 layout) names the wheels ``left_wheel`` /
``right_wheel`` (a string or a list) where jazzy has ``left_wheel_names`` /
``right_wheel_names``; that is how its layout is told apart
(:func:`is_ros1_layout`).  :func:`jazzy_params` maps the noetic
controller's parameters onto jazzy's, with noetic's defaults (see the design notes).

Design notes: docs/design/model.md#ros1_diff_drivepy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from pan_tilt_sim.model.robot import RobotModel

DIFF_DRIVE_TYPE = 'diff_drive_controller/DiffDriveController'
LEFT, RIGHT = 'left_wheel', 'right_wheel'
LIMIT_GROUPS = (('linear', 'x'), ('angular', 'z'))
# noetic keys with the same meaning under jazzy's name.
SAME_KEYS = ('wheel_separation', 'wheel_radius', 'wheel_separation_multiplier',
             'left_wheel_radius_multiplier', 'right_wheel_radius_multiplier',
             'pose_covariance_diagonal', 'twist_covariance_diagonal', 'publish_rate',
             'cmd_vel_timeout', 'base_frame_id', 'odom_frame_id', 'enable_odom_tf',
             'open_loop', 'velocity_rolling_window_size')
# noetic keys the simulation reads but has no use for.
UNSIMULATED_KEYS = ('allow_multiple_cmd_vel_publishers', 'publish_wheel_joint_controller_state')


def is_ros1_layout(params: Mapping[str, Any]) -> bool:
    """Whether diff drive ``params`` are noetic's: ``left_wheel``/``right_wheel``, no names."""
    return (LEFT in params or RIGHT in params) and not (
        'left_wheel_names' in params or 'right_wheel_names' in params)


def wheel_list(value: Any) -> Any:
    """Return noetic's ``left_wheel``/``right_wheel`` value as a list (a string is one wheel)."""
    return [value] if isinstance(value, str) else value


def with_urdf_geometry(type_name: Any, params: Mapping[str, Any],
                       model: RobotModel | None) -> Mapping[str, Any]:
    """Fill a noetic diff drive's missing ``wheel_separation``/``wheel_radius`` from ``model``.

    Anything else (another type, jazzy's layout, no model, both given, a
    wheel the URDF lacks or one without a cylinder or sphere collision) is
    returned as it is: the controller's own checks then name what is missing.
    """
    if type_name != DIFF_DRIVE_TYPE or model is None or not is_ros1_layout(params):
        return params
    filled = dict(params)
    left, right = wheel_list(params.get(LEFT)), wheel_list(params.get(RIGHT))
    if not (isinstance(left, list) and isinstance(right, list) and left and right):
        return params
    joints = {joint.name: joint for joint in model.joints}
    first_left, first_right = joints.get(str(left[0])), joints.get(str(right[0]))
    if first_left is None or first_right is None:
        return params
    if 'wheel_separation' not in filled:
        filled['wheel_separation'] = math.dist(first_left.origin.translation,
                                               first_right.origin.translation)
    if 'wheel_radius' not in filled:
        links = {link.name: link for link in model.links}
        link = links.get(first_left.child)
        radii = [shape.geometry.radius for shape in (link.collisions if link else ())
                 if shape.geometry.kind in ('cylinder', 'sphere')]
        if radii:
            filled['wheel_radius'] = radii[0]
    return filled


def jazzy_params(params: Mapping[str, Any]) -> dict[str, Any]:
    """Return noetic diff drive ``params`` as jazzy's (see the module); keys left as they are.

    A key neither controller knows is passed on unchanged, so that the
    controller's own check warns about it by name.
    """
    known = {LEFT, RIGHT, 'wheel_radius_multiplier', 'publish_cmd', *SAME_KEYS,
             *UNSIMULATED_KEYS, *(axis for axis, _ in LIMIT_GROUPS)}
    result: dict[str, Any] = {key: value for key, value in params.items() if key not in known}
    if LEFT in params:
        result['left_wheel_names'] = wheel_list(params[LEFT])
    if RIGHT in params:
        result['right_wheel_names'] = wheel_list(params[RIGHT])
    result.update({key: params[key] for key in SAME_KEYS if key in params})
    multiplier = params.get('wheel_radius_multiplier')
    if multiplier is not None:
        for side in ('left_wheel_radius_multiplier', 'right_wheel_radius_multiplier'):
            result.setdefault(side, multiplier)
    if 'publish_cmd' in params:
        result['publish_limited_velocity'] = params['publish_cmd']
    result['tf_frame_prefix_enable'] = False
    for axis, direction in LIMIT_GROUPS:
        group = params.get(axis)
        if group is None:
            continue
        inner = group.get(direction) if isinstance(group, Mapping) else group
        if not isinstance(inner, Mapping):
            result[axis] = group  # the controller's check names the wrong shape
            continue
        result[axis] = {direction: _jazzy_limits(inner)}
    return result


def _jazzy_limits(group: Mapping[str, Any]) -> dict[str, Any]:
    """Return one noetic limit group (``linear/x``) as jazzy's entries (NaN: off)."""
    limits: dict[str, Any] = {}
    for kind, upper, lower in (('velocity', 'max_velocity', 'min_velocity'),
                               ('acceleration', 'max_acceleration', 'min_acceleration'),
                               ('jerk', 'max_jerk', 'min_jerk')):
        if not group.get(f'has_{kind}_limits', False):
            continue
        top = group.get(upper, 0.0)
        bottom = group.get(lower)
        if bottom is None:
            bottom = -top if isinstance(top, int | float) else top
        limits[upper] = top
        if kind == 'acceleration':
            limits['max_deceleration'] = bottom
            limits['max_acceleration_reverse'] = bottom
        else:
            limits[lower] = bottom
    return limits


def ros1_message(message: str) -> str:
    """Return a configuration error about the jazzy names with the noetic names the file used.

    A missing ``wheel_radius``/``wheel_separation`` also says where noetic
    would have found it.
    """
    for jazzy, noetic in (('left_wheel_names', LEFT), ('right_wheel_names', RIGHT),
                          ('publish_limited_velocity', 'publish_cmd')):
        message = message.replace(jazzy, noetic)
    if '.wheel_radius:' in message or '.wheel_separation:' in message:
        message += (" (noetic reads it from the URDF when absent: the first left and right "
                    "wheel joints' origins, the first left wheel link's collision cylinder or "
                    'sphere)')
    return message
