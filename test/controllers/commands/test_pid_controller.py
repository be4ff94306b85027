"""pid_controller/PidController: a PID per DoF from its references to its command, chainable.

Pure-Python tests on real JointHandles made from JointSpecs (the state is
set by hand, no physics); the chain runs under a ControllerManager, which
updates a preceding controller before the PidController it feeds.
"""

import math
import pathlib

import pytest

from pan_tilt_sim.controllers import CommandResult, JointHandle, create_controller
from pan_tilt_sim.controllers.commands.forward_command_controller import ReferenceForwarder
from pan_tilt_sim.controllers.commands.pid_controller import (
    FEEDFORWARD_SERVICE_NOTICE,
    PidController,
)
from pan_tilt_sim.controllers.framework.base import ActuatorKind, Drive
from pan_tilt_sim.controllers.framework.manager import ControllerManager
from pan_tilt_sim.controllers.framework.surface import CommandTopic, Service, StateTopic
from pan_tilt_sim.controllers.toolbox.pid import PidGains
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.controller_config import ControllersConfig, ControllerSpec
from pan_tilt_sim.model.robot import JointKind, JointSpec, Mimic

TYPE = 'pid_controller/PidController'
FORWARD = 'forward_command_controller/ForwardCommandController'
DT = 0.001
EFFORT_LIMIT, VELOCITY_LIMIT = 5.0, 2.0


def make_handles():
    specs = [
        JointSpec('joint1', JointKind.REVOLUTE, lower=-1.0, upper=1.0,
                  effort_limit=EFFORT_LIMIT, velocity_limit=VELOCITY_LIMIT),
        JointSpec('joint2', JointKind.REVOLUTE, lower=-1.0, upper=1.0,
                  effort_limit=EFFORT_LIMIT, velocity_limit=VELOCITY_LIMIT),
        JointSpec('wheel', JointKind.CONTINUOUS, effort_limit=EFFORT_LIMIT,
                  velocity_limit=VELOCITY_LIMIT),
        JointSpec('follower', JointKind.REVOLUTE, lower=-1.0, upper=1.0,
                  mimic=Mimic('joint1', 1.0, 0.0)),
    ]
    return {spec.name: JointHandle(spec) for spec in specs}


def build(**params):
    """Return an unconfigured controller ``pid`` of ``params`` over the minimal example."""
    params.setdefault('dof_names', ['joint1'])
    params.setdefault('command_interface', 'effort')
    params.setdefault('reference_and_state_interfaces', ['position'])
    return create_controller('pid', TYPE, params, 'test.yaml')


def configured(handles=None, **params):
    """Return ``pid`` of ``params`` configured (and so reset, as on activation) on ``handles``."""
    controller = build(**params)
    controller.configure(handles if handles is not None else make_handles())
    return controller


def reference(dofs=(), values=(), values_dot=()):
    """A ``~/reference`` or ``~/measured_state`` message, as the node extracts it."""
    return list(dofs), list(values), list(values_dot)


def refused(match, **params):
    with pytest.raises(ControllerConfigError, match=match):
        configured(**params)


# --- parameters ----------------------------------------------------------------------------

@pytest.mark.parametrize('missing', ['dof_names', 'command_interface',
                                     'reference_and_state_interfaces'])
def test_a_missing_required_parameter_is_named(missing):
    params = {'dof_names': ['joint1'], 'command_interface': 'effort',
              'reference_and_state_interfaces': ['position']}
    del params[missing]
    with pytest.raises(ControllerConfigError, match=rf'^test\.yaml: pid\.{missing}: missing'):
        create_controller('pid', TYPE, params, 'test.yaml')


