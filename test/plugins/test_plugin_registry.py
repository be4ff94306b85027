"""The plugin registry: every plugin unit is listed once, and each element finds its unit."""

import importlib
import inspect
import pathlib
import pkgutil

import pytest
from mobile_fixtures import GZ_DIFF_DRIVE, GZ_ODOMETRY, PLANAR_MOVE, plugin_rover_urdf

import pan_tilt_sim.plugins
from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.plugins import registry
from pan_tilt_sim.plugins.framework.plugin import Plugin
from pan_tilt_sim.plugins.gazebo_classic.diff_drive import GazeboDiffDrive
from pan_tilt_sim.plugins.gazebo_classic.joint_state_publisher import GazeboJointStatePublisher
from pan_tilt_sim.plugins.gazebo_classic.p3d import GazeboP3d
from pan_tilt_sim.plugins.gazebo_classic.planar_move import GazeboPlanarMove
from pan_tilt_sim.plugins.gz.diff_drive import GzDiffDrive
from pan_tilt_sim.plugins.gz.odometry_publisher import GzOdometryPublisher
from pan_tilt_sim.plugins.registry import (
    PLUGIN_TYPES,
    base_drivers,
    create_plugins,
    plugin_type,
    runs_by_plugins,
)

SOURCE = pathlib.Path('rover.urdf')


def plugin_classes() -> set[type]:
    """Return every Plugin class defined in a module of plugins/gazebo_classic or plugins/gz."""
    found = set()
    for folder in ('gazebo_classic', 'gz'):
        package = importlib.import_module(f'pan_tilt_sim.plugins.{folder}')
        for info in pkgutil.iter_modules(package.__path__):
            module = importlib.import_module(f'{package.__name__}.{info.name}')
            found.update(value for value in vars(module).values()
                         if inspect.isclass(value) and issubclass(value, Plugin)
                         and value.__module__ == module.__name__)
    return found


def test_every_plugin_module_is_registered_once():
    assert len(PLUGIN_TYPES) == len(set(PLUGIN_TYPES))
    assert plugin_classes() == set(PLUGIN_TYPES)
    assert pan_tilt_sim.plugins.__file__  # the package itself imports


def test_no_two_plugins_answer_to_the_same_file_or_name():
    files = [stem for kind in PLUGIN_TYPES for stem in kind.filenames]
    names = [name for kind in PLUGIN_TYPES for name in kind.system_names]
    assert len(files) == len(set(files)) and len(names) == len(set(names))


@pytest.mark.parametrize(('filename', 'name', 'kind'), [
    ('libgazebo_ros_diff_drive.so', 'drive', GazeboDiffDrive),
    ('gazebo_ros_diff_drive', '', GazeboDiffDrive),
    ('/opt/ros/jazzy/lib/libgazebo_ros_diff_drive.so', 'drive', GazeboDiffDrive),
    ('libgazebo_ros_planar_move.so', 'move', GazeboPlanarMove),
    ('libgazebo_ros_p3d.so', 'truth', GazeboP3d),
    ('libgazebo_ros_joint_state_publisher.so', 'js', GazeboJointStatePublisher),
    ('gz-sim-joint-state-publisher-system', 'js', GazeboJointStatePublisher),
    ('', 'gz::sim::systems::JointStatePublisher', GazeboJointStatePublisher),
    ('gz-sim-diff-drive-system', 'gz::sim::systems::DiffDrive', GzDiffDrive),
    ('libignition-gazebo-diff-drive-system.so', 'drive', GzDiffDrive),
    ('other', 'ignition::gazebo::systems::DiffDrive', GzDiffDrive),
    ('gz-sim-odometry-publisher-system', 'odometry', GzOdometryPublisher),
    ('', 'ignition::gazebo::systems::OdometryPublisher', GzOdometryPublisher),
])
def test_an_element_finds_its_plugin_by_file_or_gz_system_name(filename, name, kind):
    assert plugin_type(PluginElement(filename=filename, name=name)) is kind


@pytest.mark.parametrize(('filename', 'name'), [
    ('libgazebo_ros2_control.so', 'gazebo_ros2_control'),   # the controllers' plugin
    ('gz_ros2_control-system', 'gz_ros2_control::GazeboSimROS2ControlPlugin'),
    ('libgazebo_ros_ft_sensor.so', 'ft'),                    # a sensor: the sensor reader's
    ('libsomething_else.so', 'gazebo_ros_diff_drive'),       # a classic name is just a name
])
def test_an_element_no_plugin_answers_to_is_none(filename, name):
    assert plugin_type(PluginElement(filename=filename, name=name)) is None


def test_the_units_come_one_per_element_in_the_registrys_order():
    robot = parse_urdf(plugin_rover_urdf(GZ_DIFF_DRIVE, ground_truth=GZ_ODOMETRY + PLANAR_MOVE),
                       SOURCE)
    units = create_plugins(robot, 'test')
    assert [type(unit) for unit in units] == [GazeboPlanarMove, GzDiffDrive,
                                              GazeboJointStatePublisher, GzOdometryPublisher]
    assert all(unit._source == 'test' for unit in units)
    assert runs_by_plugins(robot)
    assert [name for name, _ in base_drivers(robot)] == [units[0].name, units[1].name]


def test_a_robot_without_plugins_has_no_units():
    robot = parse_urdf(plugin_rover_urdf('', ground_truth='', joint_states=''), SOURCE)
    assert robot.plugins == ()
    assert create_plugins(robot) == [] and not runs_by_plugins(robot) and not base_drivers(robot)


def test_a_malformed_element_ends_start_up_in_one_line_naming_file_plugin_and_element():
    robot = parse_urdf(plugin_rover_urdf(
        '<plugin name="move" filename="libgazebo_ros_planar_move.so">'
        '<update_rate>fast</update_rate></plugin>'), SOURCE)
    with pytest.raises(DescriptionError) as raised:
        create_plugins(robot)
    assert str(raised.value) == (f"{SOURCE}: plugin 'move' (libgazebo_ros_planar_move.so): "
                                 "<update_rate> 'fast' is not a number")


def test_a_plugin_recognised_but_not_simulated_is_one_warning_and_left_out(monkeypatch):
    monkeypatch.setitem(registry.UNSIMULATED, 'gazebo_ros_bumper', 'contacts are not published')
    robot = parse_urdf(plugin_rover_urdf(
        '<plugin name="bump" filename="libgazebo_ros_bumper.so"/>', ground_truth='',
        joint_states=''), SOURCE)
    warnings: list[str] = []
    assert create_plugins(robot, warn=warnings.append) == []
    assert warnings == [f"{SOURCE}: plugin 'bump' (libgazebo_ros_bumper.so) skipped: contacts "
                        'are not published']
