#!/usr/bin/env python3
"""Save the pan/tilt's depth image as a PNG and describe its point cloud: a client without ros2cli.

Start the simulator with the pan/tilt whose URDF declares a depth camera (and a lidar, an
IMU and a force-torque sensor), then run this:

    scripts/run_sim.sh --ros-args -p robot_description_file:=urdf/pan_tilt_sensors.xacro
    .venv/bin/python examples/depth_snapshot.py --pan 0.0 --png depth.png

It turns the pan joint to ``--pan`` (rad; at 0 the camera faces the blue target 2.5 m
away along -x, at -1.5708 the green one, at 1.5708 the yellow one), waits until the
joint is there, takes the next depth image and point cloud, writes the depth image as a
PNG (near = yellow, far = blue, nothing within range = black) and prints what the cloud
sees: how many points are valid, their depth range, and the depth and colour at the
image centre (2.0 m and the target's colour when it faces one).  The pan/tilt example's pan turns
at 0.1 rad/s, so a new angle takes a while at real_time_factor 1.
"""

import argparse
import math
import os
import sys
import time

import numpy
import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Image, JointState, PointCloud2
from std_msgs.msg import Float64

NAMESPACE = '/ex_urdf_pan_tilt'
PAN_COMMAND = f'{NAMESPACE}/joint1_position_controller/command'
JOINT_STATES = f'{NAMESPACE}/joint_states'
DEPTH = f'{NAMESPACE}/depth_camera/depth/image_raw'
POINTS = f'{NAMESPACE}/depth_camera/points'
PAN_TOLERANCE = 0.02  # rad


def depth_array(message: Image) -> numpy.ndarray:
    """Return a 32FC1 depth image as a height x width float array (metres)."""
    if message.encoding != '32FC1':
        raise ValueError(f'expected a 32FC1 depth image, got {message.encoding}')
    return numpy.frombuffer(bytes(message.data), '<f4').reshape(message.height, message.width)


def cloud_arrays(message: PointCloud2) -> tuple[numpy.ndarray, numpy.ndarray | None]:
    """Return the points (N x 3) of an x, y, z[, rgb] float32 cloud, and their colours (N x 3)."""
    names = [field.name for field in message.fields]
    values = numpy.frombuffer(bytes(message.data), '<f4').reshape(
        -1, message.point_step // 4)
    xyz = values[:, [names.index('x'), names.index('y'), names.index('z')]]
    colours = None
    if 'rgb' in names:
        packed = values[:, names.index('rgb')].view(numpy.uint32)
        colours = numpy.stack([(packed >> 16) & 255, (packed >> 8) & 255, packed & 255], axis=1)
    return xyz, colours


def save_png(depth: numpy.ndarray, path: str) -> None:
    """Write ``depth`` as a PNG: near yellow, far blue (log scale), nothing in range black."""
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import colormaps, pyplot

    finite = numpy.isfinite(depth)
    rgba = numpy.zeros(depth.shape + (4,))
    rgba[..., 3] = 1.0
    if finite.any():
        logs = numpy.log(depth[finite])
        span = max(logs.max() - logs.min(), 1e-9)
        rgba[finite] = colormaps['viridis_r']((logs - logs.min()) / span)
    pyplot.imsave(path, rgba)


def describe(depth: numpy.ndarray, xyz: numpy.ndarray, colours: numpy.ndarray | None) -> str:
    """Return a few lines about the depth image and the point cloud."""
    rows, columns = depth.shape
    valid = numpy.isfinite(xyz).all(axis=1)
    lines = [f'depth image {columns}x{rows}: centre {depth[rows // 2, columns // 2]:.3f} m',
             f'point cloud: {valid.sum()} of {len(xyz)} points valid']
    if valid.any():
        z = xyz[valid, 2]
        lines.append(f'  depth (z) min {z.min():.3f} m, median {numpy.median(z):.3f} m, '
                     f'max {z.max():.3f} m')
        lines.append(f'  x from {xyz[valid, 0].min():+.3f} to {xyz[valid, 0].max():+.3f} m, '
                     f'y from {xyz[valid, 1].min():+.3f} to {xyz[valid, 1].max():+.3f} m '
                     '(optical frame: x right, y down, z forward)')
        centre = (rows // 2) * columns + columns // 2
        where = ', '.join(f'{value:+.3f}' for value in xyz[centre])
        colour = '' if colours is None else f', colour rgb {tuple(int(c) for c in colours[centre])}'
        lines.append(f'  centre point ({where}) m{colour}')
    return '\n'.join(lines)


def main(argv: list[str] | None = None) -> int:
    """Turn the pan, take one depth image and cloud; 0 on success, 1 on timeout."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--pan', type=float, default=0.0, help='pan angle to look from (rad)')
    parser.add_argument('--png', default='depth.png', help='where to write the depth image')
    parser.add_argument('--timeout', type=float, default=120.0, help='wall seconds')
    args = parser.parse_args(argv)

    # Talk to a sim_node started by scripts/run_sim.sh, which keeps DDS on loopback.
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    rclpy.init()
    node = Node('depth_snapshot')
    state = {}
    node.create_subscription(JointState, JOINT_STATES, lambda m: state.update(
        zip(m.name, m.position, strict=False)), 10)
    command = node.create_publisher(Float64, PAN_COMMAND, 10)
    deadline = time.monotonic() + args.timeout
    try:
        while command.get_subscription_count() == 0 and time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=0.1)
        command.publish(Float64(data=args.pan))
        while time.monotonic() < deadline and (
                'pan_joint' not in state or abs(state['pan_joint'] - args.pan) > PAN_TOLERANCE):
            rclpy.spin_once(node, timeout_sec=0.1)
        if time.monotonic() >= deadline:
            print(f'timed out: pan_joint {state.get("pan_joint", math.nan):+.3f}, '
                  f'wanted {args.pan:+.3f} (is sim_node running with '
                  'urdf/pan_tilt_sensors.xacro?)', file=sys.stderr)
            return 1
        print(f'pan_joint at {state["pan_joint"]:+.3f} rad')
        # Subscribe only now: the sensors render only while someone listens.
        latest = {}
        node.create_subscription(Image, DEPTH, lambda m: latest.__setitem__('depth', m), 1)
        node.create_subscription(PointCloud2, POINTS,
                                 lambda m: latest.__setitem__('points', m), 1)
        while time.monotonic() < deadline and len(latest) < 2:
            rclpy.spin_once(node, timeout_sec=0.1)
        if len(latest) < 2:
            print(f'timed out waiting for {DEPTH} and {POINTS}', file=sys.stderr)
            return 1
        depth = depth_array(latest['depth'])
        save_png(depth, args.png)
        print(f'depth image written to {args.png} (frame {latest["depth"].header.frame_id})')
        print(describe(depth, *cloud_arrays(latest['points'])))
    except KeyboardInterrupt:
        return 1
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