@pytest.mark.parametrize(('params', 'problem'), [
    ({'dof_names': []}, r'pid\.dof_names: must not be empty'),
    ({'dof_names': ['joint1', 'joint1']}, r"pid\.dof_names: 'joint1' is named more than once"),
    ({'command_interface': 7}, r'pid\.command_interface: 7 must be a string'),
    ({'reference_and_state_interfaces': ['position', 'velocity', 'effort']},
     r'pid\.reference_and_state_interfaces: must have 1 or 2 elements, has 3'),
    ({'reference_and_state_dof_names': ['joint1', 'joint2']},
     r'pid\.reference_and_state_dof_names: has 2 entries and dof_names 1: they must be the '
     'same size'),
    ({'gains': {'joint1': {'p': -1.0}}}, r'pid\.gains\.joint1\.p: -1\.0 must be >= 0'),
    ({'gains': {'joint1': {'d': 'high'}}}, r"pid\.gains\.joint1\.d: 'high' must be a finite"),
    ({'gains': {'joint9': {'p': 1.0}}},
     r"pid\.gains\.joint9: 'joint9' is not one of this controller's dof_names \(joint1\)"),
    ({'gains': {'joint1': {'i_clamp_min': 1.0, 'i_clamp_max': -1.0}}},
     r'pid\.gains\.joint1: i_clamp_min \(1\.0\) is greater than i_clamp_max'),
    ({'gains': {'joint1': {'u_clamp_min': 2.0, 'u_clamp_max': 1.0}}},
     r'pid\.gains\.joint1\.u_clamp_min: 2 is greater than u_clamp_max \(1\)'),
    ({'gains': {'joint1': {'u_clamp_max': math.nan}}},
     r'pid\.gains\.joint1\.u_clamp_max: nan must be a number'),
    ({'gains': {'joint1': {'antiwindup_strategy': 'clamp'}}},
     r"pid\.gains\.joint1\.antiwindup_strategy: 'clamp' must be one of back_calculation"),
])
def test_an_invalid_parameter_is_named_with_what_is_wrong(params, problem):
    with pytest.raises(ControllerConfigError, match=rf'^test\.yaml: {problem}'):
        build(**params)


def test_parameters_not_given_take_jazzys_defaults():
    controller = build()
    assert controller.params['reference_and_state_dof_names'] == []
    assert controller.params['set_current_state_as_first_setpoint'] is True
    assert controller.params['use_external_measured_states'] is False
    assert controller.params['enable_feedforward'] is False
    assert controller.params['gains'] == {'joint1': {
        'p': 0.0, 'i': 0.0, 'd': 0.0, 'u_clamp_max': math.inf, 'u_clamp_min': -math.inf,
        'antiwindup': False, 'i_clamp_max': math.inf, 'i_clamp_min': -math.inf,
        'antiwindup_strategy': 'legacy', 'tracking_time_constant': 0.0,
        'error_deadband': 1e-16, 'feedforward_gain': 0.0, 'angle_wraparound': False,
        'save_i_term': True, 'activate_state_publisher': False}}
    assert controller.config_warnings == []


def test_a_misspelt_key_and_a_value_not_simulated_are_warned_about():
    controller = build(use_external_measured_state=True,
                       gains={'joint1': {'antiwindup_strategy': 'back_calculation'}})
    assert controller.config_warnings == [
        "test.yaml: pid.gains.joint1.antiwindup_strategy: 'back_calculation' is accepted but "
        'not simulated; it has no effect here',
        'test.yaml: pid.use_external_measured_state: unknown parameter, ignored (did you mean '
        "'use_external_measured_states'?)"]


# --- configure ------------------------------------------------------------------------------

def test_it_exports_a_reference_per_interface_and_dof_before_it_is_configured():
    controller = build(dof_names=['joint1', 'joint2'],
                       reference_and_state_interfaces=['position', 'velocity'])
    assert controller.chainable
    assert list(controller.reference_interfaces()) == [
        'pid/joint1/position', 'pid/joint2/position', 'pid/joint1/velocity',
        'pid/joint2/velocity']
    assert all(math.isnan(reference.value)
               for reference in controller.reference_interfaces().values())


def test_references_and_state_follow_reference_and_state_dof_names():
    controller = configured(dof_names=['joint1'], reference_and_state_dof_names=['joint2'],
                            reference_and_state_interfaces=['position', 'velocity'])
    assert list(controller.reference_interfaces()) == ['pid/joint2/position',
                                                       'pid/joint2/velocity']
    assert controller.command_interfaces() == {'joint1': ('effort',)}
    assert controller.state_interfaces() == {'joint2': ('position', 'velocity')}


@pytest.mark.parametrize(('interface', 'kind', 'drive'), [
    ('effort', ActuatorKind.POSITION_PID, Drive.EFFORT),
    ('velocity', ActuatorKind.IDEAL_VELOCITY, Drive.VELOCITY),
    ('position', ActuatorKind.IDEAL_POSITION, Drive.VELOCITY),
])
def test_the_command_interface_chooses_how_the_joint_is_driven(interface, kind, drive):
    controller = configured(command_interface=interface, gains={'joint1': {'p': 3.0}})
    (actuator,) = controller.actuators().values()
    assert (actuator.kind, actuator.drive, actuator.controller) == (kind, drive, 'pid')
    assert actuator.pid is controller.pids()['joint1']
    assert actuator.pid.gains.p == 3.0 and actuator.gains_from == 'pid.gains.joint1'


