"""gazebo_ros's gazebo.launch.py arguments, read as sim_node's start (Gazebo classic)."""

import pathlib

import launch_stand_in
import pytest

from pan_tilt_sim.tools.stand_ins.gazebo_classic import ARGUMENTS, server
from pan_tilt_sim.tools.stand_ins.gz_sim import GzArgsError


def launch_arguments(**given: str) -> dict[str, str]:
    """The launch arguments as the launch file performs them: defaults, then ``given``."""
    return {**ARGUMENTS, **given}


def test_the_defaults_are_gzservers_empty_world_playing_and_quiet():
    started = server(launch_arguments(), environ={})
    assert started.run and started.warnings == []
    assert started.parameters == {'world': 'ground', 'robot_from_spawn': True, 'paused': False,
                                  'autostart_controllers': False, 'publish_tf': False}
    assert started.ros_arguments == ['--log-level', 'warn']


def test_pause_verbose_and_extra_gazebo_args():
    assert server(launch_arguments(pause='true'), environ={}).parameters['paused'] is True
    started = server(launch_arguments(extra_gazebo_args='-u --verbose -s libfoo.so'),
                     environ={})
    assert started.parameters['paused'] is True and started.ros_arguments == []
    assert started.warnings == ["extra_gazebo_args: '-s libfoo.so' is not honoured by sim_node"]


def test_arguments_given_a_value_sim_node_does_not_honour_are_named():
    started = server(launch_arguments(physics='bullet', seed='4'), environ={})
    assert started.warnings == [
        "gazebo.launch.py: physics:='bullet' is not honoured by sim_node",
        "gazebo.launch.py: seed:='4' is not honoured by sim_node"]


def test_a_world_on_the_resource_path_and_one_that_is_nowhere(tmp_path):
    (tmp_path / 'worlds').mkdir()
    world = tmp_path / 'worlds' / 'room.world'
    world.write_text('<sdf version="1.6"><world name="room"/></sdf>')
    found = server(launch_arguments(world='worlds/room.world'),
                   environ={'GAZEBO_RESOURCE_PATH': str(tmp_path)}, cwd=tmp_path / 'worlds')
    assert found.parameters['world'] == str(world)
    with pytest.raises(GzArgsError, match="world 'cafe.world' not found"):
        server(launch_arguments(world='cafe.world'), environ={}, cwd=tmp_path)


def test_server_false_starts_nothing():
    assert not server(launch_arguments(server='false'), environ={}).run


def test_a_gzserver_option_is_named_with_its_value_in_one_warning():
    started = server(launch_arguments(extra_gazebo_args='-e bullet --seed=4 --lockstep'),
                     environ={})
    assert started.warnings == ["extra_gazebo_args: '-e bullet' is not honoured by sim_node",
                                "extra_gazebo_args: '--seed=4' is not honoured by sim_node",
                                "extra_gazebo_args: '--lockstep' is not honoured by sim_node"]


@pytest.mark.parametrize(('required', 'shutdown'), [('true', True), ('false', False)])
def test_server_required_ends_the_launch_when_sim_node_ends(required, shutdown):
    started = server(launch_arguments(server_required=required), environ={})
    assert started.shutdown_on_exit is shutdown and started.warnings == []


@pytest.mark.parametrize(('required', 'shutdown'), [('true', True), ('false', False)])
def test_the_launch_file_gives_sim_node_a_shutdown_on_exit_when_server_is_required(
        monkeypatch, tmp_path, required, shutdown):
    launch_file = pathlib.Path(__file__).parents[3] / 'launch' / 'gazebo.launch.py'
    launch = launch_stand_in.StandInLaunch(launch_stand_in.load(launch_file, monkeypatch),
                                           tmp_path, {'server_required': required})
    (sim_node,) = launch.nodes()
    on_exit = sim_node.kwargs['on_exit']
    assert isinstance(on_exit, launch_stand_in.Shutdown) is shutdown


def _launch(monkeypatch, tmp_path, name: str, **arguments: str):
    launch_file = pathlib.Path(__file__).parents[3] / 'launch' / name
    return launch_stand_in.StandInLaunch(launch_stand_in.load(launch_file, monkeypatch),
                                         tmp_path, arguments)


def test_gzserver_launch_py_alone_starts_sim_node_as_gazebo_launch_py_does(monkeypatch,
                                                                            tmp_path):
    # turtlebot3_gazebo's shape: gzserver.launch.py and gzclient.launch.py included apart.
    launch = _launch(monkeypatch, tmp_path, 'gzserver.launch.py', pause='true',
                     server_required='true')
    (sim_node,) = launch.nodes()
    assert sim_node.kwargs['name'] == 'gazebo'
    (parameters,) = sim_node.kwargs['parameters']
    assert parameters['world'] == 'ground' and parameters['paused'] is True
    assert isinstance(sim_node.kwargs['on_exit'], launch_stand_in.Shutdown)


def test_gzclient_launch_py_starts_nothing(monkeypatch, tmp_path):
    launch = _launch(monkeypatch, tmp_path, 'gzclient.launch.py', verbose='true')
    assert list(launch.nodes()) == []
