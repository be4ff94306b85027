"""Scenery for the camera: a ground plane and a few coloured targets, a ground alone, or nothing.

Built from PyBullet primitives in the simulation's own client.  The ground is the plane
z = 0; it becomes a collision body only when an object or a free robot needs it, and the
links of a fixed robot that start touching it never collide with it.

Design notes: docs/design/sim.md#worldpy.
"""

from __future__ import annotations

import dataclasses
import math

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.world_file import EMPTY, GROUND, SCENERIES, TARGETS
from pan_tilt_sim.sim.bullet import pybullet

WORLDS = SCENERIES  # empty, ground (the plane alone), targets
DEFAULT_WORLD = TARGETS
TARGET_PREFIX = 'target_'  # a target's entity name: target_red, target_green, ...

GROUND_HALF_SIZE = 15.0  # m: the GUI's ground box is a 30 m square ...
GROUND_HALF_THICKNESS = 0.005  # m: ... whose top face is at z = 0
GROUND_RGB = (130, 130, 130)  # the ground's colour in camera images (rgb8)
GROUND_RGBA = (*(channel / 255.0 for channel in GROUND_RGB), 1.0)
STATIC_MASS = 0.0  # PyBullet: mass 0 makes a body static
NO_SHAPE = -1
BASE_LINK = -1  # PyBullet's link index of a body's base
GROUND_FRICTION = 1.0  # the ground plane's (see add_ground_plane)
# A body without a visual shape is drawn by TinyRenderer from its collision
# shape (a plane: the whole lower half of every view, shaded pixel by pixel); a
# speck of a visual shape, fully transparent, keeps the ground plane unseen.
INVISIBLE_RADIUS = 1e-6
INVISIBLE_RGBA = (0.0, 0.0, 0.0, 0.0)
# A robot link whose box (PyBullet's, with its ~1 mm margin) reaches below this
# height in the initial pose touches the ground: the plane leaves it alone.
GROUND_CLEARANCE = 0.002  # m


@dataclasses.dataclass(frozen=True)
class Target:
    """A coloured box standing on the ground."""

    name: str
    rgba: tuple[float, float, float, float]
    azimuth_deg: float  # direction from the origin, counter-clockwise from +x
    distance: float = 2.5  # m from the origin to the box's centre
    half_size: float = 0.3  # m: the box is a cube of twice this side

    @property
    def position(self) -> tuple[float, float, float]:
        """Centre of the box in the world frame."""
        azimuth = math.radians(self.azimuth_deg)
        return (self.distance * math.cos(azimuth), self.distance * math.sin(azimuth),
                self.half_size)


TARGET_SET = (
    Target('red', (0.9, 0.1, 0.1, 1.0), 0.0),
    Target('green', (0.1, 0.8, 0.1, 1.0), 90.0),
    Target('blue', (0.1, 0.2, 0.9, 1.0), 180.0),
    Target('yellow', (0.9, 0.85, 0.1, 1.0), 270.0),
)


def check_world(name: str) -> str:
    """Return ``name`` if it names a world; ParameterError naming the choices otherwise."""
    if name not in WORLDS:
        raise ParameterError(
            f"parameter 'world' must be one of {', '.join(WORLDS)}, got '{name}'")
    return name


def has_ground(name: str) -> bool:
    """Whether the world called ``name`` has a ground plane."""
    return check_world(name) != EMPTY


def build_world(name: str, client: int, *, ground: bool = False) -> dict[str, int]:
    """Add the world's bodies to PyBullet ``client``; return the targets' body ids by name.

    The names are the targets' entity names (``target_red``...).  The ground
    plane becomes a body only with ``ground`` (for a GUI window); the camera
    paints it instead (see the module's design notes).
    """
    check_world(name)
    if name == EMPTY:
        return {}
    if ground:
        _visual_box(client, (GROUND_HALF_SIZE, GROUND_HALF_SIZE, GROUND_HALF_THICKNESS),
                    (0.0, 0.0, -GROUND_HALF_THICKNESS), GROUND_RGBA)
    if name == GROUND:
        return {}
    targets = {}
    for target in TARGET_SET:
        half = target.half_size
        targets[TARGET_PREFIX + target.name] = _visual_box(
            client, (half, half, half), target.position, target.rgba, collide=True)
    return targets


def grounded_links(client: int, robot: int) -> list[int]:
    """Return the robot's links (-1: the base) within GROUND_CLEARANCE of z = 0 or below it."""
    return [link for link in range(BASE_LINK, pybullet.getNumJoints(robot, physicsClientId=client))
            if pybullet.getAABB(robot, link, physicsClientId=client)[0][2] < GROUND_CLEARANCE]


def add_ground_plane(client: int, robot: int, grounded: list[int]) -> int:
    """Add the plane z = 0 as a static collision body, not touching ``grounded`` links; return it.

    Its friction is :data:`GROUND_FRICTION`: PyBullet multiplies the two
    surfaces' coefficients, so on the ground a link's or an object's own
    coefficient decides, as on Gazebo's ground plane (mu 100 and 50, of which
    Gazebo takes the smaller of each pair).

    ``grounded`` are the robot's links that touched the ground in its initial
    pose (:func:`grounded_links`).  The camera does not draw the plane (it
    paints the ground itself) and rays hit it where the analytic ground is
    anyway.
    """
    shape = pybullet.createCollisionShape(pybullet.GEOM_PLANE, physicsClientId=client)
    speck = pybullet.createVisualShape(pybullet.GEOM_SPHERE, radius=INVISIBLE_RADIUS,
                                       rgbaColor=INVISIBLE_RGBA, physicsClientId=client)
    plane = pybullet.createMultiBody(
        baseMass=STATIC_MASS, baseCollisionShapeIndex=shape, baseVisualShapeIndex=speck,
        useMaximalCoordinates=True, physicsClientId=client)
    pybullet.changeDynamics(plane, BASE_LINK, lateralFriction=GROUND_FRICTION,
                            physicsClientId=client)
    for link in grounded:
        pybullet.setCollisionFilterPair(plane, robot, BASE_LINK, link, enableCollision=0,
                                        physicsClientId=client)
    return plane


def _visual_box(client: int, half_extents: tuple[float, float, float],
                position: tuple[float, float, float],
                rgba: tuple[float, float, float, float], *, collide: bool = False) -> int:
    shape = pybullet.createVisualShape(
        pybullet.GEOM_BOX, halfExtents=half_extents, rgbaColor=rgba, physicsClientId=client)
    collision = NO_SHAPE
    if collide:
        collision = pybullet.createCollisionShape(
            pybullet.GEOM_BOX, halfExtents=half_extents, physicsClientId=client)
    return pybullet.createMultiBody(
        baseMass=STATIC_MASS, baseCollisionShapeIndex=collision, baseVisualShapeIndex=shape,
        basePosition=position, useMaximalCoordinates=True, physicsClientId=client)