def test_a_velocity_reference_on_the_effort_interface_is_a_velocity_pid():
    controller = configured(reference_and_state_interfaces=['velocity'])
    assert controller.actuators()['joint1'].kind is ActuatorKind.VELOCITY_PID


def test_a_dof_that_is_no_joint_is_refused_naming_the_joints():
    refused(r"pid\.dof_names: joint 'elbow' is not a movable joint of the robot \(movable "
            r'joints: follower, joint1, joint2, wheel\)', dof_names=['elbow'])


def test_a_mimic_joint_cannot_be_commanded():
    refused(r"pid\.dof_names: joint 'follower' mimics 'joint1'", dof_names=['follower'])


def test_a_command_interface_no_joint_has_is_refused():
    refused(r"pid\.command_interface: 'acceleration' is not an interface a joint is commanded "
            r'through \(position, velocity, effort\)', command_interface='acceleration')


def test_a_state_interface_no_joint_has_needs_external_measured_states():
    refused(r"pid\.reference_and_state_interfaces: 'acceleration' is not a state interface of "
            'a joint', reference_and_state_interfaces=['acceleration'])
    controller = configured(reference_and_state_interfaces=['acceleration'],
                            use_external_measured_states=True)
    assert controller.state_interfaces() == {}


def test_its_ros_surface_is_upstreams():
    controller = configured()
    reference_topic, state, service = controller.ros_surface()
    assert isinstance(reference_topic, CommandTopic) and (
        reference_topic.name, reference_topic.message, reference_topic.while_chained) == (
        '~/reference', 'control_msgs/msg/MultiDOFCommand', False)
    assert isinstance(state, StateTopic) and (state.name, state.message, state.fields) == (
        '~/controller_state', 'control_msgs/msg/MultiDOFStateStamped', {'names': ['joint1']})
    assert isinstance(service, Service) and (service.name, service.service) == (
        '~/set_feedforward_control', 'std_srvs/srv/SetBool')
    external = configured(use_external_measured_states=True).ros_surface()
    measured = [endpoint for endpoint in external if endpoint.name == '~/measured_state']
    assert [(endpoint.message, endpoint.while_chained) for endpoint in measured] == [
        ('control_msgs/msg/MultiDOFCommand', True)]


# --- activation -----------------------------------------------------------------------------

def test_activation_takes_the_present_state_as_the_first_reference_and_holds():
    handles = make_handles()
    handles['joint1'].position, handles['joint1'].velocity = 0.3, -0.2
    controller = configured(handles, reference_and_state_interfaces=['position', 'velocity'],
                            gains={'joint1': {'p': 10.0, 'd': 1.0}})
    references = controller.reference_interfaces()
    assert references['pid/joint1/position'].value == 0.3
    assert references['pid/joint1/velocity'].value == -0.2
    controller.update(0.0, DT)
    assert handles['joint1'].effort == 0.0


def test_without_a_first_setpoint_nothing_is_commanded_until_a_reference_comes():
    handles = make_handles()
    handles['joint1'].position = 0.3
    controller = configured(handles, set_current_state_as_first_setpoint=False,
                            gains={'joint1': {'p': 10.0}})
    assert math.isnan(controller.reference_interfaces()['pid/joint1/position'].value)
    handles['joint1'].effort = 1.5  # what the joint had
    controller.reset()
    assert handles['joint1'].effort == 0.0  # activated: no effort until a command
    controller.update(0.0, DT)
    assert handles['joint1'].effort == 0.0
    controller.set_command(reference(['joint1'], [0.5]))
    controller.update(DT, DT)
    assert handles['joint1'].effort == pytest.approx(10.0 * 0.2)


@pytest.mark.parametrize(('save', 'kept'), [(True, 0.5), (False, 0.0)])
def test_the_integral_term_survives_reactivation_as_save_i_term_says(save, kept):
    handles = make_handles()
    controller = configured(handles, set_current_state_as_first_setpoint=False,
                            gains={'joint1': {'i': 1.0, 'save_i_term': save}})
    controller.set_command(reference(['joint1'], [0.5]))
    controller.update(0.0, 1.0)  # one step of 1 s: integral 0.5
    assert handles['joint1'].effort == pytest.approx(0.5)
    controller.reset()
    controller.set_command(reference(['joint1'], [0.0]))
    controller.update(1.0, 1.0)
    assert handles['joint1'].effort == pytest.approx(kept)


