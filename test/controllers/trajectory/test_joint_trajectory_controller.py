"""joint_trajectory_controller/JointTrajectoryController and trajectory interpolation.

The pure-Python part drives real JointHandles made from JointSpecs and
reads the controller's desired positions; the engine part follows
trajectories with the shipped three-joint arm in PyBullet.  Goals and
tolerances are test_trajectory_goal's.

The limits it enforces:

* every point's positions are clamped to each joint's [lower, upper] (not on
  a continuous joint); a point with a NaN, infinite or absurd (beyond
  MAX_COMMAND_MAGNITUDE) position or velocity rejects the trajectory;
* without gains (the ideal actuator) the velocity target is clamped to
  +-velocity limit, however fast the trajectory;
* with a PID the effort is clamped to +-effort limit, and the integral term
  is bounded by the effort limit unless the YAML gives a clamp.
"""

import math

import pytest
from controller_fixtures import loaded, raises_naming, step
from trajectory_fixtures import (
    JOINTS,
    JTC,
    controller_for,
    limited_handles,
    make_handles,
    trajectory,
)

from pan_tilt_sim.controllers import CommandKind, CommandResult
from pan_tilt_sim.controllers.commands.joint_position_controller import DEFAULT_POSITION_GAINS
from pan_tilt_sim.controllers.framework.base import MAX_COMMAND_MAGNITUDE, Drive
from pan_tilt_sim.controllers.framework.manager import ACTIVE, INACTIVE, UNCONFIGURED
from pan_tilt_sim.controllers.framework.surface import Service, StateTopic
from pan_tilt_sim.controllers.toolbox.actuator import TRACKING_GAIN
from pan_tilt_sim.controllers.trajectory.trajectory import (
    JointTrajectory,
    TrajectoryPlan,
    TrajectoryPoint,
)
from pan_tilt_sim.controllers.trajectory.trajectory_goal import GoalStatus
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.sim.engine import make_simulation

DT = 0.001


# --- TrajectoryPlan ------------------------------------------------------------------------

def sample(plan, time):
    positions, velocities = [0.0, 0.0], [0.0, 0.0]
    plan.sample(time, positions, velocities)
    return positions, velocities


def test_linear_plan_moves_at_constant_velocity_between_knots():
    plan = TrajectoryPlan([1.0, 3.0], [[0.0, 1.0], [1.0, -1.0]], None)
    positions, velocities = sample(plan, 1.5)
    assert positions == pytest.approx([0.25, 0.5])
    assert velocities == pytest.approx([0.5, -1.0])


def test_cubic_plan_matches_positions_and_velocities_at_the_knots():
    plan = TrajectoryPlan([0.0, 1.0, 2.0], [[0.0, 0.0], [1.0, 2.0], [0.5, 0.0]],
                          [[0.0, 1.0], [0.5, 0.0], [0.0, 0.0]])
    for time, position, velocity in [(0.0, [0.0, 0.0], [0.0, 1.0]),
                                     (1.0, [1.0, 2.0], [0.5, 0.0])]:
        assert sample(plan, time) == (pytest.approx(position), pytest.approx(velocity))
        just_before = sample(plan, time - 1e-7) if time > 0.0 else None
        if just_before:
            assert just_before[0] == pytest.approx(position, abs=1e-6)
            assert just_before[1] == pytest.approx(velocity, abs=1e-5)


def test_cubic_plan_velocity_is_the_derivative_of_its_position():
    plan = TrajectoryPlan([0.0, 2.0], [[0.0, 1.0], [1.0, -2.0]], [[0.3, 0.0], [-0.2, 1.0]])
    for time in (0.1, 0.7, 1.3, 1.9):
        step = 1e-6
        ahead, behind = sample(plan, time + step)[0], sample(plan, time - step)[0]
        numeric = [(x - y) / (2 * step) for x, y in zip(ahead, behind, strict=True)]
        assert sample(plan, time)[1] == pytest.approx(numeric, abs=1e-6)


