"""ForwardCommandController: one command per joint, the behaviour every JointGroup type shares.

The JointGroup{Position,Velocity,Effort}Controller types are this
controller with ``interface_name`` fixed (their own files say only that);
every shared test here runs on both ways to get an interface.  Pure-Python
tests drive real JointHandles made from JointSpecs (no simulator); the engine
tests run the controllers on a PyBullet robot.

The limits a group enforces are its joints' one-joint controllers' (see
test_joint_position_controller, test_joint_velocity_controller,
test_joint_effort_controller), each joint held to its own: position commands
clamped to the joint's range and ramped within its velocity limit (and, on
the ideal actuator, SETPOINT_ACCELERATION, with the velocity target within
the velocity limit); velocity commands clamped to the velocity limit;
effort commands and PID outputs clamped to the effort limit.  An element
that is NaN, infinite or beyond MAX_COMMAND_MAGNITUDE rejects the whole
command.
"""

import math

import pytest
from controller_fixtures import loaded, raises_naming, step
from group_fixtures import (
    DT,
    FORWARD,
    GROUP_TYPES,
    KIND_IDS,
    KINDS,
    group,
    make_handles,
    way_ids,
    ways,
)
from robot_fixtures import (
    LINK_LENGTH,
    LINK_MASS,
    LINK_WIDTH,
    JointDef,
    write_star_robot,
    write_text,
)

from pan_tilt_sim.controllers import CommandKind, CommandResult, JointHandle, create_controller
from pan_tilt_sim.controllers.framework.base import MAX_COMMAND_MAGNITUDE, ActuatorKind, Drive
from pan_tilt_sim.controllers.framework.manager import ACTIVE, INACTIVE, UNCONFIGURED
from pan_tilt_sim.controllers.toolbox.actuator import SETPOINT_ACCELERATION, TRACKING_GAIN
from pan_tilt_sim.controllers.toolbox.pid import PidGains
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.sim.engine import make_simulation

# --- the interface every group shares -----------------------------------------------------

@pytest.mark.parametrize(('interface', 'type_name', 'extra'), KINDS, ids=KIND_IDS)
def test_group_takes_float64_arrays_on_commands(interface, type_name, extra):
    controller = group(type_name, **extra)
    assert controller.command_topic == 'commands'
    assert controller.command_kind is CommandKind.FLOAT64_ARRAY
    assert controller.joint_names == ('shoulder', 'slide')
    assert controller.interface_name == interface


def efforts_over_steps(controller, handles, steps, start=0):
    """Update ``steps`` times (state frozen); return every step's efforts and velocity targets."""
    efforts = []
    for step_number in range(start, start + steps):
        controller.update(step_number * DT, DT)
        efforts.append([(handle.effort, handle.velocity_target) for handle in handles.values()])
    return efforts


@pytest.mark.parametrize(('interface', 'type_name', 'extra'), KINDS, ids=KIND_IDS)
@pytest.mark.parametrize('command', [[0.5], [0.5, 0.1, 0.2], [], 'ab', 3.0])
def test_wrong_length_is_rejected_and_changes_nothing(interface, type_name, extra, command):
    handles, reference_handles = make_handles(), make_handles()
    controller = group(type_name, handles, **extra)
    reference = group(type_name, reference_handles, **extra)
    for each in (controller, reference):
        assert each.set_command([0.4, 0.2]) is CommandResult.ACCEPTED
    assert efforts_over_steps(controller, handles, 5) == efforts_over_steps(
        reference, reference_handles, 5)
    assert controller.set_command(command) is CommandResult.REJECTED
    problem = controller.command_problem(command, CommandResult.REJECTED)
    assert 'expected 2 values, one per joint (shoulder, slide)' in problem
    assert efforts_over_steps(controller, handles, 5, start=5) == efforts_over_steps(
        reference, reference_handles, 5, start=5)


