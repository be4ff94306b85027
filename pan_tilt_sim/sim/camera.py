"""A camera on a robot link, rendered headless with PyBullet's TinyRenderer. No ROS.

Where the camera sits: at the tip of its link -- as far along the link's +z
as the link's visual geometry reaches -- looking along the link's +z.  It is
rigidly mounted: its "up" is the link axis (+-x or +-y) that points most
nearly up (world +z) in the robot's initial pose, so the image is upright
there.  For the pan/tilt example the tilt link starts horizontal (tilt
-pi/2), the camera looks along world -x at pan 0, and its up is the link's
+x; at tilt -pi it looks straight down.

The optical frame follows REP-103: z forward, x right, y down.  ``fov_deg``
is the horizontal field of view (Gazebo's ``horizontal_fov``); pixels are
square, so ``fx = fy = (width / 2) / tan(fov / 2)``, and the principal
point is the image centre in OpenCV's convention (pixel centres at integer
coordinates): ``cx = (width - 1) / 2``, ``cy = (height - 1) / 2``.

Design notes: docs/design/sim.md#camerapy.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

import numpy

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.robot import RobotModel
from pan_tilt_sim.model.transforms import Transform, Vector, quaternion_from_matrix, rotate
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.physics import Physics
from pan_tilt_sim.sim.sensors.mount import LinkReader
from pan_tilt_sim.sim.world import DEFAULT_WORLD, GROUND_RGB, has_ground

DEFAULT_LINK = 'tilt_link'
DEFAULT_WIDTH = 320
DEFAULT_HEIGHT = 240
DEFAULT_FOV_DEG = 60.0
DEFAULT_RATE = 10.0  # frames per second of sim time
DEFAULT_NEAR = 0.01  # m
DEFAULT_FAR = 50.0  # m
MAX_FOV_DEG = 179.0
OPTICAL_SUFFIX = '_optical'
RGBA_CHANNELS = 4
RGB_CHANNELS = 3
BACKGROUND_DEPTH = 1.0  # OpenGL depth where nothing was drawn (the far plane)
# TinyRenderer writes the far plane's depth where nothing was drawn as 1.0 give or take
# a couple of float32 steps (2**-24 each), which way depending on its rounding of near
# and far.  Buffer values within this many steps of 1.0 are taken as nothing drawn: a
# surface that close to the far plane (a few steps of the buffer's own resolution
# there) reads as beyond it.
BACKGROUND_STEPS = 8
BACKGROUND_THRESHOLD = BACKGROUND_DEPTH - BACKGROUND_STEPS * 2.0 ** -24
# Link axes that may serve as the camera's "up" (perpendicular to its +z view axis).
UP_CANDIDATES: tuple[Vector, ...] = ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0),
                                     (0.0, 1.0, 0.0), (0.0, -1.0, 0.0))
FORWARD: Vector = (0.0, 0.0, 1.0)
WORLD_UP: Vector = (0.0, 0.0, 1.0)


@dataclasses.dataclass(frozen=True)
class CameraSettings:
    """What the camera parameters ask for, checked (errors name the parameter)."""

    link: str = DEFAULT_LINK
    width: int = DEFAULT_WIDTH
    height: int = DEFAULT_HEIGHT
    fov_deg: float = DEFAULT_FOV_DEG
    rate: float = DEFAULT_RATE
    near: float = DEFAULT_NEAR
    far: float = DEFAULT_FAR

    def __post_init__(self) -> None:
        for name in ('width', 'height'):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
                raise ParameterError(f"parameter 'camera.{name}' must be an integer > 0, "
                                     f'got {value!r}')
        if not (math.isfinite(self.fov_deg) and 0.0 < self.fov_deg <= MAX_FOV_DEG):
            raise ParameterError(f"parameter 'camera.fov_deg' must be > 0 and <= {MAX_FOV_DEG}"
                                 f' degrees, got {self.fov_deg}')
        if not (math.isfinite(self.rate) and self.rate > 0.0):
            raise ParameterError(f"parameter 'camera.rate' must be a number of Hz > 0, "
                                 f'got {self.rate}')
        if not (math.isfinite(self.near) and self.near > 0.0):
            raise ParameterError(f"parameter 'camera.near' must be > 0 m, got {self.near}")
        if not (math.isfinite(self.far) and self.far > self.near):
            raise ParameterError(f"parameter 'camera.far' must be finite and greater than "
                                 f'camera.near ({self.near} m), got {self.far}')

    @property
    def period(self) -> float:
        """Seconds of sim time between frames."""
        return 1.0 / self.rate

    @property
    def optical_frame(self) -> str:
        """Name of the optical frame (REP-103) the images are in."""
        return self.link + OPTICAL_SUFFIX


@dataclasses.dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics of the image, in pixels."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @property
    def k(self) -> tuple[float, ...]:
        """The 3x3 camera matrix K, row-major (as ``sensor_msgs/CameraInfo.k``)."""
        return (self.fx, 0.0, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0)

    @property
    def p(self) -> tuple[float, ...]:
        """The 3x4 projection matrix P of a monocular camera, row-major."""
        return (self.fx, 0.0, self.cx, 0.0, 0.0, self.fy, self.cy, 0.0, 0.0, 0.0, 1.0, 0.0)


def centred_intrinsics(width: int, height: int, focal: float) -> Intrinsics:
    """Return the intrinsics of square pixels with the principal point at the image centre."""
    return Intrinsics(width, height, focal, focal, (width - 1) / 2.0, (height - 1) / 2.0)


def intrinsics(settings: CameraSettings) -> Intrinsics:
    """Return the intrinsics for the settings' size and horizontal field of view."""
    focal = (settings.width / 2.0) / math.tan(math.radians(settings.fov_deg) / 2.0)
    return centred_intrinsics(settings.width, settings.height, focal)


