"""joint_state_broadcaster/JointStateBroadcaster: its rate and joints in ros2_control files."""

import pytest
from robot_fixtures import write_text

from pan_tilt_sim.controllers import JointHandle, create_controller
from pan_tilt_sim.controllers.joint_state_controller import DEFAULT_PUBLISH_RATE
from pan_tilt_sim.errors import ControllerConfigError
from pan_tilt_sim.model.controller_config import load_controllers_config
from pan_tilt_sim.model.robot import JointKind, JointSpec, Mimic

BROADCASTER = 'joint_state_broadcaster/JointStateBroadcaster'


def handles():
    specs = [JointSpec('a', JointKind.REVOLUTE, -1.0, 1.0),
             JointSpec('b', JointKind.PRISMATIC, 0.0, 0.5),
             JointSpec('c', JointKind.REVOLUTE, -1.0, 1.0, mimic=Mimic('a'))]
    return {spec.name: JointHandle(spec) for spec in specs}


def broadcaster(**params):
    controller = create_controller('jsb', BROADCASTER, params, 'test.yaml')
    controller.configure(handles())
    return controller


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


def test_without_joints_it_samples_every_movable_joint_mimic_ones_too():
    assert broadcaster().names == ['a', 'b', 'c']


def test_joints_limit_the_sample_in_their_order():
    controller = broadcaster(joints=['c', 'a'])
    table = handles()
    controller.configure(table)
    table['a'].position, table['c'].position = 0.25, -0.25
    samples = []
    controller.set_sink(lambda time, names, positions, *_: samples.append(
        (list(names), list(positions))))
    controller.update(0.0, 0.001)
    assert samples == [(['c', 'a'], [-0.25, 0.25])]


def test_unknown_joint_names_the_field():
    with pytest.raises(ControllerConfigError, match=r"jsb\.joints: joint 'z' is not a movable"):
        broadcaster(joints=['a', 'z'])