@pytest.mark.parametrize(('interface', 'type_name', 'extra'), KINDS, ids=KIND_IDS)
@pytest.mark.parametrize('bad', [math.nan, math.inf, -math.inf])
def test_a_non_finite_element_rejects_the_whole_command(interface, type_name, extra, bad):
    handles = make_handles()
    controller = group(type_name, handles, **extra)
    controller.update(0.0, DT)
    idle = [(handle.effort, handle.velocity_target) for handle in handles.values()]
    assert controller.set_command([0.3, bad]) is CommandResult.REJECTED
    assert "'slide' is not a finite number" in controller.command_problem(
        None, CommandResult.REJECTED)
    controller.update(DT, DT)
    assert [(handle.effort, handle.velocity_target) for handle in handles.values()] == idle


PAN_TILT_GAINS = {'p': 100.0, 'i': 0.01, 'd': 10.0}
POSITION, VELOCITY, EFFORT = (pytest.mark.parametrize(
    ('type_name', 'extra'), ways(interface), ids=way_ids(interface))
    for interface in ('position', 'velocity', 'effort'))


# --- parameters ----------------------------------------------------------------------------

@pytest.mark.parametrize(('params', 'field'), [
    ({'joints': None}, 'grp.joints'),
    ({'joints': []}, 'grp.joints'),
    ({'joints': 'shoulder'}, 'grp.joints'),
    ({'joints': ['shoulder', 'shoulder']}, 'grp.joints'),
    ({'joints': ['shoulder', 'elbow']}, 'grp.joints'),
    ({'joints': ['follower']}, 'grp.joints'),
    ({'gains': {'elbow': {'p': 1.0}}}, 'grp.gains.elbow'),
    ({'gains': {'slide': {'p': -1.0}}}, 'grp.gains.slide'),
    ({'gains': [1, 2]}, 'grp.gains'),
])
@POSITION
def test_configuration_errors_name_the_field(type_name, extra, params, field):
    with raises_naming(field):
        group(type_name, **extra, **params)


@pytest.mark.parametrize('interface', [None, 'torque', 'Position'])
def test_forward_command_controller_needs_a_known_interface(interface):
    params = {} if interface is None else {'interface_name': interface}
    with raises_naming('grp.interface_name'):
        group(FORWARD, **params)


@pytest.mark.parametrize('interface', ['position', 'velocity', 'effort'])
def test_forward_command_controller_claims_interface_name_for_every_joint(interface):
    controller = group(FORWARD, interface_name=interface)
    assert controller.interface_name == interface
    assert controller.command_interfaces() == {'shoulder': (interface,), 'slide': (interface,)}


# --- lifecycle -----------------------------------------------------------------------------

def test_the_manager_configures_activates_and_cleans_it_up_and_it_holds_where_activated():
    handles = make_handles()
    manager = loaded('grp', FORWARD, {'joints': ['shoulder', 'slide'],
                                      'interface_name': 'position'}, handles)
    assert manager.state('grp') == UNCONFIGURED
    controller = manager.configure('grp')
    assert manager.state('grp') == INACTIVE
    handles['shoulder'].position, handles['slide'].position = 0.4, 0.1
    manager.switch(activate=['grp'])
    assert manager.state('grp') == ACTIVE
    assert controller.setpoints() == {'shoulder': 0.4, 'slide': 0.1}
    assert controller.set_command([-0.2, 0.3]) is CommandResult.ACCEPTED
    step(manager, 2000)
    assert controller.setpoints() == {'shoulder': -0.2, 'slide': 0.3}
    manager.switch(deactivate=['grp'])
    last = [handle.velocity_target for handle in handles.values()]
    controller.set_command([0.9, 0.0])
    step(manager, 100, start=2000)
    assert [handle.velocity_target for handle in handles.values()] == last
    manager.cleanup('grp')
    assert manager.state('grp') == UNCONFIGURED


# --- position ------------------------------------------------------------------------------

@POSITION
def test_position_group_with_gains_ramps_each_setpoint_and_pushes_toward_it(type_name, extra):
    handles = make_handles()
    controller = group(type_name, handles, **extra,
                       gains={'shoulder': PAN_TILT_GAINS, 'slide': PAN_TILT_GAINS})
    assert controller.set_command([0.5, 0.25]) is CommandResult.ACCEPTED
    controller.update(0.0, DT)
    shoulder, slide = controller.members
    # Setpoints move at the velocity limits (2 rad/s, 0.5 m/s) from where the joints are.
    assert shoulder.setpoint == pytest.approx(2.0 * DT)
    assert slide.setpoint == pytest.approx(0.5 * DT)
    assert handles['shoulder'].effort > 0.0 and handles['slide'].effort > 0.0
    assert handles['follower'].effort == 0.0
    assert {actuator.drive for actuator in controller.actuators().values()} == {Drive.EFFORT}


