"""JointStateBroadcaster (ROS 1: joint_state_controller): what it samples, which joints."""

import math
from collections.abc import Sequence

import pytest
from controller_fixtures import loaded, raises_naming
from robot_fixtures import write_text

from pan_tilt_sim.controllers import JointHandle, create_controller
from pan_tilt_sim.controllers.broadcasters.joint_state_broadcaster import DEFAULT_PUBLISH_RATE
from pan_tilt_sim.controllers.framework.manager import ACTIVE, INACTIVE, UNCONFIGURED
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.controller_config import load_controllers_config
from pan_tilt_sim.model.robot import (
    ControlInterface,
    ControlJoint,
    JointKind,
    JointSpec,
    Mimic,
)

TYPE = 'joint_state_controller/JointStateController'
BROADCASTER = 'joint_state_broadcaster/JointStateBroadcaster'
DT = 0.001


def _run(rate, seconds):
    joints = {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS)) for name in ('a', 'b')}
    controller = create_controller('jsc', TYPE, {'type': TYPE, 'publish_rate': rate})
    controller.configure(joints)
    samples = []
    controller.set_sink(lambda t, n, p, v, e: samples.append((t, list(n), list(p), list(v),
                                                              list(e))))
    for step in range(round(seconds / DT)):
        joints['a'].position = step * DT
        controller.update(step * DT, DT)
    return samples


def test_fifty_hz_gives_one_hundred_samples_in_two_seconds():
    samples = _run(50, 2.0)
    assert len(samples) == 100
    assert [round(s[0], 6) for s in samples[:3]] == [0.0, 0.02, 0.04]


def test_samples_carry_names_positions_velocities_and_efforts():
    time, names, positions, velocities, efforts = _run(50, 0.1)[-1]
    assert names == ['a', 'b']
    assert positions == [pytest.approx(time), 0.0]
    assert len(velocities) == len(efforts) == 2


def test_the_ros2_broadcaster_name_is_the_same_controller():
    controller = create_controller('jsb', BROADCASTER, {})
    assert controller.publish_rate == 50.0


@pytest.mark.parametrize('rate', [0, -5, 'fast', float('nan')])
def test_a_non_positive_publish_rate_is_refused(rate):
    with pytest.raises(ControllerConfigError, match='publish_rate'):
        create_controller('jsc', TYPE, {'publish_rate': rate})


# --- a robot with a <ros2_control> block -------------------------------------------------------

def _state(name: str, initial: str | None = None) -> ControlInterface:
    return ControlInterface(name, {} if initial is None else {'initial_value': initial})


def handles() -> dict[str, JointHandle]:
    """``a``: declares a custom ``temperature`` (initial 21.5) and ``torque``; ``b``: none.

    ``c`` mimics ``a`` and has no entry in the block.
    """
    a = ControlJoint('a', state_interfaces=(_state('position'), _state('temperature', '21.5'),
                                            _state('torque')))
    b = ControlJoint('b', state_interfaces=(_state('position'), _state('velocity')))
    specs = [(JointSpec('a', JointKind.REVOLUTE, -1.0, 1.0), a),
             (JointSpec('b', JointKind.PRISMATIC, 0.0, 0.5), b),
             (JointSpec('c', JointKind.REVOLUTE, -1.0, 1.0, mimic=Mimic('a')), None)]
    table = {spec.name: JointHandle(spec, control=control) for spec, control in specs}
    for number, handle in enumerate(table.values()):
        handle.position, handle.velocity, handle.effort = (
            0.1 * (number + 1), 1.0 * (number + 1), 10.0 * (number + 1))
    return table


def broadcaster(table: dict[str, JointHandle] | None = None, **params):
    """Configure a broadcaster with ``params`` on ``table`` (default: :func:`handles`)."""
    controller = create_controller('jsb', BROADCASTER, params, 'test.yaml')
    controller.configure(handles() if table is None else table)
    return controller


class Recorder:
    """Connects to both sinks and keeps copies of what each received."""

    def __init__(self, controller) -> None:
        self.joint_states: list[tuple] = []
        self.dynamic: list[tuple] = []
        controller.set_sink(self.joint_state)
        controller.set_dynamic_sink(self.dynamic_state)

    def joint_state(self, time, names, positions, velocities, efforts) -> None:
        self.joint_states.append((time, list(names), list(positions), list(velocities),
                                  list(efforts)))

    def dynamic_state(self, time, values: Sequence[Sequence[float]]) -> None:
        self.dynamic.append((time, [list(joint) for joint in values]))


