"""The interface packages scripts/build_interfaces.py builds into the venv.

tf2_msgs, control_msgs, controller_manager_msgs and simulation_interfaces
are not on PyPI; interfaces/ defines them as ROS 2 Jazzy does.  Checked here:
they import from the venv with their type support (without LD_LIBRARY_PATH
set by hand), messages, a service and an action go over DDS in-process, the
constants and type hashes are Jazzy's, and the build script skips what is up
to date or provided by someone else.

Where the venv has none of them on purpose (PAN_TILT_SIM_INTERFACES=skip, or
a ROS install provides one), the tests of that package skip and say why; a
package that is simply missing fails them.
"""

from __future__ import annotations

import importlib
import importlib.util
import json
import os
import pathlib
import shutil
import subprocess
import sys
import time
from collections.abc import Callable

import pytest
from ament_index_python.packages import get_package_share_directory

REPO = pathlib.Path(__file__).resolve().parents[1]
BUILD_SCRIPT = REPO / 'scripts' / 'build_interfaces.py'
STATUS = pathlib.Path(sys.prefix, 'share', 'pan_tilt_sim_interfaces', 'status.json')
# The upstream releases interfaces/ matches (interfaces/README.md).
VERSIONS = {
    'tf2_msgs': '0.36.4',
    'control_msgs': '5.8.0',
    'controller_manager_msgs': '4.46.0',
    'simulation_interfaces': '1.5.1',
}
# RIHS01 hashes of the upstream definitions of those releases, computed by
# rosidl_generator_type_description 4.6.6 from the upstream files (TFMessage
# and TF2Error are also what Jazzy systems report).  A field's name or type
# changes them; comments and constants do not.
UPSTREAM_HASHES = {
    'tf2_msgs/msg/TFMessage':
        'RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087',
    'tf2_msgs/msg/TF2Error':
        'RIHS01_db2485e7d6a0ec75bf087e058ee45df682acc3a621ca7780503d10aac141809a',
    'control_msgs/action/FollowJointTrajectory':
        'RIHS01_738ebcb7a2d7cfa42f9f1001cc99ce3a4383d1cfe508015d9be8485e4b1c66f6',
    'control_msgs/action/FollowJointTrajectory_FeedbackMessage':
        'RIHS01_80398fcb9674a79081a9906e2ccf0c804dd7cb15e22e362e606ee87186beab71',
    'control_msgs/msg/JointTrajectoryControllerState':
        'RIHS01_51d8dd89cc624cbe9daaeeb4d80d6de9b86168ffdc3be41fefc0953e3c26e480',
    'control_msgs/srv/QueryTrajectoryState':
        'RIHS01_4a0935dffef18bc5b9e101c9d03d84e681ecd4cebd724b8f11fde008751a325a',
    'control_msgs/srv/QueryTrajectoryState_Response':
        'RIHS01_f7b920129b8d5841312bcb89e6275508e19b3735a371b2df6e417447a44ea5db',
    'control_msgs/msg/DynamicJointState':
        'RIHS01_18024c98a62697680f581108eeed40b28fb4542fa0ac5a8e36f56c62b6813d26',
    'control_msgs/msg/InterfaceValue':
        'RIHS01_74a12144ef6b7af67533195cb30f7f607d3301b66950208a72d280695f3e190c',
    'control_msgs/action/GripperCommand':
        'RIHS01_e17c0e644eccf14bea84a0a93e0977182872c2eb7873ca6694900059b46dbc84',
    'control_msgs/action/GripperCommand_Goal':
        'RIHS01_607d9f41eb241e1922e90f02125e87ae6bfb78f7f64a71dc92630263d01f8b6d',
    'control_msgs/action/ParallelGripperCommand':
        'RIHS01_adfd3c1ebe8abc38ebcc0e454b6423d291d4010dd5697d14eca5b9be4726ae18',
    'control_msgs/action/ParallelGripperCommand_Result':
        'RIHS01_51acbcd62aa44097d3877c506eab1146856fa8768628ffbe102c1699152d2afa',
    'control_msgs/msg/GripperCommand':
        'RIHS01_57eb8f326c9889ca8bb34ead82cc94cc09bf6bc5c3b6c09546dca3a00b589890',
    'control_msgs/msg/MecanumDriveControllerState':
        'RIHS01_c560d21a4484fd5f2c05896a11de3315f4c33535a203d3e8d62af4b6a9cd3355',
    'control_msgs/msg/DynamicInterfaceGroupValues':
        'RIHS01_0ebef56c55cdde46b4622f7e0a4dbf26fefbf0296205463e955047252b434cbc',
    'control_msgs/msg/SteeringControllerStatus':
        'RIHS01_151ec2fabdfdf10cabe982ceab9fec8882c9efff0effc8d07ba7a1d404cf8143',
    'controller_manager_msgs/srv/SwitchController':
        'RIHS01_d4ad10aa5da7808bc522d55d4123d8ef79de73d049d165639d7663ac37cc9895',
    'controller_manager_msgs/srv/ListControllers':
        'RIHS01_4f8e36bb1fa5afdeba45c2d56ae6a2097b1493a253f961dd6290c085033bd189',
    'simulation_interfaces/srv/GetEntityState':
        'RIHS01_749c91f2a2353d98367b64f2995a0f5842ce92a08ec1ffb3e185540a91557fb5',
    'simulation_interfaces/srv/GetSimulationState':
        'RIHS01_3362dcebee4b1afebbf9c4beee5c79c1455385aded62092a892d61fde8644f30',
    'simulation_interfaces/action/SimulateSteps':
        'RIHS01_f0837c898e1219cd73bf4c041feab41e8c533e8e1057e982744dba7b093467eb',
}
SPIN_SLICE_S = 0.05
BUDGET_S = 30.0
# Fast DDS may call a service ready before the server has matched the
# client's response reader and then drops the response; a request still
# unanswered after this long is sent again (test/support/node_harness.py does the same).
RESEND_AFTER_S = 2.0