@POSITION
def test_position_group_without_gains_drives_the_ideal_actuator_within_the_limits(type_name,
                                                                                  extra):
    handles = make_handles()
    controller = group(type_name, handles, **extra)
    assert [actuator.drive for actuator in controller.actuators().values()] == [
        Drive.VELOCITY] * 2
    assert controller.pids() == {}
    assert controller.set_command([0.5, 0.25]) is CommandResult.ACCEPTED
    targets, setpoints = [], [0.0]
    for step_number in range(3000):  # joints frozen at 0: the setpoints still travel
        controller.update(step_number * DT, DT)
        targets.append(handles['shoulder'].velocity_target)
        setpoints.append(controller.members[0].setpoint)
    shoulder, slide = controller.members
    assert (shoulder.setpoint, slide.setpoint) == (0.5, 0.25)
    # The setpoint speeds up at SETPOINT_ACCELERATION, never beyond the velocity limit (2 rad/s).
    speeds = [(b - a) / DT for a, b in zip(setpoints, setpoints[1:], strict=False)]
    assert max(speeds) == pytest.approx(2.0)
    accelerations = [(b - a) / DT for a, b in zip(speeds, speeds[1:], strict=False)]
    assert max(map(abs, accelerations)) == pytest.approx(SETPOINT_ACCELERATION)
    assert speeds[0] == pytest.approx(SETPOINT_ACCELERATION * DT)
    # The target chases the setpoint (TRACKING_GAIN of the error per step), within +-2 rad/s.
    assert max(map(abs, targets)) == pytest.approx(2.0)
    assert targets[-1] == pytest.approx(2.0)  # 0.5 rad behind, the limit holds it
    assert handles['shoulder'].effort == 0.0 and handles['follower'].velocity_target == 0.0


@POSITION
def test_ideal_position_target_is_the_setpoint_rate_plus_a_tenth_of_the_error_per_step(
        type_name, extra):
    handles = make_handles()
    controller = group(type_name, handles, **extra)
    controller.set_command([0.0, 0.01])
    handles['slide'].position = 0.0013  # past the setpoint while it moves
    controller.update(0.0, DT)
    slide = controller.members[1]
    rate = SETPOINT_ACCELERATION * DT
    assert slide.setpoint == pytest.approx(rate * DT)
    assert handles['slide'].velocity_target == pytest.approx(
        rate + TRACKING_GAIN / DT * (rate * DT - 0.0013))


@POSITION
def test_position_group_clamps_to_limits_and_says_which_joint(type_name, extra):
    controller = group(type_name, **extra)
    assert controller.set_command([0.5, 0.9]) is CommandResult.CLAMPED
    assert 'outside the limits of slide; clamped' in controller.command_problem(
        None, CommandResult.CLAMPED)
    for step_number in range(2000):
        controller.update(step_number * DT, DT)
    assert [member.setpoint for member in controller.members] == pytest.approx([0.5, 0.5])


# --- velocity ------------------------------------------------------------------------------

@VELOCITY
def test_velocity_group_with_gains_pushes_by_the_velocity_error(type_name, extra):
    handles = make_handles()
    handles['slide'].velocity = 0.1
    controller = group(type_name, handles, **extra,
                       gains={'shoulder': {'p': 10.0}, 'slide': {'p': 10.0}})
    controller.set_command([1.0, -0.2])
    controller.update(0.0, DT)
    assert handles['shoulder'].effort == pytest.approx(10.0 * 1.0)
    assert handles['slide'].effort == pytest.approx(10.0 * (-0.2 - 0.1))


