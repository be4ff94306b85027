"""The one model of the robot: links, joints, limits, inertials, origins, mimic, plugins.

Parsed once from the URDF (:mod:`pan_tilt_sim.model.urdf`); physics, controllers,
kinematics, camera, TF and the tools all read this model, never the XML.
Plain values, no ROS, no PyBullet.

Kinematics is what robot_state_publisher computes: each joint's transform
from its parent link to its child link is the joint's ``<origin>`` followed
by the joint's motion (a rotation about ``<axis>`` for revolute and
continuous joints, a translation along it for prismatic ones).
"""

from __future__ import annotations

import dataclasses
import enum
import functools
import math
from collections.abc import Mapping

from pan_tilt_sim.model.plugin_elements import PluginElement
from pan_tilt_sim.model.sensors import SensorSpec
from pan_tilt_sim.model.surfaces import Surface
from pan_tilt_sim.model.transforms import (
    Transform,
    Vector,
    quaternion_from_axis_angle,
    rotation_matrix,
)
from pan_tilt_sim.model.xml_input import float_or_nan

DEFAULT_AXIS: Vector = (1.0, 0.0, 0.0)  # URDF's default joint axis
WORLD_LINK = 'world'  # a root link of this name, joined by a fixed joint, welds the robot
UNIT_SCALE: Vector = (1.0, 1.0, 1.0)  # a <mesh> without a scale attribute
Rgba = tuple[float, float, float, float]  # red, green, blue, alpha, each 0..1
POSITION_PROPORTIONAL_GAIN = 'position_proportional_gain'
# gz_ros2_control's element naming its controller manager node, and the name without it.
CONTROLLER_MANAGER_NAME = 'controller_manager_name'
DEFAULT_CONTROLLER_MANAGER = 'controller_manager'
INITIAL_VALUE = 'initial_value'  # the <param> of a ros2_control interface that sets its start
# How far above the robot's lowest point a wheel's lowest point may be and still touch (m).
WHEEL_CONTACT_TOLERANCE = 1e-3


class JointKind(enum.Enum):
    """URDF joint types the simulator distinguishes."""

    REVOLUTE = 'revolute'
    CONTINUOUS = 'continuous'
    PRISMATIC = 'prismatic'
    FIXED = 'fixed'
    FLOATING = 'floating'
    PLANAR = 'planar'
    # PyBullet's three-degree-of-freedom ball joint (SDF's ``ball``; no URDF type of
    # urdfdom's): it turns freely, no controller drives it and no joint state reports it.
    SPHERICAL = 'spherical'

    @property
    def is_actuated(self) -> bool:
        """Whether a one-degree-of-freedom motor can drive this kind of joint."""
        return self in (JointKind.REVOLUTE, JointKind.CONTINUOUS, JointKind.PRISMATIC)

    @property
    def rotates(self) -> bool:
        """Whether the joint's position is an angle about its axis."""
        return self in (JointKind.REVOLUTE, JointKind.CONTINUOUS)


@dataclasses.dataclass(frozen=True)
class Mimic:
    """A ``<mimic>`` element: position = multiplier * leader + offset."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclasses.dataclass(frozen=True)
class Inertial:
    """A link's ``<inertial>``: mass (kg), centre of mass frame, inertia tensor (kg m^2)."""

    mass: float = 0.0
    origin: Transform = Transform()
    ixx: float = 0.0
    ixy: float = 0.0
    ixz: float = 0.0
    iyy: float = 0.0
    iyz: float = 0.0
    izz: float = 0.0


@dataclasses.dataclass(frozen=True)
class Geometry:
    """A ``<geometry>``: box (``size``), cylinder or capsule (``radius``, ``length``), sphere, mesh.

    A mesh keeps its ``filename`` as written (``package://...``) and its
    ``scale`` (per axis, applied to the file's own units).
    """

    kind: str
    size: Vector = (0.0, 0.0, 0.0)
    radius: float = 0.0
    length: float = 0.0
    filename: str = ''
    scale: Vector = UNIT_SCALE

    def half_extents(self) -> Vector | None:
        """Half-size of the shape's bounding box in its own frame; None for meshes."""
        if self.kind == 'box':
            sx, sy, sz = self.size
            return (sx / 2.0, sy / 2.0, sz / 2.0)
        if self.kind == 'cylinder':
            return (self.radius, self.radius, self.length / 2.0)
        if self.kind == 'sphere':
            return (self.radius, self.radius, self.radius)
        if self.kind == 'capsule':  # a cylinder of ``length`` with hemispheres on its ends
            return (self.radius, self.radius, self.length / 2.0 + self.radius)
        return None


