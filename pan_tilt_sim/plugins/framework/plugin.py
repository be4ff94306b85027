"""What every Gazebo plugin unit is: the element names it answers to, its spec, how it binds.

A plugin is a :class:`~pan_tilt_sim.controllers.framework.base.Controller` no
controller_manager knows: always active, updated every physics step before
the controllers.  It is also a :class:`Plugin`: it names the ``<plugin>``
files (``filenames``, without ``lib``/``.so``) and gz-sim system names it
stands for, reads its element with :meth:`Plugin.read` (its element spec:
elements, defaults, checks) and binds to the running simulation in
:meth:`Plugin.attach`.  The shared sample types of the plugins live here.
Pure Python.
"""

from __future__ import annotations

import abc
import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from pan_tilt_sim.controllers.framework.base import JointHandle
from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.transforms import Transform, Vector

# A link's state: its frame in the world, the world velocity of the frame's origin (m/s)
# and its angular velocity (rad/s), both in world axes.
LinkState = tuple[Transform, Vector, Vector]
# The base's motion: its frame in the world, its linear velocity (m/s) and angular velocity
# (rad/s), both in world axes.
BaseMotion = tuple[Transform, Vector, Vector]
# The base's state: (x, y, heading) in the world (m, rad) and its twist in the base frame
# (forward m/s, sideways m/s, yaw rate rad/s).
BaseState = tuple[tuple[float, float, float], tuple[float, float, float]]
# sink(time, pose, linear, angular): a 3-D odometry sample.
SpatialOdometrySink = Callable[[float, Transform, Vector, Vector], None]
# sink(time, x, y, heading, linear, angular): a planar odometry sample (m, rad, m/s, rad/s).
PlanarOdometrySink = Callable[[float, float, float, float, float, float], None]


def heading(frame: Transform) -> float:
    """Return the yaw (rad) of ``frame``'s rotation."""
    qx, qy, qz, qw = frame.rotation
    return math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


@dataclasses.dataclass(frozen=True)
class PluginWorld:
    """What the simulation hands a plugin: joint handles and the base's and links' states."""

    handles: Mapping[str, JointHandle]
    base_state: Callable[[], BaseState]
    base_motion: Callable[[], BaseMotion]
    link_state: Callable[[str], LinkState]


class Plugin(abc.ABC):
    """The plugin side of a plugin unit (mixed into its Controller class)."""

    # The <plugin> files (stems: no lib, no .so) and gz-sim system names it stands for.
    filenames: ClassVar[frozenset[str]] = frozenset()
    system_names: ClassVar[frozenset[str]] = frozenset()
    # The file it is known by in messages (libgazebo_ros_diff_drive.so).
    filename: ClassVar[str] = ''
    # It sets the base's velocity itself (the step applies what it computed).
    sets_base_velocity: ClassVar[bool] = False
    # It publishes sensor_msgs/JointState (no joint_state_broadcaster needed).
    publishes_joint_states: ClassVar[bool] = False

    @classmethod
    def matches(cls, element: PluginElement) -> bool:
        """Whether ``element`` is this plugin: by its file, or (gz-sim) its system name."""
        return element.stem in cls.filenames or element.name.strip() in cls.system_names

    @classmethod
    @abc.abstractmethod
    def read(cls, element: PluginElement, model: RobotModel) -> Any:
        """Return the plugin's settings from ``element`` (DescriptionError if malformed)."""

    @classmethod
    def from_element(cls, element: PluginElement, model: RobotModel,
                     source: str = '') -> Plugin:
        """Return the unit for ``element``; ``source`` labels its messages."""
        return cls(cls.read(element, model), source)  # type: ignore[call-arg]

    @abc.abstractmethod
    def attach(self, world: PluginWorld) -> None:
        """Bind to the simulation: joint handles, base or link states."""