@VELOCITY
def test_velocity_group_without_gains_targets_the_clamped_command(type_name, extra):
    handles = make_handles()
    controller = group(type_name, handles, **extra)
    assert controller.set_command([1.0, -0.9]) is CommandResult.CLAMPED  # slide: 0.5 m/s
    controller.update(0.0, DT)
    assert (handles['shoulder'].velocity_target, handles['slide'].velocity_target) == (1.0, -0.5)
    assert controller.actuators()['shoulder'].drive is Drive.VELOCITY


# --- effort --------------------------------------------------------------------------------

@EFFORT
def test_effort_group_applies_the_efforts_clamped_to_the_limits(type_name, extra):
    handles = make_handles()
    controller = group(type_name, handles, **extra)
    assert controller.set_command([5.0, -100.0]) is CommandResult.CLAMPED
    controller.update(0.0, DT)
    assert (handles['shoulder'].effort, handles['slide'].effort) == (5.0, -30.0)


@EFFORT
def test_reset_forgets_the_commands(type_name, extra):
    handles = make_handles()
    controller = group(type_name, handles, **extra)
    controller.set_command([5.0, 5.0])
    controller.reset()
    controller.update(0.0, DT)
    assert (handles['shoulder'].effort, handles['slide'].effort) == (0.0, 0.0)


# --- limits, each joint held to its own ----------------------------------------------------

def _applied(handles, interface):
    """What the group drives each joint with: setpoint-tracking target, or effort."""
    if interface == 'effort':
        return [handles['shoulder'].effort, handles['slide'].effort]
    return [handles['shoulder'].velocity_target, handles['slide'].velocity_target]


@pytest.mark.parametrize(('interface', 'type_name', 'extra'), KINDS, ids=KIND_IDS)
def test_every_element_beyond_its_joints_limit_is_clamped_to_that_joints_limit(
        interface, type_name, extra):
    handles = make_handles()
    controller = group(type_name, handles, **extra)
    assert controller.set_command([50.0, -50.0]) is CommandResult.CLAMPED
    assert 'outside the limits of shoulder, slide; clamped' in controller.command_problem(
        None, CommandResult.CLAMPED)
    for step_number in range(2000):
        controller.update(step_number * DT, DT)
    if interface == 'position':  # range: shoulder +-1 rad, slide 0..0.5 m
        assert list(controller.setpoints().values()) == [1.0, 0.0]
    else:  # velocity: +-2 rad/s and +-0.5 m/s; effort: +-20 N*m and +-30 N
        assert _applied(handles, interface) == (
            [2.0, -0.5] if interface == 'velocity' else [20.0, -30.0])


@pytest.mark.parametrize(('interface', 'commands'), [('position', [-1.0, 0.5]),
                                                     ('velocity', [-2.0, 0.5])])
@pytest.mark.parametrize('forward', [False, True], ids=['JointGroup', 'Forward'])
def test_with_gains_each_joints_pid_effort_is_clamped_to_its_own_effort_limit(
        interface, commands, forward):
    type_name, extra = ways(interface)[1 if forward else 0]
    handles = make_handles()
    controller = group(type_name, handles, **extra,
                       gains={'shoulder': {'p': 1e6}, 'slide': {'p': 1e6}})
    controller.set_command(commands)
    for step_number in range(100):
        controller.update(step_number * DT, DT)
    assert _applied(handles, 'effort') == [-20.0, 30.0]


@pytest.mark.parametrize(('interface', 'type_name', 'extra'), KINDS, ids=KIND_IDS)
def test_an_element_beyond_the_command_magnitude_bound_rejects_the_whole_command(
        interface, type_name, extra):
    handles = make_handles()
    controller = group(type_name, handles, **extra)
    controller.update(0.0, DT)
    idle = _applied(handles, interface)
    assert controller.set_command([0.3, 10 * MAX_COMMAND_MAGNITUDE]) is CommandResult.REJECTED
    controller.update(DT, DT)
    assert _applied(handles, interface) == idle


# --- gains ---------------------------------------------------------------------------------

