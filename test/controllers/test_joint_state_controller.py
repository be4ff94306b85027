"""JointStateController: samples of every joint at publish_rate Hz of sim time."""

import pytest

from pan_tilt_sim.controllers import JointHandle, create_controller
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.robot import JointKind, JointSpec

TYPE = 'joint_state_controller/JointStateController'
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
    controller = create_controller('jsb', 'joint_state_broadcaster/JointStateBroadcaster', {})
    assert controller.publish_rate == 50.0


@pytest.mark.parametrize('rate', [0, -5, 'fast', float('nan')])
def test_a_non_positive_publish_rate_is_refused(rate):
    with pytest.raises(ControllerConfigError, match='publish_rate'):
        create_controller('jsc', TYPE, {'publish_rate': rate})
