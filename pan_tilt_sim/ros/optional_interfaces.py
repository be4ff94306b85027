"""The interface packages some features need, and the one line that says which features are off.

tf2_msgs, control_msgs, controller_manager_msgs and simulation_interfaces
are not on PyPI: a ROS
install has them, and the standalone path builds them into the venv
(``scripts/build_interfaces.sh``; ``scripts/run_tests.sh`` does it on first
use, ``scripts/run_sim.sh`` only with ``PAN_TILT_SIM_INTERFACES=build``).
Where one is missing, sim_node runs without the features that need it and
says so in one info line at start-up (:func:`missing_features_line`).
"""

from __future__ import annotations

import importlib.util
from collections.abc import Iterable

# package -> the feature that needs it, as the start-up line names it.
FEATURES = {
    'tf2_msgs': 'TF (/tf, /tf_static; robot_state_publisher can publish it from '
                'robot_description and joint_states)',
    'control_msgs': 'the follow_joint_trajectory and gripper_cmd actions, dynamic_joint_states '
                    "and the controller topics of control_msgs types (pid_controller's "
                    "~/reference, ~/controller_state, the gpio controllers')",
    'controller_manager_msgs': "the controller_manager services (ros2_control's spawner)",
    'simulation_interfaces': 'the simulator services (get_simulator_features, '
                             'step_simulation, spawn_entity, ...)',
}
BUILD_HINT = 'scripts/build_interfaces.sh builds them into the venv'


def available(package: str) -> bool:
    """Whether the interface package ``package`` can be imported."""
    try:
        return importlib.util.find_spec(package) is not None
    except (ImportError, ValueError):
        return False


def missing_features_line(missing: Iterable[str]) -> str | None:
    """Return the one info line naming the features off for want of the ``missing`` packages."""
    missing = list(missing)
    if not missing:
        return None
    features = '; '.join(f'{FEATURES.get(package, package)} ({package})' for package in missing)
    return f'off, for want of their interface packages: {features}. {BUILD_HINT}'