@POSITION
def test_gains_section_sets_each_joint_pid_and_the_ideal_actuator_drives_the_rest(type_name,
                                                                                  extra):
    handles = make_handles()
    controller = group(type_name, handles, **extra,
                       gains={'slide': {'p': 500.0, 'i': 2.0, 'd': 20.0, 'i_clamp': 3.0}})
    shoulder, slide = controller.members
    assert shoulder.pid is None
    assert slide.pid.gains == PidGains(p=500.0, i=2.0, d=20.0, i_clamp_min=-3.0, i_clamp_max=3.0)
    assert list(controller.pids()) == ['slide']
    actuators = controller.actuators()
    assert actuators['shoulder'].kind is ActuatorKind.IDEAL_POSITION
    assert actuators['slide'].kind is ActuatorKind.POSITION_PID
    assert actuators['slide'].gains_from == 'grp.gains.slide'


@POSITION
def test_gazebo_ros_control_pid_gains_drive_a_joint_without_gains_of_its_own(type_name, extra):
    handles = make_handles()
    handles['shoulder'].plugin_gains = PidGains(p=7.0)
    handles['slide'].plugin_gains = PidGains(p=8.0)
    controller = group(type_name, handles, **extra, gains={'slide': {'p': 500.0}})
    shoulder, slide = controller.members
    assert (shoulder.pid.gains.p, slide.pid.gains.p) == (7.0, 500.0)
    assert controller.actuators()['shoulder'].gains_from == (
        'gazebo_ros_control.pid_gains.shoulder')


@VELOCITY
def test_ros2_controllers_gain_options_are_accepted(type_name, extra):
    controller = group(type_name, **extra, gains={
        'shoulder': {'p': 5.0, 'ff_velocity_scale': 1.0, 'angle_wraparound': False}})
    assert controller.members[1].pid is None
    assert controller.members[0].pid.gains.p == 5.0


# --- on a PyBullet robot -------------------------------------------------------------------

# A star-robot link about its joint's z axis: box about its centre plus m * (L / 2)^2.
PAN_INERTIA = LINK_MASS * (LINK_LENGTH ** 2 + LINK_WIDTH ** 2) / 12 + LINK_MASS * (
    LINK_LENGTH / 2) ** 2
STAR_JOINTS = [JointDef('pan', 'revolute', -1.5, 1.5, velocity=2.0),
               JointDef('slide', 'prismatic', -0.3, 0.3, velocity=0.5)]
STAR_INERTIAS = {'pan': PAN_INERTIA, 'slide': LINK_MASS}  # about / along each joint's axis


def star_simulation(tmp_path, type_name, **params):
    robot = write_star_robot(tmp_path, STAR_JOINTS)
    lines = ''.join(f'\n            {key}: {value}' for key, value in params.items())
    controllers = write_text(tmp_path, 'controllers.yaml', f"""
        controller_manager:
          ros__parameters:
            group:
              type: {type_name}
        group:
          ros__parameters:
            joints: [pan, slide]{lines}
        """)
    return make_simulation(str(robot), str(controllers), DT)


def interface_params(type_name, interface):
    """The ForwardCommandController is told its interface; a JointGroup*Controller knows it."""
    return {'interface_name': interface} if type_name == FORWARD else {}


def star_velocities_after(tmp_path, type_name, interface, commands, seconds):
    """Command a fresh star robot's group from rest; return the joint velocities ``seconds`` on."""
    with star_simulation(tmp_path, type_name, **interface_params(type_name, interface)) as sim:
        sim.controller('group').set_command(commands)
        sim.advance(round(seconds / DT))
        return sim.joint_velocities()


def first_order_speed(drive, damping, inertia, seconds):
    """Solve inertia * v' = drive - damping * v from rest: v after ``seconds``."""
    return drive / damping * (1.0 - math.exp(-damping * seconds / inertia))


@pytest.mark.parametrize('type_name', [GROUP_TYPES['position'], FORWARD])
def test_position_group_brings_its_joints_to_the_command(tmp_path, type_name):
    with star_simulation(tmp_path, type_name, **interface_params(type_name, 'position')) as sim:
        sim.controller('group').set_command([0.8, -0.2])
        sim.advance(3000)
        positions = sim.joint_positions()
    assert positions['pan'] == pytest.approx(0.8, abs=0.01)
    assert positions['slide'] == pytest.approx(-0.2, abs=0.005)


