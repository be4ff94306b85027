"""URDF text to :class:`~pan_tilt_sim.model.robot.RobotModel`: the one parser. No ROS.

Everything the simulator reads from a URDF is read here, once, with one
error policy: anything malformed that the simulator would use -- a number,
a vector, a joint type, a link a joint names -- ends start-up with a
:class:`~pan_tilt_sim.errors.DescriptionError` naming the file, the element
and the attribute.  Elements the simulator does not use are not checked.

The robot, every spawned object and every world file's object is read here
before PyBullet sees it, and nothing PyBullet crashes on or cannot integrate
gets through (test/dependencies/test_pybullet_limits.py shows what PyBullet
does with each) (see the design notes).

Design notes: docs/design/model.md#urdfpy.
"""

from __future__ import annotations

import math
import pathlib
import xml.etree.ElementTree as ElementTree

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.plugin_elements import read_plugin_elements
from pan_tilt_sim.model.rates import rate_problem
from pan_tilt_sim.model.robot import (
    CONTROLLER_MANAGER_NAME,
    DEFAULT_AXIS,
    INITIAL_VALUE,
    POSITION_PROPORTIONAL_GAIN,
    UNIT_SCALE,
    ControlGpio,
    ControlInterface,
    ControlJoint,
    ControlPlugin,
    ControlSensor,
    ControlSystem,
    Geometry,
    Inertial,
    JointKind,
    JointSpec,
    Link,
    Mimic,
    Rgba,
    RobotModel,
    Shape,
)
from pan_tilt_sim.model.sensors import (
    CHILD,
    CHILD_TO_PARENT,
    PARENT,
    PARENT_TO_CHILD,
    ROS1,
    ROS1_ONLY_PLUGINS,
    ROS2_ONLY_PLUGINS,
    SENSOR,
    SENSOR_TYPES,
    SHARED_PLUGINS,
    CameraSpec,
    ForceTorqueSpec,
    ImuSpec,
    Noise,
    PluginSpec,
    RaySpec,
    ScanAxis,
    SensorKind,
    SensorSpec,
    clip_problem,
    image_size_problem,
    plugin_stem,
    scan_size_problem,
)
from pan_tilt_sim.model.surfaces import read_surfaces
from pan_tilt_sim.model.transforms import ZERO_VECTOR, Transform, Vector, quaternion_from_rpy
from pan_tilt_sim.model.xml_input import float_or_nan, parse_root

URDF_ROOT_TAG = 'robot'
# Gazebo plugins that run the robot's controllers (ROS 1, Gazebo classic ROS 2, gz).
GAZEBO_ROS_CONTROL_PLUGINS = ('libgazebo_ros_control.so', 'libgazebo_ros2_control.so',
                              'gz_ros2_control-system', 'libgz_ros2_control-system.so',
                              'ign_ros2_control-system', 'libign_ros2_control-system.so')
POSITION = 'position'
INERTIA_FIELDS = ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz')
SHAPE_ROLES = ('visual', 'collision')
# PyBullet's name buffers (b3JointInfo, b3BodyInfo) hold 1024 bytes with the NUL.
MAX_NAME_BYTES = 1023
# An axis no longer than this has no direction (SDFormat's zero test, sdf::equal's epsilon).
MIN_AXIS_LENGTH = 1e-6
MAX_MASS = 1e6  # kg: a thousand tonnes
MAX_INERTIA = MAX_MASS * 10.0 ** 2  # kg m^2: that mass 10 m from its centre of mass
SHOWN_NAME_CHARS = 40  # a longer name is shortened in messages
# URDF joint types PyBullet does not simulate as the URDF means them, and why.
UNSIMULATED_KINDS = {
    JointKind.PLANAR: 'PyBullet moves it in three degrees of freedom that no joint state '
                      'reports, and its mass matrix has no planar joints (two prismatic joints '
                      'and a revolute one can stand in for it)',
    JointKind.FLOATING: 'PyBullet would silently make it fixed (declare it fixed if that is '
                        'what it is; a free body is an object of its own)',
}
VISUAL = 'visual'
RGBA_LENGTH = 4


def parse_xml(urdf_xml: str, source: pathlib.Path) -> ElementTree.Element:
    """Parse URDF text, requiring a ``<robot>`` root."""
    root = parse_root(urdf_xml, source)
    if root.tag != URDF_ROOT_TAG:
        raise DescriptionError(
            f'{source}: not a URDF: the root element is <{root.tag}>, expected <{URDF_ROOT_TAG}> '
            '(or an SDF: <sdf>)')
    return root


