"""test/support/launch_stand_in.py carries out a launch file as ROS 2's launch would.

test/data/gz_shaped/arm_sim_control.launch.py is written in the shape of
Universal Robots' gz simulation launch (an OpaqueFunction building the nodes,
FindExecutable, choices, conditions on spawners and on a RegisterEventHandler,
IfElseSubstitution); here it is only loaded and carried out up to the nodes,
with the spawners recorded instead of run.  test/end_to_end/test_drop_in_launch.py
runs it against sim_node.
"""

from __future__ import annotations

import os
import pathlib
import sys

import launch_stand_in
import pytest
import yaml
from launch_stand_in import (
    FindExecutable,
    IfElseSubstitution,
    LaunchConfiguration,
    LaunchContext,
    StandInLaunch,
    perform,
)

FIXTURE = pathlib.Path(__file__).resolve().parent / 'data' / 'gz_shaped' / (
    'arm_sim_control.launch.py')
INCLUDING = '''
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import IfElseSubstitution, LaunchConfiguration
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('gazebo_gui', default_value='true'),
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource(
                [FindPackageShare('ros_gz_sim'), '/launch/gz_sim.launch.py']),
            launch_arguments={
                'gz_args': IfElseSubstitution(LaunchConfiguration('gazebo_gui'),
                                              if_value=[' -r -v 4 ', 'empty.sdf'],
                                              else_value=[' -s -r -v 4 ', 'empty.sdf'])
            }.items(),
        ),
    ])
'''


STOPPED = '''
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([Node(package='controller_manager', executable='spawner',
                                   arguments=['arm_controller', '--stopped'])])
'''


def _launch(monkeypatch, tmp_path, **arguments) -> StandInLaunch:
    return StandInLaunch(launch_stand_in.load(FIXTURE, monkeypatch), tmp_path, arguments)


def _node(launch: StandInLaunch, executable: str):
    (node,) = [node for node in launch.nodes() if node.kwargs['executable'] == executable]
    return node


def test_the_opaque_functions_nodes_take_its_place_made_from_the_arguments(
        monkeypatch, tmp_path):
    launch = _launch(monkeypatch, tmp_path, activate_joint_controller='false')
    assert [node.kwargs['executable'] for node in launch.nodes()] == [
        'robot_state_publisher', 'spawner', 'spawner', 'sim_node']
    # The UnlessCondition's spawner, its controller a text the file performed itself.
    spawner = list(launch.nodes())[2]
    assert spawner.kwargs['arguments'] == ['arm_controller', '-c', '/controller_manager',
                                           '--inactive']
    assert not any(isinstance(action, launch_stand_in.OpaqueFunction)
                   for action in launch.actions)


def test_a_default_is_performed_and_a_given_argument_wins(monkeypatch, tmp_path):
    launch = _launch(monkeypatch, tmp_path, world='ground')
    from ament_index_python.packages import get_package_share_directory

    assert launch.arguments['description_file'] == os.path.join(
        get_package_share_directory('pan_tilt_sim'), 'urdf', 'three_joint_arm.xacro')
    assert launch.arguments['world'] == 'ground'


def test_a_value_outside_the_choices_is_refused_as_launch_refuses_it(monkeypatch, tmp_path):
    with pytest.raises(ValueError) as refused:
        _launch(monkeypatch, tmp_path, initial_joint_controller='elbow_controller')
    assert str(refused.value) == (
        'Argument "initial_joint_controller" provided value "elbow_controller" is not valid. '
        "Valid options are: ['arm_controller', 'gripper_controller']")


def test_if_else_substitution_gives_the_if_value_when_its_condition_holds(
        monkeypatch, tmp_path):
    scenery = _launch(monkeypatch, tmp_path, world='ground')
    assert perform(_node(scenery, 'sim_node').kwargs['parameters'], scenery.arguments) == [
        {'world': 'ground'}]
    bare = _launch(monkeypatch, tmp_path, scenery='False', world='ground')
    assert perform(_node(bare, 'sim_node').kwargs['parameters'], bare.arguments) == [
        {'world': 'empty'}]


def test_a_condition_text_launch_would_not_read_is_refused():
    choice = IfElseSubstitution(LaunchConfiguration('gui'), if_value='a', else_value='b')
    assert perform(choice, {'gui': '1'}) == 'a'
    assert perform(choice, {'gui': '0'}) == 'b'
    with pytest.raises(ValueError, match="'yes' is not a condition"):
        perform(choice, {'gui': 'yes'})


def test_a_substitution_performs_with_the_contexts_launch_configurations():
    context = LaunchContext({'ur_type': 'ur5e'})
    assert LaunchConfiguration('ur_type').perform(context) == 'ur5e'


def test_find_executable_finds_xacro_in_this_environments_bin():
    assert perform(FindExecutable(name='xacro'), {}) == os.path.join(
        os.path.dirname(sys.executable), 'xacro')
    with pytest.raises(ValueError, match="executable 'no-such-program' not found"):
        perform(FindExecutable(name='no-such-program'), {})