@pytest.mark.parametrize('type_name', [GROUP_TYPES['velocity'], FORWARD])
def test_velocity_group_spins_its_joints_at_the_command(tmp_path, type_name):
    # No gains: the ideal actuator holds the commanded speed, damping or not.
    commands, seconds = [0.5, -0.1], 0.5
    velocities = star_velocities_after(tmp_path, type_name, 'velocity', commands, seconds)
    assert [velocities['pan'], velocities['slide']] == pytest.approx(commands, abs=1e-6)


@pytest.mark.parametrize('type_name', [GROUP_TYPES['velocity'], FORWARD])
def test_velocity_group_with_gains_lags_like_a_first_order_loop(tmp_path, type_name):
    commands, seconds, gain = [0.5, -0.1], 0.5, 10.0
    gains = f'{{pan: {{p: {gain}}}, slide: {{p: {gain}}}}}'
    # At every physics step: the loop's law, without the lag of an effort held 10 steps.
    with star_simulation(tmp_path, type_name, gains=gains, update_rate=1.0 / DT,
                         **interface_params(type_name, 'velocity')) as sim:
        sim.controller('group').set_command(commands)
        sim.advance(round(seconds / DT))
        velocities = sim.joint_velocities()
    # inertia * v' = p * (command - v) - b * v: a first-order lag toward p * command / (p + b).
    damping = STAR_JOINTS[0].damping
    for (joint, inertia), command in zip(STAR_INERTIAS.items(), commands, strict=True):
        expected = first_order_speed(gain * command, gain + damping, inertia, seconds)
        assert velocities[joint] == pytest.approx(expected, rel=0.03)


@pytest.mark.parametrize('type_name', [GROUP_TYPES['effort'], FORWARD])
def test_effort_group_drives_its_joints_with_the_efforts(tmp_path, type_name):
    efforts, seconds = [0.5, -0.2], 0.5
    velocities = star_velocities_after(tmp_path, type_name, 'effort', efforts, seconds)
    # Against viscous damping b: v(t) = (F / b) * (1 - exp(-b t / inertia)).
    damping = STAR_JOINTS[0].damping
    for (joint, inertia), effort in zip(STAR_INERTIAS.items(), efforts, strict=True):
        expected = first_order_speed(effort, damping, inertia, seconds)
        assert velocities[joint] == pytest.approx(expected, rel=0.03)


# --- interfaces beyond position, velocity and effort; unknown keys -------------------------

def test_acceleration_group_integrates_the_command_into_the_velocity_target():
    handles = make_handles()
    controller = group(FORWARD, handles, interface_name='acceleration')
    assert [actuator.kind for actuator in controller.actuators().values()] == [
        ActuatorKind.IDEAL_ACCELERATION] * 2
    assert controller.actuators()['slide'].drive is Drive.VELOCITY
    assert controller.set_command([3.0, -0.25]) is CommandResult.ACCEPTED
    for index in range(100):  # joints frozen: the target is the integral, not the measurement
        controller.update(index * DT, DT)
    assert handles['shoulder'].velocity_target == pytest.approx(3.0 * 100 * DT)
    assert handles['slide'].velocity_target == pytest.approx(-0.25 * 100 * DT)
    controller.set_command([0.0, 0.0])  # no acceleration: the velocity stays
    controller.update(0.1, DT)
    assert handles['shoulder'].velocity_target == pytest.approx(0.3)


def test_acceleration_group_keeps_the_velocity_within_the_limit_without_winding_up():
    handles = make_handles()
    controller = group(FORWARD, handles, interface_name='acceleration')
    controller.set_command([100.0, 100.0])
    for index in range(100):
        controller.update(index * DT, DT)
    assert (handles['shoulder'].velocity_target, handles['slide'].velocity_target) == (2.0, 0.5)
    controller.set_command([-100.0, -100.0])
    controller.update(0.1, DT)
    assert handles['shoulder'].velocity_target == pytest.approx(2.0 - 0.1)
    assert handles['slide'].velocity_target == pytest.approx(0.5 - 0.1)


