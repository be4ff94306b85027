"""PoseBroadcaster (pose_broadcaster/), without a simulator.

The pose on ~/pose always; as a transform on /tf only when valid (finite, a
unit quaternion), at most at tf.publish_rate when given.
"""

import math

import pytest
from controller_fixtures import DT, FakeSource, hardware, loaded, raises_naming, sample_sink, sensor

from pan_tilt_sim.controllers import create_controller

TYPE = 'pose_broadcaster/PoseBroadcaster'
POSE = ('position.x', 'position.y', 'position.z',
        'orientation.x', 'orientation.y', 'orientation.z', 'orientation.w')
HALF_TURN = math.sqrt(0.5)
UPRIGHT = dict(zip(POSE, (0.1, 0.2, 0.75, 0.0, 0.0, HALF_TURN, HALF_TURN), strict=True))


def broadcaster(readings=UPRIGHT, **params):
    source = FakeSource(readings)
    manager = loaded('pose', TYPE, {'pose_name': 'tool_pose', 'frame_id': 'world', **params},
                     {}, hardware(sensor('tool_pose', POSE, source)))
    manager.configure('pose')
    controller = manager.controller('pose')
    topics = {topic.name: topic for topic in controller.ros_surface()}
    poses, transforms = [], []
    topics['~/pose'].connect(sample_sink(poses))
    if '/tf' in topics:
        topics['/tf'].connect(sample_sink(transforms))
    return controller, topics, source, poses, transforms


def test_publishes_the_pose_and_the_transform_to_the_pose_name():
    controller, topics, _source, poses, transforms = broadcaster()
    assert {name: topic.message for name, topic in topics.items()} == {
        '~/pose': 'geometry_msgs/msg/PoseStamped', '/tf': 'tf2_msgs/msg/TFMessage'}
    controller.update(0.0, DT)
    expected = (0.0, [0.1, 0.2, 0.75], [0.0, 0.0, HALF_TURN, HALF_TURN])
    assert poses == [expected]
    ((time, frames),) = transforms
    ((parent, child, transform),) = frames
    assert (time, parent, child) == (0.0, 'world', 'tool_pose')
    assert transform.translation == pytest.approx((0.1, 0.2, 0.75))
    assert transform.rotation == pytest.approx((0.0, 0.0, HALF_TURN, HALF_TURN))


def test_tf_disabled_no_tf_topic_and_a_child_frame_can_be_named():
    _controller, topics, *_ = broadcaster(tf={'enable': False})
    assert set(topics) == {'~/pose'}
    controller, topics, _source, _poses, transforms = broadcaster(tf={'child_frame_id': 'tcp'})
    controller.update(0.0, DT)
    ((_time, ((parent, child, _transform),)),) = transforms
    assert (parent, child) == ('world', 'tcp')


@pytest.mark.parametrize('bad', [
    {'orientation.w': 0.5},  # not a unit quaternion
    {'position.x': math.nan},
])
def test_an_invalid_pose_is_published_on_pose_but_not_as_a_transform_and_noticed_once(bad):
    controller, _topics, source, poses, transforms = broadcaster({**UPRIGHT, **bad})
    controller.update(0.0, DT)
    controller.update(0.01, DT)
    assert len(poses) == 2 and transforms == []
    assert len(controller.notices) == 1 and 'invalid pose' in controller.notices[0]
    source.readings = dict(UPRIGHT)
    controller.update(0.02, DT)
    assert len(transforms) == 1


def test_tf_publish_rate_limits_the_transforms_and_is_warned_about_as_deprecated():
    controller, _topics, _source, poses, transforms = broadcaster(
        update_rate=100, tf={'publish_rate': 25.0})
    assert any('tf.publish_rate: deprecated' in line for line in controller.config_warnings)
    for step in range(81):
        controller.update(step * DT, DT)
    assert len(poses) == 9
    assert [round(time, 6) for time, *_ in transforms] == [0.0, 0.04, 0.08]


@pytest.mark.parametrize('missing', ['pose_name', 'frame_id'])
def test_pose_name_and_frame_id_must_be_given(missing):
    params = {'pose_name': 'tool_pose', 'frame_id': 'world'}
    del params[missing]
    with raises_naming(f'pose.{missing}'):
        create_controller('pose', TYPE, params)
