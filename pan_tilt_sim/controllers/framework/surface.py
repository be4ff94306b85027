"""A controller's ROS surface, declared as data: its topics, services and actions.

A controller returns its surface from
:meth:`~pan_tilt_sim.controllers.framework.base.Controller.ros_surface`; the ROS
adapter (:mod:`pan_tilt_sim.ros.controller_bindings`) creates one entity per
entry while the controller is configured and removes them at cleanup.  The
adapter knows message, service and action types, never controller types: an
entry names its interface type (``std_msgs/msg/Float64MultiArray``) and
carries the controller's callable that takes or gives the data.

Topic names follow ros2_controllers: ``~/name`` is in the controller's own
namespace (``<robot namespace>/<controller>/name``), any other relative name
in the robot's namespace (``joint_states``), and ``/name`` is absolute.
Pure Python: no rclpy.
"""

from __future__ import annotations

import dataclasses
import enum
from collections.abc import Callable
from typing import Any, NamedTuple

PRIVATE = '~/'


@dataclasses.dataclass(frozen=True)
class CommandTopic:
    """A subscription whose messages become commands.

    ``accept(value)`` stores the value the adapter extracted from a message
    (see the adapter's table for each message type) and says what became of
    it; ``problem(value, result)`` describes a refused or clamped value for
    the node's throttled warning.  Commands reach an inactive controller
    only as a warning, and a controller in chained mode (whose references
    come from the controller before it) likewise -- unless ``while_chained``:
    the topic carries something else than references (measurements).
    """

    name: str
    message: str
    accept: Callable[[Any], Any]  # returns a base.CommandResult
    problem: Callable[[Any, Any], str]
    while_chained: bool = False


@dataclasses.dataclass(frozen=True)
class StateTopic:
    """A publisher fed by the controller's samples.

    ``connect(sink)`` hands the controller the adapter's sink for the
    message type (None: nobody listens, take no samples); ``fields`` are
    what the sink needs to build the message once (the joint names, say).
    """

    name: str
    message: str
    connect: Callable[[Any], None]
    fields: dict[str, Any] = dataclasses.field(default_factory=dict)


@dataclasses.dataclass(frozen=True)
class Service:
    """A service served while the controller is configured, active or not.

    ``call(value)`` takes the value the adapter extracted from a request and
    returns the answer the adapter writes into the response; both are set by
    the adapter's table for each service type (``std_srvs/srv/SetBool``: the
    request's ``data`` in, ``(success, message)`` out).  ``inactive``, if
    not None, is the answer while the controller is not active, given
    without calling it (a service upstream refuses then).
    """

    name: str
    service: str
    call: Callable[[Any], Any]
    inactive: Any = None


@dataclasses.dataclass(frozen=True)
class ActionServer:
    """An action server run by the controller (the adapter has one server per action type)."""

    name: str
    action: str


Endpoint = CommandTopic | StateTopic | Service | ActionServer


class GoalStatus(enum.Enum):
    """Where an action goal is in its life."""

    EXECUTING = 'executing'
    SUCCEEDED = 'succeeded'
    ABORTED = 'aborted'
    CANCELED = 'canceled'


class StampedTwist(NamedTuple):
    """A ``geometry_msgs/msg/TwistStamped`` as a command value.

    ``stamp``: the header's time in seconds (0: not stamped); ``linear``
    (m/s) and ``angular`` (rad/s): (x, y, z) in the header's frame.
    """

    stamp: float
    linear: tuple[float, float, float]
    angular: tuple[float, float, float]


class TrajectoryStateAnswer(NamedTuple):
    """A ``control_msgs/srv/QueryTrajectoryState`` answer.

    ``success`` and ``message`` (why not); per joint of ``names``, the
    desired ``positions`` (rad or m), ``velocities`` (per s) and
    ``accelerations`` (per s^2) at the requested time.
    """

    success: bool
    message: str
    names: tuple[str, ...]
    positions: tuple[float, ...]
    velocities: tuple[float, ...]
    accelerations: tuple[float, ...]