def test_plan_holds_the_last_knot_at_rest_after_the_end():
    plan = TrajectoryPlan([0.0, 1.0], [[0.0, 0.0], [1.0, 2.0]], [[0.0, 0.0], [3.0, 3.0]])
    assert sample(plan, 5.0) == ([1.0, 2.0], [0.0, 0.0])


def test_plan_sampling_goes_back_after_a_reset_of_time():
    plan = TrajectoryPlan([0.0, 1.0, 2.0], [[0.0, 0.0], [1.0, 1.0], [3.0, 3.0]], None)
    late = sample(plan, 1.5)
    assert sample(plan, 0.5)[0] == pytest.approx([0.5, 0.5])
    assert sample(plan, 1.5) == late


# --- the controller, without a simulator ---------------------------------------------------

class Clock:
    """Steps a controller through sim time, one update per physics step."""

    def __init__(self, controller):
        self.controller = controller
        self.step = -1

    def run_to(self, time):
        """Update at every step up to and including ``time``; return the desired positions."""
        while self.step < round(time / DT):
            self.step += 1
            self.controller.update(self.step * DT, DT)
        return self.controller.desired_positions


def test_takes_joint_trajectories_on_joint_trajectory():
    controller = controller_for()
    assert controller.command_topic == 'joint_trajectory'
    assert controller.command_kind is CommandKind.JOINT_TRAJECTORY
    assert controller.joint_names == JOINTS


def test_holds_the_start_position_before_any_trajectory():
    handles = make_handles()
    handles['a'].position = 0.3
    controller = controller_for(handles)
    clock = Clock(controller)
    assert clock.run_to(0.5) == [0.3, 0.0]
    assert handles['a'].effort == 0.0


def test_linear_trajectory_is_followed_in_sim_time():
    controller = controller_for()
    clock = Clock(controller)
    controller.set_command(trajectory((1.0, (1.0, 0.2)), (2.0, (-1.0, 0.4))))
    assert clock.run_to(0.5) == pytest.approx([0.5, 0.1])
    assert clock.run_to(1.5) == pytest.approx([0.0, 0.3])
    assert clock.run_to(4.0) == pytest.approx([-1.0, 0.4])


def test_joints_may_come_in_any_order():
    controller = controller_for()
    clock = Clock(controller)
    controller.set_command(trajectory((1.0, (0.2, 1.0)), names=('b', 'a')))
    assert clock.run_to(2.0) == pytest.approx([1.0, 0.2])


def test_zero_stamp_starts_at_the_next_update():
    controller = controller_for()
    clock = Clock(controller)
    clock.run_to(1.0)
    controller.set_command(trajectory((1.0, (1.0, 0.0))))
    # The next update is at 1.001 s: the trajectory runs from there.
    assert clock.run_to(1.5) == pytest.approx([0.499, 0.0])


def test_future_stamp_waits_and_the_old_trajectory_goes_on_until_then():
    controller = controller_for()
    clock = Clock(controller)
    controller.set_command(trajectory((2.0, (2.0, 0.0))))
    clock.run_to(0.5)
    controller.set_command(trajectory((1.0, (-1.0, 0.0)), start=1.0))
    assert clock.run_to(1.0) == pytest.approx([1.0, 0.0], abs=DT)
    # From 1.0 s the new trajectory takes over, starting from the desired state then.
    assert clock.run_to(1.5) == pytest.approx([0.0, 0.0], abs=2 * DT)
    assert clock.run_to(3.0) == pytest.approx([-1.0, 0.0])


def test_points_already_past_are_skipped():
    controller = controller_for()
    clock = Clock(controller)
    clock.run_to(2.0)
    controller.set_command(trajectory((1.0, (5.0, 0.0)), (3.0, (1.0, 0.0)), start=0.5))
    # Point 0 fell due at 1.5 s: the plan goes from here (0) to point 1 at 3.5 s.
    assert clock.run_to(2.75) == pytest.approx([0.5, 0.0], abs=DT)