def sample(**params):
    """Configure a broadcaster on :func:`handles`, take one sample; return it and the controller."""
    controller = broadcaster(**params)
    recorder = Recorder(controller)
    controller.update(0.0, DT)
    (joint_state,) = recorder.joint_states
    (dynamic,) = recorder.dynamic
    return controller, joint_state[1:], dynamic[1]


def same(values, expected) -> bool:
    """Equal, NaN matching NaN."""
    return len(values) == len(expected) and all(
        (math.isnan(x) and math.isnan(y)) if isinstance(y, float) and math.isnan(y) else x == y
        for x, y in zip(values, expected, strict=True))


NAN = math.nan


@pytest.mark.parametrize(('params', 'rate'), [
    ({}, DEFAULT_PUBLISH_RATE),
    ({'update_rate': 100}, 100.0),
    ({'publish_rate': 30, 'update_rate': 100}, 30.0),
])
def test_rate_is_publish_rate_else_update_rate_else_the_pan_tilt_examples_50_hz(params, rate):
    assert broadcaster(**params).publish_rate == pytest.approx(rate)


def test_bad_update_rate_names_it():
    with pytest.raises(ControllerConfigError, match=r'test.yaml: jsb\.update_rate: 0 must be'):
        broadcaster(update_rate=0)


def test_publishes_at_the_controller_manager_rate_of_a_ros2_file(tmp_path):
    config = load_controllers_config(write_text(tmp_path, 'c.yaml', f"""
        controller_manager:
          ros__parameters:
            update_rate: 200
            joint_state_broadcaster:
              type: {BROADCASTER}
        """))
    (spec,) = config.controllers
    controller = create_controller(spec.name, spec.type, spec.params)
    controller.configure(handles())
    samples = []
    controller.set_sink(lambda time, *_: samples.append(round(time, 6)))
    for step in range(101):
        controller.update(step * 0.001, 0.001)
    assert samples == [round(0.005 * k, 6) for k in range(21)]


def test_by_default_every_movable_joint_mimic_ones_too_with_every_state_interface():
    controller, (names, positions, velocities, efforts), dynamic = sample()
    assert names == ['a', 'b', 'c']
    assert positions == [0.1, 0.2, pytest.approx(0.3)]
    assert (velocities, efforts) == ([1.0, 2.0, 3.0], [10.0, 20.0, 30.0])
    assert controller.dynamic_names == ['a', 'b', 'c']
    assert controller.dynamic_interfaces == [
        ('position', 'velocity', 'effort', 'temperature', 'torque'),
        ('position', 'velocity', 'effort'), ('position', 'velocity', 'effort')]
    # What the physics cannot measure holds its initial_value, else NaN (as on mock hardware).
    assert same(dynamic[0], [0.1, 1.0, 10.0, 21.5, NAN])
    assert dynamic[1:] == [[0.2, 2.0, 20.0], [pytest.approx(0.3), 3.0, 30.0]]


def test_joints_and_interfaces_publish_only_those_pairs_in_their_order():
    controller, (names, positions, velocities, efforts), dynamic = sample(
        joints=['c', 'a'], interfaces=['temperature', 'position'])
    assert names == ['c', 'a']
    assert positions == [pytest.approx(0.3), 0.1]
    # No velocity or effort selected: NaN, as joint_state_broadcaster leaves them.
    assert all(math.isnan(value) for value in velocities + efforts)
    assert controller.dynamic_names == ['c', 'a']
    assert controller.dynamic_interfaces == [('position',), ('temperature', 'position')]
    assert dynamic == [[pytest.approx(0.3)], [21.5, 0.1]]
    assert controller.state_interfaces() == {'c': ('position',), 'a': ('temperature', 'position')}


def test_a_pair_the_robot_lacks_is_left_out_with_a_warning():
    controller = broadcaster(joints=['a', 'b'], interfaces=['position', 'temperature'])
    assert controller.state_interfaces() == {'a': ('position', 'temperature'),
                                             'b': ('position',)}
    assert controller.config_warnings == [
        'test.yaml: jsb.interfaces: not published, the robot lacks them: b/temperature']


def test_a_joint_with_no_joint_state_field_is_in_the_dynamic_message_only():
    controller, (names, *_), dynamic = sample(joints=['a', 'b'], interfaces=['temperature'])
    assert names == []
    assert controller.dynamic_names == ['a']
    assert dynamic == [[21.5]]