def _not_built_reason(package: str) -> str | None:
    """Say why the venv has no `package` on purpose, or None if it should have it."""
    if os.environ.get('PAN_TILT_SIM_INTERFACES') == 'skip':
        return 'PAN_TILT_SIM_INTERFACES=skip: the interface packages are not built'
    try:
        entry = json.loads(STATUS.read_text())['packages'][package]
    except (OSError, ValueError, KeyError):
        return None
    if entry.get('state') == 'provided':
        return f'{package} is provided by {entry.get("by")}, so it was not built into this venv'
    return None


def _require(package: str):
    """Import `package` and its msg/srv/action; skip if absent on purpose, fail if missing."""
    try:
        module = importlib.import_module(package)
    except ImportError:
        reason = _not_built_reason(package)
        if reason is not None:
            pytest.skip(reason)
        raise
    for kind in ('msg', 'srv', 'action'):
        if importlib.util.find_spec(f'{package}.{kind}') is not None:
            importlib.import_module(f'{package}.{kind}')
    return module


def _spin_until(executor, condition: Callable[[], bool], budget_s: float = BUDGET_S) -> bool:
    deadline = time.monotonic() + budget_s
    while not condition():
        if time.monotonic() > deadline:
            return False
        executor.spin_once(timeout_sec=SPIN_SLICE_S)
    return True


def _until_answered(executor, send: Callable[[], object], budget_s: float = BUDGET_S):
    """Call ``send()`` for a future, again if unanswered after RESEND_AFTER_S; return its result."""
    deadline = time.monotonic() + budget_s
    while True:
        future = send()
        if _spin_until(executor, future.done, RESEND_AFTER_S):
            return future.result()
        assert time.monotonic() < deadline, 'no answer'


@pytest.fixture
def executor(context):
    from rclpy.executors import SingleThreadedExecutor

    executor = SingleThreadedExecutor(context=context)
    nodes = []

    def add(name: str):
        from rclpy.node import Node

        node = Node(name, context=context)
        executor.add_node(node)
        nodes.append(node)
        return node

    executor.add = add
    yield executor
    for node in nodes:
        executor.remove_node(node)
        node.destroy_node()
    executor.shutdown()


def _build_script(*args: str, prefix: pathlib.Path | str = sys.prefix,
                  env: dict | None = None) -> list[str]:
    """Run build_interfaces.py on `prefix` (this venv); return its stdout lines."""
    result = subprocess.run(
        [sys.executable, str(BUILD_SCRIPT), '--prefix', str(prefix), *args],
        capture_output=True, text=True, env=env, timeout=120, check=False)
    assert result.returncode == 0, result.stderr
    return result.stdout.splitlines()


@pytest.mark.parametrize('package', sorted(VERSIONS))
def test_each_package_imports_from_the_venv(package):
    module = _require(package)
    assert pathlib.Path(module.__file__).resolve().is_relative_to(pathlib.Path(sys.prefix))
    share = pathlib.Path(get_package_share_directory(package))
    assert share.is_relative_to(pathlib.Path(sys.prefix)), share
    assert f'<version>{VERSIONS[package]}</version>' in (share / 'package.xml').read_text()