def test_a_point_due_exactly_now_is_the_start():
    controller = controller_for()
    clock = Clock(controller)
    controller.set_command(trajectory((0.0, (1.0, 0.1)), (1.0, (1.0, 0.3))))
    assert clock.run_to(0.0) == pytest.approx([1.0, 0.1])


def test_a_trajectory_entirely_in_the_past_goes_to_its_last_point():
    controller = controller_for()
    clock = Clock(controller)
    clock.run_to(5.0)
    controller.set_command(trajectory((1.0, (0.7, 0.2)), start=1.0))
    assert clock.run_to(5.001) == [0.7, 0.2]


def test_cubic_when_velocities_are_given():
    controller = controller_for()
    clock = Clock(controller)
    controller.set_command(trajectory((1.0, (1.0, 0.0), (0.0, 0.0))))
    # Hermite from rest to rest: halfway in time is halfway in position, at 1.5x the mean speed.
    assert clock.run_to(0.25) == pytest.approx([0.15625, 0.0], abs=2e-3)
    assert clock.run_to(0.5) == pytest.approx([0.5, 0.0], abs=2e-3)


def test_new_trajectory_starts_from_the_desired_state_not_the_measured_one():
    handles = make_handles()
    controller = controller_for(handles)
    clock = Clock(controller)
    controller.set_command(trajectory((1.0, (1.0, 0.0))))
    clock.run_to(0.5)
    handles['a'].position = -1.0  # the joint lags far behind
    controller.set_command(trajectory((0.5, (1.0, 0.0))))
    assert clock.run_to(0.5 + DT) == pytest.approx([0.5, 0.0], abs=3 * DT)


def test_positions_outside_the_limits_are_clamped():
    controller = controller_for()
    clock = Clock(controller)
    assert controller.set_command(trajectory((1.0, (3.0, 0.2)))) is CommandResult.CLAMPED
    assert 'trajectory positions of a' in controller.command_problem(None, CommandResult.CLAMPED)
    assert clock.run_to(2.0) == pytest.approx([2.0, 0.2])


def test_continuous_joints_are_neither_clamped_nor_wrapped():
    controller = controller_for(joints=['c'])
    clock = Clock(controller)
    assert controller.set_command(trajectory((1.0, (7.5,)), names=('c',))) is (
        CommandResult.ACCEPTED)
    assert clock.run_to(2.0) == [7.5]


@pytest.mark.parametrize(('bad', 'problem'), [
    (trajectory((1.0, (1.0,)), names=('a',)), 'missing b'),
    (trajectory((1.0, (1.0, 1.0, 1.0)), names=('a', 'b', 'z')), 'unknown z'),
    (trajectory((1.0, (1.0, 1.0)), names=('a', 'a')), 'named more than once'),
    (trajectory(), 'no points'),
    (trajectory((1.0, (1.0, 0.0)), (1.0, (2.0, 0.0))), 'point 1: time_from_start 1.0 must be'),
    (trajectory((-1.0, (1.0, 0.0))), 'point 0: time_from_start -1.0'),
    (trajectory((1.0, (1.0,))), 'point 0: 1 positions for 2 joints'),
    (trajectory((1.0, (1.0, 0.0), (0.0,))), 'point 0: 1 velocities for 2 joints'),
    (trajectory((1.0, (1.0, 0.0), (0.0, 0.0)), (2.0, (1.0, 0.0))), 'in every point or in none'),
    (trajectory((1.0, (math.nan, 0.0))), 'point 0: a position or velocity is not a finite'),
    (trajectory((1.0, (0.0, 0.0), (math.inf, 0.0))), 'not a finite number'),
    (trajectory((1.0, (1.0, 0.0)), start=math.nan), 'start time is not finite'),
    ([1.0, 2.0], 'expected a JointTrajectory'),
])
def test_bad_trajectories_are_rejected_and_change_nothing(bad, problem):
    handles = make_handles()
    controller = controller_for(handles)
    clock = Clock(controller)
    controller.set_command(trajectory((1.0, (1.0, 0.2))))
    clock.run_to(0.5)
    assert controller.set_command(bad) is CommandResult.REJECTED
    message = controller.command_problem(bad, CommandResult.REJECTED)
    assert message.startswith('ignored trajectory: ') and problem in message
    assert clock.run_to(1.0) == pytest.approx([1.0, 0.2])