@dataclasses.dataclass(frozen=True)
class Shape:
    """A ``<visual>`` or ``<collision>``: geometry placed by ``origin`` in the link frame.

    ``rgba`` is a visual's ``<material>`` colour: its own ``<color>``, else
    that of the robot-level ``<material>`` of the same name; None when the
    description gives it none (a collision never has one).
    """

    origin: Transform
    geometry: Geometry
    rgba: Rgba | None = None


@dataclasses.dataclass(frozen=True)
class Link:
    """A ``<link>``; ``inertial`` is None when the URDF gives none (a massless frame)."""

    name: str
    inertial: Inertial | None = None
    visuals: tuple[Shape, ...] = ()
    collisions: tuple[Shape, ...] = ()

    def reach(self) -> float:
        """How far the link's visual geometry reaches along the link's +z (0 if none).

        Boxes, cylinders and spheres count (a cylinder as its bounding box);
        meshes, whose size is not known here, are ignored.
        """
        reach = 0.0
        for visual in self.visuals:
            half = visual.geometry.half_extents()
            if half is None:
                continue
            # Half-extent of the rotated box along the link's z: |R[2,:]| . half.
            row = rotation_matrix(visual.origin.rotation)[2]
            extent = sum(abs(r) * h for r, h in zip(row, half, strict=True))
            reach = max(reach, visual.origin.translation[2] + extent)
        return reach


@dataclasses.dataclass(frozen=True)
class JointSpec:
    """What the URDF says about one joint.

    Limits that the URDF does not give are infinite.  A non-positive effort or
    velocity limit is taken as "no limit", since a zero limit would make the
    joint impossible to move and is almost always a placeholder.
    """

    name: str
    kind: JointKind
    lower: float = -math.inf
    upper: float = math.inf
    effort_limit: float = math.inf
    velocity_limit: float = math.inf
    damping: float = 0.0
    friction: float = 0.0
    mimic: Mimic | None = None
    parent: str = ''
    child: str = ''
    origin: Transform = Transform()
    axis: Vector = DEFAULT_AXIS

    @property
    def has_position_limits(self) -> bool:
        """Whether the position is bounded (not for continuous joints)."""
        return self.kind is not JointKind.CONTINUOUS and self.lower <= self.upper and (
            math.isfinite(self.lower) or math.isfinite(self.upper))

    def clamp_position(self, position: float) -> float:
        """Return ``position`` clamped into the joint's position limits."""
        if not self.has_position_limits:
            return position
        return min(max(position, self.lower), self.upper)

    @property
    def initial_position(self) -> float:
        """Zero, or the nearest limit when zero lies outside the limits."""
        return self.clamp_position(0.0)

    @property
    def moves(self) -> bool:
        """Whether the joint's transform follows a joint position (else it is constant)."""
        return self.kind.is_actuated

    def transform(self, position: float = 0.0) -> Transform:
        """Return the parent-to-child transform at joint ``position`` (rad or m)."""
        if self.kind.rotates:
            return self.origin.then(
                Transform(rotation=quaternion_from_axis_angle(self.axis, position)))
        if self.kind is JointKind.PRISMATIC:
            ax, ay, az = self.axis
            return self.origin.then(Transform(translation=(ax * position, ay * position,
                                                           az * position)))
        return self.origin


@dataclasses.dataclass(frozen=True)
class ControlInterface:
    """A ``<command_interface>`` or ``<state_interface>`` of a joint, sensor or gpio."""

    name: str
    params: Mapping[str, str] = dataclasses.field(default_factory=dict)

    @property
    def initial_value(self) -> float:
        """The value the interface holds until something writes it: ``initial_value``, else NaN.

        A ros2_control interface starts so (hardware_interface's handles).  A
        text that is not a number gives NaN too (an interface of another data
        type, ``data_type="bool"``, holds no number).
        """
        return float_or_nan(self.params.get(INITIAL_VALUE, 'nan'))


@dataclasses.dataclass(frozen=True)
class ControlJoint:
    """A ``<joint>`` of a ``<ros2_control>`` block: its interfaces and parameters."""

    name: str
    command_interfaces: tuple[ControlInterface, ...] = ()
    state_interfaces: tuple[ControlInterface, ...] = ()
    params: Mapping[str, str] = dataclasses.field(default_factory=dict)
    initial_position: float | None = None  # the position state interface's initial_value

    @property
    def command_interface_names(self) -> tuple[str, ...]:
        """Names of the command interfaces, in file order.

        Any name ros2_control allows (``acceleration``, ``pid_gain``...): what
        the simulator can drive is decided when a controller claims one.
        """
        return tuple(interface.name for interface in self.command_interfaces)

    @property
    def state_interface_names(self) -> tuple[str, ...]:
        """Names of the state interfaces, in file order."""
        return tuple(interface.name for interface in self.state_interfaces)


