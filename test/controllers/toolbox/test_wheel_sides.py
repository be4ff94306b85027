"""WheelSides: a differential drive's left and right wheels, bound by name, and their targets."""

from __future__ import annotations

from pan_tilt_sim.controllers.framework.base import JointHandle
from pan_tilt_sim.controllers.toolbox.wheel_sides import WheelSides
from pan_tilt_sim.model.robot import JointKind, JointSpec


def handles(*names: str) -> dict[str, JointHandle]:
    return {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS)) for name in names}


def test_the_wheels_are_bound_by_side_left_ones_first():
    joints = handles('rear_right', 'front_left', 'rear_left', 'front_right', 'caster')
    asked = []

    def lookup(joints, joint, field):
        asked.append((joint, field))
        return joints[joint]
    wheels = WheelSides(('front_left', 'rear_left'), ('front_right', 'rear_right'),
                        right_field='rightJoint')
    assert wheels.all == []  # nothing bound yet
    wheels.bind(joints, lookup)
    assert [handle.name for handle in wheels.left] == ['front_left', 'rear_left']
    assert [handle.name for handle in wheels.right] == ['front_right', 'rear_right']
    assert [handle.name for handle in wheels.all] == [
        'front_left', 'rear_left', 'front_right', 'rear_right']
    assert asked == [('front_left', 'left_joint'), ('rear_left', 'left_joint'),
                     ('front_right', 'rightJoint'), ('rear_right', 'rightJoint')]


def test_the_setpoints_are_each_bound_wheels_velocity_target():
    joints = handles('left', 'right')
    wheels = WheelSides(('left',), ('right',))
    wheels.bind(joints, lambda joints, joint, field: joints[joint])
    joints['left'].velocity_target, joints['right'].velocity_target = -1.5, 2.5
    assert wheels.setpoints() == {'left': -1.5, 'right': 2.5}