def test_no_pair_at_all_is_an_error_naming_interfaces():
    with pytest.raises(ControllerConfigError,
                       match=r"test\.yaml: jsb\.interfaces: no joint named in 'joints' has any "
                             r'of humidity \(their state interfaces: b: position, velocity, '
                             r'effort\)'):
        broadcaster(joints=['b'], interfaces=['humidity'])


@pytest.mark.parametrize(('given', 'empty'), [('joints', 'interfaces'),
                                              ('interfaces', 'joints')])
def test_either_list_alone_is_ignored_with_a_warning(given, empty):
    values = {'joints': ['b'], 'interfaces': ['position']}
    controller = broadcaster(**{given: values[given]})
    assert controller.names == ['a', 'b', 'c']
    assert controller.config_warnings == [
        f"test.yaml: jsb.{given}: ignored while '{empty}' is empty: every state interface of "
        'every movable joint is published']


def test_unknown_joint_names_the_field():
    with pytest.raises(ControllerConfigError, match=r"jsb\.joints: joint 'z' is not a movable"):
        broadcaster(joints=['a', 'z'], interfaces=['position'])


def test_a_mapped_interface_is_published_as_the_joint_state_field():
    controller, (names, positions, _velocities, efforts), dynamic = sample(
        map_interface_to_joint_state={'position': 'temperature', 'effort': 'torque'})
    # a has them; b and c publish their own position and effort.
    assert names == ['a', 'b', 'c']
    assert positions == [21.5, 0.2, pytest.approx(0.3)]
    assert same(efforts, [NAN, 20.0, 30.0])
    # The dynamic message keeps every interface under its own name.
    assert controller.dynamic_interfaces[0] == (
        'position', 'velocity', 'effort', 'temperature', 'torque')
    assert same(dynamic[0], [0.1, 1.0, 10.0, 21.5, NAN])


def test_a_mapping_is_ignored_where_interfaces_names_the_field_itself():
    controller, (names, positions, *_), _dynamic = sample(
        joints=['a'], interfaces=['position', 'temperature'],
        map_interface_to_joint_state={'position': 'temperature'})
    assert (names, positions) == (['a'], [0.1])
    assert controller.config_warnings == [
        "test.yaml: jsb.map_interface_to_joint_state.position: 'temperature' is not published "
        "as JointState.position: 'interfaces' names 'position' itself"]


def test_a_mapped_interface_no_joint_has_gets_one_warning_and_the_field_stays_its_own():
    controller, (names, positions, *_), _dynamic = sample(
        map_interface_to_joint_state={'position': 'nonexistent_iface'})
    assert names == ['a', 'b', 'c'] and positions == [0.1, 0.2, pytest.approx(0.3)]
    assert controller.config_warnings == [
        "test.yaml: jsb.map_interface_to_joint_state.position: 'nonexistent_iface' is not a "
        "state interface of any published joint: JointState.position is each joint's own "
        "'position'"]
    controller.configure(handles())  # configured again: still one warning
    assert len(controller.config_warnings) == 1


def test_only_interfaces_mapped_to_a_field_put_a_joint_into_joint_states():
    _controller, (names, positions, *_), _dynamic = sample(
        joints=['a', 'b'], interfaces=['temperature', 'velocity'],
        map_interface_to_joint_state={'position': 'temperature'})
    assert names == ['a', 'b']
    assert same(positions, [21.5, NAN])