def test_effort_is_pid_on_position_with_derivative_on_velocity_error():
    handles = make_handles()
    controller = controller_for(handles, command_interfaces=['effort'],
                                gains={'a': {'p': 50.0, 'd': 5.0, 'ff_velocity_scale': 2.0}})
    controller.set_command(trajectory((1.0, (1.0, 0.0))))
    handles['a'].velocity = 0.25
    controller.update(0.0, DT)
    controller.update(0.1, DT)
    # Desired 0.1 rad moving at 1 rad/s; measured 0 rad at 0.25 rad/s.
    expected = 50.0 * 0.1 + 5.0 * (1.0 - 0.25) + 2.0 * 1.0
    assert handles['a'].effort == pytest.approx(expected)
    # On the effort interface a joint without gains gets the default PID.
    assert controller.pids()['b'].gains == DEFAULT_POSITION_GAINS.with_default_clamp(1000.0)
    assert controller.actuators()['b'].gains_from == ''


@pytest.mark.parametrize('interfaces', [['position'], ['position', 'velocity'], ['velocity'], []])
def test_without_gains_the_ideal_actuator_tracks_the_desired_state(interfaces):
    handles = make_handles()
    controller = controller_for(handles, command_interfaces=interfaces,
                                gains={'a': {'p': 50.0}})
    assert list(controller.pids()) == ['a']
    actuators = controller.actuators()
    assert actuators['b'].drive is Drive.VELOCITY and actuators['a'].drive is Drive.EFFORT
    controller.set_command(trajectory((1.0, (0.0, 0.4))))
    handles['b'].position = 0.01
    for step_number in range(101):
        controller.update(step_number * DT, DT)
    # Desired 0.04 m moving at 0.4 m/s; measured 0.01 m: the target is the desired
    # velocity plus a tenth of the position error per step.
    assert handles['b'].velocity_target == pytest.approx(0.4 + TRACKING_GAIN / DT * 0.03)
    assert handles['b'].effort == 0.0


@pytest.mark.parametrize(('params', 'field'), [
    ({'joints': []}, 'arm.joints'),
    ({'joints': None}, 'arm.joints'),
    ({'joints': ['a', 'a']}, 'arm.joints'),
    ({'command_interfaces': ['torque']}, 'arm.command_interfaces'),
    ({'command_interfaces': 'position'}, 'arm.command_interfaces'),
    ({'state_interfaces': ['effort']}, 'arm.state_interfaces'),
    ({'action_monitor_rate': 0.0}, 'arm.action_monitor_rate'),
    ({'action_monitor_rate': 'often'}, 'arm.action_monitor_rate'),
    ({'allow_partial_joints_goal': 'yes'}, 'arm.allow_partial_joints_goal'),
    ({'allow_nonzero_velocity_at_trajectory_end': 1},
     'arm.allow_nonzero_velocity_at_trajectory_end'),
    ({'constraints': {'goal_time': 'soon'}}, 'arm.constraints.goal_time'),
    ({'gains': {'a': {'p': 'high'}}}, 'arm.gains.a'),
    ({'gains': {'z': {'p': 1.0}}}, 'arm.gains.z'),
    ({'gains': {'a': {'ff_velocity_scale': 'x'}}}, 'arm.gains.a.ff_velocity_scale'),
])
def test_configuration_errors_name_the_field(params, field):
    with raises_naming(field):
        controller_for(**params)