def _spawned(monkeypatch, launch: StandInLaunch) -> list[str]:
    """Run the launch's spawners, recorded instead of run; return their controllers."""
    ran = []
    monkeypatch.setattr(launch_stand_in, 'spawner_main',
                        lambda harness, arguments, namespace: ran.append(arguments[0]) or 0)
    assert set(launch.run_spawners(None)) == {0}
    return ran


def test_an_event_handler_whose_condition_holds_runs_its_spawner_after_the_target(
        monkeypatch, tmp_path):
    launch = _launch(monkeypatch, tmp_path)
    assert _spawned(monkeypatch, launch) == [
        'joint_state_broadcaster', 'arm_controller', 'gripper_controller']


def test_an_event_handler_whose_condition_does_not_hold_registers_nothing(
        monkeypatch, tmp_path):
    launch = _launch(monkeypatch, tmp_path, with_gripper='false')
    assert _spawned(monkeypatch, launch) == ['joint_state_broadcaster', 'arm_controller']


def test_an_include_left_in_is_refused_naming_the_file_and_its_launch_arguments(
        monkeypatch, tmp_path):
    path = tmp_path / 'gz.launch.py'
    path.write_text(INCLUDING)
    launch = StandInLaunch(launch_stand_in.load(path, monkeypatch), tmp_path,
                           {'gazebo_gui': 'false'})
    with pytest.raises(ValueError) as refused:
        launch.start_processes()
    assert str(refused.value) == (
        "IncludeLaunchDescription of gz_sim.launch.py(gz_args=' -s -r -v 4 empty.sdf') is not "
        'carried out by the launch stand-in')
    assert launch.processes == {}


def test_a_spawner_refusing_its_arguments_exits_2_as_the_program_would(
        monkeypatch, tmp_path, capsys):
    path = tmp_path / 'stopped.launch.py'
    path.write_text(STOPPED)  # humble's --stopped, gone from jazzy's spawner
    launch = StandInLaunch(launch_stand_in.load(path, monkeypatch), tmp_path)
    assert launch.run_spawners(None) == [2]
    assert 'unrecognized arguments: --stopped' in capsys.readouterr().err


GROUPED = '''
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction, LogInfo
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, PushROSNamespace, PushRosNamespace, SetParameter, SetRemap


def robot(name):
    return GroupAction([
        PushRosNamespace(name),
        SetRemap(src='/tf', dst='tf'),
        SetParameter(name='use_sim_time', value=True),
        Node(package='pan_tilt_sim', executable='create', name='spawn',
             arguments=['-name', LaunchConfiguration('robot')]),
        GroupAction([
            PushROSNamespace(namespace='inner'),
            Node(package='robot_state_publisher', executable='robot_state_publisher',
                 namespace='rsp', remappings=[('a', 'b')]),
        ]),
        Node(package='robot_state_publisher', executable='robot_state_publisher',
             namespace='/absolute'),
    ], launch_configurations={'robot': name})


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument('robot', default_value='none'),
        robot('robot1'),
        robot('robot2'),
        Node(package='pan_tilt_sim', executable='sim_node', name='gzserver'),
        LogInfo(msg=['robot is ', LaunchConfiguration('robot')]),
    ])
'''


def _from_text(monkeypatch, tmp_path, source: str, **arguments) -> StandInLaunch:
    path = tmp_path / 'under_test.launch.py'
    path.write_text(source)
    return StandInLaunch(launch_stand_in.load(path, monkeypatch), tmp_path, arguments)


def test_a_group_scopes_its_configurations_namespace_remaps_and_parameters(
        monkeypatch, tmp_path):
    # As nav2_bringup's multi-robot launch: each robot's group sees its own values.
    launch = _from_text(monkeypatch, tmp_path, GROUPED)
    seen = [(node.kwargs['executable'], launch.ros_args(node),
             perform(node.kwargs.get('arguments', []), launch.arguments_of(node)))
            for node in launch.nodes()]
    in_group = ['-p', 'use_sim_time:=True', '-r', '/tf:=tf']
    assert seen == [
        ('create', ['-r', '__node:=spawn', '-r', '__ns:=/robot1', *in_group],
         ['-name', 'robot1']),
        ('robot_state_publisher', ['-r', '__ns:=/robot1/inner/rsp', *in_group, '-r', 'a:=b'],
         []),
        ('robot_state_publisher', ['-r', '__ns:=/absolute', *in_group], []),
        ('create', ['-r', '__node:=spawn', '-r', '__ns:=/robot2', *in_group],
         ['-name', 'robot2']),
        ('robot_state_publisher', ['-r', '__ns:=/robot2/inner/rsp', *in_group, '-r', 'a:=b'],
         []),
        ('robot_state_publisher', ['-r', '__ns:=/absolute', *in_group], []),
        ('sim_node', ['-r', '__node:=gzserver'], []),
    ]
    assert launch.arguments['robot'] == 'none'  # the groups' values stayed in them