def test_acceleration_group_starts_from_the_joints_present_velocity():
    handles = make_handles()
    controller = group(FORWARD, handles, interface_name='acceleration')
    controller.set_command([1.0, 1.0])
    handles['shoulder'].velocity, handles['slide'].velocity = 0.7, 9.0
    controller.reset()  # as when activated: zero command, from the present state
    controller.update(0.0, DT)
    assert (handles['shoulder'].velocity_target, handles['slide'].velocity_target) == (0.7, 0.5)


@pytest.mark.parametrize(('interface', 'problem'), [
    (None, 'missing'), ('', 'must not be empty'), (5, '5 must be a string')])
def test_forward_command_controller_needs_an_interface_name(interface, problem):
    params = {} if interface is None else {'interface_name': interface}
    with pytest.raises(ControllerConfigError) as caught:
        create_controller('grp', FORWARD, {'joints': ['shoulder'], **params}, 'test.yaml')
    assert str(caught.value).startswith(f'test.yaml: grp.interface_name: {problem}')


@pytest.mark.parametrize('interface', ['pid_gain', 'torque', 'Position'])
def test_an_interface_the_simulator_cannot_drive_is_read_then_refused_at_configure(interface):
    controller = create_controller('grp', FORWARD, {'joints': ['shoulder', 'slide'],
                                                    'interface_name': interface}, 'test.yaml')
    assert controller.command_interfaces() == {'shoulder': (interface,), 'slide': (interface,)}
    with pytest.raises(ControllerConfigError) as caught:
        controller.configure(make_handles())
    assert str(caught.value) == (
        f"test.yaml: grp.interface_name: joint 'shoulder' interface '{interface}': the "
        'simulator can drive position, velocity, effort and acceleration')


def test_one_the_joints_block_declares_configures_and_names_the_joints_it_cannot_drive():
    from pan_tilt_sim.model.robot import ControlInterface, ControlJoint

    handles = make_handles()
    for name in ('shoulder', 'slide'):
        handles[name] = JointHandle(handles[name].spec, control=ControlJoint(
            name, command_interfaces=(ControlInterface('position'),
                                      ControlInterface('pid_gain'))))
    controller = create_controller('grp', FORWARD, {'joints': ['shoulder', 'slide'],
                                                    'interface_name': 'pid_gain'}, 'test.yaml')
    assert controller.undrivable_interfaces() == {}
    controller.configure(handles)
    assert controller.undrivable_interfaces() == {'shoulder': 'pid_gain', 'slide': 'pid_gain'}
    assert controller.members == () and controller.actuators() == {}
    # A joint whose block lacks it is still refused.
    handles['slide'] = make_handles()['slide']
    with pytest.raises(ControllerConfigError, match="joint 'slide' interface 'pid_gain'"):
        controller.configure(handles)


def test_an_unknown_gain_is_named_in_a_warning_with_the_closest_known_one():
    controller = group(GROUP_TYPES['position'], gains={'slide': {'q': 1.0, 'pp': 2.0}})
    assert controller.members[1].pid is None
    assert any('grp.gains.slide.q: unknown parameter' in line
               for line in controller.config_warnings)
    assert any("grp.gains.slide.pp: unknown parameter, ignored (did you mean 'gains.slide.p'?)"
               in line for line in controller.config_warnings)


def test_acceleration_group_speeds_its_joints_up_at_the_command(tmp_path):
    accelerations, steps = [1.0, -0.2], 500
    with star_simulation(tmp_path, FORWARD, interface_name='acceleration') as sim:
        sim.controller('group').set_command(accelerations)
        sim.advance(steps)
        velocities, positions = sim.joint_velocities(), sim.joint_positions()
    # As ros2_control's mock hardware at the controller_manager's 100 Hz: v += a * period
    # at every update, held for its 10 physics steps, over which x grows by v * dt each.
    period, updates = 0.01, steps // 10
    for joint, acceleration in zip(('pan', 'slide'), accelerations, strict=True):
        assert velocities[joint] == pytest.approx(acceleration * steps * DT, abs=1e-6)
        assert positions[joint] == pytest.approx(
            acceleration * period * period * updates * (updates + 1) / 2, abs=1e-5)