def read_model(root: ElementTree.Element, source: pathlib.Path) -> RobotModel:
    """Build the robot model from a parsed ``<robot>`` element."""
    reader = _Reader(source)
    name = root.get('name', '')
    _check_name_length(name, f'<robot name="{shown(name)}">', source)
    reader.materials = reader.robot_materials(root)
    links = tuple(reader.link(element) for element in root.findall('link'))
    joints = tuple(reader.joint(element) for element in root.findall('joint'))
    _check_unique('link', [link.name for link in links], source)
    _check_unique('joint', [joint.name for joint in joints], source)
    link_names = {link.name for link in links}
    joint_names = {joint.name for joint in joints}
    for joint in joints:
        for role, link in (('parent', joint.parent), ('child', joint.child)):
            if link not in link_names:
                raise DescriptionError(
                    f"{source}: joint '{joint.name}': {role} link '{link}' is not a link "
                    'of this robot')
        if joint.mimic is not None and joint.mimic.joint not in joint_names:
            raise DescriptionError(
                f"{source}: joint '{joint.name}' mimics '{joint.mimic.joint}', "
                'which is not a joint of this robot')
    _check_tree(links, joints, source)
    _check_mimic_cycles(joints, source)
    plugins = _control_plugins(root)
    for plugin in plugins:
        namespace = plugin.namespace
        if namespace and not naming.is_valid_namespace(naming.normalize(namespace)):
            raise DescriptionError(
                f"{source}: the gazebo_ros_control plugin's namespace '{namespace}' is not a "
                f'valid ROS namespace ({naming.NAMESPACE_RULE})')
    systems = tuple(reader.control_system(element) for element in root.findall('ros2_control'))
    for system in systems:
        for joint in system.joints:
            if joint.name not in joint_names:
                raise DescriptionError(
                    f"{source}: <ros2_control name=\"{system.name}\">: joint '{joint.name}' is "
                    'not a joint of this robot')
    _check_position_gain(plugins, systems, source)
    _check_manager_name(plugins, source)
    _check_component_names(systems, source)
    sensors, sensor_warnings = _SensorReader(source, links, joints).read(root)
    return RobotModel(name=name, links=links, joints=joints,
                      ros2_control=systems, control_plugins=plugins,
                      sensors=sensors, sensor_warnings=sensor_warnings,
                      plugins=read_plugin_elements(root, source),
                      surfaces=read_surfaces(root, source, link_names))


def shown(name: str) -> str:
    """Return ``name`` as messages show it: shortened when it is long."""
    if len(name) <= SHOWN_NAME_CHARS:
        return name
    return name[:SHOWN_NAME_CHARS] + '...'


def inertial_beyond_bounds(inertial: Inertial) -> str:
    """Say what of ``inertial`` lies beyond the parser's bounds ('' if nothing).

    For inertials made after parsing (a physical variation's): PyBullet gets
    nothing the parser would refuse.
    """
    if not 0.0 <= inertial.mass <= MAX_MASS:
        return f'mass {inertial.mass:g} kg is beyond 0 to {MAX_MASS:g} kg'
    for field in INERTIA_FIELDS:
        value = getattr(inertial, field)
        if not abs(value) <= MAX_INERTIA:
            return f'inertia {field} {value:g} kg*m^2 is beyond {MAX_INERTIA:g} in magnitude'
    return ''


def _check_name_length(name: str, owner: str, source: pathlib.Path) -> None:
    """Refuse a name longer than PyBullet's buffers take: MAX_NAME_BYTES bytes in UTF-8."""
    size = len(name.encode('utf-8'))
    if size > MAX_NAME_BYTES:
        raise DescriptionError(
            f'{source}: {owner}: the name is {size} bytes long; PyBullet takes names of at '
            f'most {MAX_NAME_BYTES} bytes (UTF-8)')


def _check_unique(kind: str, names: list[str], source: pathlib.Path) -> None:
    seen: set[str] = set()
    for name in names:
        if name in seen:
            raise DescriptionError(
                f"{source}: {kind} '{name}' is declared twice: {kind} names must be unique")
        seen.add(name)


def _check_mimic_cycles(joints: tuple[JointSpec, ...], source: pathlib.Path) -> None:
    """Refuse ``<mimic>`` joints that follow each other round: no position would satisfy them."""
    leader_of = {joint.name: joint.mimic.joint for joint in joints if joint.mimic is not None}
    cleared: set[str] = set()
    for start in leader_of:
        chain: list[str] = []
        name = start
        while name in leader_of and name not in cleared:
            if name in chain:
                cycle = ' -> '.join((*chain[chain.index(name):], name))
                raise DescriptionError(f'{source}: mimic joints form a cycle: {cycle}')
            chain.append(name)
            name = leader_of[name]
        cleared.update(chain)


def _check_tree(links: tuple[Link, ...], joints: tuple[JointSpec, ...],
                source: pathlib.Path) -> None:
    """Refuse joints that make the links anything but one tree: one root, one parent each.

    urdfdom refuses every other shape; PyBullet crashes on them or silently drops links.
    """
    parent_joint: dict[str, JointSpec] = {}
    for joint in joints:
        if joint.parent == joint.child:
            raise DescriptionError(
                f"{source}: joint '{joint.name}': link '{joint.child}' is both its parent and "
                'its child: a URDF must be a tree')
        other = parent_joint.get(joint.child)
        if other is not None:
            raise DescriptionError(
                f"{source}: link '{joint.child}' is the child of two joints, '{other.name}' and "
                f"'{joint.name}': in a URDF tree each link has one parent")
        parent_joint[joint.child] = joint
    roots = [link.name for link in links if link.name not in parent_joint]
    if len(roots) > 1:
        raise DescriptionError(
            f"{source}: links {', '.join(repr(root) for root in roots)} are each the child of "
            'no joint: a URDF must be one tree with one root link')
    children: dict[str, list[str]] = {}
    for joint in joints:
        children.setdefault(joint.parent, []).append(joint.child)
    reached, pending = set(roots), list(roots)
    while pending:
        for child in children.get(pending.pop(), ()):
            reached.add(child)
            pending.append(child)
    stranded = [link.name for link in links if link.name not in reached]
    if not stranded:
        return
    # Each stranded link has a parent that is stranded too: going up, one comes back.
    path, link = [], stranded[0]
    while link not in path:
        path.append(link)
        link = parent_joint[link].parent
    cycle = list(reversed(path[path.index(link):]))  # parents before children
    names = ', '.join(f"'{parent_joint[child].name}'" for child in [*cycle[1:], cycle[0]])
    route = ' -> '.join([*cycle, cycle[0]])
    raise DescriptionError(
        f'{source}: joints {names} form a cycle ({route}): a URDF must be a tree')