@pytest.mark.parametrize('interfaces', [
    ['position', 'acceleration'], ['position', 'velocity', 'acceleration'],
    ['position', 'effort'], ['velocity'],
])
def test_command_interfaces_take_the_combinations_upstream_takes(interfaces):
    controller = controller_for(command_interfaces=interfaces)
    assert controller.command_interfaces()['a'] == tuple(interfaces)


@pytest.mark.parametrize(('interfaces', 'problem'), [
    (['acceleration'], "'acceleration' command interface can only be used if 'velocity' and "
                       "'position' command interfaces are present"),
    (['velocity', 'acceleration'], "'velocity' command interface can be used either alone or "
                                   "'position' command interface has to be present"),
    (['velocity', 'effort'], "'velocity' command interface can be used either alone"),
    (['position', 'velocity', 'effort'], "'effort' command interface has to be used alone or "
                                         "with a 'position' interface"),
])
def test_command_interfaces_refuse_the_combinations_upstream_refuses(interfaces, problem):
    with pytest.raises(ControllerConfigError) as caught:
        controller_for(command_interfaces=interfaces)
    assert str(caught.value).startswith(f'test.yaml: arm.command_interfaces: {interfaces!r}: ')
    assert problem in str(caught.value)


def test_a_joint_the_robot_lacks_fails_at_configure_naming_the_joints_field():
    with raises_naming('arm.joints'):
        controller_for(joints=['a', 'elbow'])


def test_it_claims_its_command_and_state_interfaces_for_every_joint():
    controller = controller_for(command_interfaces=['position', 'velocity'])
    assert controller.command_interfaces() == {'a': ('position', 'velocity'),
                                               'b': ('position', 'velocity')}
    assert controller.state_interfaces() == {'a': ('position', 'velocity'),
                                             'b': ('position', 'velocity')}


def test_the_manager_configures_activates_and_cleans_it_up_and_it_holds_where_activated():
    handles = limited_handles()
    manager = loaded('arm', JTC, {'joints': list(JOINTS)}, handles)
    assert manager.state('arm') == UNCONFIGURED
    controller = manager.configure('arm')
    assert manager.state('arm') == INACTIVE
    handles['a'].position = 0.3
    manager.switch(activate=['arm'])
    assert manager.state('arm') == ACTIVE
    assert controller.desired_positions == [0.3, 0.0]  # holds where the joints are
    assert controller.set_command(trajectory((1.0, (1.0, 0.2)))) is CommandResult.ACCEPTED
    step(manager, 1500)
    assert controller.desired_positions == pytest.approx([1.0, 0.2])
    goal = controller.start_goal(trajectory((1.0, (0.0, 0.0))), controller.default_tolerances)
    manager.switch(deactivate=['arm'])
    assert goal.status is GoalStatus.ABORTED
    manager.cleanup('arm')
    assert manager.state('arm') == UNCONFIGURED


def test_reset_forgets_the_trajectory():
    controller = controller_for()
    clock = Clock(controller)
    controller.set_command(trajectory((1.0, (1.0, 0.2))))
    clock.run_to(0.5)
    controller.reset()
    assert Clock(controller).run_to(2.0) == [0.0, 0.0]



# --- ~/controller_state and ~/query_state ------------------------------------------------

def test_it_declares_controller_state_and_query_state_as_upstream():
    surface = {endpoint.name: endpoint for endpoint in controller_for().ros_surface()}
    state, query = surface['~/controller_state'], surface['~/query_state']
    assert isinstance(state, StateTopic) and isinstance(query, Service)
    assert state.message == 'control_msgs/msg/JointTrajectoryControllerState'
    assert state.fields == {'joint_names': list(JOINTS)}
    assert query.service == 'control_msgs/srv/QueryTrajectoryState'
    assert query.inactive == (False, "Can't sample trajectory. Controller is not active.",
                              (), (), (), ())