@dataclasses.dataclass(frozen=True)
class ControlSensor:
    """A ``<sensor>`` of a ``<ros2_control>`` block: its state interfaces and parameters.

    Its state interfaces are ``<name>/<interface>`` (``tcp_fts_sensor/force.x``).
    """

    name: str
    state_interfaces: tuple[ControlInterface, ...] = ()
    params: Mapping[str, str] = dataclasses.field(default_factory=dict)

    @property
    def state_interface_names(self) -> tuple[str, ...]:
        """Names of the state interfaces, in file order."""
        return tuple(interface.name for interface in self.state_interfaces)


@dataclasses.dataclass(frozen=True)
class ControlGpio:
    """A ``<gpio>`` of a ``<ros2_control>`` block: I/O ports that belong to no joint or sensor."""

    name: str
    command_interfaces: tuple[ControlInterface, ...] = ()
    state_interfaces: tuple[ControlInterface, ...] = ()
    params: Mapping[str, str] = dataclasses.field(default_factory=dict)

    @property
    def command_interface_names(self) -> tuple[str, ...]:
        """Names of the command interfaces, in file order."""
        return tuple(interface.name for interface in self.command_interfaces)

    @property
    def state_interface_names(self) -> tuple[str, ...]:
        """Names of the state interfaces, in file order."""
        return tuple(interface.name for interface in self.state_interfaces)


@dataclasses.dataclass(frozen=True)
class ControlSystem:
    """A ``<ros2_control>`` block: its hardware plugin and parameters, joints, sensors, gpios."""

    name: str
    type: str = 'system'
    plugin: str = ''
    hardware_params: Mapping[str, str] = dataclasses.field(default_factory=dict)
    joints: tuple[ControlJoint, ...] = ()
    sensors: tuple[ControlSensor, ...] = ()
    gpios: tuple[ControlGpio, ...] = ()


@dataclasses.dataclass(frozen=True)
class ControlPlugin:
    """A Gazebo plugin that runs the robot's controllers, as the URDF's ``<gazebo>`` names it.

    gazebo_ros_control (ROS 1: ``robotNamespace``), gazebo_ros2_control and
    gz_ros2_control (``<ros><namespace>``, ``<parameters>`` controller files).
    """

    filename: str
    name: str = ''
    namespace: str | None = None
    parameters: tuple[str, ...] = ()  # controller YAML files, as written (after xacro)
    # The plugin's other one-value settings (hold_joints, position_proportional_gain...).
    settings: Mapping[str, str] = dataclasses.field(default_factory=dict)


