"""gz_sim.launch.py's gz_args, read as `gz sim` reads them, make sim_node's start."""

import pathlib

import pytest

from pan_tilt_sim.tools.stand_ins.gz_sim import GzArgsError, server


def test_run_verbosity_and_the_built_in_empty_world():
    started = server(' -r -v 3 empty.sdf', environ={})
    assert started.run
    assert started.parameters == {'world': 'ground', 'robot_from_spawn': True, 'paused': False,
                                  'autostart_controllers': False, 'publish_tf': False}
    assert started.ros_arguments == ['--log-level', 'info'] and started.warnings == []


def test_without_r_it_starts_paused_as_gz_sim_does_and_no_world_is_the_empty_one():
    started = server('-s --headless-rendering', environ={})
    assert started.parameters['paused'] is True
    assert started.parameters['world'] == 'ground' and started.warnings == []


@pytest.mark.parametrize(('level', 'ros'), [('0', 'fatal'), ('1', 'error'), ('2', 'warn'),
                                            ('4', 'info')])
def test_verbosity_levels_map_to_log_levels(level, ros):
    assert server(f'-v {level}', environ={}).ros_arguments == ['--log-level', ros]


def test_a_world_file_is_found_by_path_then_on_the_resource_path(tmp_path: pathlib.Path):
    world = tmp_path / 'models' / 'sandbox.sdf'
    world.parent.mkdir()
    world.write_text('<sdf version="1.8"><world name="w"/></sdf>')
    assert server(str(world), environ={}).parameters['world'] == str(world)
    found = server('-r sandbox.sdf', environ={'GZ_SIM_RESOURCE_PATH': str(world.parent)},
                   cwd=tmp_path)
    assert found.parameters['world'] == str(world)


def test_a_world_that_is_nowhere_is_one_line_naming_it(tmp_path):
    with pytest.raises(GzArgsError, match="world 'shapes.sdf' not found"):
        server('-r shapes.sdf', environ={}, cwd=tmp_path)


def test_a_world_path_not_written_yet_is_read_when_sim_node_starts(tmp_path):
    # nav2_bringup's shape: `xacro -o <tmp>.sdf` (an ExecuteProcess) writes the world while
    # gz sim starts; gz sim reads it then, not when the launch file is read.
    later = tmp_path / 'nav2_world.sdf'
    assert server(f'-r -s {later}', environ={}).parameters['world'] == str(later)
    relative = server('-r worlds/later.sdf', environ={}, cwd=tmp_path).parameters['world']
    assert relative == str(tmp_path / 'worlds' / 'later.sdf')


def test_options_not_honoured_are_named_once_each_with_their_value():
    started = server('-r --physics-engine gz-physics-bullet -z 1000 --seed=3 empty.sdf',
                     environ={})
    assert started.warnings == [
        "gz_args: '--physics-engine gz-physics-bullet' is not honoured by sim_node",
        "gz_args: '-z 1000' is not honoured by sim_node",
        "gz_args: '--seed 3' is not honoured by sim_node"]
    assert started.parameters['world'] == 'ground'


def test_a_gui_only_gz_sim_starts_nothing():
    started = server('-g -v 4', environ={})
    assert not started.run and "'-g'" in started.warnings[-1]


def test_levels_takes_no_value_so_the_world_after_it_is_still_the_world(tmp_path):
    world = tmp_path / 'sandbox.sdf'
    world.write_text('<sdf version="1.8"><world name="w"/></sdf>')
    started = server(f'-r --levels {world}', environ={})
    assert started.parameters['world'] == str(world)
    assert started.warnings == ["gz_args: '--levels' is not honoured by sim_node"]


def test_an_option_value_is_optional_and_never_the_next_option():
    # gz sim's OptionParser: `[arg]` values are optional, a following `-...` is an option.
    started = server('--iterations -r empty.sdf', environ={})
    assert started.parameters['paused'] is False
    assert started.warnings == ["gz_args: '--iterations' is not honoured by sim_node"]


@pytest.mark.parametrize(('word', 'ros'), [('-v4', 'info'), ('-v1', 'error'),
                                           ('--verbose=2', 'warn')])
def test_a_verbosity_attached_to_its_flag_is_read(word, ros):
    started = server(f'-r {word} empty.sdf', environ={})
    assert started.ros_arguments == ['--log-level', ros] and started.warnings == []


def test_of_two_worlds_the_last_is_loaded_as_gz_sim_does_and_the_other_named(tmp_path):
    world = tmp_path / 'sandbox.sdf'
    world.write_text('<sdf version="1.8"><world name="w"/></sdf>')
    started = server(f'shapes.sdf {world}', environ={}, cwd=tmp_path)
    assert started.parameters['world'] == str(world)
    assert started.warnings == ["gz_args: 'shapes.sdf' is not honoured by sim_node (gz sim "
                                'loads the last world given)']


def _launch(monkeypatch, tmp_path, name: str, **arguments: str):
    import launch_stand_in

    launch_file = pathlib.Path(__file__).parents[3] / 'launch' / name
    launch = launch_stand_in.StandInLaunch(launch_stand_in.load(launch_file, monkeypatch),
                                           tmp_path, arguments)
    return launch, launch_stand_in


def test_gz_spawn_model_launch_py_runs_create_with_its_arguments_as_parameters(monkeypatch,
                                                                             tmp_path):
    launch, stand_in = _launch(monkeypatch, tmp_path, 'gz_spawn_model.launch.py',
                               topic='robot_description', entity_name='rover',
                               allow_renaming='true', x='1.5', Y='0.5')
    (create,) = launch.nodes()
    assert (create.kwargs['package'], create.kwargs['executable']) == ('pan_tilt_sim', 'create')
    (parameters,) = stand_in.perform(create.kwargs['parameters'], launch.arguments_of(create))
    assert parameters == {'world': '', 'file': '', 'string': '', 'topic': 'robot_description',
                          'name': 'rover', 'allow_renaming': 'true', 'x': '1.5', 'y': '0.0',
                          'z': '0.0', 'R': '0.0', 'P': '0.0', 'Y': '0.5'}


def test_gz_server_launch_py_starts_sim_node_running_with_the_world_file_or_string(
        monkeypatch, tmp_path):
    world = tmp_path / 'sandbox.sdf'
    world.write_text('<sdf version="1.8"><world name="w"/></sdf>')
    launch, _stand_in = _launch(monkeypatch, tmp_path, 'gz_server.launch.py',
                                world_sdf_file=str(world))
    (sim_node,) = launch.nodes()
    (parameters,) = sim_node.kwargs['parameters']
    assert sim_node.kwargs['name'] == 'gzserver'
    assert parameters['world'] == str(world) and parameters['paused'] is False
    text = '<sdf version="1.8"><world name="from_string"/></sdf>'
    launch, _stand_in = _launch(monkeypatch, tmp_path, 'gz_server.launch.py',
                                world_sdf_string=text, use_composition='True')
    (sim_node,) = launch.nodes()  # composition or not: sim_node is a process of its own
    (parameters,) = sim_node.kwargs['parameters']
    assert pathlib.Path(parameters['world']).read_text() == text