def test_a_text_parameter_is_typed_as_launch_ros_types_it(monkeypatch, tmp_path):
    # tb3_simulation_launch.py gives robot_state_publisher use_sim_time as a launch
    # configuration's text: launch_ros reads 'True' as a bool.
    launch = _from_text(monkeypatch, tmp_path, '''
from launch import LaunchDescription
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([Node(
        package='robot_state_publisher', executable='robot_state_publisher',
        parameters=[{'use_sim_time': LaunchConfiguration('use_sim_time', default='True'),
                     'rate': '2.5', 'frame_prefix': 'robot1/'}])])
''')
    (node,) = launch.nodes()
    arguments = launch.ros_args(node)
    written = yaml.safe_load(pathlib.Path(arguments[arguments.index('--params-file') + 1])
                             .read_text())
    assert written == {'/**': {'ros__parameters': {
        'use_sim_time': True, 'rate': 2.5, 'frame_prefix': 'robot1/'}}}


REFUSED = {
    'a node it cannot start': (
        "Node(package='rviz2', executable='rviz2')",
        "Node(package='rviz2', executable='rviz2') is not started by the launch stand-in"),
    'a group not forwarding': (
        'GroupAction([], forwarding=False)',
        'GroupAction(forwarding=False) is not carried out by the launch stand-in'),
    'something not an action': (
        "'just text'", 'str is not a launch action the launch stand-in carries out'),
}


@pytest.mark.parametrize('entry', REFUSED.values(), ids=REFUSED.keys())
def test_what_it_cannot_carry_out_is_refused_naming_it(monkeypatch, tmp_path, entry):
    action, message = entry
    with pytest.raises(ValueError) as refused:
        launch = _from_text(monkeypatch, tmp_path, f'''
from launch import LaunchDescription
from launch.actions import GroupAction
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([{action}])
''')
        launch.start_processes()
    assert str(refused.value) == message


def test_a_launch_name_it_does_not_know_is_an_import_error(monkeypatch, tmp_path):
    with pytest.raises(ImportError, match='ForEach'):
        _from_text(monkeypatch, tmp_path, 'from launch.actions import ForEach\n')


def test_an_action_whose_condition_does_not_hold_is_not_carried_out(monkeypatch, tmp_path):
    launch = _from_text(monkeypatch, tmp_path, '''
from launch import LaunchDescription
from launch.actions import GroupAction, OpaqueFunction, SetEnvironmentVariable
from launch.conditions import IfCondition, UnlessCondition
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, PushRosNamespace

ON = IfCondition(LaunchConfiguration('on'))


def generate_launch_description():
    return LaunchDescription([
        SetEnvironmentVariable('CHOSEN', 'on', condition=ON),
        SetEnvironmentVariable('CHOSEN', 'off', condition=UnlessCondition(
            LaunchConfiguration('on'))),
        OpaqueFunction(function=lambda context: [Node(
            package='pan_tilt_sim', executable='sim_node', name='unwanted')], condition=ON),
        GroupAction([PushRosNamespace('unwanted', condition=ON),
                     Node(package='pan_tilt_sim', executable='create')]),
    ])
''', on='false')
    (node,) = launch.nodes()
    assert launch.ros_args(node) == []
    assert launch.environment == {'CHOSEN': 'off'}


ON_SHUTDOWN = '''
import os
import pathlib

from launch import LaunchDescription
from launch.actions import OpaqueFunction, RegisterEventHandler
from launch.conditions import IfCondition
from launch.event_handlers import OnShutdown
from launch.substitutions import LaunchConfiguration


def generate_launch_description():
    world_sdf = LaunchConfiguration('world')
    notes = LaunchConfiguration('notes')

    def note(text):
        def write(context):
            with pathlib.Path(notes.perform(context)).open('a') as file:
                file.write(text + chr(10))

        return OpaqueFunction(function=write)

    return LaunchDescription([
        # nav2_bringup's shape: its temporary world file goes when the launch ends.
        RegisterEventHandler(event_handler=OnShutdown(on_shutdown=[
            OpaqueFunction(function=lambda context: os.remove(world_sdf.perform(context)))])),
        RegisterEventHandler(OnShutdown(
            on_shutdown=lambda event, context: note(f'{event.reason} {event.due_to_sigint}'))),
        RegisterEventHandler(OnShutdown(on_shutdown=note('not registered')),
                             condition=IfCondition('false')),
    ])
'''


def test_on_shutdown_actions_run_when_the_launch_ends_as_launch_runs_them(
        monkeypatch, tmp_path):
    world, notes = tmp_path / 'world.sdf', tmp_path / 'notes.txt'
    world.write_text('<sdf/>')
    launch = _from_text(monkeypatch, tmp_path, ON_SHUTDOWN, world=str(world), notes=str(notes))
    launch.start_processes()
    assert world.exists() and not notes.exists()  # not before the end
    launch.close()
    assert not world.exists()
    assert notes.read_text() == 'ctrl-c (SIGINT) True\n'
