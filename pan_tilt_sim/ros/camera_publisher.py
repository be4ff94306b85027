"""sim_node's camera: parameters, ``image_raw`` and ``camera_info`` topics.

A frame is due every ``1 / camera.rate`` seconds of sim time
(:class:`~pan_tilt_sim.schedule.PeriodicSchedule`); it is taken after the
first chunk of physics steps that reaches the due time (sim_node checks
every /clock period, 10 ms of sim time, so with the default 10 Hz the frames
fall exactly on the 0.1 s grid).  When someone subscribes to the image, the
renderer (:mod:`pan_tilt_sim.sim.camera`) draws the world as the physics has it
now; the image is stamped with the sim time and published in the
``<link>_optical`` frame, with a CameraInfo whose K and P follow from
``camera.fov_deg`` and the image size.  A reset of the simulation starts the
schedule again (:meth:`CameraPublisher.reset`).

Design notes: docs/design/ros.md#camera_publisherpy.
"""

from __future__ import annotations

import array
from collections.abc import Callable, Sequence

from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.transforms import Transform
from pan_tilt_sim.model.world_file import World, world_from_parameter
from pan_tilt_sim.ros import parameters as params
from pan_tilt_sim.ros.ros_interfaces import stamp
from pan_tilt_sim.schedule import PeriodicSchedule
from pan_tilt_sim.sim.camera import (
    DEFAULT_FAR,
    DEFAULT_FOV_DEG,
    DEFAULT_HEIGHT,
    DEFAULT_LINK,
    DEFAULT_NEAR,
    DEFAULT_RATE,
    DEFAULT_WIDTH,
    CameraSettings,
    Intrinsics,
    Renderer,
    intrinsics,
)
from pan_tilt_sim.sim.world import DEFAULT_WORLD, WORLDS

IMAGE_ENCODING = 'rgb8'
BYTES_PER_PIXEL = 3
DISTORTION_MODEL = 'plumb_bob'
NO_DISTORTION = [0.0] * 5
IDENTITY_3X3 = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
QUEUE_DEPTH = 5


def declare_world(node: Node) -> World:
    """Declare the ``world`` parameter and return what it names: a scenery, or a world file."""
    return world_from_parameter(params.declare(
        node, 'world', params.STRING, DEFAULT_WORLD,
        f"Scenery around the robot: {', '.join(WORLDS)} (ground: a ground plane; targets: "
        'the ground and coloured target cubes, static; cameras and lidars see them), a '
        'YAML world file (path, file:// or package:// URI) naming a scenery and URDF objects '
        'to spawn at start, or an SDF world (.sdf, .world, .sdf.xacro).'))


def declare_camera(node: Node, links: Sequence[str],
                   urdf_cameras: bool = False) -> CameraSettings | None:
    """Declare the ``camera.*`` parameters; return the settings, or None when it is off.

    ``links`` are the robot's link names: the camera is on by default when the
    robot has ``camera.link`` and its URDF declares no camera sensor of its
    own (``urdf_cameras``).
    """
    link = params.declare(node, 'camera.link', params.STRING, DEFAULT_LINK,
                          'Link carrying the camera, at its tip, looking along its +z.')
    enabled = params.declare(
        node, 'camera.enabled', params.BOOL, link in links and not urdf_cameras,
        'Render and publish camera images (default: true when the robot has camera.link '
        'and its URDF declares no camera sensor).')
    values = {
        'width': params.declare(node, 'camera.width', params.INTEGER, DEFAULT_WIDTH,
                                'Image width in pixels.'),
        'height': params.declare(node, 'camera.height', params.INTEGER, DEFAULT_HEIGHT,
                                 'Image height in pixels.'),
        'fov_deg': params.declare(node, 'camera.fov_deg', params.DOUBLE, DEFAULT_FOV_DEG,
                                  'Horizontal field of view in degrees.'),
        'rate': params.declare(node, 'camera.rate', params.DOUBLE, DEFAULT_RATE,
                               'Frames per second of sim time.'),
        'near': params.declare(node, 'camera.near', params.DOUBLE, DEFAULT_NEAR,
                               'Near clipping distance in metres.'),
        'far': params.declare(node, 'camera.far', params.DOUBLE, DEFAULT_FAR,
                              'Far clipping distance in metres.'),
    }
    if not enabled:
        return None
    if link not in links:
        raise ParameterError(f"parameter 'camera.link': '{link}' is not a link of the robot "
                             f"(links: {', '.join(links)})")
    return CameraSettings(link=link, **values)


