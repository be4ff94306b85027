"""libgazebo_ros_joint_state_publisher.so's unit on its own: which joints, how often."""

from __future__ import annotations

import pathlib

from mobile_fixtures import plugin_rover_urdf

from pan_tilt_sim.controllers import JointHandle
from pan_tilt_sim.model.robot import JointKind, JointSpec
from pan_tilt_sim.model.urdf import parse_urdf
from pan_tilt_sim.plugins.gazebo_classic.joint_state_publisher import GazeboJointStatePublisher
from pan_tilt_sim.plugins.registry import read_settings

DT = 0.001
WHEELS = ('left_wheel_joint', 'right_wheel_joint')


def publisher(elements: str) -> tuple[GazeboJointStatePublisher, dict[str, JointHandle], list]:
    """Return the configured unit of ``elements``, the wheels' handles and its samples."""
    text = (f'<plugin name="js" filename="libgazebo_ros_joint_state_publisher.so">{elements}'
            '</plugin>')
    (plugin,) = read_settings(parse_urdf(plugin_rover_urdf(joint_states=text),
                                         pathlib.Path('r.urdf')), GazeboJointStatePublisher)
    handles = {name: JointHandle(JointSpec(name, JointKind.CONTINUOUS)) for name in WHEELS}
    unit = GazeboJointStatePublisher(plugin)
    unit.configure(handles)
    samples: list = []
    unit.set_joint_state_sink(lambda *sample: samples.append(sample))
    return unit, handles, samples


def test_it_publishes_the_named_joints_in_its_order_at_its_rate():
    unit, handles, samples = publisher('<joint_name>right_wheel_joint</joint_name>'
                                       '<joint_name>left_wheel_joint</joint_name>'
                                       '<update_rate>100</update_rate>')
    handles['left_wheel_joint'].position, handles['right_wheel_joint'].velocity = 1.5, 2.0
    handles['right_wheel_joint'].effort = 0.3
    for step in range(31):  # 0 to 0.030 s
        unit.update(step * DT, DT)
    assert [round(time, 6) for time, *_ in samples] == [0.01, 0.02, 0.03]
    _, names, positions, velocities, efforts = samples[-1]
    assert names == ('right_wheel_joint', 'left_wheel_joint')
    assert (positions, velocities, efforts) == ([0.0, 1.5], [2.0, 0.0], [0.3, 0.0])


def test_nobody_listening_takes_no_sample():
    unit, _, samples = publisher('<joint_name>left_wheel_joint</joint_name>')
    unit.set_joint_state_sink(None)
    for step in range(30):
        unit.update(step * DT, DT)
    assert samples == []
