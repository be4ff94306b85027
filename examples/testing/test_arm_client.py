"""The trajectory client against the shipped three-joint arm."""

import pytest
from arm_client import JOINTS, ArmClient

ARM = 'package://pan_tilt_sim/urdf/three_joint_arm.xacro'
ARM_CONTROLLERS = 'package://pan_tilt_sim/config/three_joint_arm_controllers.yaml'
TARGET = (0.5, 0.1, 0.8)  # rad, m, rad


def test_the_client_moves_the_arm_to_its_target(sim):
    from control_msgs.action import FollowJointTrajectory

    arm = sim(robot=ARM, controllers=ARM_CONTROLLERS)
    client = arm.add_node(ArmClient())
    arm.run_until(client.ready, timeout=1.0)
    result = client.move_to(TARGET, seconds=2.0)
    arm.run_until(result.done, timeout=5.0)
    assert result.result().error_code == FollowJointTrajectory.Result.SUCCESSFUL
    reached = arm.joint_positions()
    assert [reached[joint] for joint in JOINTS] == pytest.approx(TARGET, abs=0.02)
