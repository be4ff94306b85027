"""Group controllers: ForwardCommandController and the three JointGroup*Controllers.

Pure-Python tests drive real JointHandles made from JointSpecs (no
simulator); the engine tests run the controllers on a PyBullet robot.
"""

import math

import pytest
from robot_fixtures import (
    LINK_LENGTH,
    LINK_MASS,
    LINK_WIDTH,
    JointDef,
    write_star_robot,
    write_text,
)

from pan_tilt_sim.controllers import CommandKind, CommandResult, JointHandle, create_controller
from pan_tilt_sim.controllers.actuator import SETPOINT_ACCELERATION, TRACKING_GAIN
from pan_tilt_sim.controllers.base import ActuatorKind, Drive
from pan_tilt_sim.controllers.pid import PidGains
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.robot import JointKind, JointSpec, Mimic
from pan_tilt_sim.sim.engine import make_simulation

DT = 0.001
GROUP_TYPES = {
    'position': 'position_controllers/JointGroupPositionController',
    'velocity': 'velocity_controllers/JointGroupVelocityController',
    'effort': 'effort_controllers/JointGroupEffortController',
}
FORWARD = 'forward_command_controller/ForwardCommandController'


def make_handles():
    specs = [
        JointSpec('shoulder', JointKind.REVOLUTE, lower=-1.0, upper=1.0, effort_limit=20.0,
                  velocity_limit=2.0),
        JointSpec('slide', JointKind.PRISMATIC, lower=0.0, upper=0.5, effort_limit=30.0,
                  velocity_limit=0.5),
        JointSpec('follower', JointKind.REVOLUTE, lower=-1.0, upper=1.0,
                  mimic=Mimic('shoulder', -1.0, 0.0)),
    ]
    return {spec.name: JointHandle(spec) for spec in specs}


def group(type_name, handles=None, **params):
    params.setdefault('joints', ['shoulder', 'slide'])
    controller = create_controller('grp', type_name, params, 'test.yaml')
    controller.configure(handles if handles is not None else make_handles())
    return controller


def all_kinds():
    """(type string, params) of every way to build a group on each interface."""
    for interface, type_name in GROUP_TYPES.items():
        yield interface, type_name, {}
        yield interface, FORWARD, {'interface_name': interface}
    yield 'acceleration', FORWARD, {'interface_name': 'acceleration'}


KINDS = list(all_kinds())
KIND_IDS = [f'{type_name.split("/")[1]}-{interface}' for interface, type_name, _ in KINDS]


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
    for step in range(start, start + steps):
        controller.update(step * DT, DT)
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


SEED_GAINS = {'p': 100.0, 'i': 0.01, 'd': 10.0}


def test_position_group_with_gains_ramps_each_setpoint_and_pushes_toward_it():
    handles = make_handles()
    controller = group(GROUP_TYPES['position'], handles,
                       gains={'shoulder': SEED_GAINS, 'slide': SEED_GAINS})
    assert controller.set_command([0.5, 0.25]) is CommandResult.ACCEPTED
    controller.update(0.0, DT)
    shoulder, slide = controller.members
    # Setpoints move at the velocity limits (2 rad/s, 0.5 m/s) from where the joints are.
    assert shoulder.setpoint == pytest.approx(2.0 * DT)
    assert slide.setpoint == pytest.approx(0.5 * DT)
    assert handles['shoulder'].effort > 0.0 and handles['slide'].effort > 0.0
    assert handles['follower'].effort == 0.0
    assert {actuator.drive for actuator in controller.actuators().values()} == {Drive.EFFORT}


def test_position_group_without_gains_drives_the_ideal_actuator_within_the_limits():
    handles = make_handles()
    controller = group(GROUP_TYPES['position'], handles)
    assert [actuator.drive for actuator in controller.actuators().values()] == [
        Drive.VELOCITY] * 2
    assert controller.pids() == {}
    assert controller.set_command([0.5, 0.25]) is CommandResult.ACCEPTED
    targets, setpoints = [], [0.0]
    for step in range(3000):  # joints frozen at 0: the setpoints still travel to the command
        controller.update(step * DT, DT)
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


def test_ideal_position_target_is_the_setpoint_rate_plus_a_tenth_of_the_error_per_step():
    handles = make_handles()
    controller = group(GROUP_TYPES['position'], handles)
    controller.set_command([0.0, 0.01])
    handles['slide'].position = 0.0013  # past the setpoint while it moves
    controller.update(0.0, DT)
    slide = controller.members[1]
    rate = SETPOINT_ACCELERATION * DT
    assert slide.setpoint == pytest.approx(rate * DT)
    assert handles['slide'].velocity_target == pytest.approx(
        rate + TRACKING_GAIN / DT * (rate * DT - 0.0013))


