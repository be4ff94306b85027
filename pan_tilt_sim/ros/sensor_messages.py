"""sensor_msgs and geometry_msgs messages from sensor readings (numpy arrays in, messages out).

* Depth images: ``32FC1`` in metres, REP 118: ``-inf`` closer than the
  valid range, ``+inf`` beyond it or where nothing is seen; no NaN (a
  simulated depth is never invalid).
* Point clouds: organized (height x width of the image or scan), little
  endian float32 ``x, y, z`` (plus ``rgb`` packed as PCL packs it -- the
  uint32 ``0x00RRGGBB`` read as a float32 -- for cameras with colour, or
  ``intensity`` for lidars); a point without a valid depth or return is
  NaN, and ``is_dense`` is false then.
* LaserScan: REP 117 (``+inf`` no return within range), no intensities.
"""

from __future__ import annotations

import array
import math
from collections.abc import Sequence

import numpy
from geometry_msgs.msg import WrenchStamped
from sensor_msgs.msg import CameraInfo, Image, Imu, LaserScan, PointCloud2, PointField

from pan_tilt_sim.ros.ros_interfaces import stamp

FLOAT32 = PointField.FLOAT32
FLOAT_BYTES = 4
DEPTH_ENCODING = '32FC1'
DISTORTION_MODEL = 'plumb_bob'
IDENTITY_3X3 = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
# Gazebo image formats -> (ROS encoding, channels).
FORMATS = {
    'R8G8B8': ('rgb8', 3), 'RGB_INT8': ('rgb8', 3),
    'B8G8R8': ('bgr8', 3), 'BGR_INT8': ('bgr8', 3),
    'L8': ('mono8', 1), 'L_INT8': ('mono8', 1),
}
DEFAULT_FORMAT = 'R8G8B8'
LUMA = numpy.array((0.299, 0.587, 0.114))  # ITU-R BT.601, as OpenCV's rgb -> gray


def image_encoding(gazebo_format: str) -> str:
    """Return the ROS encoding of a Gazebo image ``<format>`` (rgb8 for unknown ones)."""
    return FORMATS.get(gazebo_format, FORMATS[DEFAULT_FORMAT])[0]


def camera_info_message(k: Sequence[float], p: Sequence[float], width: int, height: int,
                        frame_id: str) -> CameraInfo:
    """Return the CameraInfo of an ideal pinhole camera."""
    message = CameraInfo()
    message.header.frame_id = frame_id
    message.width, message.height = width, height
    message.distortion_model = DISTORTION_MODEL
    message.d = [0.0] * 5
    message.k = list(k)
    message.r = list(IDENTITY_3X3)
    message.p = list(p)
    return message


def colour_image(rgb: numpy.ndarray, gazebo_format: str, frame_id: str, time: float,
                 into: Image | None = None) -> Image:
    """Return an Image of an rgb8 array (height x width x 3) in the sensor's format."""
    encoding, channels = FORMATS.get(gazebo_format, FORMATS[DEFAULT_FORMAT])
    if encoding == 'bgr8':
        pixels = rgb[:, :, ::-1]
    elif encoding == 'mono8':
        pixels = numpy.rint(rgb @ LUMA).astype(numpy.uint8)
    else:
        pixels = rgb
    message = Image() if into is None else into
    stamp(time, message.header.stamp)
    message.header.frame_id = frame_id
    message.height, message.width = rgb.shape[:2]
    message.encoding = encoding
    message.is_bigendian = 0
    message.step = message.width * channels
    message.data = byte_array(numpy.ascontiguousarray(pixels, numpy.uint8))
    return message


def depth_in_range(depth: numpy.ndarray, lower: float, upper: float) -> numpy.ndarray:
    """Return float32 depth with REP 118's ``-inf`` below ``lower`` and ``+inf`` above ``upper``."""
    out = depth.astype(numpy.float32)
    out[depth < lower] = -math.inf
    out[depth > upper] = math.inf
    return out


def depth_image(depth: numpy.ndarray, frame_id: str, time: float,
                into: Image | None = None) -> Image:
    """Return a 32FC1 Image of planar depth in metres (already ranged)."""
    message = Image() if into is None else into
    stamp(time, message.header.stamp)
    message.header.frame_id = frame_id
    message.height, message.width = depth.shape
    message.encoding = DEPTH_ENCODING
    message.is_bigendian = 0
    message.step = message.width * FLOAT_BYTES
    message.data = byte_array(numpy.ascontiguousarray(depth, '<f4'))
    return message


