"""gazebo_ros's world services for sim_node: reset and pause (``std_srvs/srv/Empty``).

The names are relative, so they follow the node's namespace as gazebo_ros's do
(``/reset_simulation`` for a node at the root, ``/left/reset_simulation``
under ``-r __ns:=/left``):

* ``reset_simulation``: joints back to their initial state, setpoints and PID
  integrators reset, sim time back to 0 -- and a /clock message says so at once;
* ``reset_world``: the same, but sim time goes on;
* ``pause_physics`` / ``unpause_physics``: hold / release the physics, through
  the node's ``paused`` parameter (``SimNode.set_paused``), so the parameter
  always tells the state and ``ros2 param set /sim_node paused true`` is the
  same switch.  While paused, sim time stands still and commands are still
  taken; they act on unpause.

The callbacks run on the node's executor, in the node's default (mutually
exclusive) callback group, so a reset never lands inside a batch of steps.
"""

from __future__ import annotations

from collections.abc import Callable

from rclpy.node import Node
from rclpy.service import Service
from std_srvs.srv import Empty

from pan_tilt_sim.ros.ros_interfaces import SERVICE_QOS

RESET_SIMULATION = 'reset_simulation'
RESET_WORLD = 'reset_world'
PAUSE_PHYSICS = 'pause_physics'
UNPAUSE_PHYSICS = 'unpause_physics'


def create_world_services(node: Node, *, reset: Callable[..., None],
                          set_paused: Callable[[bool], None]) -> list[Service]:
    """Offer ``reset_simulation``, ``reset_world``, ``pause_physics``, ``unpause_physics``.

    ``reset(reset_time=...)`` puts the world back; ``set_paused(bool)`` holds or
    releases the physics.
    """

    def resetting(reset_time: bool):
        def serve(request: Empty.Request, response: Empty.Response) -> Empty.Response:
            reset(reset_time=reset_time)
            return response
        return serve

    def pausing(paused: bool):
        def serve(request: Empty.Request, response: Empty.Response) -> Empty.Response:
            set_paused(paused)
            return response
        return serve

    return [
        node.create_service(Empty, RESET_SIMULATION, resetting(reset_time=True),
                            qos_profile=SERVICE_QOS),
        node.create_service(Empty, RESET_WORLD, resetting(reset_time=False),
                            qos_profile=SERVICE_QOS),
        node.create_service(Empty, PAUSE_PHYSICS, pausing(paused=True), qos_profile=SERVICE_QOS),
        node.create_service(Empty, UNPAUSE_PHYSICS, pausing(paused=False),
                            qos_profile=SERVICE_QOS),
    ]
