"""Group controllers over hand-made joints: ForwardCommandController and JointGroup*Controllers.

A revolute 'shoulder' (+-1 rad, 2 rad/s, 20 N*m), a prismatic 'slide'
(0..0.5 m, 0.5 m/s, 30 N) and a 'follower' mimicking the shoulder; every
group named 'grp' in 'test.yaml'.
"""

from __future__ import annotations

from typing import Any

from pan_tilt_sim.controllers import JointHandle, create_controller
from pan_tilt_sim.model.robot import JointKind, JointSpec, Mimic

DT = 0.001
GROUP_TYPES = {
    'position': 'position_controllers/JointGroupPositionController',
    'velocity': 'velocity_controllers/JointGroupVelocityController',
    'effort': 'effort_controllers/JointGroupEffortController',
}
FORWARD = 'forward_command_controller/ForwardCommandController'


def make_handles() -> dict[str, JointHandle]:
    """Return fresh handles of the shoulder, the slide and the follower."""
    specs = [
        JointSpec('shoulder', JointKind.REVOLUTE, lower=-1.0, upper=1.0, effort_limit=20.0,
                  velocity_limit=2.0),
        JointSpec('slide', JointKind.PRISMATIC, lower=0.0, upper=0.5, effort_limit=30.0,
                  velocity_limit=0.5),
        JointSpec('follower', JointKind.REVOLUTE, lower=-1.0, upper=1.0,
                  mimic=Mimic('shoulder', -1.0, 0.0)),
    ]
    return {spec.name: JointHandle(spec) for spec in specs}


def group(type_name: str, handles: dict[str, JointHandle] | None = None, **params: Any):
    """Return a configured group 'grp' of ``type_name`` (joints: shoulder, slide by default)."""
    params.setdefault('joints', ['shoulder', 'slide'])
    controller = create_controller('grp', type_name, params, 'test.yaml')
    controller.configure(handles if handles is not None else make_handles())
    return controller


def ways(interface: str) -> list[tuple[str, dict[str, Any]]]:
    """The two ways to build a group on ``interface``: its JointGroup type, or told so."""
    return [(GROUP_TYPES[interface], {}), (FORWARD, {'interface_name': interface})]


def way_ids(interface: str) -> list[str]:
    """Test ids for :func:`ways`."""
    return [type_name.split('/')[1] for type_name, _params in ways(interface)]


KINDS = [(interface, type_name, extra) for interface in GROUP_TYPES
         for type_name, extra in ways(interface)]
KIND_IDS = [f'{type_name.split("/")[1]}-{interface}' for interface, type_name, _ in KINDS]