# In PyBullet's projection matrix (column-major, 16 values): row 0 and row 1 of column 2.
PROJECTION_X_SHIFT, PROJECTION_Y_SHIFT = 8, 9


def projection_matrix(vertical_fov: float, width: int, height: int, near: float, far: float,
                      client: int) -> list[float]:
    """Return PyBullet's projection for ``width`` x ``height`` pixels, centred as the intrinsics.

    TinyRenderer samples pixel ``i`` at normalised device coordinate
    ``2 i / width - 1`` -- the principal point at ``width / 2``, half a pixel
    from the ``(width - 1) / 2`` of the intrinsics (:func:`centred_intrinsics`),
    which CameraInfo publishes; the view shifted by half a pixel in both axes
    puts it there.  ``vertical_fov`` in degrees.
    """
    matrix = list(pybullet.computeProjectionMatrixFOV(vertical_fov, width / height, near, far,
                                                      physicsClientId=client))
    matrix[PROJECTION_X_SHIFT] += 1.0 / width
    matrix[PROJECTION_Y_SHIFT] += 1.0 / height
    return matrix


def vertical_fov_deg(settings: CameraSettings) -> float:
    """Return the vertical field of view (PyBullet's ``fov``) for square pixels."""
    half = math.atan(math.tan(math.radians(settings.fov_deg) / 2.0)
                     * settings.height / settings.width)
    return math.degrees(2.0 * half)


def camera_mount(model: RobotModel, link: str,
                 initial_positions: Mapping[str, float]) -> Transform:
    """Return the pose of the optical frame in ``link``'s frame.

    The origin is the tip of the link on its +z axis; the optical z is the
    link's +z, the optical y (image down) is minus the link axis that points
    most nearly up in the initial pose, and optical x = y cross z (image right).
    """
    reach = model.link(link).reach()
    poses = model.link_poses(initial_positions)
    link_pose = poses.get(link, Transform())
    up = max(UP_CANDIDATES,
             key=lambda axis: _dot(rotate(link_pose.rotation, axis), WORLD_UP))
    down = tuple(-c for c in up)
    right = _cross(down, FORWARD)
    rotation = quaternion_from_matrix((right, down, FORWARD))  # type: ignore[arg-type]
    return Transform((0.0, 0.0, reach), rotation)