# --- references from the topic ----------------------------------------------------------------

def effort_pid(handles=None, **params):
    params.setdefault('gains', {dof: {'p': 2.0} for dof in params.get('dof_names', ['joint1'])})
    return configured(handles, **params)


def test_a_reference_from_the_topic_is_taken_at_the_next_update():
    handles = make_handles()
    handles['joint1'].position = 0.1
    controller = effort_pid(handles)
    assert controller.set_command(reference(['joint1'], [0.6])) is CommandResult.ACCEPTED
    assert controller.setpoints() == {'joint1': 0.1}  # the first setpoint, still
    controller.update(0.0, DT)
    assert controller.setpoints() == {'joint1': 0.6}
    assert handles['joint1'].effort == pytest.approx(2.0 * 0.5)


def test_the_topic_names_its_dofs_in_any_order_or_none_for_the_declared_one():
    handles = make_handles()
    controller = effort_pid(handles, dof_names=['joint1', 'joint2'])
    controller.set_command(reference(['joint2', 'joint1'], [0.2, 0.4]))
    controller.update(0.0, DT)
    assert controller.setpoints() == {'joint1': 0.4, 'joint2': 0.2}
    controller.set_command(reference([], [0.1, math.nan]))  # NaN: leave that reference
    controller.update(DT, DT)
    assert controller.setpoints() == {'joint1': 0.1, 'joint2': 0.2}
    assert (handles['joint1'].effort, handles['joint2'].effort) == pytest.approx((0.2, 0.4))


def test_values_dot_are_the_second_interfaces_references():
    controller = effort_pid(reference_and_state_interfaces=['position', 'velocity'])
    controller.set_command(reference(['joint1'], [0.3], [0.7]))
    controller.update(0.0, DT)
    references = controller.reference_interfaces()
    assert (references['pid/joint1/position'].value,
            references['pid/joint1/velocity'].value) == (0.3, 0.7)


@pytest.mark.parametrize(('message', 'problem'), [
    (reference(['joint1', 'joint2'], [0.1, 0.2]), 'Size of input data names (2) and/or values '
     '(2) is not matching the expected size (1).'),
    (reference([], [0.1, 0.2]), 'Size of input data names (0) and/or values (2) is not '
     'matching the expected size (1).'),
    (reference(['joint1'], [0.1], [0.1, 0.2]), 'Size of input data values_dot (2) is not '
     'matching the expected size (1).'),
    (reference(['elbow'], [0.1]), "DoF name 'elbow' not found in the defined list of state "
     'DoFs.'),
    (reference(['joint1'], [math.inf]), "ignored reference: the value for 'joint1' is not a "
     'finite number (within +-1e+12)'),
])
def test_a_malformed_reference_is_ignored_and_said_why(message, problem):
    controller = effort_pid()
    assert controller.set_command(message) is CommandResult.REJECTED
    assert controller.command_problem(message, CommandResult.REJECTED) == problem
    controller.update(0.0, DT)
    assert controller.setpoints() == {'joint1': 0.0}


# --- chained mode ---------------------------------------------------------------------------

def chain(handles, forward_interface='position', **pid_params):
    """A manager running ``forward`` (a group on ``pid/joint1``) feeding ``pid``, both active."""
    pid_params = {'dof_names': ['joint1'], 'command_interface': 'effort',
                  'reference_and_state_interfaces': ['position', 'velocity'],
                  'gains': {'joint1': {'p': 2.0}}, **pid_params}
    specs = (ControllerSpec('pid', TYPE, pid_params),
             ControllerSpec('forward', FORWARD, {'joints': ['pid/joint1'],
                                                 'interface_name': forward_interface}))
    manager = ControllerManager(ControllersConfig(specs, pathlib.Path('chain.yaml')), handles)
    return manager, manager.controller('pid'), manager.controller('forward')


def step(manager, time=0.0):
    for update in manager.updates:
        update(time, DT)


