"""Sensor messages: REP 118 depth, PCL's packed colour, organized clouds, image formats."""

import math

import numpy
import pytest

from pan_tilt_sim.ros import sensor_messages as messages


def test_depth_outside_the_range_is_minus_or_plus_infinity_rep_118():
    depth = numpy.array([[0.05, 0.5, 2.0], [9.0, 11.0, math.inf]])
    ranged = messages.depth_in_range(depth, 0.1, 10.0)
    assert ranged.dtype == numpy.float32
    assert ranged[0, 0] == -math.inf  # closer than the minimum
    assert ranged[0, 1] == pytest.approx(0.5) and ranged[1, 0] == pytest.approx(9.0)
    assert ranged[1, 1] == math.inf and ranged[1, 2] == math.inf  # too far / nothing
    assert not numpy.isnan(ranged).any()


def test_depth_image_is_32fc1_little_endian_metres():
    depth = numpy.array([[1.5, 2.5]], numpy.float32)
    image = messages.depth_image(depth, 'cam', 3.25)
    assert (image.encoding, image.height, image.width, image.step) == ('32FC1', 1, 2, 8)
    assert image.is_bigendian == 0
    assert numpy.frombuffer(bytes(image.data), '<f4').tolist() == [1.5, 2.5]
    assert (image.header.stamp.sec, image.header.stamp.nanosec) == (3, 250_000_000)


def test_rgb_is_packed_as_pcl_packs_it():
    rgb = numpy.array([[[0x12, 0x34, 0x56]]], numpy.uint8)
    packed = messages.pack_rgb(rgb)
    assert packed.dtype == numpy.float32
    assert int(packed.view(numpy.uint32)[0, 0]) == 0x123456


def test_point_cloud_is_organized_with_nan_for_missing_points():
    depth = numpy.array([[2.0, math.inf], [-math.inf, 4.0]], numpy.float32)
    ray_x = numpy.array([[-0.5, 0.5], [-0.5, 0.5]])
    ray_y = numpy.array([[-0.25, -0.25], [0.25, 0.25]])
    xyz = messages.depth_points(depth, ray_x, ray_y)
    assert xyz[0, 0].tolist() == [-1.0, -0.5, 2.0]
    assert numpy.isnan(xyz[0, 1]).all() and numpy.isnan(xyz[1, 0]).all()
    cloud = messages.point_cloud(xyz, 'cam', 1.0, ('rgb', numpy.zeros((2, 2), numpy.float32)))
    assert (cloud.height, cloud.width, cloud.point_step, cloud.row_step) == (2, 2, 16, 32)
    assert [(f.name, f.offset, f.datatype) for f in cloud.fields] == [
        ('x', 0, 7), ('y', 4, 7), ('z', 8, 7), ('rgb', 12, 7)]
    assert not cloud.is_dense
    values = numpy.frombuffer(bytes(cloud.data), '<f4').reshape(2, 2, 4)
    assert values[1, 1, :3].tolist() == [2.0, 1.0, 4.0]


@pytest.mark.parametrize(('gazebo_format', 'encoding', 'first'), [
    ('R8G8B8', 'rgb8', [10, 20, 30]),
    ('B8G8R8', 'bgr8', [30, 20, 10]),
    ('L8', 'mono8', [round(0.299 * 10 + 0.587 * 20 + 0.114 * 30)]),
    ('FLOAT32', 'rgb8', [10, 20, 30]),
])
def test_colour_images_follow_the_gazebo_format(gazebo_format, encoding, first):
    rgb = numpy.array([[[10, 20, 30], [0, 0, 0]]], numpy.uint8)
    image = messages.colour_image(rgb, gazebo_format, 'cam', 0.0)
    assert image.encoding == encoding
    channels = len(first)
    assert image.step == 2 * channels
    assert list(bytes(image.data))[:channels] == first


def test_laser_scan_keeps_infinity_for_no_return():
    scan = messages.laser_scan(numpy.array([1.0, math.inf]), -0.5, 0.5, 1.0, 0.1, 10.0, 0.1,
                               'laser', 2.0)
    assert scan.ranges.tolist() == [1.0, math.inf]
    assert (scan.angle_min, scan.angle_max, scan.angle_increment) == (-0.5, 0.5, 1.0)
    assert len(scan.intensities) == 0
