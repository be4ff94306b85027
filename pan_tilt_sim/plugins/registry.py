"""The plugin registry: which ``<plugin>`` element is which plugin unit. Pure Python.

:data:`PLUGIN_TYPES` lists every plugin unit, one line each; each names the
files and gz-sim system names it answers to (:class:`~.framework.plugin.Plugin`).
Their order is the order the simulation updates them in.  An element no
unit answers to is not a plugin the simulation runs (Gazebo would load it;
sim_node has nothing to do for it, or another reader handles it: the
ros2_control plugins, sensors).
"""

from __future__ import annotations

from collections.abc import Callable

from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.plugins.framework.plugin import Plugin
from pan_tilt_sim.plugins.gazebo_classic.diff_drive import GazeboDiffDrive
from pan_tilt_sim.plugins.gazebo_classic.joint_state_publisher import GazeboJointStatePublisher
from pan_tilt_sim.plugins.gazebo_classic.p3d import GazeboP3d
from pan_tilt_sim.plugins.gazebo_classic.planar_move import GazeboPlanarMove
from pan_tilt_sim.plugins.gz.diff_drive import GzDiffDrive
from pan_tilt_sim.plugins.gz.odometry_publisher import GzOdometryPublisher

PLUGIN_TYPES: tuple[type[Plugin], ...] = (
    GazeboDiffDrive,            # libgazebo_ros_diff_drive.so
    GazeboPlanarMove,           # libgazebo_ros_planar_move.so
    GzDiffDrive,                # gz-sim-diff-drive-system, gz::sim::systems::DiffDrive
    GazeboJointStatePublisher,  # libgazebo_ros_joint_state_publisher.so, gz-sim's too
    GazeboP3d,                  # libgazebo_ros_p3d.so
    GzOdometryPublisher,        # gz-sim-odometry-publisher-system
)
# Plugins the simulation recognises but does not simulate, by file (no lib, no .so) or gz-sim
# system name, with why: each gets one warning and is left out; the rest runs.
UNSIMULATED: dict[str, str] = {}


def plugin_type(element: PluginElement) -> type[Plugin] | None:
    """Return the unit ``element`` is (by its file, or a gz-sim system's name), or None."""
    return next((kind for kind in PLUGIN_TYPES if kind.matches(element)), None)


def recognised(model: RobotModel) -> list[tuple[PluginElement, type[Plugin]]]:
    """Return the model's plugin elements a unit answers to, with it, in update order."""
    found = [(element, kind) for element in model.plugins
             if (kind := plugin_type(element)) is not None]
    return sorted(found, key=lambda pair: PLUGIN_TYPES.index(pair[1]))


def create_plugins(model: RobotModel, source: str = '',
                   warn: Callable[[str], None] | None = None) -> list[Plugin]:
    """Return one unit per recognised element (DescriptionError: a malformed element).

    ``source`` labels the units' messages (the controllers file's label);
    ``warn`` gets one line per element of :data:`UNSIMULATED`.
    """
    for element in model.plugins:
        why = UNSIMULATED.get(element.stem) or UNSIMULATED.get(element.name.strip())
        if why and warn is not None:
            warn(f"{element.source}: plugin '{element.name or element.stem}' "
                 f'({element.filename}) skipped: {why}')
    return [kind.from_element(element, model, source) for element, kind in recognised(model)]


def read_settings(model: RobotModel, kind: type[Plugin]) -> tuple[object, ...]:
    """Return the settings of the model's elements of plugin ``kind``, in document order."""
    return tuple(kind.read(element, model) for element in model.plugins
                 if plugin_type(element) is kind)


def base_drivers(model: RobotModel) -> list[tuple[str, str]]:
    """Return (name, file) of each plugin that moves the base (freeing it: ``fixed_base`` auto)."""
    return [(element.name or element.stem, kind.filename) for element, kind in recognised(model)
            if getattr(kind, 'drives_base', False)]


def runs_by_plugins(model: RobotModel) -> bool:
    """Whether a plugin of the model gives it topics without any controller."""
    return bool(recognised(model))
