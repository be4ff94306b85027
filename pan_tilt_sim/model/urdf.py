"""URDF text to :class:`~pan_tilt_sim.model.robot.RobotModel`: the one parser. No ROS.

Everything the simulator reads from a URDF is read here, once, with one
error policy: anything malformed that the simulator would use -- a number,
a vector, a joint type, a link a joint names -- ends start-up with a
:class:`~pan_tilt_sim.errors.DescriptionError` naming the file, the element
and the attribute.  Elements the simulator does not use are not checked.
"""

from __future__ import annotations

import math
import pathlib
import xml.etree.ElementTree as ElementTree

from pan_tilt_sim.errors import DescriptionError
from pan_tilt_sim.model import naming
from pan_tilt_sim.model.robot import (
    DEFAULT_AXIS,
    ControlInterface,
    ControlJoint,
    ControlPlugin,
    ControlSystem,
    Geometry,
    Inertial,
    JointKind,
    JointSpec,
    Link,
    Mimic,
    RobotModel,
    Shape,
)
from pan_tilt_sim.model.transforms import ZERO_VECTOR, Transform, Vector, quaternion_from_rpy

URDF_ROOT_TAG = 'robot'
# Gazebo plugins that run the robot's controllers (ROS 1, Gazebo classic ROS 2, gz).
GAZEBO_ROS_CONTROL_PLUGINS = ('libgazebo_ros_control.so', 'libgazebo_ros2_control.so',
                              'gz_ros2_control-system', 'libgz_ros2_control-system.so',
                              'ign_ros2_control-system', 'libign_ros2_control-system.so')
INITIAL_VALUE = 'initial_value'
POSITION = 'position'
INERTIA_FIELDS = ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz')
SHAPE_ROLES = ('visual', 'collision')


def parse_xml(urdf_xml: str, source: pathlib.Path) -> ElementTree.Element:
    """Parse URDF text, requiring a ``<robot>`` root."""
    try:
        root = ElementTree.fromstring(urdf_xml)
    except ElementTree.ParseError as err:
        line, _column = err.position
        raise DescriptionError(f'{source}:{line}: not well-formed XML: {err.msg}') from None
    if root.tag != URDF_ROOT_TAG:
        raise DescriptionError(
            f'{source}: not a URDF: the root element is <{root.tag}>, expected <{URDF_ROOT_TAG}>')
    return root


def read_model(root: ElementTree.Element, source: pathlib.Path) -> RobotModel:
    """Build the robot model from a parsed ``<robot>`` element."""
    reader = _Reader(source)
    links = tuple(reader.link(element) for element in root.findall('link'))
    joints = tuple(reader.joint(element) for element in root.findall('joint'))
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
    children = {joint.child for joint in joints}
    roots = [link.name for link in links if link.name not in children]
    if len(roots) > 1:
        # urdfdom refuses such a file; PyBullet crashes on it.
        raise DescriptionError(
            f"{source}: links {', '.join(repr(root) for root in roots)} are each the child of "
            'no joint: a URDF must be one tree with one root link')
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
    return RobotModel(name=root.get('name', ''), links=links, joints=joints,
                      ros2_control=systems, control_plugins=plugins)


def parse_urdf(urdf_xml: str, source: pathlib.Path) -> RobotModel:
    """Parse URDF text into a robot model (errors name ``source``)."""
    return read_model(parse_xml(urdf_xml, source), source)


class _Reader:
    """Reads elements of one file; every error names the file and the element."""

    def __init__(self, source: pathlib.Path) -> None:
        self.source = source

    def error(self, owner: str, problem: str) -> DescriptionError:
        return DescriptionError(f'{self.source}: {owner}: {problem}')

    def number(self, element: ElementTree.Element, attribute: str, default: float,
               owner: str) -> float:
        text = element.get(attribute)
        if text is None:
            return default
        try:
            value = float(text)
        except ValueError:
            value = math.nan
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
        owner = f"link '{name}'"
        inertial = element.find('inertial')
        shapes = {role: tuple(filter(None, (self.shape(child, owner)
                                            for child in element.findall(role))))
                  for role in SHAPE_ROLES}
        return Link(name=name,
                    inertial=None if inertial is None else self.inertial(inertial, owner),
                    visuals=shapes['visual'], collisions=shapes['collision'])

    def inertial(self, element: ElementTree.Element, owner: str) -> Inertial:
        mass = element.find('mass')
        inertia = element.find('inertia')
        values = {field: 0.0 if inertia is None else self.number(inertia, field, 0.0, owner)
                  for field in INERTIA_FIELDS}
        return Inertial(mass=0.0 if mass is None else self.number(mass, 'value', 0.0, owner),
                        origin=self.origin(element.find('origin'), owner), **values)

    def shape(self, element: ElementTree.Element, owner: str) -> Shape | None:
        geometry = element.find('geometry')
        if geometry is None or not len(geometry):
            return None
        shape = geometry[0]
        origin = self.origin(element.find('origin'), owner)
        if shape.tag == 'box':
            return Shape(origin, Geometry('box', size=self.vector(shape, 'size', ZERO_VECTOR,
                                                                   owner)))
        if shape.tag in ('cylinder', 'sphere'):
            return Shape(origin, Geometry(shape.tag,
                                          radius=self.number(shape, 'radius', 0.0, owner),
                                          length=self.number(shape, 'length', 0.0, owner)))
        if shape.tag == 'mesh':
            return Shape(origin, Geometry('mesh', filename=shape.get('filename', '')))
        return Shape(origin, Geometry(shape.tag))

    def control_system(self, element: ElementTree.Element) -> ControlSystem:
        name = element.get('name', '')
        hardware = element.find('hardware')
        joints = tuple(self.control_joint(joint, name) for joint in element.findall('joint'))
        return ControlSystem(
            name=name, type=element.get('type', 'system'),
            plugin=(hardware.findtext('plugin') or '').strip() if hardware is not None else '',
            hardware_params=_params(hardware) if hardware is not None else {},
            joints=joints)

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
            try:
                initial = float(text)
            except ValueError:
                initial = math.nan
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
        owner = f"joint '{name}'"
        type_name = element.get('type', '')
        try:
            kind = JointKind(type_name)
        except ValueError:
            raise DescriptionError(
                f"{self.source}: joint '{name}' has unknown type '{type_name}'") from None
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
        return JointSpec(name=name, kind=kind, parent=parent.get('link', ''),
                         child=child.get('link', ''),
                         origin=self.origin(element.find('origin'), owner),
                         axis=self.vector(element.find('axis'), 'xyz', DEFAULT_AXIS, owner),
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
        plugins.append(ControlPlugin(filename=filename, name=plugin.get('name', ''),
                                     namespace=namespace, parameters=parameters))
    return tuple(plugins)
