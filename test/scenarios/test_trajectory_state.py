"""<controller>/controller_state and <controller>/query_state of a joint trajectory controller.

The three-joint arm's ``arm_controller`` publishes
control_msgs/msg/JointTrajectoryControllerState every update while someone
subscribes, and answers control_msgs/srv/QueryTrajectoryState with the
desired state at a requested sim time, as ros2_controllers' controller does
(what rqt_joint_trajectory_controller reads).
"""

from __future__ import annotations

import importlib.util

import pytest
from builtin_interfaces.msg import Time
from node_harness import PROBE_QUEUE, sim_node, stamp_s
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from pan_tilt_sim.share import package_share

pytestmark = pytest.mark.skipif(importlib.util.find_spec('control_msgs') is None,
                                reason='control_msgs is not installed')

ARM = package_share() / 'urdf' / 'three_joint_arm.xacro'
CONTROLLERS = package_share() / 'config' / 'three_joint_arm_controllers.yaml'
JOINTS = ['shoulder_joint', 'extend_joint', 'wrist_joint']
STATE_TOPIC = '/arm_controller/controller_state'
QUERY = '/arm_controller/query_state'


@pytest.fixture
def arm():
    with sim_node(robot_description_file=str(ARM), controllers_file=str(CONTROLLERS)) as arm:
        yield arm


def swing(seconds: float = 2.0) -> JointTrajectory:
    """A trajectory from now to (0.6, 0.1, 1.0) in ``seconds``."""
    return JointTrajectory(joint_names=JOINTS, points=[JointTrajectoryPoint(
        positions=[0.6, 0.1, 1.0], time_from_start=Time(sec=int(seconds)))])


def query(arm, seconds: float):
    from control_msgs.srv import QueryTrajectoryState

    whole = int(seconds)
    request = QueryTrajectoryState.Request(
        time=Time(sec=whole, nanosec=round((seconds - whole) * 1e9)))
    return arm.call(QueryTrajectoryState, QUERY, request)


def test_controller_state_is_published_every_update_with_desired_measured_and_error(arm):
    from control_msgs.msg import JointTrajectoryControllerState

    states = arm.collect(JointTrajectoryControllerState, STATE_TOPIC, PROBE_QUEUE)
    arm.wait_for_subscribers(STATE_TOPIC)
    arm.command('arm_controller', swing())
    arm.run_for(0.5)
    assert len(states) > 10, f'{len(states)} messages on {STATE_TOPIC}'
    stamps = [stamp_s(state) for state in states[-10:]]
    steps = [later - earlier for earlier, later in zip(stamps, stamps[1:], strict=False)]
    assert steps == pytest.approx([arm.simulation.time_step] * 9)  # every physics step
    last = states[-1]
    assert list(last.joint_names) == JOINTS
    assert 0.0 < last.reference.positions[0] < 0.6  # on its way
    assert len(last.reference.velocities) == len(last.reference.accelerations) == 3
    assert len(last.feedback.velocities) == 3  # a velocity state interface
    for joint in (0, 1):  # the wrist is continuous: its error is wrapped
        assert last.error.positions[joint] == pytest.approx(
            last.reference.positions[joint] - last.feedback.positions[joint])
    assert len(last.output.effort) == 3 and not last.output.positions  # an effort interface


def test_query_state_answers_the_desired_state_at_a_time_within_the_trajectory(arm):
    arm.send_paused('arm_controller', swing())
    arm.run_for(0.2)
    controller = arm.simulation.controller('arm_controller')
    answer = query(arm, 1.5)
    assert answer.success, answer.message
    assert list(answer.name) == JOINTS
    expected = controller.query_state(1.5)
    assert list(answer.position) == pytest.approx(expected.positions)
    assert list(answer.velocity) == pytest.approx(expected.velocities)
    assert list(answer.acceleration) == pytest.approx(expected.accelerations)
    assert 0.0 < answer.position[0] < 0.6


def test_query_state_past_the_end_fails_with_upstreams_text(arm):
    arm.send_paused('arm_controller', swing(1.0))
    arm.run_for(0.1)
    answer = query(arm, 30.0)
    assert not answer.success
    assert answer.message == 'Requested sample time precedes the current trajectory end time.'


def test_query_state_fails_while_the_controller_is_inactive(arm):
    arm.simulation.manager.switch(deactivate=['arm_controller'])
    answer = query(arm, 0.0)
    assert not answer.success
    assert answer.message == "Can't sample trajectory. Controller is not active."
    assert arm.own_services()[QUERY] == 'control_msgs/srv/QueryTrajectoryState'