def test_controller_state_is_sampled_every_update_while_someone_listens():
    handles = make_handles()
    handles['a'].position, handles['a'].velocity = 0.1, 0.4
    controller = controller_for(handles)
    samples = []
    controller.connect_state(lambda *sample: samples.append(sample))
    controller.set_command(trajectory((1.0, (1.0, 0.2))))
    clock = Clock(controller)
    clock.run_to(0.5)
    assert len(samples) == 501  # every update, from 0 s to 0.5 s
    time, reference, feedback, error, output = samples[-1]
    assert time == pytest.approx(0.5)
    # The linear segment from where the joints were held (0.1, 0) at 0 s to (1, 0.2) at 1 s.
    assert reference == (pytest.approx([0.55, 0.1]), pytest.approx([0.9, 0.2]), [0.0, 0.0])
    assert feedback == ([0.1, 0.0], [0.4, 0.0])
    assert error == (pytest.approx([0.45, 0.1]), pytest.approx([0.5, 0.2]))
    assert output == (pytest.approx([0.55, 0.1]), [])  # the position commands; no effort
    controller.connect_state(None)
    clock.run_to(0.6)
    assert len(samples) == 501


def test_controller_state_has_the_efforts_on_an_effort_interface_and_no_velocities_unmeasured():
    handles = make_handles()
    controller = controller_for(handles, command_interfaces=['effort'],
                                state_interfaces=['position'])
    samples = []
    controller.connect_state(lambda *sample: samples.append(sample))
    controller.set_command(trajectory((1.0, (1.0, 0.2))))
    Clock(controller).run_to(0.1)
    _time, _reference, feedback, error, output = samples[-1]
    assert feedback[1] == [] and error[1] == []
    assert output == ([], [handles['a'].effort, handles['b'].effort])
    assert handles['a'].effort > 0.0


def test_controller_state_error_is_wrapped_on_a_continuous_joint():
    handles = make_handles()
    handles['c'].position = 3.0
    controller = controller_for(handles, joints=['c'])
    samples = []
    controller.connect_state(lambda *sample: samples.append(sample))
    controller.set_command(trajectory((0.001, (-3.0,)), names=('c',)))
    Clock(controller).run_to(0.01)
    assert samples[-1][3][0] == pytest.approx([2 * math.pi - 6.0])


def test_query_state_answers_the_desired_state_at_a_time_within_the_trajectory():
    controller = controller_for()
    controller.set_command(trajectory((1.0, (1.0, 0.2), (0.5, 0.0)), (2.0, (0.0, 0.4), (0.0, 0.0))))
    Clock(controller).run_to(0.2)
    answer = controller.query_state(1.5)
    assert answer.success and answer.message == ''
    assert answer.names == JOINTS
    # Cubic between (1, 0.2) at 1 s and (0, 0.4) at 2 s, with velocities (0.5, 0) and (0, 0).
    assert answer.positions == pytest.approx([0.5625, 0.3])
    assert answer.velocities == pytest.approx([-1.625, 0.3])
    assert answer.accelerations == pytest.approx([-0.5, 0.0])


def test_query_state_does_not_move_the_desired_state():
    controller = controller_for()
    clock = Clock(controller)
    controller.set_command(trajectory((1.0, (1.0, 0.2)), (2.0, (-1.0, 0.4))))
    before = clock.run_to(0.2)
    controller.query_state(1.9)
    assert controller.desired_positions == before
    assert clock.run_to(0.5) == pytest.approx([0.5, 0.1])


def test_query_state_fails_without_a_trajectory_with_upstreams_text_and_the_measured_state():
    handles = make_handles()
    handles['a'].position, handles['a'].velocity = 0.3, 0.1
    controller = controller_for(handles)
    Clock(controller).run_to(0.01)
    assert controller.query_state(0.0) == (
        False, 'Currently there is no valid trajectory instance.', JOINTS, (0.3, 0.0),
        (0.1, 0.0), (0.0, 0.0))


@pytest.mark.parametrize('time, text', [
    (0.05, 'Requested sample time is earlier than the current trajectory start time.'),
    (1.1, 'Requested sample time precedes the current trajectory end time.'),
    (5.0, 'Requested sample time precedes the current trajectory end time.')])