def pack_rgb(rgb: numpy.ndarray) -> numpy.ndarray:
    """Return PCL's packed colour: uint32 0x00RRGGBB of each pixel, viewed as float32."""
    packed = numpy.zeros(rgb.shape[:2] + (4,), numpy.uint8)
    packed[..., :3] = rgb[..., ::-1]  # little endian: the bytes of 0x00RRGGBB are B, G, R, 0
    return packed.view('<f4')[..., 0]


def point_cloud(xyz: numpy.ndarray, frame_id: str, time: float,
                extra: tuple[str, numpy.ndarray] | None = None,
                into: PointCloud2 | None = None) -> PointCloud2:
    """Return an organized PointCloud2 of ``xyz`` (rows x columns x 3, NaN = no point).

    ``extra`` adds one float32 field (``rgb`` or ``intensity``) after z.
    """
    rows, columns = xyz.shape[:2]
    names = ['x', 'y', 'z'] + ([extra[0]] if extra is not None else [])
    points = numpy.empty((rows, columns, len(names)), '<f4')
    points[..., :3] = xyz
    if extra is not None:
        points[..., 3] = extra[1]
    message = PointCloud2() if into is None else into
    stamp(time, message.header.stamp)
    message.header.frame_id = frame_id
    message.height, message.width = rows, columns
    message.fields = [PointField(name=name, offset=index * FLOAT_BYTES, datatype=FLOAT32,
                                 count=1) for index, name in enumerate(names)]
    message.is_bigendian = False
    message.point_step = FLOAT_BYTES * len(names)
    message.row_step = message.point_step * columns
    message.is_dense = bool(numpy.isfinite(points[..., 2]).all())
    message.data = byte_array(points)
    return message


def byte_array(values: numpy.ndarray) -> array.array:
    """Return the bytes of a numpy array as the ``array('B')`` messages hold (one copy)."""
    data = array.array('B')
    data.frombytes(memoryview(numpy.ascontiguousarray(values)).cast('B'))
    return data


def depth_points(depth: numpy.ndarray, ray_x: numpy.ndarray,
                 ray_y: numpy.ndarray) -> numpy.ndarray:
    """Return the optical-frame points of a ranged depth image (NaN where not finite)."""
    points = numpy.empty(depth.shape + (3,), numpy.float32)
    z = points[..., 2]
    z[...] = depth
    z[~numpy.isfinite(depth)] = numpy.nan
    numpy.multiply(ray_x, z, out=points[..., 0])
    numpy.multiply(ray_y, z, out=points[..., 1])
    return points


def laser_scan(ranges: numpy.ndarray, angle_min: float, angle_max: float, increment: float,
               range_min: float, range_max: float, scan_time: float, frame_id: str,
               time: float, into: LaserScan | None = None) -> LaserScan:
    """Return a LaserScan of one row of ranges (``inf``: no return)."""
    message = LaserScan() if into is None else into
    stamp(time, message.header.stamp)
    message.header.frame_id = frame_id
    message.angle_min, message.angle_max = angle_min, angle_max
    message.angle_increment = increment
    message.time_increment = 0.0
    message.scan_time = scan_time
    message.range_min, message.range_max = range_min, range_max
    message.ranges = array.array('f', ranges.astype(numpy.float32).tobytes())
    message.intensities = array.array('f')
    return message


def imu_message(orientation: Sequence[float], angular_velocity: Sequence[float],
                linear_acceleration: Sequence[float], covariances: Sequence[Sequence[float]],
                frame_id: str, time: float, into: Imu | None = None) -> Imu:
    """Return an Imu message; ``covariances`` are the three 3x3 row-major covariances."""
    message = Imu() if into is None else into
    stamp(time, message.header.stamp)
    message.header.frame_id = frame_id
    q = message.orientation
    q.x, q.y, q.z, q.w = (float(value) for value in orientation)
    w = message.angular_velocity
    w.x, w.y, w.z = (float(value) for value in angular_velocity)
    a = message.linear_acceleration
    a.x, a.y, a.z = (float(value) for value in linear_acceleration)
    (message.orientation_covariance, message.angular_velocity_covariance,
     message.linear_acceleration_covariance) = (list(c) for c in covariances)
    return message


def wrench_message(force: Sequence[float], torque: Sequence[float], frame_id: str, time: float,
                   into: WrenchStamped | None = None) -> WrenchStamped:
    """Return a WrenchStamped."""
    message = WrenchStamped() if into is None else into
    stamp(time, message.header.stamp)
    message.header.frame_id = frame_id
    f, t = message.wrench.force, message.wrench.torque
    f.x, f.y, f.z = (float(value) for value in force)
    t.x, t.y, t.z = (float(value) for value in torque)
    return message