def _check_position_gain(plugins: tuple[ControlPlugin, ...], systems: tuple[ControlSystem, ...],
                         source: pathlib.Path) -> None:
    """``position_proportional_gain``, wherever given, must be a number > 0."""
    places = [(f"the {plugin.filename} plugin's <{POSITION_PROPORTIONAL_GAIN}>",
               plugin.settings.get(POSITION_PROPORTIONAL_GAIN)) for plugin in plugins]
    places += [(f'<ros2_control name="{system.name}">: <hardware> <param '
                f'name="{POSITION_PROPORTIONAL_GAIN}">',
                system.hardware_params.get(POSITION_PROPORTIONAL_GAIN)) for system in systems]
    for place, text in places:
        if text is None:
            continue
        value = float_or_nan(text)
        if not (math.isfinite(value) and value > 0.0):
            raise DescriptionError(f"{source}: {place}: '{text}' must be a number > 0")


def _check_manager_name(plugins: tuple[ControlPlugin, ...], source: pathlib.Path) -> None:
    """``controller_manager_name``, where given, must be a ROS node name."""
    for plugin in plugins:
        name = plugin.settings.get(CONTROLLER_MANAGER_NAME)
        if name is not None and not naming.is_valid_name(name):
            raise DescriptionError(
                f"{source}: the {plugin.filename} plugin's <{CONTROLLER_MANAGER_NAME}>: "
                f"'{name}' is not a valid node name ({naming.NAME_RULE})")


def _check_component_names(systems: tuple[ControlSystem, ...], source: pathlib.Path) -> None:
    """Refuse a sensor or gpio whose name another joint, sensor or gpio of the blocks has.

    Its interfaces are named ``<name>/<interface>``: ros2_control's resource
    manager refuses a second component exporting the same names.
    """
    seen: dict[str, str] = {}
    for system in systems:
        components = [('joint', joint.name) for joint in system.joints]
        components += [('sensor', sensor.name) for sensor in system.sensors]
        components += [('gpio', gpio.name) for gpio in system.gpios]
        for kind, name in components:
            where = f'<{kind} name="{name}"> of <ros2_control name="{system.name}">'
            if name in seen and (kind != 'joint' or not seen[name].startswith('<joint')):
                raise DescriptionError(f'{source}: {where}: the name is already taken by '
                                       f'{seen[name]}')
            seen.setdefault(name, where)


def parse_urdf(urdf_xml: str, source: pathlib.Path) -> RobotModel:
    """Parse URDF text into a robot model (errors name ``source``)."""
    return read_model(parse_xml(urdf_xml, source), source)