def test_type_support_loads_without_ld_library_path_set_by_hand():
    _require('tf2_msgs')
    _require('control_msgs')
    # As a user's shell starts the venv's python: nothing set, so the ROS
    # wheels' .pth bootstrap puts <venv>/lib on LD_LIBRARY_PATH, where the
    # build installs these packages' libraries too.
    env = {key: value for key, value in os.environ.items()
           if key not in ('LD_LIBRARY_PATH', '_ROS_WHEELS_BOOTSTRAP_COMPLETE')}
    code = (
        'from tf2_msgs.msg import TFMessage\n'
        'from control_msgs.action import FollowJointTrajectory\n'
        'from controller_manager_msgs.srv import SwitchController\n'
        'from simulation_interfaces.srv import GetEntityState\n'
        'for t in (TFMessage, FollowJointTrajectory, SwitchController, GetEntityState):\n'
        '    t.__class__.__import_type_support__()\n'
        'print(TFMessage._TYPE_SUPPORT is not None)\n')
    result = subprocess.run([sys.executable, '-c', code], env=env, capture_output=True,
                            text=True, timeout=60, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == 'True'


def test_tf_message_round_trips_over_dds_with_the_upstream_hash(executor):
    tf2_msgs = _require('tf2_msgs')
    from geometry_msgs.msg import TransformStamped

    node = executor.add('tf_probe')
    received = []
    node.create_subscription(tf2_msgs.msg.TFMessage, 'tf_round_trip', received.append, 10)
    publisher = node.create_publisher(tf2_msgs.msg.TFMessage, 'tf_round_trip', 10)
    sent = tf2_msgs.msg.TFMessage(transforms=[TransformStamped(child_frame_id='tilt_link')])
    sent.transforms[0].header.frame_id = 'pan_link'
    sent.transforms[0].transform.translation.z = 0.25
    sent.transforms[0].transform.rotation.w = 0.5

    assert _spin_until(executor, lambda: publisher.get_subscription_count() > 0)
    publisher.publish(sent)
    assert _spin_until(executor, lambda: bool(received))
    assert received[0] == sent
    (endpoint,) = node.get_publishers_info_by_topic('/tf_round_trip')
    assert str(endpoint.topic_type_hash) == UPSTREAM_HASHES['tf2_msgs/msg/TFMessage']


def test_a_controller_manager_service_call_goes_round(executor):
    cm = _require('controller_manager_msgs')
    server_node, client_node = executor.add('controller_manager'), executor.add('spawner')

    def switch(request, response):
        response.ok = request.strictness == cm.srv.SwitchController.Request.STRICT
        response.message = ','.join(request.activate_controllers) + \
            f'|{request.timeout.sec}|{request.activate_asap}'
        return response

    def list_controllers(_request, response):
        response.controller = [cm.msg.ControllerState(
            name='arm_controller', state='active', type='joint_trajectory_controller/JTC',
            update_rate=100, claimed_interfaces=['pan/position'], is_chainable=True,
            chain_connections=[cm.msg.ChainConnection(
                name='pid', reference_interfaces=['pan/velocity'])])]
        return response

    server_node.create_service(cm.srv.SwitchController, 'switch_controller', switch)
    server_node.create_service(cm.srv.ListControllers, 'list_controllers', list_controllers)
    switch_client = client_node.create_client(cm.srv.SwitchController, 'switch_controller')
    list_client = client_node.create_client(cm.srv.ListControllers, 'list_controllers')
    assert _spin_until(executor, lambda: switch_client.service_is_ready()
                       and list_client.service_is_ready())

    request = cm.srv.SwitchController.Request(
        activate_controllers=['arm_controller', 'gripper'],
        strictness=cm.srv.SwitchController.Request.STRICT, activate_asap=True)
    request.timeout.sec = 5
    response = _until_answered(executor, lambda: switch_client.call_async(request))
    assert response.ok
    assert response.message == 'arm_controller,gripper|5|True'

    response = _until_answered(
        executor, lambda: list_client.call_async(cm.srv.ListControllers.Request()))
    (state,) = response.controller
    assert (state.name, state.update_rate, state.claimed_interfaces) == \
        ('arm_controller', 100, ['pan/position'])
    assert state.chain_connections[0].reference_interfaces == ['pan/velocity']


def test_a_follow_joint_trajectory_goal_goes_round(executor):
    control_msgs = _require('control_msgs')
    from rclpy.action import ActionClient, ActionServer
    from trajectory_msgs.msg import JointTrajectoryPoint

    action = control_msgs.action.FollowJointTrajectory
    server_node, client_node = executor.add('jtc'), executor.add('moveit')
    goals = []

    def execute(goal_handle):
        goal = goal_handle.request
        goals.append(goal)
        feedback = action.Feedback(joint_names=list(goal.trajectory.joint_names))
        feedback.desired = goal.trajectory.points[-1]
        goal_handle.publish_feedback(feedback)
        goal_handle.succeed()
        return action.Result(
            error_code=action.Result.SUCCESSFUL,
            error_string=f'{len(goal.path_tolerance)} path tolerance(s)')

    server = ActionServer(server_node, action, 'follow_joint_trajectory', execute)
    client = ActionClient(client_node, action, 'follow_joint_trajectory')
    try:
        assert _spin_until(executor, client.server_is_ready)
        goal = action.Goal()
        goal.trajectory.joint_names = ['pan_joint', 'tilt_joint']
        goal.trajectory.points = [JointTrajectoryPoint(positions=[0.5, -0.25])]
        goal.trajectory.points[0].time_from_start.sec = 2
        goal.path_tolerance = [control_msgs.msg.JointTolerance(name='pan_joint', position=0.1)]
        goal.component_goal_tolerance = [control_msgs.msg.JointComponentTolerance(
            joint_name='base', component=control_msgs.msg.JointComponentTolerance.ROTATION)]
        goal.goal_time_tolerance.nanosec = 500_000_000
        feedback = []

        goal_handle = _until_answered(
            executor, lambda: client.send_goal_async(goal, feedback_callback=feedback.append))
        assert goal_handle.accepted
        result = _until_answered(executor, goal_handle.get_result_async).result
        assert result.error_code == action.Result.SUCCESSFUL
        assert result.error_string == '1 path tolerance(s)'
        assert goals[-1] == goal
        assert _spin_until(executor, lambda: bool(feedback))
        assert list(feedback[0].feedback.desired.positions) == [0.5, -0.25]
        (endpoint,) = client_node.get_publishers_info_by_topic(
            '/follow_joint_trajectory/_action/feedback')
        assert str(endpoint.topic_type_hash) == \
            UPSTREAM_HASHES['control_msgs/action/FollowJointTrajectory_FeedbackMessage']
    finally:
        client.destroy()
        server.destroy()


@pytest.mark.parametrize('action_name', ['GripperCommand', 'ParallelGripperCommand'])
def test_a_gripper_goal_goes_round(executor, action_name):
    control_msgs = _require('control_msgs')
    from rclpy.action import ActionClient, ActionServer

    action = getattr(control_msgs.action, action_name)
    server_node, client_node = executor.add('gripper'), executor.add('moveit')
    goals = []

    def execute(goal_handle):
        goals.append(goal_handle.request)
        goal_handle.succeed()
        result = action.Result(stalled=True, reached_goal=False)
        if action_name == 'GripperCommand':
            result.position, result.effort = 0.02, 6.0
        else:
            result.state.position, result.state.effort = [0.02], [6.0]
        return result

    server = ActionServer(server_node, action, 'gripper_cmd', execute)
    client = ActionClient(client_node, action, 'gripper_cmd')
    try:
        assert _spin_until(executor, client.server_is_ready)
        goal = action.Goal()
        if action_name == 'GripperCommand':
            goal.command = control_msgs.msg.GripperCommand(position=0.0, max_effort=6.0)
        else:
            goal.command.name, goal.command.position = ['finger'], [0.0]
            goal.command.effort = [6.0]
        goal_handle = _until_answered(executor, lambda: client.send_goal_async(goal))
        assert goal_handle.accepted
        result = _until_answered(executor, goal_handle.get_result_async).result
        assert goals[-1] == goal
        assert (result.stalled, result.reached_goal) == (True, False)
        if action_name == 'GripperCommand':
            assert (result.position, result.effort) == (0.02, 6.0)
        else:
            assert (list(result.state.position), list(result.state.effort)) == ([0.02], [6.0])
    finally:
        client.destroy()
        server.destroy()


def test_a_simulation_interfaces_service_call_goes_round(executor):
    si = _require('simulation_interfaces')
    server_node, client_node = executor.add('simulator'), executor.add('sim_client')

    def get_entity_state(request, response):
        if request.entity != 'pan_tilt':
            response.result.result = si.msg.Result.RESULT_NOT_FOUND
            response.result.error_message = f'no entity {request.entity}'
            return response
        response.result.result = si.msg.Result.RESULT_OK
        response.state.header.frame_id = 'world'
        response.state.pose.position.z = 0.3
        response.state.twist.angular.z = 0.1
        response.state.acceleration.linear.x = -1.5
        return response

    server_node.create_service(si.srv.GetEntityState, 'get_entity_state', get_entity_state)
    client = client_node.create_client(si.srv.GetEntityState, 'get_entity_state')
    assert _spin_until(executor, client.service_is_ready)

    response = _until_answered(executor, lambda: client.call_async(
        si.srv.GetEntityState.Request(entity='pan_tilt')))
    assert response.result.result == si.msg.Result.RESULT_OK
    state = response.state
    assert (state.header.frame_id, state.pose.position.z, state.twist.angular.z,
            state.acceleration.linear.x) == ('world', 0.3, 0.1, -1.5)
    response = _until_answered(executor, lambda: client.call_async(
        si.srv.GetEntityState.Request(entity='ghost')))
    assert (response.result.result, response.result.error_message) == \
        (si.msg.Result.RESULT_NOT_FOUND, 'no entity ghost')


def test_constants_have_their_upstream_values():
    tf2_msgs = _require('tf2_msgs')
    control_msgs = _require('control_msgs')
    cm = _require('controller_manager_msgs')
    si = _require('simulation_interfaces')

    result = si.msg.Result
    assert (result.RESULT_FEATURE_UNSUPPORTED, result.RESULT_OK, result.RESULT_NOT_FOUND,
            result.RESULT_INCORRECT_STATE, result.RESULT_OPERATION_FAILED) == (0, 1, 2, 3, 4)
    state = si.msg.SimulationState
    assert (state.STATE_STOPPED, state.STATE_PLAYING, state.STATE_PAUSED, state.STATE_QUITTING,
            state.STATE_NO_WORLD, state.STATE_LOADING_WORLD) == (0, 1, 2, 3, 4, 5)
    features = si.msg.SimulatorFeatures
    assert (features.SPAWNING, features.SPAWNABLES, features.SIMULATION_RESET,
            features.SIMULATION_STATE_PAUSE, features.STEP_SIMULATION_ACTION,
            features.AVAILABLE_WORLDS, features.SPAWNING_ENTITIES) == (0, 14, 20, 26, 33, 45, 50)
    assert si.srv.ResetSimulation.Request.SCOPE_ALL == 255
    assert si.srv.SpawnEntity.Response.INVALID_POSE == 109
    assert si.srv.SetEntityState.Response.INVALID_POSE == 101
    assert si.srv.SpawnEntities.Response.ENTITIES_SPAWN_FAILED == 150
    assert si.srv.StepSimulation.Request().steps == 1

    codes = control_msgs.action.FollowJointTrajectory.Result
    assert (codes.SUCCESSFUL, codes.INVALID_GOAL, codes.INVALID_JOINTS,
            codes.OLD_HEADER_TIMESTAMP, codes.PATH_TOLERANCE_VIOLATED,
            codes.GOAL_TOLERANCE_VIOLATED) == (0, -1, -2, -3, -4, -5)
    component = control_msgs.msg.JointComponentTolerance
    assert (component.X_AXIS, component.TRANSLATION, component.ROTATION) == (1, 4, 5)

    switch = cm.srv.SwitchController.Request
    assert (switch.BEST_EFFORT, switch.STRICT, switch.AUTO, switch.FORCE_AUTO) == (1, 2, 3, 4)
    assert (tf2_msgs.msg.TF2Error.NO_ERROR, tf2_msgs.msg.TF2Error.TIMEOUT_ERROR,
            tf2_msgs.msg.TF2Error.TRANSFORM_ERROR) == (0, 5, 6)


@pytest.mark.parametrize('type_name', sorted(UPSTREAM_HASHES))
def test_type_hash_equals_upstream(type_name):
    package, kind, name = type_name.split('/')
    _require(package)
    # rosidl_generator_type_description's output; actions and services also list
    # their generated parts (Goal, FeedbackMessage, Response, ...) with their hashes.
    file = name.split('_')[0] if kind in ('action', 'srv') else name
    description = pathlib.Path(get_package_share_directory(package), kind, f'{file}.json')
    hashes = {entry['type_name']: entry['hash_string']
              for entry in json.loads(description.read_text())['type_hashes']}
    assert hashes[type_name] == UPSTREAM_HASHES[type_name]


def test_up_to_date_packages_are_not_rebuilt():
    for package in VERSIONS:
        _require(package)
    env = {**os.environ, 'AMENT_PREFIX_PATH': sys.prefix}
    env.pop('PYTHONPATH', None)
    assert sorted(_build_script('--dry-run', env=env)) == \
        sorted(f'{package}: up to date' for package in VERSIONS)


def test_only_the_package_whose_definitions_changed_is_rebuilt(tmp_path):
    for package in VERSIONS:
        _require(package)
    interfaces = tmp_path / 'interfaces'
    shutil.copytree(REPO / 'interfaces', interfaces)
    with (interfaces / 'tf2_msgs' / 'msg' / 'TFMessage.msg').open('a') as definition:
        definition.write('# one more comment\n')
    env = {**os.environ, 'AMENT_PREFIX_PATH': sys.prefix}
    env.pop('PYTHONPATH', None)
    decisions = dict(line.split(': ', 1) for line in _build_script(
        '--dry-run', '--interfaces', str(interfaces), env=env))
    assert decisions == {'tf2_msgs': 'to build', 'control_msgs': 'up to date',
                         'controller_manager_msgs': 'up to date',
                         'simulation_interfaces': 'up to date'}


def test_a_package_a_ros_install_provides_is_not_built(tmp_path):
    ros = tmp_path / 'opt_ros_jazzy'
    marker = ros / 'share' / 'ament_index' / 'resource_index' / 'packages' / 'tf2_msgs'
    marker.parent.mkdir(parents=True)
    marker.touch()
    python_path = tmp_path / 'ros_python'
    (python_path / 'control_msgs').mkdir(parents=True)
    (python_path / 'control_msgs' / '__init__.py').touch()
    env = {**os.environ, 'AMENT_PREFIX_PATH': os.pathsep.join([str(ros), sys.prefix]),
           'PYTHONPATH': str(python_path)}
    decisions = dict(line.split(': ', 1) for line in _build_script('--dry-run', env=env))
    assert decisions['tf2_msgs'] == f'provided by {ros}'
    assert decisions['control_msgs'] == f'provided by {python_path}'


def test_never_installs_over_a_package_it_did_not_install(tmp_path):
    # A package of the same name already in the venv (a wheel, say) is not
    # ours: no build, no install over it.  A made-up package name in a
    # made-up venv keeps this venv's real packages out of it.
    interfaces = tmp_path / 'interfaces'
    shutil.copytree(REPO / 'interfaces' / 'cmake', interfaces / 'cmake')
    package = interfaces / 'pts_probe_msgs'
    shutil.copytree(REPO / 'interfaces' / 'tf2_msgs', package)
    for file in ('package.xml', 'CMakeLists.txt'):
        text = (package / file).read_text()
        (package / file).write_text(text.replace('tf2_msgs', 'pts_probe_msgs'))
    venv = tmp_path / 'venv'
    venv.mkdir()
    (venv / 'pyvenv.cfg').write_text('home = /nowhere\n')
    env = {**os.environ, 'AMENT_PREFIX_PATH': str(venv)}
    env.pop('PYTHONPATH', None)

    def decision() -> str:
        lines = _build_script('--dry-run', '--interfaces', str(interfaces),
                              prefix=venv, env=env)
        return dict(line.split(': ', 1) for line in lines)['pts_probe_msgs']

    assert decision() == 'to build'
    marker = venv / 'share' / 'ament_index' / 'resource_index' / 'packages' / 'pts_probe_msgs'
    marker.parent.mkdir(parents=True)
    marker.touch()
    assert decision() == f'provided by {venv.resolve()} (not installed by this script)'


def test_a_ros_workspace_never_builds_the_stand_ins():
    # colcon and rosdep (catkin_pkg) skip interfaces/ (COLCON_IGNORE), so
    # `colcon build` in a workspace holding this repo builds pan_tilt_sim only
    # and the real tf2_msgs etc. are used.
    from catkin_pkg.packages import find_packages

    assert sorted(package.name for package in find_packages(str(REPO)).values()) == \
        ['pan_tilt_sim']
    # Also if the repo root stops being a package (crawlers do not look
    # inside one), or a workspace lists interfaces/ itself.
    assert find_packages(str(REPO / 'interfaces')) == {}
    for folder in (REPO / 'interfaces').iterdir():
        if (folder / 'package.xml').is_file():
            assert f'<version>{VERSIONS[folder.name]}</version>' in \
                (folder / 'package.xml').read_text()