def test_extra_joints_follow_with_zero_state_in_both_messages():
    controller, (names, positions, velocities, efforts), dynamic = sample(
        joints=['b'], interfaces=['position'], extra_joints=['wheel', 'caster'])
    assert names == ['b', 'wheel', 'caster']
    assert positions == [0.2, 0.0, 0.0]
    assert velocities[1:] == efforts[1:] == [0.0, 0.0]
    assert controller.dynamic_names == ['b', 'wheel', 'caster']
    assert controller.dynamic_interfaces[1] == ('position', 'velocity', 'effort')
    assert dynamic[1:] == [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
    assert controller.state_interfaces() == {'b': ('position',)}


def test_an_extra_joint_already_published_is_skipped_with_a_warning():
    controller = broadcaster(extra_joints=['b', 'wheel'])
    assert controller.names == ['a', 'b', 'c', 'wheel']
    assert controller.config_warnings == [
        "test.yaml: jsb.extra_joints: 'b' is published with its own state already"]


def test_each_sample_reads_the_joints_anew():
    joints = handles()
    controller = broadcaster(joints, publish_rate=1000)
    recorder = Recorder(controller)
    controller.update(0.0, DT)
    joints['b'].position, joints['a'].effort = 0.45, -3.0
    controller.update(DT, DT)
    (_, _, first, *_), (_, _, second, _, efforts) = recorder.joint_states
    assert (first[1], second[1], efforts[0]) == (0.2, 0.45, -3.0)
    assert [values[0][2] for _time, values in recorder.dynamic] == [10.0, -3.0]


def test_a_topic_without_a_sink_costs_no_reads():
    joints = handles()
    controller = broadcaster(joints, publish_rate=1000)
    joint_states = []
    controller.set_sink(lambda time, names, positions, *_: joint_states.append(list(positions)))
    joints['a'].position = 0.7
    controller.update(0.0, DT)
    assert joint_states == [[0.7, 0.2, pytest.approx(0.3)]]
    assert controller.dynamic_values[0][0] == 0.1  # as configured: never read
    controller.set_sink(None)
    joints['a'].position = 0.9
    controller.update(DT, DT)
    assert controller.positions[0] == 0.7


def test_topics_are_global_by_default_and_local_with_use_local_topics():
    plain = broadcaster(joints=['a'], interfaces=['position', 'temperature'])
    assert [(topic.name, topic.message) for topic in plain.ros_surface()] == [
        ('joint_states', 'sensor_msgs/msg/JointState'),
        ('dynamic_joint_states', 'control_msgs/msg/DynamicJointState')]
    assert [topic.fields for topic in plain.ros_surface()] == [
        {'names': ('a',)},
        {'joint_names': ('a',), 'interface_names': (('position', 'temperature'),)}]
    local = broadcaster(use_local_topics=True)
    assert [topic.name for topic in local.ros_surface()] == [
        '~/joint_states', '~/dynamic_joint_states']


def test_publish_dynamic_joint_states_false_leaves_the_dynamic_topic_out():
    controller = broadcaster(publish_dynamic_joint_states=False)
    assert [topic.name for topic in controller.ros_surface()] == ['joint_states']

# --- limits and lifecycle ------------------------------------------------------------------

def _handles():
    return {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS)) for name in ('a', 'b')}


def _sampled(controller, samples):
    controller.set_sink(lambda t, n, p, v, e: samples.append((t, list(n), list(p), list(v),
                                                              list(e))))


@pytest.mark.parametrize('rate', [0.0, True, float('inf')])
def test_a_bad_update_rate_is_refused_when_it_sets_the_rate(rate):
    with raises_naming('jsb.update_rate'):
        create_controller('jsb', BROADCASTER, {'update_rate': rate})


@pytest.mark.parametrize('joints', ['a', [''], ['a', 'a'], [3]])
def test_a_joints_parameter_that_is_not_distinct_joint_names_is_refused(joints):
    with raises_naming('jsb.joints'):
        create_controller('jsb', BROADCASTER, {'joints': joints})


def test_it_reports_the_joints_as_they_are_and_commands_nothing():
    spec = JointSpec('slide', JointKind.PRISMATIC, 0.0, 0.1, effort_limit=1.0,
                     velocity_limit=0.1)
    handle = JointHandle(spec)
    controller = create_controller('jsb', BROADCASTER, {})
    controller.configure({'slide': handle})
    samples = []
    _sampled(controller, samples)
    handle.position, handle.velocity, handle.effort = 0.3, -2.0, 5.0  # all beyond the limits
    controller.update(0.0, DT)
    assert samples[0][2:] == ([0.3], [-2.0], [5.0])
    assert (handle.position, handle.velocity, handle.effort, handle.velocity_target) == (
        0.3, -2.0, 5.0, 0.0)
    assert controller.actuators() == {} and controller.command_interfaces() == {}


def test_the_manager_schedules_it_while_active_and_cleans_it_up():
    handles = _handles()
    manager = loaded('jsb', BROADCASTER, {'publish_rate': 100}, handles)
    assert manager.state('jsb') == UNCONFIGURED
    controller = manager.configure('jsb')
    assert manager.state('jsb') == INACTIVE and manager.scheduled_updates == []
    manager.switch(activate=['jsb'])
    assert manager.state('jsb') == ACTIVE
    assert manager.updates == []  # not every step: on its schedule
    ((schedule, update),) = manager.scheduled_updates
    assert schedule.period == pytest.approx(0.01)
    samples = []
    _sampled(controller, samples)
    for step in range(50):
        update(step * DT, DT)
    assert len(samples) == 5
    manager.switch(deactivate=['jsb'])
    assert manager.scheduled_updates == []
    manager.cleanup('jsb')
    assert manager.state('jsb') == UNCONFIGURED