class _Reader:
    """Reads elements of one file; every error names the file and the element."""

    def __init__(self, source: pathlib.Path) -> None:
        self.source = source
        self.materials: dict[str, Rgba] = {}  # the robot-level <material>s with a colour

    def error(self, owner: str, problem: str) -> DescriptionError:
        return DescriptionError(f'{self.source}: {owner}: {problem}')

    def robot_materials(self, root: ElementTree.Element) -> dict[str, Rgba]:
        """Return the colour of every named ``<robot><material>`` that has a ``<color>``."""
        found = {}
        for element in root.findall('material'):
            name = element.get('name', '')
            rgba = self.colour(element, f"material '{name}'")
            if name and rgba is not None:
                found[name] = rgba
        return found

    def colour(self, material: ElementTree.Element, owner: str) -> Rgba | None:
        """Return a ``<material>``'s own ``<color rgba>``, or None if it has none."""
        colour = material.find('color')
        if colour is None or colour.get('rgba') is None:
            return None
        text = colour.get('rgba', '')
        try:
            values = tuple(float(value) for value in text.split())
        except ValueError:
            values = ()
        if len(values) != RGBA_LENGTH or not all(0.0 <= value <= 1.0 for value in values):
            raise self.error(owner, f'<color rgba="{text}"> is not four numbers from 0 to 1')
        return values  # type: ignore[return-value]

    def visual_colour(self, element: ElementTree.Element, owner: str) -> Rgba | None:
        """Return a ``<visual>``'s colour: its material's own, else the robot-level one's."""
        material = element.find('material')
        if material is None:
            return None
        own = self.colour(material, owner)
        return own if own is not None else self.materials.get(material.get('name', ''))

    def number(self, element: ElementTree.Element, attribute: str, default: float,
               owner: str) -> float:
        text = element.get(attribute)
        if text is None:
            return default
        value = float_or_nan(text)
        if not math.isfinite(value):
            raise self.error(owner, f'<{element.tag} {attribute}="{text}"> is not a number')
        return value

    def vector(self, element: ElementTree.Element | None, attribute: str, default: Vector,
               owner: str) -> Vector:
        if element is None or element.get(attribute) is None:
            return default
        text = element.get(attribute, '')
        try:
            x, y, z = (float(value) for value in text.split())
        except ValueError:
            raise self.error(
                owner, f'<{element.tag} {attribute}="{text}"> is not three numbers') from None
        if not all(math.isfinite(value) for value in (x, y, z)):
            raise self.error(owner, f'<{element.tag} {attribute}="{text}"> is not finite')
        return (x, y, z)

    def origin(self, element: ElementTree.Element | None, owner: str) -> Transform:
        if element is None:
            return Transform()
        return Transform(self.vector(element, 'xyz', ZERO_VECTOR, owner),
                         quaternion_from_rpy(*self.vector(element, 'rpy', ZERO_VECTOR, owner)))

    def link(self, element: ElementTree.Element) -> Link:
        name = element.get('name')
        if not name:
            raise DescriptionError(f'{self.source}: a <link> has no name')
        _check_name_length(name, f"link '{shown(name)}'", self.source)
        owner = f"link '{name}'"
        inertial = element.find('inertial')
        shapes = {role: tuple(filter(None, (self.shape(child, owner)
                                            for child in element.findall(role))))
                  for role in SHAPE_ROLES}
        return Link(name=name,
                    inertial=None if inertial is None else self.inertial(inertial, owner),
                    visuals=shapes['visual'], collisions=shapes['collision'])

    def inertial(self, element: ElementTree.Element, owner: str) -> Inertial:
        mass_element = element.find('mass')
        inertia = element.find('inertia')
        values = {field: 0.0 if inertia is None else self.number(inertia, field, 0.0, owner)
                  for field in INERTIA_FIELDS}
        mass = 0.0 if mass_element is None else self.number(mass_element, 'value', 0.0, owner)
        if mass_element is not None:
            written = f'<mass value="{mass_element.get("value")}">'
            if mass < 0.0:
                raise self.error(owner, f'{written} must be >= 0 kg (0: a massless link)')
            if mass > MAX_MASS:
                raise self.error(owner, f'{written} is above {MAX_MASS:g} kg, the heaviest link '
                                 'simulated (a unit mistake?)')
        for field, value in values.items():
            if abs(value) > MAX_INERTIA:
                raise self.error(
                    owner, f'<inertia {field}="{inertia.get(field)}"> is beyond '
                    f'{MAX_INERTIA:g} kg*m^2 in magnitude, the largest inertia simulated '
                    '(a unit mistake?)')
        return Inertial(mass=mass, origin=self.origin(element.find('origin'), owner), **values)

    def shape(self, element: ElementTree.Element, owner: str) -> Shape | None:
        geometry = element.find('geometry')
        if geometry is None or not len(geometry):
            return None
        shape = geometry[0]
        origin = self.origin(element.find('origin'), owner)
        rgba = self.visual_colour(element, owner) if element.tag == VISUAL else None
        if shape.tag == 'box':
            return Shape(origin, Geometry('box', size=self.vector(shape, 'size', ZERO_VECTOR,
                                                                   owner)), rgba)
        if shape.tag in ('cylinder', 'sphere', 'capsule'):  # capsule: PyBullet's extension
            return Shape(origin, Geometry(shape.tag,
                                          radius=self.number(shape, 'radius', 0.0, owner),
                                          length=self.number(shape, 'length', 0.0, owner)),
                         rgba)
        if shape.tag == 'mesh':
            return Shape(origin, Geometry('mesh', filename=shape.get('filename', ''),
                                          scale=self.vector(shape, 'scale', UNIT_SCALE, owner)),
                         rgba)
        return Shape(origin, Geometry(shape.tag), rgba)

    def control_system(self, element: ElementTree.Element) -> ControlSystem:
        name = element.get('name', '')
        hardware = element.find('hardware')
        joints = tuple(self.control_joint(joint, name) for joint in element.findall('joint'))
        sensors = tuple(ControlSensor(
            name=self.component_name(child, name),
            state_interfaces=self.interfaces(child, 'state_interface', name),
            params=_params(child)) for child in element.findall('sensor'))
        gpios = tuple(ControlGpio(
            name=self.component_name(child, name),
            command_interfaces=self.interfaces(child, 'command_interface', name),
            state_interfaces=self.interfaces(child, 'state_interface', name),
            params=_params(child)) for child in element.findall('gpio'))
        return ControlSystem(
            name=name, type=element.get('type', 'system'),
            plugin=(hardware.findtext('plugin') or '').strip() if hardware is not None else '',
            hardware_params=_params(hardware) if hardware is not None else {},
            joints=joints, sensors=sensors, gpios=gpios)

    def component_name(self, element: ElementTree.Element, system: str) -> str:
        name = element.get('name', '')
        if not name:
            raise DescriptionError(f'{self.source}: <ros2_control name="{system}">: a '
                                   f'<{element.tag}> has no name')
        return name

    def interfaces(self, element: ElementTree.Element, tag: str,
                   system: str) -> tuple[ControlInterface, ...]:
        """Read a sensor's or gpio's ``<tag>`` children; an initial_value must be a number.

        As ros2_control, which refuses to start a component whose
        ``initial_value`` does not parse as a double.
        """
        found = []
        for child in element.findall(tag):
            interface = ControlInterface(child.get('name', ''), _params(child))
            text = interface.params.get(INITIAL_VALUE)
            if text is not None:
                try:
                    float(text)
                except ValueError:
                    raise DescriptionError(
                        f'{self.source}: <ros2_control name="{system}">: <{element.tag} '
                        f'name="{element.get("name")}">: <{tag} name="{interface.name}">: '
                        f'<param name="{INITIAL_VALUE}">{text}</param> is not a number'
                    ) from None
            found.append(interface)
        return tuple(found)

    def control_joint(self, element: ElementTree.Element, system: str) -> ControlJoint:
        name = element.get('name', '')
        if not name:
            raise DescriptionError(f'{self.source}: <ros2_control name="{system}">: a <joint> '
                                   'has no name')
        commands = tuple(ControlInterface(child.get('name', ''), _params(child))
                         for child in element.findall('command_interface'))
        states = tuple(ControlInterface(child.get('name', ''), _params(child))
                       for child in element.findall('state_interface'))
        initial = None
        for state in states:
            text = state.params.get(INITIAL_VALUE)
            if state.name != POSITION or text is None:
                continue
            initial = float_or_nan(text)
            if not math.isfinite(initial):
                raise DescriptionError(
                    f"{self.source}: <ros2_control name=\"{system}\">: joint '{name}': "
                    f'<param name="{INITIAL_VALUE}">{text}</param> is not a number')
        return ControlJoint(name=name, command_interfaces=commands, state_interfaces=states,
                            params=_params(element), initial_position=initial)

    def joint(self, element: ElementTree.Element) -> JointSpec:
        name = element.get('name')
        if not name:
            raise DescriptionError(f'{self.source}: a <joint> has no name')
        _check_name_length(name, f"joint '{shown(name)}'", self.source)
        owner = f"joint '{name}'"
        type_name = element.get('type', '')
        try:
            kind = JointKind(type_name)
        except ValueError:
            raise DescriptionError(
                f"{self.source}: joint '{name}' has unknown type '{type_name}'") from None
        if kind in UNSIMULATED_KINDS:
            raise self.error(owner, f'type {kind.value} is not simulated: '
                             f'{UNSIMULATED_KINDS[kind]}')
        parent = element.find('parent')
        child = element.find('child')
        if parent is None or child is None or not parent.get('link') or not child.get('link'):
            raise self.error(owner, 'needs <parent link="..."/> and <child link="..."/>')
        fields = {}
        limit = element.find('limit')
        if limit is not None:
            if kind is not JointKind.CONTINUOUS:
                fields['lower'] = self.number(limit, 'lower', 0.0, owner)
                fields['upper'] = self.number(limit, 'upper', 0.0, owner)
            fields['effort_limit'] = _positive_or_inf(self.number(limit, 'effort', 0.0, owner))
            fields['velocity_limit'] = _positive_or_inf(
                self.number(limit, 'velocity', 0.0, owner))
        dynamics = element.find('dynamics')
        if dynamics is not None:
            fields['damping'] = self.number(dynamics, 'damping', 0.0, owner)
            fields['friction'] = self.number(dynamics, 'friction', 0.0, owner)
        mimic = element.find('mimic')
        if mimic is not None:
            fields['mimic'] = Mimic(
                joint=mimic.get('joint', ''),
                multiplier=self.number(mimic, 'multiplier', 1.0, owner),
                offset=self.number(mimic, 'offset', 0.0, owner))
        axis = self.vector(element.find('axis'), 'xyz', DEFAULT_AXIS, owner)
        if kind.is_actuated:
            length = math.hypot(*axis)
            if length <= MIN_AXIS_LENGTH:
                raise self.error(
                    owner, f'<axis xyz="{element.find("axis").get("xyz")}"> has no direction: '
                    f'a {kind.value} joint needs an axis longer than {MIN_AXIS_LENGTH:g}')
            axis = (axis[0] / length, axis[1] / length, axis[2] / length)
        return JointSpec(name=name, kind=kind, parent=parent.get('link', ''),
                         child=child.get('link', ''),
                         origin=self.origin(element.find('origin'), owner), axis=axis,
                         **fields)