@dataclasses.dataclass(frozen=True)
class RobotModel:
    """A robot as its URDF describes it (after xacro)."""

    name: str
    links: tuple[Link, ...]
    joints: tuple[JointSpec, ...]
    ros2_control: tuple[ControlSystem, ...] = ()
    control_plugins: tuple[ControlPlugin, ...] = ()
    # <gazebo reference="..."><sensor> tags the simulator models, and one line
    # per sensor tag it skipped (unsupported type, plugin or reference).
    sensors: tuple[SensorSpec, ...] = ()
    sensor_warnings: tuple[str, ...] = ()
    # Contact surfaces from <gazebo reference="LINK"> (mu1, mu2, kp, kd), for links that give any.
    surfaces: tuple[Surface, ...] = ()
    # The model-level <gazebo><plugin> elements (diff drive, p3d, ...), as data: what each
    # plugin reads of them is its own (pan_tilt_sim.plugins).
    plugins: tuple[PluginElement, ...] = ()

    @property
    def link_frictions(self) -> dict[str, Surface]:
        """The surfaces the URDF gives, by link (a link without surface tags is absent)."""
        return {surface.link: surface for surface in self.surfaces}

    def surface(self, link: str) -> Surface:
        """Return ``link``'s contact surface: the URDF's, else a ball caster's, else Gazebo's.

        A link that stands for a ball caster (:meth:`is_ball_caster`) and whose
        URDF gives no surface rolls freely: friction 0, so that it carries
        weight without dragging, as the ball it models does.
        """
        given = next((surface for surface in self.surfaces if surface.link == link), None)
        if given is not None:
            return given
        if self.is_ball_caster(link):
            return Surface(link, mu1=0.0, mu2=0.0)
        return Surface(link)

    def is_ball_caster(self, link: str) -> bool:
        """Whether ``link`` models a ball caster: named ``*caster*``, fixed, its collisions spheres.

        Robots meant for mock hardware (ros2_control_demos' DiffBot) model
        their free-rolling ball casters as spheres fixed to the base; with a
        sliding contact of Gazebo's default friction such a sphere brakes the
        robot, which its real ball would not.
        """
        if 'caster' not in link.lower():
            return False
        found = self._links_by_name.get(link)
        shapes = found.collisions if found is not None else ()
        fixed = any(joint.child == link for joint in self.fixed_joints)
        return fixed and bool(shapes) and all(
            shape.geometry.kind == 'sphere' for shape in shapes)

    @property
    def welded_to_world(self) -> bool:
        """Whether the root link is ``world``, a fixed joint hanging the robot on it (a weld)."""
        return self.root == WORLD_LINK and any(
            joint.parent == WORLD_LINK and joint.kind is JointKind.FIXED for joint in self.joints)

    @functools.cached_property
    def ground_wheels(self) -> tuple[str, ...]:
        """The continuous joints whose wheels are the robot's lowest points, at zero positions.

        A wheel is a cylinder or sphere collision of a continuous joint's child
        link; it touches the ground when its lowest point lies within
        ``WHEEL_CONTACT_TOLERANCE`` (m) of the lowest point of every box,
        cylinder and sphere collision of the robot (meshes, whose size is not
        known here, do not count).  A robot that stands on such wheels is one
        that drives, whichever controller will turn them.
        """
        poses = self.link_poses({})
        lowest: dict[str, float] = {}
        for link in self.links:
            if link.name not in poses:
                continue
            heights = [_lowest_point(poses[link.name].then(shape.origin), shape.geometry)
                       for shape in link.collisions]
            heights = [height for height in heights if height is not None]
            if heights:
                lowest[link.name] = min(heights)
        if not lowest:
            return ()
        ground = min(lowest.values())
        parents = {joint.child: joint for joint in self.joints}
        wheels = []
        for link in self.links:
            joint = parents.get(link.name)
            if (joint is None or joint.kind is not JointKind.CONTINUOUS
                    or lowest.get(link.name, math.inf) > ground + WHEEL_CONTACT_TOLERANCE):
                continue
            if any(shape.geometry.kind in ('cylinder', 'sphere') for shape in link.collisions):
                wheels.append(joint.name)
        return tuple(wheels)

    @property
    def plugin_namespace(self) -> str | None:
        """The namespace the first control plugin gives the robot's topics, if any."""
        return next((plugin.namespace for plugin in self.control_plugins if plugin.namespace),
                    None)

    @property
    def controller_manager_name(self) -> str:
        """The controller manager's node name: the control plugin's ``<controller_manager_name>``.

        As gz_ros2_control names it (``controller_manager`` when no plugin sets
        it); the parser checks that it is a valid node name.
        """
        return next((plugin.settings[CONTROLLER_MANAGER_NAME] for plugin in self.control_plugins
                     if plugin.settings.get(CONTROLLER_MANAGER_NAME)), DEFAULT_CONTROLLER_MANAGER)

    @property
    def position_proportional_gain(self) -> float | None:
        """gz_ros2_control's ``position_proportional_gain``, if the URDF sets it.

        gz_ros2_control turns a position command into a joint velocity
        command of ``gain * update_rate * (command - position)``; the gain is
        read from the plugin's ``<position_proportional_gain>`` element, else
        from a ``<param name="position_proportional_gain">`` of a
        ``<ros2_control>`` block's ``<hardware>``.  The parser checks that it
        is a number > 0.
        """
        texts = [plugin.settings.get(POSITION_PROPORTIONAL_GAIN)
                 for plugin in self.control_plugins]
        texts += [system.hardware_params.get(POSITION_PROPORTIONAL_GAIN)
                  for system in self.ros2_control]
        text = next((text for text in texts if text is not None), None)
        return None if text is None else float(text)

    def control_joint(self, name: str) -> ControlJoint | None:
        """Return the ``<ros2_control>`` entry of joint ``name``, or None if it has none."""
        return next((joint for system in self.ros2_control for joint in system.joints
                     if joint.name == name), None)

    @property
    def control_sensors(self) -> tuple[ControlSensor, ...]:
        """Every ``<sensor>`` of the ``<ros2_control>`` blocks, in file order."""
        return tuple(sensor for system in self.ros2_control for sensor in system.sensors)

    @property
    def control_gpios(self) -> tuple[ControlGpio, ...]:
        """Every ``<gpio>`` of the ``<ros2_control>`` blocks, in file order."""
        return tuple(gpio for system in self.ros2_control for gpio in system.gpios)

    def parent_joint(self, link: str) -> JointSpec | None:
        """Return the joint whose child is ``link`` (None for the root link)."""
        return next((joint for joint in self.joints if joint.child == link), None)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Names of all joints, in file order."""
        return tuple(joint.name for joint in self.joints)

    @property
    def link_names(self) -> tuple[str, ...]:
        """Names of all links, in file order."""
        return tuple(link.name for link in self.links)

    @property
    def actuated_joints(self) -> tuple[JointSpec, ...]:
        """Joints a one-degree-of-freedom controller can drive (non-fixed), in file order."""
        return tuple(joint for joint in self.joints if joint.kind.is_actuated)

    def joint(self, name: str) -> JointSpec:
        """Return the joint called ``name``; KeyError if there is none."""
        return self._joints_by_name[name]

    def link(self, name: str) -> Link:
        """Return the link called ``name``; KeyError if there is none."""
        return self._links_by_name[name]

    @functools.cached_property
    def _joints_by_name(self) -> dict[str, JointSpec]:
        return {joint.name: joint for joint in self.joints}

    @functools.cached_property
    def _links_by_name(self) -> dict[str, Link]:
        return {link.name: link for link in self.links}

    @functools.cached_property
    def root(self) -> str:
        """The root link: the first link that is no joint's child."""
        children = {joint.child for joint in self.joints}
        roots = [link.name for link in self.links if link.name not in children]
        return (roots or [link.name for link in self.links] or [''])[0]

    @functools.cached_property
    def tree_joints(self) -> tuple[JointSpec, ...]:
        """The joints reachable from the root, parents before children."""
        children: dict[str, list[JointSpec]] = {}
        for joint in self.joints:
            children.setdefault(joint.parent, []).append(joint)
        ordered = []
        pending = [self.root]
        while pending:
            link = pending.pop(0)
            for joint in children.get(link, ()):
                ordered.append(joint)
                pending.append(joint.child)
        return tuple(ordered)

    @property
    def fixed_joints(self) -> tuple[JointSpec, ...]:
        """Joints of the tree whose transform is constant (for /tf_static)."""
        return tuple(joint for joint in self.tree_joints if not joint.moves)

    @property
    def moving_joints(self) -> tuple[JointSpec, ...]:
        """Joints of the tree whose transform follows a joint position (for /tf)."""
        return tuple(joint for joint in self.tree_joints if joint.moves)

    @functools.cached_property
    def mimics(self) -> dict[str, Mimic]:
        """The ``<mimic>`` of every joint that has one, by joint name."""
        return {joint.name: joint.mimic for joint in self.joints if joint.mimic is not None}

    def joint_position(self, positions: Mapping[str, float], joint: str) -> float:
        """Return ``joint``'s position: from ``positions``, else by its mimic, else 0."""
        if joint in positions:
            return positions[joint]
        mimic = self.mimics.get(joint)
        if mimic is None:
            return 0.0
        return mimic.multiplier * self.joint_position(positions, mimic.joint) + mimic.offset

    def link_poses(self, positions: Mapping[str, float]) -> dict[str, Transform]:
        """Return every link's pose in the root link's frame at joint ``positions``.

        Joints missing from ``positions`` follow their mimic, else stand at 0.
        """
        poses = {self.root: Transform()}
        for joint in self.tree_joints:  # parents come first
            poses[joint.child] = poses[joint.parent].then(
                joint.transform(self.joint_position(positions, joint.name)))
        return poses


def _lowest_point(pose: Transform, geometry: Geometry) -> float | None:
    """Height of a shape's lowest point in the frame ``pose`` is given in; None for a mesh."""
    height = pose.translation[2]
    row = rotation_matrix(pose.rotation)[2]  # the z components of the shape's own axes
    if geometry.kind == 'sphere':
        return height - geometry.radius
    if geometry.kind == 'cylinder':  # its axis along the shape's z
        axis_z = abs(row[2])
        return height - (geometry.length / 2.0 * axis_z
                         + geometry.radius * math.sqrt(max(0.0, 1.0 - axis_z * axis_z)))
    half = geometry.half_extents()
    if half is None:
        return None
    return height - sum(abs(r) * h for r, h in zip(row, half, strict=True))