def camera_info_message(camera: Intrinsics, frame_id: str) -> CameraInfo:
    """Return the CameraInfo of an ideal pinhole camera with these intrinsics."""
    message = CameraInfo()
    message.header.frame_id = frame_id
    message.width = camera.width
    message.height = camera.height
    message.distortion_model = DISTORTION_MODEL
    message.d = list(NO_DISTORTION)
    message.k = list(camera.k)
    message.r = list(IDENTITY_3X3)
    message.p = list(camera.p)
    return message


class CameraPublisher:
    """Renders the camera when a frame is due and publishes it with its CameraInfo."""

    def __init__(self, node: Node, renderer: Renderer, clock: Callable[[], float],
                 image_topic: str, info_topic: str) -> None:
        settings = renderer.settings
        self._renderer = renderer
        self._clock = clock
        self.settings = settings
        self._schedule = PeriodicSchedule(settings.period)
        self._image_publisher = node.create_publisher(Image, image_topic, QUEUE_DEPTH)
        self._info_publisher = node.create_publisher(CameraInfo, info_topic, QUEUE_DEPTH)
        # Who watches, asked once per batch of steps (refresh_readers), not per
        # step: each question is a call into DDS.
        self.refresh_readers()
        self._info = camera_info_message(intrinsics(settings), settings.optical_frame)
        self._image = Image(height=settings.height, width=settings.width,
                            encoding=IMAGE_ENCODING, is_bigendian=0,
                            step=settings.width * BYTES_PER_PIXEL)
        self._image.header.frame_id = settings.optical_frame
        self._frames = 0

    @property
    def image_topic(self) -> str:
        """The image topic's full name."""
        return self._image_publisher.topic_name

    @property
    def mount(self) -> Transform:
        """Pose of the optical frame in the camera link's frame."""
        return self._renderer.mount

    def optical_axes(self):
        """Return the camera's eye position, forward and up vectors in the world, as now."""
        return self._renderer.optical_axes()

    @property
    def frames(self) -> int:
        """Images rendered and published so far."""
        return self._frames

    def destroy(self, node: Node) -> None:
        """Destroy the image and camera info publishers on ``node`` (the robot left)."""
        node.destroy_publisher(self._image_publisher)
        node.destroy_publisher(self._info_publisher)

    def refresh_readers(self) -> None:
        """Ask whether anybody watches the image or the camera info."""
        self._image_watched = self._image_publisher.get_subscription_count() > 0
        self._info_watched = self._info_publisher.get_subscription_count() > 0

    def next_step(self, step: int, time_step: float) -> int | None:
        """Return the next step after ``step`` at which a frame is due (None: unwatched)."""
        if not (self._image_watched or self._info_watched):
            return None
        return self._schedule.next_step(step, time_step)

    def update(self) -> None:
        """Publish a frame if one is due at the present sim time (render it if watched)."""
        now = self._clock()
        if not self._schedule.take(now):
            return
        stamp(now, self._info.header.stamp)
        if self._image_watched:
            pixels = self._renderer.render()
            image = self._image
            stamp(now, image.header.stamp)
            image.data = array.array('B', pixels)
            self._image_publisher.publish(image)
            self._frames += 1
        if self._info_watched:
            self._info_publisher.publish(self._info)

    def reset(self) -> None:
        """Start the frame schedule again (after sim time was reset or moved)."""
        self._schedule.reset()