def test_position_group_clamps_to_limits_and_says_which_joint():
    controller = group(GROUP_TYPES['position'])
    assert controller.set_command([0.5, 0.9]) is CommandResult.CLAMPED
    assert 'outside the limits of slide; clamped' in controller.command_problem(
        None, CommandResult.CLAMPED)
    for step in range(2000):
        controller.update(step * DT, DT)
    assert [member.setpoint for member in controller.members] == pytest.approx([0.5, 0.5])


def test_velocity_group_with_gains_pushes_by_the_velocity_error():
    handles = make_handles()
    handles['slide'].velocity = 0.1
    controller = group(GROUP_TYPES['velocity'], handles,
                       gains={'shoulder': {'p': 10.0}, 'slide': {'p': 10.0}})
    controller.set_command([1.0, -0.2])
    controller.update(0.0, DT)
    assert handles['shoulder'].effort == pytest.approx(10.0 * 1.0)
    assert handles['slide'].effort == pytest.approx(10.0 * (-0.2 - 0.1))


def test_velocity_group_without_gains_targets_the_clamped_command():
    handles = make_handles()
    controller = group(GROUP_TYPES['velocity'], handles)
    assert controller.set_command([1.0, -0.9]) is CommandResult.CLAMPED  # slide: 0.5 m/s
    controller.update(0.0, DT)
    assert (handles['shoulder'].velocity_target, handles['slide'].velocity_target) == (1.0, -0.5)
    assert controller.actuators()['shoulder'].drive is Drive.VELOCITY


def test_effort_group_applies_the_efforts_clamped_to_the_limits():
    handles = make_handles()
    controller = group(GROUP_TYPES['effort'], handles)
    assert controller.set_command([5.0, -100.0]) is CommandResult.CLAMPED
    controller.update(0.0, DT)
    assert (handles['shoulder'].effort, handles['slide'].effort) == (5.0, -30.0)


def test_acceleration_group_integrates_the_command_into_the_velocity_target():
    handles = make_handles()
    controller = group(FORWARD, handles, interface_name='acceleration')
    assert [actuator.kind for actuator in controller.actuators().values()] == [
        ActuatorKind.IDEAL_ACCELERATION] * 2
    assert controller.actuators()['slide'].drive is Drive.VELOCITY
    assert controller.set_command([3.0, -0.25]) is CommandResult.ACCEPTED
    for step in range(100):  # joints frozen: the target is the integral, not the measurement
        controller.update(step * DT, DT)
    assert handles['shoulder'].velocity_target == pytest.approx(3.0 * 100 * DT)
    assert handles['slide'].velocity_target == pytest.approx(-0.25 * 100 * DT)
    controller.set_command([0.0, 0.0])  # no acceleration: the velocity stays
    controller.update(0.1, DT)
    assert handles['shoulder'].velocity_target == pytest.approx(0.3)


def test_acceleration_group_keeps_the_velocity_within_the_limit_without_winding_up():
    handles = make_handles()
    controller = group(FORWARD, handles, interface_name='acceleration')
    controller.set_command([100.0, 100.0])
    for step in range(100):
        controller.update(step * DT, DT)
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


def test_reset_forgets_the_commands():
    handles = make_handles()
    controller = group(GROUP_TYPES['effort'], handles)
    controller.set_command([5.0, 5.0])
    controller.reset()
    controller.update(0.0, DT)
    assert (handles['shoulder'].effort, handles['slide'].effort) == (0.0, 0.0)


# --- gains and configuration errors --------------------------------------------------------

def test_gains_section_sets_each_joint_pid_and_the_ideal_actuator_drives_the_rest():
    handles = make_handles()
    controller = group(GROUP_TYPES['position'], handles,
                       gains={'slide': {'p': 500.0, 'i': 2.0, 'd': 20.0, 'i_clamp': 3.0}})
    shoulder, slide = controller.members
    assert shoulder.pid is None
    assert slide.pid.gains == PidGains(p=500.0, i=2.0, d=20.0, i_clamp_min=-3.0, i_clamp_max=3.0)
    assert list(controller.pids()) == ['slide']
    actuators = controller.actuators()
    assert actuators['shoulder'].kind is ActuatorKind.IDEAL_POSITION
    assert actuators['slide'].kind is ActuatorKind.POSITION_PID
    assert actuators['slide'].gains_from == 'grp.gains.slide'