class Renderer:
    """Renders the camera's view from the simulation's PyBullet client, as it is now."""

    def __init__(self, physics: Physics, model: RobotModel, settings: CameraSettings,
                 world: str = DEFAULT_WORLD) -> None:
        self.settings = settings
        self._client = physics.client_id
        try:
            self._link = LinkReader(physics, settings.link)
        except KeyError:
            raise ParameterError(
                f"parameter 'camera.link': '{settings.link}' is not a link of the robot "
                f"(links: {', '.join(model.link_names)})") from None
        self._ground = has_ground(world)
        camera = intrinsics(settings)
        # Each pixel's viewing ray in optical axes: ((u - cx) / fx, (v - cy) / fy, 1).
        self._ray_x = (numpy.arange(settings.width) - camera.cx) / camera.fx
        self._ray_y = (numpy.arange(settings.height) - camera.cy) / camera.fy
        initial = {joint.name: position for joint, position in zip(
            physics.joints, physics.initial_positions, strict=True)}
        self.mount = camera_mount(model, settings.link, initial)
        self._projection = projection_matrix(vertical_fov_deg(settings), settings.width,
                                             settings.height, settings.near, settings.far,
                                             self._client)

    def render(self) -> bytes:
        """Return an rgb8 image (rows top first) of the world as the physics has it now."""
        eye, forward, up = self.optical_axes()
        target = [e + f for e, f in zip(eye, forward, strict=True)]
        view = pybullet.computeViewMatrix(eye, target, up, physicsClientId=self._client)
        settings = self.settings
        _, _, rgba, depth, _ = pybullet.getCameraImage(
            settings.width, settings.height, view, self._projection,
            renderer=pybullet.ER_TINY_RENDERER, flags=pybullet.ER_NO_SEGMENTATION_MASK,
            physicsClientId=self._client)
        pixels = numpy.array(rgba, dtype=numpy.uint8).reshape(
            settings.height, settings.width, RGBA_CHANNELS)[:, :, :RGB_CHANNELS]
        if self._ground:
            self._paint_ground(pixels, depth, eye, forward, up)
        return pixels.tobytes()

    def optical_axes(self) -> tuple[Vector, Vector, Vector]:
        """Return the camera's eye position, forward and up vectors in the world frame."""
        link = self.link_pose()
        optical = link.then(self.mount)
        forward = rotate(optical.rotation, FORWARD)
        up = rotate(optical.rotation, (0.0, -1.0, 0.0))
        return optical.translation, forward, up

    def _paint_ground(self, pixels: numpy.ndarray, depth, eye: Vector, forward: Vector,
                      up: Vector) -> None:
        # Where nothing was drawn and the viewing ray meets z = 0, the ground shows.
        background = nothing_drawn(numpy.asarray(depth).reshape(pixels.shape[:2]))
        right_z = forward[0] * up[1] - forward[1] * up[0]  # z of forward x up
        ray_z = (forward[2] + self._ray_x[numpy.newaxis, :] * right_z
                 - self._ray_y[:, numpy.newaxis] * up[2])
        pixels[background & (ray_z * eye[2] < 0.0)] = GROUND_RGB

    def link_pose(self) -> Transform:
        """Return the camera link's URDF frame in the world, as the scene has it now.

        The root link's too: PyBullet reports a body's base by its centre of
        mass, which :class:`~pan_tilt_sim.sim.sensors.mount.LinkReader` takes
        back to the link frame, as for every other sensor.
        """
        return self._link.frame()


def nothing_drawn(buffer: numpy.ndarray) -> numpy.ndarray:
    """Return where a TinyRenderer depth buffer (values in [0, 1]) holds nothing drawn.

    Robust to the renderer's rounding of the far plane (:data:`BACKGROUND_THRESHOLD`),
    whatever the image size and clip planes.
    """
    return numpy.asarray(buffer, dtype=numpy.float64) >= BACKGROUND_THRESHOLD


def _dot(a: Sequence[float], b: Sequence[float]) -> float:
    return sum(x * y for x, y in zip(a, b, strict=True))


def _cross(a: Sequence[float], b: Sequence[float]) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
