"""JointStateController (ROS 2: joint_state_broadcaster): samples at publish_rate Hz of sim time.

Parameters, the lifecycle through the controller manager, and the samples it
hands its sink.  A broadcaster only reads: it commands no joint and enforces
no limit, so it reports joints as they are, even beyond their limits.
"""

import pytest
from controller_fixtures import DT, loaded, raises_naming

from pan_tilt_sim.controllers import JointHandle, create_controller
from pan_tilt_sim.controllers.manager import ACTIVE, INACTIVE, UNCONFIGURED
from pan_tilt_sim.model.robot import JointKind, JointSpec, Mimic

TYPE = 'joint_state_controller/JointStateController'
BROADCASTER = 'joint_state_broadcaster/JointStateBroadcaster'


def _handles():
    return {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS)) for name in ('a', 'b')}


def _sampled(controller, samples):
    controller.set_sink(lambda t, n, p, v, e: samples.append((t, list(n), list(p), list(v),
                                                              list(e))))


def _run(rate, seconds):
    joints = _handles()
    controller = create_controller('jsc', TYPE, {'type': TYPE, 'publish_rate': rate})
    controller.configure(joints)
    samples = []
    _sampled(controller, samples)
    for step in range(round(seconds / DT)):
        joints['a'].position = step * DT
        controller.update(step * DT, DT)
    return samples


# --- parameters ----------------------------------------------------------------------------

@pytest.mark.parametrize('rate', [0, -5, 'fast', float('nan')])
def test_a_non_positive_publish_rate_is_refused(rate):
    with raises_naming('jsc.publish_rate'):
        create_controller('jsc', TYPE, {'publish_rate': rate})


@pytest.mark.parametrize('rate', [0.0, True, float('inf')])
def test_a_bad_update_rate_is_refused_when_it_sets_the_rate(rate):
    with raises_naming('jsb.update_rate'):
        create_controller('jsb', BROADCASTER, {'update_rate': rate})


@pytest.mark.parametrize('joints', ['a', [''], ['a', 'a'], [3]])
def test_a_joints_parameter_that_is_not_distinct_joint_names_is_refused(joints):
    with raises_naming('jsb.joints'):
        create_controller('jsb', BROADCASTER, {'joints': joints})


def test_a_joint_the_robot_lacks_fails_at_configure_naming_the_joints_field():
    controller = create_controller('jsb', BROADCASTER, {'joints': ['a', 'elbow']})
    with raises_naming('jsb.joints'):
        controller.configure(_handles())


# --- rate ----------------------------------------------------------------------------------

def test_fifty_hz_gives_one_hundred_samples_in_two_seconds():
    samples = _run(50, 2.0)
    assert len(samples) == 100
    assert [round(s[0], 6) for s in samples[:3]] == [0.0, 0.02, 0.04]


def test_the_ros2_broadcaster_name_is_the_same_controller():
    controller = create_controller('jsb', BROADCASTER, {})
    assert controller.publish_rate == 50.0


def test_without_publish_rate_the_update_rate_sets_it_and_publish_rate_wins_over_it():
    assert create_controller('jsb', BROADCASTER, {'update_rate': 200}).publish_rate == 200.0
    assert create_controller('jsb', BROADCASTER, {'update_rate': 200,
                                                  'publish_rate': 25}).publish_rate == 25.0


# --- samples -------------------------------------------------------------------------------

def test_samples_carry_names_positions_velocities_and_efforts():
    time, names, positions, velocities, efforts = _run(50, 0.1)[-1]
    assert names == ['a', 'b']
    assert positions == [pytest.approx(time), 0.0]
    assert len(velocities) == len(efforts) == 2


def test_joints_limits_the_sample_to_those_joints_in_that_order_mimic_joints_included():
    spec = JointSpec('follower', JointKind.REVOLUTE, -1.0, 1.0, mimic=Mimic('a'))
    joints = {**_handles(), 'follower': JointHandle(spec)}
    controller = create_controller('jsb', BROADCASTER, {'joints': ['follower', 'a']})
    controller.configure(joints)
    samples = []
    _sampled(controller, samples)
    joints['follower'].position, joints['a'].velocity = -0.4, 2.0
    controller.update(0.0, DT)
    assert samples == [(0.0, ['follower', 'a'], [-0.4, 0.0], [0.0, 2.0], [0.0, 0.0])]


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


# --- lifecycle -----------------------------------------------------------------------------

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
