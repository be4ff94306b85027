"""EffortGripperActionController (effort_controllers/), without a simulator.

Its goals run as the position type's (test_gripper_action_controller.py);
here its own law: a PID on the position error from ``gains.<joint>`` (or
the position controller's defaults), its effort clamped to |max_effort| --
0 applies no effort, with a notice, as upstream's clamp does -- and to the
URDF effort limit; the result's effort is the last one computed.
"""

import pytest
from controller_fixtures import DT, raises_naming
from hand_moved_gripper import EFFORT_LIMIT, EFFORT_TYPE, FINGER, HandMovedGripper

from pan_tilt_sim.controllers import JointHandle, create_controller
from pan_tilt_sim.controllers.trajectory.trajectory_goal import GoalStatus


def test_the_effort_type_takes_gains_for_its_joint_and_refuses_them_for_another():
    controller = create_controller('g', EFFORT_TYPE, {'joint': 'finger',
                                                     'gains': {'finger': {'p': 500.0}}})
    controller.configure({'finger': JointHandle(FINGER)})
    assert controller.pids()['finger'].gains.p == 500.0
    with raises_naming('g.gains.thumb'):
        create_controller('g', EFFORT_TYPE, {'joint': 'finger', 'gains': {'thumb': {'p': 1.0}}})


def test_the_effort_type_clamps_its_pids_effort_to_max_effort_and_reports_it():
    gripper = HandMovedGripper(EFFORT_TYPE, start=0.04, gains={'finger': {'p': 1000.0}},
                               goal_tolerance=1e-6)
    gripper.goal(0.0, max_effort=6.0)
    gripper.controller.update(0.0, DT)
    assert gripper.handle.effort == -6.0  # the PID asks for -40 N
    goal = gripper.goal(0.0399, max_effort=6.0)
    gripper.controller.update(DT, DT)
    assert gripper.handle.effort == pytest.approx(-0.1)  # within the clamp: the PID's own
    gripper.handle.position = 0.0399
    gripper.controller.update(2 * DT, DT)
    assert goal.status is GoalStatus.SUCCEEDED
    assert goal.result.effort == pytest.approx(-0.1)  # the last effort computed


def test_the_effort_type_clamps_to_the_effort_limit_too():
    gripper = HandMovedGripper(EFFORT_TYPE, start=0.05, gains={'finger': {'p': 10000.0}})
    gripper.goal(0.0, max_effort=1000.0)
    gripper.controller.update(0.0, DT)
    assert gripper.handle.effort == -EFFORT_LIMIT


def test_the_effort_type_applies_no_effort_for_max_effort_zero_and_says_so():
    gripper = HandMovedGripper(EFFORT_TYPE, start=0.04, gains={'finger': {'p': 1000.0}})
    gripper.goal(0.0, max_effort=0.0)
    gripper.controller.update(0.0, DT)
    assert gripper.handle.effort == 0.0
    assert any('max_effort 0' in notice for notice in gripper.controller.notices)


def test_the_effort_type_without_gains_uses_the_position_controllers_defaults():
    gripper = HandMovedGripper(EFFORT_TYPE, start=0.04)
    gains = gripper.controller.pids()['finger'].gains
    assert (gains.p, gains.i, gains.d) == (100.0, 0.01, 10.0)