def test_query_state_fails_outside_the_trajectory_with_upstreams_text(time, text):
    controller = controller_for()
    clock = Clock(controller)
    clock.run_to(0.09)
    controller.set_command(trajectory((1.0, (1.0, 0.2))))  # from the next update, 0.091 s
    clock.run_to(0.2)
    answer = controller.query_state(time)
    assert (answer.success, answer.message) == (False, text)


def test_plan_accelerations_are_the_derivative_of_its_velocity():
    plan = TrajectoryPlan([0.0, 2.0], [[0.0, 1.0], [1.0, -2.0]], [[0.3, 0.0], [-0.2, 1.0]])
    for time in (0.1, 0.7, 1.3, 1.9):
        step = 1e-6
        ahead, behind = plan.at(time + step)[1], plan.at(time - step)[1]
        numeric = [(x - y) / (2 * step) for x, y in zip(ahead, behind, strict=True)]
        assert plan.at(time)[2] == pytest.approx(numeric, abs=1e-5)
        assert plan.at(time)[:2] == sample(plan, time)



# --- limits --------------------------------------------------------------------------------

@pytest.mark.parametrize('goal', [False, True], ids=['topic', 'goal'])
def test_every_point_is_clamped_to_each_joints_position_limits(goal):
    controller = controller_for(limited_handles())
    clock = Clock(controller)
    beyond = trajectory((1.0, (-3.0, 0.9)), (2.0, (3.0, -0.9)))
    if goal:
        assert controller.start_goal(beyond, controller.default_tolerances).status is (
            GoalStatus.EXECUTING)
    else:
        assert controller.set_command(beyond) is CommandResult.CLAMPED
        assert 'trajectory positions of a, b' in controller.command_problem(
            None, CommandResult.CLAMPED)
    desired = [clock.run_to(step_number * 0.01) for step_number in range(300)]
    assert desired[100] == pytest.approx([-2.0, 0.5])
    assert desired[-1] == pytest.approx([2.0, -0.5])
    assert max(abs(a) for a, _b in desired) == 2.0
    assert max(abs(b) for _a, b in desired) == 0.5


@pytest.mark.parametrize('value', [10 * MAX_COMMAND_MAGNITUDE, -10 * MAX_COMMAND_MAGNITUDE])
def test_a_point_beyond_the_command_magnitude_bound_rejects_the_trajectory(value):
    controller = controller_for(joints=['c'])
    assert controller.set_command(trajectory((1.0, (value,)), names=('c',))) is (
        CommandResult.REJECTED)
    assert Clock(controller).run_to(2.0) == [0.0]


@pytest.mark.parametrize('sign', [1.0, -1.0])
def test_without_gains_the_velocity_target_never_exceeds_the_joints_velocity_limit(sign):
    handles = limited_handles()
    controller = controller_for(handles)
    # 1.5 rad in 0.3 s is 5 rad/s of a 1 rad/s joint; 0.3 m in 0.3 s is 1 m/s of a 0.2 m/s one.
    controller.set_command(trajectory((0.3, (1.5 * sign, 0.3 * sign))))
    fastest = {'a': 0.0, 'b': 0.0}
    for step_number in range(3000):
        controller.update(step_number * DT, DT)
        for name in fastest:
            handle = handles[name]
            fastest[name] = max(fastest[name], abs(handle.velocity_target))
            handle.position += handle.velocity_target * DT  # a motor that keeps to its target
    assert fastest == {'a': 1.0, 'b': 0.2}
    # Held to its limit, each joint arrives late, but arrives.
    assert [handles['a'].position, handles['b'].position] == pytest.approx(
        [1.5 * sign, 0.3 * sign], abs=1e-3)