def test_gazebo_ros_control_pid_gains_drive_a_joint_without_gains_of_its_own():
    handles = make_handles()
    handles['shoulder'].plugin_gains = PidGains(p=7.0)
    handles['slide'].plugin_gains = PidGains(p=8.0)
    controller = group(GROUP_TYPES['position'], handles, gains={'slide': {'p': 500.0}})
    shoulder, slide = controller.members
    assert (shoulder.pid.gains.p, slide.pid.gains.p) == (7.0, 500.0)
    assert controller.actuators()['shoulder'].gains_from == (
        'gazebo_ros_control.pid_gains.shoulder')


def test_ros2_controllers_gain_options_are_accepted():
    controller = group(GROUP_TYPES['velocity'], gains={
        'shoulder': {'p': 5.0, 'ff_velocity_scale': 1.0, 'angle_wraparound': False}})
    assert controller.members[1].pid is None
    assert controller.members[0].pid.gains.p == 5.0


@pytest.mark.parametrize(('params', 'field', 'problem'), [
    ({'joints': None}, 'grp.joints', 'missing'),
    ({'joints': 'shoulder'}, 'grp.joints', 'must be a list of strings'),
    ({'joints': []}, 'grp.joints', 'empty'),
    ({'joints': ['shoulder', 'shoulder']}, 'grp.joints', "'shoulder' is named more than once"),
    ({'joints': ['shoulder', 'elbow']}, 'grp.joints', "joint 'elbow' is not a movable joint"),
    ({'joints': ['follower']}, 'grp.joints', "'follower' mimics 'shoulder'"),
    ({'gains': {'elbow': {'p': 1.0}}}, 'grp.gains.elbow', "not one of this controller's joints"),
    ({'gains': {'slide': {'p': -1.0}}}, 'grp.gains.slide.p', '-1.0 must be'),
    ({'gains': [1, 2]}, 'grp.gains', 'expected a mapping'),
])
def test_configuration_errors_name_the_field(params, field, problem):
    with pytest.raises(ControllerConfigError) as err:
        group(GROUP_TYPES['position'], **params)
    assert str(err.value).startswith(f'test.yaml: {field}: ')
    assert problem in str(err.value)


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


def test_an_unknown_gain_is_named_in_a_warning_with_the_closest_known_one():
    controller = group(GROUP_TYPES['position'], gains={'slide': {'q': 1.0, 'pp': 2.0}})
    assert controller.members[1].pid is None
    assert any('grp.gains.slide.q: unknown parameter' in line
               for line in controller.config_warnings)
    assert any("grp.gains.slide.pp: unknown parameter, ignored (did you mean 'gains.slide.p'?)"
               in line for line in controller.config_warnings)


def test_joint_group_types_fix_their_interface():
    assert group(GROUP_TYPES['effort'], interface_name='position').interface_name == 'effort'


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
    with star_simulation(tmp_path, type_name, gains=gains,
                         **interface_params(type_name, 'velocity')) as sim:
        sim.controller('group').set_command(commands)
        sim.advance(round(seconds / DT))
        velocities = sim.joint_velocities()
    # inertia * v' = p * (command - v) - b * v: a first-order lag toward p * command / (p + b).
    damping = STAR_JOINTS[0].damping
    for (joint, inertia), command in zip(STAR_INERTIAS.items(), commands, strict=True):
        expected = first_order_speed(gain * command, gain + damping, inertia, seconds)
        assert velocities[joint] == pytest.approx(expected, rel=0.03)


def test_acceleration_group_speeds_its_joints_up_at_the_command(tmp_path):
    accelerations, steps = [1.0, -0.2], 500
    with star_simulation(tmp_path, FORWARD, interface_name='acceleration') as sim:
        sim.controller('group').set_command(accelerations)
        sim.advance(steps)
        velocities, positions = sim.joint_velocities(), sim.joint_positions()
    # As ros2_control's mock hardware: v += a * dt, then x += v * dt, every step.
    for joint, acceleration in zip(('pan', 'slide'), accelerations, strict=True):
        assert velocities[joint] == pytest.approx(acceleration * steps * DT, abs=1e-6)
        assert positions[joint] == pytest.approx(
            acceleration * DT * DT * steps * (steps + 1) / 2, abs=1e-5)


@pytest.mark.parametrize('type_name', [GROUP_TYPES['effort'], FORWARD])
def test_effort_group_drives_its_joints_with_the_efforts(tmp_path, type_name):
    efforts, seconds = [0.5, -0.2], 0.5
    velocities = star_velocities_after(tmp_path, type_name, 'effort', efforts, seconds)
    # Against viscous damping b: v(t) = (F / b) * (1 - exp(-b t / inertia)).
    damping = STAR_JOINTS[0].damping
    for (joint, inertia), effort in zip(STAR_INERTIAS.items(), efforts, strict=True):
        expected = first_order_speed(effort, damping, inertia, seconds)
        assert velocities[joint] == pytest.approx(expected, rel=0.03)