def test_in_chained_mode_a_preceding_controllers_reference_takes_effect_the_same_step():
    handles = make_handles()
    manager, pid, forward = chain(handles)
    assert pid.is_chained and isinstance(forward.members[0], ReferenceForwarder)
    assert forward.set_command([0.8]) is CommandResult.ACCEPTED
    step(manager)
    assert pid.setpoints() == {'joint1': 0.8}
    assert handles['joint1'].effort == pytest.approx(2.0 * 0.8)


def test_a_preceding_velocity_group_writes_the_velocity_reference():
    handles = make_handles()
    manager, pid, forward = chain(handles, 'velocity', gains={'joint1': {'d': 0.5}})
    forward.set_command([1.2])
    step(manager)
    assert pid.reference_interfaces()['pid/joint1/velocity'].value == 1.2
    assert handles['joint1'].effort == pytest.approx(0.5 * 1.2)


def test_in_chained_mode_the_topics_reference_is_ignored():
    handles = make_handles()
    manager, pid, forward = chain(handles)
    forward.set_command([0.8])
    step(manager)
    pid.set_command(reference(['joint1'], [-0.5]))
    step(manager, DT)
    assert pid.setpoints() == {'joint1': 0.8}
    manager.switch(deactivate=['forward'])  # out of chained mode: a fresh start
    assert not pid.is_chained and pid.setpoints() == {'joint1': 0.0}
    pid.set_command(reference(['joint1'], [-0.5]))
    step(manager, 2 * DT)
    assert pid.setpoints() == {'joint1': -0.5}


def test_a_dof_naming_a_chainable_controllers_reference_is_commanded_through_it():
    handles = make_handles()
    specs = (ControllerSpec('inner', TYPE, {
                 'dof_names': ['joint1'], 'command_interface': 'effort',
                 'reference_and_state_interfaces': ['velocity'], 'gains': {'joint1': {'p': 1.0}}}),
             ControllerSpec('outer', TYPE, {
                 'dof_names': ['inner/joint1'], 'reference_and_state_dof_names': ['joint1'],
                 'command_interface': 'velocity', 'reference_and_state_interfaces': ['position'],
                 'gains': {'inner/joint1': {'p': 3.0}}}))
    manager = ControllerManager(ControllersConfig(specs, pathlib.Path('cascade.yaml')), handles)
    outer, inner = manager.controller('outer'), manager.controller('inner')
    assert manager.chain_connections('outer') == {'inner': ('inner/joint1/velocity',)}
    assert inner.is_chained and outer.actuators() == {}
    outer.set_command(reference(['joint1'], [0.5]))
    step(manager)
    assert inner.reference_interfaces()['inner/joint1/velocity'].value == pytest.approx(1.5)
    assert handles['joint1'].effort == pytest.approx(1.5)  # inner: p 1 * (1.5 - 0)


# --- the command on the joint ---------------------------------------------------------------

@pytest.mark.parametrize('target', [10.0, -10.0])
def test_the_effort_is_clamped_to_the_joints_effort_limit(target):
    handles = make_handles()
    controller = effort_pid(handles, gains={'joint1': {'p': 100.0}})
    controller.set_command(reference([], [target]))
    controller.update(0.0, DT)
    assert handles['joint1'].effort == math.copysign(EFFORT_LIMIT, target)


def test_on_the_velocity_interface_the_command_is_the_velocity_target_within_the_limit():
    handles = make_handles()
    controller = configured(handles, command_interface='velocity',
                            gains={'joint1': {'p': 2.0}})
    controller.set_command(reference([], [0.25]))
    controller.update(0.0, DT)
    assert handles['joint1'].velocity_target == pytest.approx(0.5)
    controller.set_command(reference([], [1.5]))  # a velocity command of 3
    controller.update(DT, DT)
    assert handles['joint1'].velocity_target == VELOCITY_LIMIT


def test_on_the_position_interface_the_joint_follows_the_ideal_position_path():
    handles = make_handles()
    controller = configured(handles, command_interface='position',
                            reference_and_state_interfaces=['velocity'],
                            gains={'joint1': {'p': 5.0}})
    controller.set_command(reference([], [1.0]))  # a position command of 5: beyond the limit
    targets = []
    for index in range(3000):
        controller.update(index * DT, DT)
        handle = handles['joint1']
        targets.append(handle.velocity_target)
        handle.position += handle.velocity_target * DT
    assert max(targets) == pytest.approx(VELOCITY_LIMIT)
    assert handles['joint1'].position == pytest.approx(1.0, abs=1e-3)  # the upper limit


