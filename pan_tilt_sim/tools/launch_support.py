"""What launch/pan_tilt.launch.py computes, without the ``launch`` package.

The launch file starts sim_node and robot_state_publisher; this module reads
the model and controllers once, as sim_node will, to hand
robot_state_publisher the processed URDF and the joint_states topic in the
robot's namespace.  Kept apart so it can be tested where ``launch`` is not
installed.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from pan_tilt_sim.model import naming
from pan_tilt_sim.model.controller_config import load_controllers_config
from pan_tilt_sim.model.description import load_description

ROOT_NAMESPACE = '/'


@dataclasses.dataclass(frozen=True)
class RobotSetup:
    """The processed URDF and the namespace of the robot's topics."""

    urdf_xml: str
    namespace: str

    def topic(self, *names: str) -> str:
        """Absolute name of a topic of the robot."""
        return naming.join(self.namespace, *names)


def robot_setup(model: str, controllers: str, xacro_args: Sequence[str] = (),
                robot_namespace: str = '') -> RobotSetup:
    """Load the model and controllers as sim_node does (in the root namespace)."""
    description = load_description(model, xacro_args)
    config = load_controllers_config(controllers)
    namespace = naming.resolve_robot_namespace(
        ROOT_NAMESPACE, robot_namespace, config.namespace, description.plugin_namespace)
    return RobotSetup(description.urdf_xml, namespace)


def sim_node_parameters(model: str, controllers: str, *, real_time_factor: float,
                        world: str, gui: bool) -> dict[str, Any]:
    """Return sim_node's parameters when robot_state_publisher runs beside it.

    robot_state_publisher publishes TF from joint_states, so sim_node does not.
    sim_node keeps use_sim_time off: it is the clock (it publishes /clock).
    """
    return {
        'robot_description_file': model,
        'controllers_file': controllers,
        'real_time_factor': real_time_factor,
        'world': world,
        'gui': gui,
        'publish_tf': False,
    }


def robot_state_publisher_parameters(setup: RobotSetup) -> dict[str, Any]:
    """Return robot_state_publisher's parameters: the URDF, on sim time."""
    return {'robot_description': setup.urdf_xml, 'use_sim_time': True}
