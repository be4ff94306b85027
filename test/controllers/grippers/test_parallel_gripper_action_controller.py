"""parallel_gripper_action_controller/GripperActionController, without a simulator.

What differs from the gripper action controllers (whose goal rules it
shares, see test_gripper_action_controller.py): ParallelGripperCommand
goals with exactly one position; the goal's effort and velocity bound the
force and speed only through ``max_effort_interface`` /
``max_velocity_interface``, which it then claims; jazzy's parameters and
defaults; the result's effort is the one the actuator applied.
"""

import pytest
from controller_fixtures import DT, loaded, raises_naming

from pan_tilt_sim.controllers import JointHandle, create_controller
from pan_tilt_sim.controllers.framework.surface import ActionServer
from pan_tilt_sim.controllers.grippers.gripper_action_controller import GripperRequest
from pan_tilt_sim.controllers.trajectory.trajectory_goal import GoalStatus
from pan_tilt_sim.model.robot import JointKind, JointSpec

PARALLEL_TYPE = 'parallel_gripper_action_controller/GripperActionController'
EFFORT_LIMIT = 40.0
VELOCITY_LIMIT = 0.2
FINGER = JointSpec('finger', JointKind.PRISMATIC, 0.0, 0.05, effort_limit=EFFORT_LIMIT,
                   velocity_limit=VELOCITY_LIMIT)
JAZZY_DEFAULTS = {'action_monitor_rate': 20.0, 'goal_tolerance': 0.01, 'max_effort': 10.0,
                  'allow_stalling': False, 'stall_velocity_threshold': 0.001,
                  'stall_timeout': 1.0, 'state_interfaces': ['position', 'velocity'],
                  'max_effort_interface': '', 'max_velocity_interface': '',
                  'max_velocity': 0.1}


def parallel(**params):
    handle = JointHandle(FINGER, initial_position=0.05)
    manager = loaded('gripper', PARALLEL_TYPE, {'joint': 'finger', **params}, {'finger': handle})
    controller = manager.configure('gripper')
    manager.switch(activate=['gripper'])
    return controller, handle


def test_the_defaults_are_jazzys_and_the_monitor_rate_is_read_only():
    controller = create_controller('g', PARALLEL_TYPE, {'joint': 'finger'})
    assert {key: controller.params[key] for key in JAZZY_DEFAULTS} == JAZZY_DEFAULTS
    assert type(controller).parameters['action_monitor_rate'].read_only


@pytest.mark.parametrize(('field', 'value'), [
    ('state_interfaces', ['position']), ('max_effort_interface', 'max_effort'),
    ('max_velocity_interface', 'finger/'), ('max_velocity', -0.1), ('max_effort', -1.0),
    ('joint', '')])
def test_a_wrong_value_is_a_configuration_error_naming_the_field(field, value):
    with raises_naming(f'g.{field}'):
        create_controller('g', PARALLEL_TYPE, {'joint': 'finger', field: value}, 'f.yaml')


def test_it_serves_parallel_gripper_command_and_claims_position_alone_by_default():
    controller, _handle = parallel()
    assert controller.ros_surface() == (
        ActionServer('~/gripper_cmd', 'control_msgs/action/ParallelGripperCommand'),)
    assert controller.command_interfaces() == {'finger': ('position',)}
    assert controller.state_interfaces() == {'finger': ('position', 'velocity')}


def test_it_claims_the_max_effort_and_max_velocity_interfaces_it_names():
    controller, _handle = parallel(max_effort_interface='finger/max_effort',
                                   max_velocity_interface='finger/max_velocity')
    assert controller.command_interfaces() == {
        'finger': ('position', 'max_effort', 'max_velocity')}


@pytest.mark.parametrize('positions', [[], [0.01, 0.01]])
def test_a_goal_without_exactly_one_position_is_rejected_with_upstreams_reason(positions):
    controller, _handle = parallel()
    request, problem = controller.goal_request(positions, [], [])
    assert request is None
    assert problem == ('Received action goal with wrong number of position values, expects 1, '
                       f'got {len(positions)}')


def test_without_the_interfaces_the_goals_effort_and_velocity_bound_nothing():
    controller, handle = parallel()
    request, _problem = controller.goal_request([0.0], [0.05], [3.0])
    assert request == GripperRequest(0.0, 0.0, None)
    controller.start_goal(request, 0.0)
    controller.update(0.0, DT)
    assert (handle.force_limit, handle.velocity_target) == (EFFORT_LIMIT, -VELOCITY_LIMIT)


def test_through_the_interfaces_the_goals_effort_and_velocity_bound_force_and_speed():
    controller, handle = parallel(max_effort_interface='finger/max_effort',
                                  max_velocity_interface='finger/max_velocity')
    request, _problem = controller.goal_request([0.0], [0.05], [3.0])
    controller.start_goal(request, 0.0)
    controller.update(0.0, DT)
    assert (handle.force_limit, handle.velocity_target) == (3.0, -0.05)


def test_a_goal_without_effort_and_velocity_takes_the_parameters_through_the_interfaces():
    controller, handle = parallel(max_effort_interface='finger/max_effort', max_effort=7.0,
                                  max_velocity_interface='finger/max_velocity',
                                  max_velocity=0.03)
    request, _problem = controller.goal_request([0.0], [], [])
    assert request == GripperRequest(0.0, 7.0, 0.03)
    controller.start_goal(request, 0.0)
    controller.update(0.0, DT)
    assert (handle.force_limit, handle.velocity_target) == (7.0, -0.03)


def test_a_cancel_holds_with_the_parameters_effort_and_speed():
    controller, handle = parallel(max_effort_interface='finger/max_effort', max_effort=7.0)
    request, _problem = controller.goal_request([0.0], [], [2.0])
    goal = controller.start_goal(request, 0.0)
    handle.position = 0.03
    controller.cancel_goal(goal)
    assert goal.status is GoalStatus.CANCELED and goal.result is None
    assert controller.command == GripperRequest(0.03, 7.0, None)


def test_the_results_effort_is_the_one_the_actuator_applied():
    controller, handle = parallel(max_effort_interface='finger/max_effort')
    request, _problem = controller.goal_request([0.045], [], [5.0])
    goal = controller.start_goal(request, 0.0)
    handle.position, handle.effort = 0.046, -4.5
    controller.update(0.0, DT)
    assert goal.status is GoalStatus.SUCCEEDED
    assert (goal.result.position, goal.result.effort, goal.result.reached_goal) == (
        0.046, -4.5, True)