# --- the control law ------------------------------------------------------------------------

def test_with_two_interfaces_the_derivative_acts_on_the_velocity_error():
    handles = make_handles()
    controller = effort_pid(handles, reference_and_state_interfaces=['position', 'velocity'],
                            gains={'joint1': {'p': 2.0, 'd': 0.5}})
    handles['joint1'].velocity = 0.4
    controller.set_command(reference([], [0.1], [1.0]))
    controller.update(0.0, DT)
    assert handles['joint1'].effort == pytest.approx(2.0 * 0.1 + 0.5 * (1.0 - 0.4))


def test_with_one_interface_the_derivative_acts_on_the_change_of_the_error():
    handles = make_handles()
    controller = effort_pid(handles, gains={'joint1': {'d': 0.001}})
    controller.set_command(reference([], [0.5]))
    controller.update(0.0, DT)
    assert handles['joint1'].effort == pytest.approx(0.001 * 0.5 / DT)  # from no error
    handles['joint1'].position = 0.1
    controller.update(DT, DT)
    assert handles['joint1'].effort == pytest.approx(0.001 * (0.4 - 0.5) / DT)


def test_u_clamp_bounds_the_pid_output():
    handles = make_handles()
    controller = effort_pid(handles, gains={'joint1': {'p': 10.0, 'u_clamp_max': 1.5,
                                                       'u_clamp_min': -0.5}})
    controller.set_command(reference([], [0.5]))
    controller.update(0.0, DT)
    assert handles['joint1'].effort == 1.5
    controller.set_command(reference([], [-0.5]))
    controller.update(DT, DT)
    assert handles['joint1'].effort == -0.5


def test_angle_wraparound_takes_the_short_way_round():
    handles = make_handles()
    handles['wheel'].position = -3.0
    controller = effort_pid(handles, dof_names=['wheel'],
                            gains={'wheel': {'p': 1.0, 'angle_wraparound': True}})
    controller.set_command(reference([], [3.0]))
    controller.update(0.0, DT)
    assert handles['wheel'].effort == pytest.approx(6.0 - 2.0 * math.pi)


# --- feed-forward ----------------------------------------------------------------------------

def test_in_feedforward_mode_the_reference_times_feedforward_gain_is_added():
    handles = make_handles()
    controller = effort_pid(handles, enable_feedforward=True,
                            gains={'joint1': {'p': 2.0, 'feedforward_gain': 3.0,
                                              'u_clamp_max': 0.5}})
    controller.set_command(reference([], [0.4]))
    controller.update(0.0, DT)
    # The PID's 0.8, clamped to 0.5, plus 3 * 0.4 (after the clamp).
    assert handles['joint1'].effort == pytest.approx(0.5 + 1.2)


def test_with_two_interfaces_the_feedforward_is_on_the_derivatives_reference():
    handles = make_handles()
    controller = effort_pid(handles, enable_feedforward=True,
                            reference_and_state_interfaces=['position', 'velocity'],
                            gains={'joint1': {'feedforward_gain': 2.0}})
    controller.set_command(reference([], [0.4], [0.3]))
    controller.update(0.0, DT)
    assert handles['joint1'].effort == pytest.approx(2.0 * 0.3)


def test_the_feedforward_service_switches_the_mode_with_upstreams_warning():
    handles = make_handles()
    controller = effort_pid(handles, gains={'joint1': {'feedforward_gain': 3.0}})
    controller.set_command(reference([], [0.4]))
    controller.update(0.0, DT)
    assert handles['joint1'].effort == pytest.approx(0.0)  # p 0, not in feed-forward mode
    assert controller.set_feedforward_control(True) == (True, '')
    assert controller.feedforward and controller.notices == [FEEDFORWARD_SERVICE_NOTICE]
    controller.update(DT, DT)
    assert handles['joint1'].effort == pytest.approx(1.2)
    controller.set_feedforward_control(False)
    controller.update(2 * DT, DT)
    assert handles['joint1'].effort == pytest.approx(0.0)


# --- gains and state ------------------------------------------------------------------------