def _positive_or_inf(value: float) -> float:
    return value if value > 0.0 else math.inf


def _params(element: ElementTree.Element) -> dict[str, str]:
    """Return the ``<param name="...">value</param>`` children of ``element``."""
    return {param.get('name', ''): (param.text or '').strip()
            for param in element.findall('param')}


def _control_plugins(root: ElementTree.Element) -> tuple[ControlPlugin, ...]:
    plugins = []
    for plugin in root.iterfind('gazebo/plugin'):
        filename = plugin.get('filename', '')
        if filename not in GAZEBO_ROS_CONTROL_PLUGINS:
            continue
        namespace = None
        for path in ('robotNamespace', 'ros/namespace'):
            text = plugin.findtext(path)
            if text and text.strip():
                namespace = text.strip()
                break
        parameters = tuple(text.strip() for text in (
            element.text for element in plugin.findall('parameters')) if text and text.strip())
        settings = {child.tag: (child.text or '').strip() for child in plugin
                    if child.tag != 'parameters' and not len(child)}
        plugins.append(ControlPlugin(filename=filename, name=plugin.get('name', ''),
                                     namespace=namespace, parameters=parameters,
                                     settings=settings))
    return tuple(plugins)


# --- sensors: <gazebo reference="..."><sensor>, and the ft_sensor model plugin -------------

CAMERA_MAX_FOV = math.pi  # rad: a pinhole camera sees less than a half-space
FT_FRAMES = (CHILD, PARENT, SENSOR)
FT_DIRECTIONS = (CHILD_TO_PARENT, PARENT_TO_CHILD)
NOISE_AXES = ('x', 'y', 'z')
PLUGIN_NUMBERS = ('updateRate', 'updateRateHZ', 'gaussianNoise', 'pointCloudCutoff',
                  'pointCloudCutoffMax', 'min_depth', 'max_depth', 'update_rate',
                  'gaussian_noise')