@pytest.mark.parametrize('sign', [1.0, -1.0])
def test_with_gains_the_effort_is_clamped_to_the_joints_effort_limit(sign):
    handles = limited_handles()
    controller = controller_for(handles, command_interfaces=['effort'],
                                gains={'a': {'p': 1e4}, 'b': {'p': 1e4}})
    controller.set_command(trajectory((0.5, (1.0 * sign, 0.4 * sign))))
    efforts = []
    for step_number in range(300):  # the joints stay where they are
        controller.update(step_number * DT, DT)
        efforts.append((handles['a'].effort, handles['b'].effort))
    assert efforts[-1] == (30.0 * sign, 50.0 * sign)
    assert max(abs(effort) for effort, _ in efforts) == 30.0
    assert max(abs(effort) for _, effort in efforts) == 50.0


def _windup_then_overshoot(controller, handle):
    """Hold the joint 0.2 short of a desired position of 0 for a second, then 0.5 past it."""
    handle.position = -0.2
    for step_number in range(1000):
        controller.update(step_number * DT, DT)
    handle.position = 0.5
    controller.update(1.0, DT)
    return handle.effort


def test_the_integral_term_is_bounded_by_the_effort_limit_unless_the_yaml_clamps_it():
    # i 1e4 integrates 2 N*m per step: without a bound the term would reach 2000 N*m,
    # and still outweigh the proportional -20 N*m once the joint overshoots.
    handles = limited_handles()
    controller = controller_for(handles, gains={'a': {'p': 40.0, 'i': 1e4}})
    assert _windup_then_overshoot(controller, handles['a']) == pytest.approx(-20.0 + 30.0)
    assert controller.pids()['a'].integral_term == 30.0
    handles = limited_handles()
    controller = controller_for(handles, gains={'a': {'p': 40.0, 'i': 1e4, 'i_clamp': 5.0}})
    assert _windup_then_overshoot(controller, handles['a']) == pytest.approx(-20.0 + 5.0)


# --- on the three-joint arm in PyBullet ----------------------------------------------------

ARM_JOINTS = ('wrist_joint', 'shoulder_joint', 'extend_joint')  # not the controller's order
WAYPOINTS = [(1.0, (1.0, 0.5, 0.05)), (2.0, (3.0, 1.0, 0.15)), (3.0, (7.0, -0.5, 0.1))]
START = 0.5  # s of sim time


@pytest.fixture
def arm(repo_root):
    with make_simulation(str(repo_root / 'urdf' / 'three_joint_arm.xacro'),
                         str(repo_root / 'config' / 'three_joint_arm_controllers.yaml'),
                         DT) as simulation:
        yield simulation


def errors_at_waypoints(simulation, points):
    simulation.controller('arm_controller').set_command(
        JointTrajectory(ARM_JOINTS, points, START))
    errors = []
    for point in points:
        simulation.advance(round((START + point.time_from_start - simulation.time) / DT))
        measured = simulation.joint_positions()
        errors.append([measured[joint] - target
                       for joint, target in zip(ARM_JOINTS, point.positions, strict=True)])
    return errors


@pytest.mark.parametrize('with_velocities', [False, True], ids=['linear', 'cubic'])
def test_three_point_trajectory_passes_within_20_mrad_of_each_waypoint(arm, with_velocities):
    points = tuple(TrajectoryPoint(when, positions, (0.0, 0.0, 0.0) if with_velocities else ())
                   for when, positions in WAYPOINTS)
    errors = errors_at_waypoints(arm, points)
    assert max(abs(error) for row in errors for error in row) < 0.02, errors


def test_arm_holds_the_last_waypoint_after_the_end(arm):
    points = tuple(TrajectoryPoint(when, positions) for when, positions in WAYPOINTS)
    errors_at_waypoints(arm, points)
    arm.advance(2000)
    measured = arm.joint_positions()
    assert [measured[joint] for joint in ARM_JOINTS] == pytest.approx(WAYPOINTS[-1][1], abs=0.005)
    assert max(abs(v) for v in arm.joint_velocities().values()) < 1e-3