def test_the_pid_gains_are_tunable_live_per_dof():
    tunable = [param.name for param in PidController.parameters.tunable()]
    assert tunable == [f'gains.__map_dof_names.{name}' for name in (
        'p', 'i', 'd', 'antiwindup', 'i_clamp_max', 'i_clamp_min')]
    assert PidController.gains_field == 'gains'
    handles = make_handles()
    controller = effort_pid(handles, dof_names=['joint1', 'joint2'])
    assert list(controller.pids()) == ['joint1', 'joint2']
    pid = controller.pids()['joint1']
    controller.set_command(reference([], [0.5, 0.0]))
    controller.update(0.0, DT)
    assert handles['joint1'].effort == pytest.approx(1.0)
    pid.gains = PidGains(p=4.0)
    controller.update(DT, DT)
    assert handles['joint1'].effort == pytest.approx(2.0)


def test_controller_state_is_sampled_every_update_while_someone_listens():
    handles = make_handles()
    handles['joint1'].velocity = 0.2
    controller = effort_pid(handles, reference_and_state_interfaces=['position', 'velocity'])
    samples = []
    controller.connect_state(lambda time, rows: samples.append((time, list(rows))))
    controller.set_command(reference([], [0.5], [0.1]))
    controller.update(0.25, DT)
    assert samples == [(0.25, [(0.5, 0.0, 0.2, 0.5, pytest.approx(-0.1), DT, 1.0)])]
    controller.connect_state(None)
    controller.update(0.25 + DT, DT)
    assert len(samples) == 1


def test_external_measured_states_replace_the_joints_state():
    handles = make_handles()
    handles['joint1'].position = 0.9  # not what the controller reads
    controller = effort_pid(handles, use_external_measured_states=True,
                            reference_and_state_interfaces=['position', 'velocity'],
                            gains={'joint1': {'p': 2.0, 'd': 1.0}})
    assert math.isnan(controller.setpoints()['joint1'])  # no state yet: no first setpoint
    controller.set_command(reference([], [0.5], [0.0]))
    controller.update(0.0, DT)
    assert handles['joint1'].effort == 0.0  # no state yet: nothing commanded
    assert controller.set_measured_state(reference(['joint1'], [0.1], [0.3])) is (
        CommandResult.ACCEPTED)
    controller.update(DT, DT)
    assert handles['joint1'].effort == pytest.approx(2.0 * 0.4 + 1.0 * -0.3)


@pytest.mark.parametrize(('interfaces', 'message', 'problem'), [
    (['position'], reference([], [0.1]), 'Size of input data names (0) is not matching the '
     'expected size (1).'),
    (['position'], reference(['joint1'], []), 'Size of input data values (0) is not matching '
     'the expected size (1).'),
    (['position'], reference(['joint1'], [0.1], [0.2]), 'The reference_and_state_interfaces '
     'parameter has to have two interfaces [the interface and the derivative of the '
     'interface], in order to use the values_dot field.'),
    (['position', 'velocity'], reference(['joint1'], [0.1], [0.2, 0.3]), 'Size of input data '
     'values_dot (2) is not matching the expected size (1).'),
])
def test_a_malformed_measured_state_is_ignored_and_said_why(interfaces, message, problem):
    controller = effort_pid(use_external_measured_states=True,
                            reference_and_state_interfaces=interfaces)
    assert controller.set_measured_state(message) is CommandResult.REJECTED
    assert controller.measured_state_problem(message, CommandResult.REJECTED) == problem


def test_cleanup_and_configure_again_start_from_the_yamls_gains_and_no_integral():
    handles = make_handles()
    specs = (ControllerSpec('pid', TYPE, {
        'dof_names': ['joint1'], 'command_interface': 'effort',
        'reference_and_state_interfaces': ['position'], 'set_current_state_as_first_setpoint':
        False, 'gains': {'joint1': {'p': 1.0, 'i': 1.0}}}),)
    manager = ControllerManager(ControllersConfig(specs, pathlib.Path('pid.yaml')), handles)
    pid = manager.controller('pid')
    pid.set_command(reference([], [0.5]))
    for update in manager.updates:
        update(0.0, 1.0)
    pid.pids()['joint1'].gains = PidGains(p=7.0, i=1.0)
    manager.switch(deactivate=['pid'])
    manager.cleanup('pid')
    assert manager.state('pid') == 'unconfigured'
    manager.configure('pid')
    manager.switch(activate=['pid'])
    assert pid.pids()['joint1'].gains.p == 1.0
    assert math.isnan(pid.setpoints()['joint1'])
    pid.set_command(reference([], [0.0]))
    for update in manager.updates:
        update(1.0, 1.0)
    assert handles['joint1'].effort == 0.0  # no integral carried over the cleanup