REMAP_SEPARATOR = ':='
ROS1_REQUIRED = {  # gazebo_plugins (ROS 1) that stop without these elements
    'gazebo_ros_imu_sensor': 'frameName',
    'gazebo_ros_ft_sensor': 'topicName',
}


class _SensorReader:
    """Reads the sensors of one URDF; what it cannot use becomes a warning, not an error.

    Malformed numbers in a sensor the simulator would use end start-up
    (:class:`DescriptionError` naming the sensor and the element); a sensor
    type, plugin or reference the simulator does not support is skipped with
    one warning naming it, as Gazebo skips what it cannot load.
    """

    def __init__(self, source: pathlib.Path, links: tuple[Link, ...],
                 joints: tuple[JointSpec, ...]) -> None:
        self.source = source
        self.links = {link.name for link in links}
        self.joints = {joint.name: joint for joint in joints}
        self.warnings: list[str] = []

    def read(self, root: ElementTree.Element) -> tuple[tuple[SensorSpec, ...], tuple[str, ...]]:
        sensors = []
        for gazebo in root.findall('gazebo'):
            reference = gazebo.get('reference')
            for element in gazebo.findall('sensor'):
                sensor = self.sensor(element, reference)
                if sensor is not None:
                    sensors.append(sensor)
            if reference is None:
                for plugin in gazebo.findall('plugin'):
                    sensor = self.model_plugin(plugin)
                    if sensor is not None:
                        sensors.append(sensor)
        return tuple(sensors), tuple(self.warnings)

    def skip(self, what: str, why: str) -> None:
        self.warnings.append(f'{self.source}: {what} skipped: {why}')

    def error(self, owner: str, problem: str) -> DescriptionError:
        return DescriptionError(f'{self.source}: {owner}: {problem}')

    # --- one <sensor> ------------------------------------------------------------------

    def sensor(self, element: ElementTree.Element, reference: str | None) -> SensorSpec | None:
        name = element.get('name', '')
        sensor_type = element.get('type', '')
        what = f"sensor '{name}' (type '{sensor_type}')"
        owner = f"sensor '{name}'"
        if sensor_type not in SENSOR_TYPES:
            self.skip(what, f"type '{sensor_type}' is not simulated (supported: "
                      f"{', '.join(SENSOR_TYPES)})")
            return None
        kind, colour = SENSOR_TYPES[sensor_type]
        joint = parent_link = ''
        if reference is None:
            self.skip(what, 'its <gazebo> has no reference="..." naming a link')
            return None
        if reference in self.joints and reference not in self.links:
            if kind is not SensorKind.FORCE_TORQUE:
                self.skip(what, f"it references joint '{reference}'; only force_torque "
                          'sensors go on joints')
                return None
            joint = reference
            link = self.joints[reference].child
            parent_link = self.joints[reference].parent
        elif reference in self.links:
            if kind is SensorKind.FORCE_TORQUE:
                self.skip(what, f"a force_torque sensor references a joint, not link "
                          f"'{reference}'")
                return None
            link = reference
        else:
            self.skip(what, f"reference '{reference}' is not a link or joint of this robot")
            return None
        plugin = None
        plugin_elements = element.findall('plugin')
        if plugin_elements:
            plugin = self.plugin(plugin_elements[0], owner)
            problem = self.plugin_problem(plugin, kind, sensor_type)
            if problem:
                self.skip(what, problem)
                return None
        fields: dict = {}
        if kind in (SensorKind.CAMERA, SensorKind.DEPTH):
            fields['camera'] = self.camera(element.find('camera'), owner)
        elif kind is SensorKind.LIDAR:
            ray = element.find('ray')
            fields['ray'] = self.ray(ray if ray is not None else element.find('lidar'), owner)
        elif kind is SensorKind.IMU:
            fields['imu'] = self.imu(element.find('imu'), owner)
        else:
            fields['force_torque'] = self.force_torque(element.find('force_torque'), owner)
        frame_id = ''
        for tag in ('frame_id', 'gz_frame_id', 'ignition_frame_id'):
            text = (element.findtext(tag) or '').strip()
            if text:
                frame_id = text
                break
        return SensorSpec(
            name=name, type=sensor_type, kind=kind, link=link, joint=joint,
            parent_link=parent_link, colour=colour,
            pose=self.pose(element.find('pose'), owner),
            update_rate=self.rate(element, owner),
            topic=(element.findtext('topic') or '').strip(), frame_id=frame_id,
            plugin=plugin, **fields)

    def plugin_problem(self, plugin: PluginSpec, kind: SensorKind, sensor_type: str) -> str:
        stem = plugin.stem
        served = (ROS1_ONLY_PLUGINS.get(stem), ROS2_ONLY_PLUGINS.get(stem),
                  *SHARED_PLUGINS.get(stem, ()))
        if kind not in served:
            return (f"plugin '{plugin.filename}' is not simulated for a {sensor_type} sensor")
        if plugin.generation == ROS1:
            required = ROS1_REQUIRED.get(stem)
            if required and plugin.get(required) is None:
                return f"ROS 1 plugin '{plugin.filename}' needs <{required}> (Gazebo stops it)"
        elif stem == 'gazebo_ros_ray_sensor':
            output = plugin.get('output_type', 'sensor_msgs/PointCloud2')
            if output not in ('sensor_msgs/LaserScan', 'sensor_msgs/PointCloud2'):
                return f'<output_type>{output}</output_type> is not simulated (LaserScan, ' \
                    'PointCloud2 are)'
        return ''

    def model_plugin(self, element: ElementTree.Element) -> SensorSpec | None:
        """Read a ``<gazebo><plugin>`` that is a sensor: gazebo_ros_ft_sensor on a joint."""
        stem = plugin_stem(element.get('filename', ''))
        if stem == 'gazebo_ros_imu':
            self.skip(f"plugin '{element.get('filename')}'",
                      'the ROS 1 model-plugin IMU is not simulated; declare <sensor type="imu"> '
                      'with libgazebo_ros_imu_sensor.so')
            return None
        if stem != 'gazebo_ros_ft_sensor':
            return None
        name = element.get('name', stem)
        owner = f"plugin '{name}'"
        plugin = self.plugin(element, owner)
        what = f"force-torque plugin '{name}'"
        joint = plugin.get('jointName') if plugin.generation == ROS1 else plugin.get('joint_name')
        if not joint:
            self.skip(what, 'it names no joint (<jointName> / <joint_name>; <body_name> is not '
                      'simulated)')
            return None
        if joint not in self.joints:
            self.skip(what, f"joint '{joint}' is not a joint of this robot")
            return None
        problem = self.plugin_problem(plugin, SensorKind.FORCE_TORQUE, 'force_torque')
        if problem:
            self.skip(what, problem)
            return None
        return SensorSpec(name=name, type='force_torque', kind=SensorKind.FORCE_TORQUE,
                          link=self.joints[joint].child, joint=joint,
                          parent_link=self.joints[joint].parent, plugin=plugin,
                          force_torque=ForceTorqueSpec(), model_plugin=True)

    def plugin(self, element: ElementTree.Element, owner: str) -> PluginSpec:
        params = {child.tag: (child.text or '').strip() for child in element
                  if child.tag != 'ros'}
        for key in PLUGIN_NUMBERS:
            text = params.get(key)
            if text:
                self.float_text(text, f'{owner}: plugin <{key}>')
        namespace = None
        remappings = []
        ros = element.find('ros')
        if ros is not None:
            text = ros.findtext('namespace')
            if text is not None:
                namespace = text.strip()
            rules = [(child.text or '').strip() for child in ros.findall('remapping')]
            for argument in ros.findall('argument'):
                words = (argument.text or '').split()
                rules += [word for word in words if REMAP_SEPARATOR in word]
            for rule in rules:
                source, separator, target = rule.partition(REMAP_SEPARATOR)
                if not separator or not source.strip() or not target.strip():
                    raise self.error(owner, f"<remapping>{rule}</remapping> is not 'from:=to'")
                remappings.append((source.strip(), target.strip()))
        return PluginSpec(filename=element.get('filename', ''), name=element.get('name', ''),
                          params=params, ros_namespace=namespace,
                          remappings=tuple(remappings))

    # --- values ------------------------------------------------------------------------

    def float_text(self, text: str, owner: str) -> float:
        value = float_or_nan(text)
        if math.isnan(value):
            raise DescriptionError(f'{self.source}: {owner}: "{text}" is not a number')
        return value

    def number(self, element: ElementTree.Element | None, path: str, default: float,
               owner: str) -> float:
        if element is None:
            return default
        text = element.findtext(path)
        if text is None or not text.strip():
            return default
        value = self.float_text(text.strip(), f'{owner}: <{path}>')
        if not math.isfinite(value):
            raise self.error(owner, f'<{path}>{text.strip()}</{path}> is not finite')
        return value

    def integer(self, element: ElementTree.Element | None, path: str, default: int,
                owner: str) -> int:
        value = self.number(element, path, float(default), owner)
        if value != int(value) or value < 1:
            raise self.error(owner, f'<{path}> must be a whole number >= 1, got {value:g}')
        return int(value)

    def rate(self, element: ElementTree.Element, owner: str) -> float:
        rate = self.number(element, 'update_rate', 0.0, owner)
        if rate < 0.0:
            raise self.error(owner, f'<update_rate> must be >= 0 Hz, got {rate:g}')
        problem = rate_problem(rate, zero_allowed=True)
        if problem:
            raise self.error(owner, f'<update_rate> {problem}')
        return rate

    def pose(self, element: ElementTree.Element | None, owner: str) -> Transform:
        if element is None or not (element.text or '').strip():
            return Transform()
        text = element.text.strip()
        try:
            values = [float(value) for value in text.split()]
        except ValueError:
            values = []
        if len(values) != 6 or not all(math.isfinite(value) for value in values):
            raise self.error(owner, f'<pose>{text}</pose> is not six numbers (x y z roll pitch '
                             'yaw)')
        return Transform(tuple(values[:3]), quaternion_from_rpy(*values[3:]))

    def noise(self, element: ElementTree.Element | None, owner: str,
              kind: str | None = None) -> Noise:
        if element is None:
            return Noise()
        noise_type = (kind or element.get('type') or element.findtext('type') or '').strip()
        if noise_type == 'none' or not noise_type:
            return Noise()
        if not noise_type.startswith('gaussian'):
            raise self.error(owner, f"noise type '{noise_type}' is not gaussian or none")
        values = {field: self.number(element, field, 0.0, owner)
                  for field in ('mean', 'stddev', 'bias_mean', 'bias_stddev')}
        for field in ('stddev', 'bias_stddev'):
            if values[field] < 0.0:
                raise self.error(owner, f'<noise><{field}> must be >= 0, got {values[field]:g}')
        return Noise(**values)

    def axes_noise(self, element: ElementTree.Element | None, owner: str
                   ) -> tuple[Noise, Noise, Noise]:
        if element is None:
            return (Noise(), Noise(), Noise())
        return tuple(self.noise(element.find(f'{axis}/noise'), owner)  # type: ignore[return-value]
                     for axis in NOISE_AXES)

    def camera(self, element: ElementTree.Element | None, owner: str) -> CameraSpec:
        if element is None:
            return CameraSpec()
        default = CameraSpec()
        fov = self.number(element, 'horizontal_fov', default.horizontal_fov, owner)
        if not 0.0 < fov < CAMERA_MAX_FOV:
            raise self.error(owner, f'<horizontal_fov> must be > 0 and < pi rad, got {fov:g}')
        near = self.number(element, 'clip/near', default.near, owner)
        far = self.number(element, 'clip/far', default.far, owner)
        if not 0.0 < near < far:
            raise self.error(owner, f'<clip> needs 0 < near < far, got near {near:g}, '
                             f'far {far:g}')
        depth_near = self.number(element, 'depth_camera/clip/near', 0.0, owner) or None
        depth_far = self.number(element, 'depth_camera/clip/far', 0.0, owner) or None
        camera = CameraSpec(
            width=self.integer(element, 'image/width', default.width, owner),
            height=self.integer(element, 'image/height', default.height, owner),
            horizontal_fov=fov, near=near, far=far,
            format=(element.findtext('image/format') or default.format).strip(),
            noise=self.noise(element.find('noise'), owner),
            depth_near=depth_near, depth_far=depth_far)
        problem = image_size_problem(camera) or clip_problem(camera)
        if problem:
            raise self.error(owner, problem)
        return camera

    def scan_axis(self, element: ElementTree.Element | None, owner: str,
                  default_samples: int) -> ScanAxis:
        if element is None:
            return ScanAxis()
        axis = ScanAxis(
            samples=self.integer(element, 'samples', default_samples, owner),
            resolution=self.number(element, 'resolution', 1.0, owner),
            min_angle=self.number(element, 'min_angle', 0.0, owner),
            max_angle=self.number(element, 'max_angle', 0.0, owner))
        if axis.resolution <= 0.0:
            raise self.error(owner, f'<{element.tag}><resolution> must be > 0, got '
                             f'{axis.resolution:g}')
        return axis

    def ray(self, element: ElementTree.Element | None, owner: str) -> RaySpec:
        if element is None:
            raise self.error(owner, 'a ray/lidar sensor needs <ray> (or <lidar>) with <scan> '
                             'and <range>')
        scan = element.find('scan')
        horizontal = self.scan_axis(None if scan is None else scan.find('horizontal'), owner,
                                    640)
        vertical = self.scan_axis(None if scan is None else scan.find('vertical'), owner, 1)
        range_min = self.number(element, 'range/min', 0.0, owner)
        range_max = self.number(element, 'range/max', 0.0, owner)
        if not 0.0 <= range_min < range_max:
            raise self.error(owner, f'<range> needs 0 <= min < max, got min {range_min:g}, '
                             f'max {range_max:g}')
        ray = RaySpec(horizontal=horizontal, vertical=vertical, range_min=range_min,
                      range_max=range_max,
                      range_resolution=self.number(element, 'range/resolution', 0.0, owner),
                      noise=self.noise(element.find('noise'), owner))
        problem = scan_size_problem(ray)
        if problem:
            raise self.error(owner, problem)
        return ray

    def imu(self, element: ElementTree.Element | None, owner: str) -> ImuSpec:
        if element is None:
            return ImuSpec()
        angular = self.axes_noise(element.find('angular_velocity'), owner)
        linear = self.axes_noise(element.find('linear_acceleration'), owner)
        old = element.find('noise')  # SDF 1.4: one <noise> with <rate> and <accel>
        if old is not None:
            kind = (old.get('type') or old.findtext('type') or '').strip()
            rate = self.noise(old.find('rate'), owner, kind)
            accel = self.noise(old.find('accel'), owner, kind)
            angular, linear = (rate, rate, rate), (accel, accel, accel)
        return ImuSpec(angular_velocity_noise=angular, linear_acceleration_noise=linear)

    def force_torque(self, element: ElementTree.Element | None, owner: str) -> ForceTorqueSpec:
        if element is None:
            return ForceTorqueSpec()
        frame = (element.findtext('frame') or CHILD).strip()
        direction = (element.findtext('measure_direction') or CHILD_TO_PARENT).strip()
        if frame not in FT_FRAMES:
            raise self.error(owner, f"<frame>{frame}</frame> is not one of "
                             f"{', '.join(FT_FRAMES)}")
        if direction not in FT_DIRECTIONS:
            raise self.error(owner, f"<measure_direction>{direction}</measure_direction> is "
                             f"not one of {', '.join(FT_DIRECTIONS)}")
        return ForceTorqueSpec(frame=frame, measure_direction=direction,
                               force_noise=self.axes_noise(element.find('force'), owner),
                               torque_noise=self.axes_noise(element.find('torque'), owner))
