"""Hypothesis strategies for what a user hands sim_node: controller parameters, tags, requests.

* :func:`controller_inputs` -- one controller of any registered type, its
  parameters drawn from the type's own :class:`ParameterSpec`: the spec's
  examples (a valid start), then a few entries given hostile values of
  their declared type (zero, negative, NaN, infinite, huge, empty, names
  with spaces or '..'), of the wrong type, or left out.  Nothing here names
  a type or a parameter: a new controller type is fuzzed as it registers.
* :func:`plugin_and_sensor_inputs` -- a rover whose Gazebo drive plugin
  (gazebo_ros, gz-sim, planar move) and lidar and camera tags carry hostile
  wheels, geometry, frames, sizes and angles.
* :func:`requests` -- the run-time requests sent once it runs: numbers for
  every command (the worker shapes them into each controller's command
  kind) and a gripper goal.

Each draw is a JSON-able request for test/sim/input_worker.py.  The robot
(:data:`ROBOT_URDF`) has the joints, sensor and gpio the specs' examples
name: four continuous wheels ``joint1`` to ``joint4`` on a free base with
position, velocity and effort interfaces, ``sensor1`` with every sensor
interface the broadcasters read, and ``gpio1`` with ``output1``.
"""

from __future__ import annotations

import math
from typing import Any

import yaml
from hypothesis import strategies as st

from pan_tilt_sim.controllers.framework.hardware_interfaces import (
    EXAMPLE_GPIO,
    EXAMPLE_SENSOR,
    EXAMPLE_SENSOR_INTERFACES,
)
from pan_tilt_sim.controllers.framework.parameter_spec import (
    BOOL,
    DOUBLE,
    INT,
    STRING,
    Param,
    ParameterSpec,
)
from pan_tilt_sim.controllers.framework.registry import CONTROLLER_TYPES

JOINTS = ('joint1', 'joint2', 'joint3', 'joint4')
NAME = 'under_test'
MAX_FUZZED = 4  # entries of one spec given hostile values per example
HOSTILE_DOUBLES = (0.0, -0.0, -1.0, 1.0, 0.5, 2.0, 1e-300, -1e-300, 1e300, -1e300, 5e-324,
                   math.nan, math.inf, -math.inf, 2.0 * math.pi + 1e-9, 100.0, -100.0)
HOSTILE_INTS = (0, -1, 1, 2, 3, 10, -5, 2 ** 31, 2 ** 63, -(2 ** 63))
HOSTILE_STRINGS = ('', ' ', 'a b', '/', '//', '..', 'a b/..//', 'odom', 'base_link', '/odom',
                   'joint1', 'joint2', 'joint5', 'sensor1', 'gpio1', 'position', 'velocity',
                   'effort', 'nonexistent_iface', 'x' * 300, 'é日', '~', 'ns/frame/')
WRONG_TYPES = ('text', [], {}, True, None, [1.0, 'a'])


def _interfaces(*names: str, command: bool = False) -> str:
    kind = 'command_interface' if command else 'state_interface'
    return ''.join(f'<{kind} name="{name}"/>' for name in names)


def _wheel(index: int) -> str:
    x, y = ((0.15, 0.15), (0.15, -0.15), (-0.15, -0.15), (-0.15, 0.15))[index]
    return f'''
  <joint name="joint{index + 1}" type="continuous">
    <parent link="base_link"/><child link="wheel{index + 1}"/>
    <origin xyz="{x} {y} -0.02"/><axis xyz="0 1 0"/><limit effort="20" velocity="30"/>
  </joint>
  <link name="wheel{index + 1}">
    <inertial><mass value="0.3"/>
      <inertia ixx="0.0002" ixy="0" ixz="0" iyy="0.0004" iyz="0" izz="0.0002"/></inertial>
    <collision><origin rpy="1.5707963267948966 0 0"/>
      <geometry><cylinder radius="0.05" length="0.03"/></geometry></collision>
  </link>'''


ROBOT_URDF_HEAD = '''<?xml version="1.0"?>
<robot name="fuzz_rover">
  <link name="base_link">
    <inertial><mass value="3.0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>
    <collision><geometry><box size="0.3 0.2 0.04"/></geometry></collision>
  </link>
  <joint name="caster_joint" type="fixed">
    <parent link="base_link"/><child link="caster"/><origin xyz="0 0 -0.05"/>
  </joint>
  <link name="caster">
    <inertial><mass value="0.1"/>
      <inertia ixx="0.00003" ixy="0" ixz="0" iyy="0.00003" iyz="0" izz="0.00003"/></inertial>
  </link>
''' + ''.join(_wheel(index) for index in range(4))
ROS2_CONTROL = f'''
  <ros2_control name="fuzz_rover" type="system">
    <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>
    {''.join(f'<joint name="{joint}">'
             + _interfaces('position', 'velocity', 'effort', command=True)
             + _interfaces('position', 'velocity', 'effort') + '</joint>' for joint in JOINTS)}
    <sensor name="{EXAMPLE_SENSOR}">{_interfaces(*EXAMPLE_SENSOR_INTERFACES)}</sensor>
    <gpio name="{EXAMPLE_GPIO}">{_interfaces('output1', command=True)}{_interfaces('output1')}
    </gpio>
  </ros2_control>
'''
ROBOT_URDF = ROBOT_URDF_HEAD + ROS2_CONTROL + '</robot>\n'


def _values(param: Param) -> st.SearchStrategy:
    """Hostile values of ``param``'s declared type, now and then one of another type."""
    element = param.type.removesuffix('_array')
    if element == DOUBLE:
        scalar = st.one_of(st.sampled_from(HOSTILE_DOUBLES), st.sampled_from(HOSTILE_DOUBLES),
                           st.floats(allow_nan=True, allow_infinity=True))
    elif element == INT:
        scalar = st.one_of(st.sampled_from(HOSTILE_INTS), st.integers(-10, 10 ** 6))
    elif element == BOOL:
        scalar = st.booleans()
    else:
        scalar = st.one_of(st.sampled_from(HOSTILE_STRINGS), st.text(max_size=12))
    if param.type.endswith('_array'):
        typed = st.lists(scalar, max_size=8)
        if element == STRING:
            typed = st.one_of(typed, st.lists(st.sampled_from(JOINTS), max_size=5))
    else:
        typed = scalar
    return st.one_of(typed, typed, typed, typed, st.sampled_from(WRONG_TYPES))


def _flatten(values: dict[str, Any], prefix: str = '') -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for key, value in values.items():
        if isinstance(value, dict) and value:
            flat.update(_flatten(value, f'{prefix}{key}.'))
        else:
            flat[f'{prefix}{key}'] = value
    return flat


def _nest(flat: dict[str, Any]) -> dict[str, Any]:
    nested: dict[str, Any] = {}
    for name, value in flat.items():
        node = nested
        *parents, leaf = name.split('.')
        for parent in parents:
            child = node.get(parent)
            if not isinstance(child, dict):
                child = node[parent] = {}
            node = child
        node[leaf] = value
    return nested


def _names(spec: ParameterSpec, example: dict[str, Any]) -> list[tuple[str, Param]]:
    """Every concrete parameter name of ``spec`` (``__map_`` entries over the example's list)."""
    names = []
    for param in spec:
        entries = example.get(param.map_list) if param.map_list else None
        entries = [entries] if isinstance(entries, str) else list(entries or JOINTS[:1])
        names += [(name, param) for name in param.expand([str(entry) for entry in entries])]
    return names


@st.composite
def controller_parameters(draw, type_name: str) -> dict[str, Any]:
    """Draw the parameters of one controller of ``type_name``: the spec's examples, fuzzed."""
    spec = CONTROLLER_TYPES[type_name].parameters
    flat = _flatten(spec.example())
    names = _names(spec, flat)
    chosen = draw(st.lists(st.sampled_from(names), max_size=MAX_FUZZED,
                           unique_by=lambda pair: pair[0])) if names else []
    for name, param in chosen:
        if draw(st.integers(0, 9)) == 0:
            flat.pop(name, None)  # left out: its default, or "missing" if required
        else:
            flat[name] = draw(_values(param))
    return _nest(flat)


@st.composite
def requests(draw) -> dict[str, Any]:
    """Draw the run-time requests: command numbers and a gripper goal (see the worker)."""
    numbers = st.one_of(st.sampled_from(HOSTILE_DOUBLES), st.floats(-1e3, 1e3))
    return {
        'numbers': draw(st.lists(numbers, min_size=0, max_size=6)),
        'stamp': draw(st.sampled_from((0.0, -1.0, 1e300, math.nan, 0.5))),
        'goal': draw(st.lists(numbers, min_size=3, max_size=3)),
    }


def controller_request(type_name: str, params: dict[str, Any], requests_: dict[str, Any],
                       steps: int) -> dict[str, Any]:
    """Return the worker's request: ``type_name`` with ``params`` on :data:`ROBOT_URDF`."""
    controllers = yaml.safe_dump({
        'controller_manager': {'ros__parameters': {'update_rate': 100,
                                                   NAME: {'type': type_name}}},
        NAME: {'ros__parameters': params}}, allow_unicode=True)
    return {'kind': 'controller', 'type': type_name, 'urdf': ROBOT_URDF,
            'controllers': controllers, 'requests': requests_, 'steps': steps}


def example_parameters(type_name: str, **changes: Any) -> dict[str, Any]:
    """Return the spec's examples of ``type_name`` with ``changes`` (dotted names)."""
    flat = _flatten(CONTROLLER_TYPES[type_name].parameters.example())
    flat.update(changes)
    return _nest(flat)


@st.composite
def controller_inputs(draw, steps: int) -> dict[str, Any]:
    """Draw one controller of any type on :data:`ROBOT_URDF`, and the requests sent to it."""
    type_name = draw(st.sampled_from(sorted(CONTROLLER_TYPES)))
    params = draw(controller_parameters(type_name))
    return controller_request(type_name, params, draw(requests()), steps)


# --- plugin and sensor tags -------------------------------------------------------------------

WHEELS = ('joint3', 'joint1', 'joint2', 'caster_joint', 'wheel1', 'nonexistent', '')
RIGHT_WHEELS = ('joint2', *WHEELS)
ODOM_FRAMES = ('odom', 'base_link', 'base_footprint', '', 'a b', '/odom', '..', 'odom//x', 'é')
BASE_FRAMES = ('base_link', *ODOM_FRAMES)
NUMBERS = ('0', '-1', '0.3', '1e300', '-1e300', 'nan', 'inf', '1e-300', 'wide', '', '100',
           '3.5', '7', '-7', '10000000', '100000', '2e9')


def _numbers(valid: str) -> tuple[str, ...]:
    return (valid, *NUMBERS)


def _element(tag: str, text: str | None) -> str:
    return '' if text is None else f'<{tag}>{text}</{tag}>'


@st.composite
def _tags(draw, elements: dict[str, tuple[str, ...]]) -> str:
    """Each element as its first (valid) candidate, but for up to three: left out or hostile."""
    fuzzed = draw(st.sets(st.sampled_from(sorted(elements)), max_size=MAX_FUZZED - 1))
    return ''.join(_element(tag, draw(st.one_of(st.none(), st.sampled_from(texts)))
                            if tag in fuzzed else texts[0])
                   for tag, texts in elements.items())


@st.composite
def drive_plugins(draw) -> str:
    """Draw one Gazebo drive plugin with hostile wheels, geometry, rates and frames."""
    kind = draw(st.sampled_from(('ros2', 'ros1', 'gz', 'planar')))
    if kind == 'ros2':
        return ('<plugin name="diff_drive" filename="libgazebo_ros_diff_drive.so">'
                + draw(_tags({'left_joint': WHEELS, 'right_joint': RIGHT_WHEELS,
                              'wheel_separation': _numbers('0.3'),
                              'wheel_diameter': _numbers('0.1'),
                              'max_wheel_torque': _numbers('20'),
                              'max_wheel_acceleration': _numbers('1'),
                              'update_rate': _numbers('100'), 'odometry_source': _numbers('0'),
                              'publish_odom': ('true', 'false', 'maybe'),
                              'publish_odom_tf': ('true', 'false'),
                              'odometry_frame': ODOM_FRAMES, 'robot_base_frame': BASE_FRAMES}))
                + '</plugin>')
    if kind == 'ros1':
        return ('<plugin name="differential_drive_controller" '
                'filename="libgazebo_ros_diff_drive.so">'
                + draw(_tags({'leftJoint': WHEELS, 'rightJoint': RIGHT_WHEELS,
                              'wheelSeparation': _numbers('0.3'),
                              'wheelDiameter': _numbers('0.1'), 'wheelTorque': _numbers('20'),
                              'updateRate': _numbers('100'),
                              'odometryFrame': ODOM_FRAMES, 'robotBaseFrame': BASE_FRAMES}))
                + '<robotNamespace>/</robotNamespace></plugin>')
    if kind == 'gz':
        return ('<plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">'
                + draw(_tags({'left_joint': WHEELS, 'right_joint': RIGHT_WHEELS,
                              'wheel_separation': _numbers('0.3'),
                              'wheel_radius': _numbers('0.05'),
                              'odom_publish_frequency': _numbers('50'),
                              'max_linear_velocity': _numbers('1'),
                              'min_linear_velocity': _numbers('-1'),
                              'max_angular_acceleration': _numbers('2'),
                              'frame_id': ODOM_FRAMES, 'child_frame_id': BASE_FRAMES}))
                + '</plugin>')
    return ('<plugin name="planar_move" filename="libgazebo_ros_planar_move.so">'
            + draw(_tags({'update_rate': _numbers('20'), 'publish_rate': _numbers('20'),
                          'odometry_frame': ODOM_FRAMES, 'robot_base_frame': BASE_FRAMES,
                          'covariance_x': _numbers('0.00001')}))
            + '</plugin>')


ANGLES = ('-1.5708', '1.5708', '0', '3.14159', '-3.14159', '6.3', '-6.3', '1e300', '-1e300',
          'nan', '6.283185307179586')


@st.composite
def lidars(draw) -> str:
    """Draw a lidar with hostile sample counts, resolutions, angles and ranges."""
    samples = ('1', '2', '90', '16383', '16384', '20000', '10000000', '0', '-3', '1e308', '2.5')
    horizontal = draw(_tags({'samples': ('90', *samples),
                             'resolution': ('1', '0.5', '2', '0', '-1', '1e308', '1e-300'),
                             'min_angle': ('-1.5708', *ANGLES),
                             'max_angle': ('1.5708', *ANGLES)}))
    vertical = draw(st.one_of(st.just(''), _tags({
        'samples': ('16', *samples), 'min_angle': ('-0.2', *ANGLES),
        'max_angle': ('0.2', *ANGLES)})))
    ranges = draw(_tags({'min': ('0.05', '0', '-1', '10', '1e300', 'nan'),
                         'max': ('8', '0.01', '1e300', '1e6', 'inf', '0')}))
    return f'''<gazebo reference="base_link"><sensor type="ray" name="lidar">
      {draw(_tags({'update_rate': ('10', '0', '-1', '1e300')}))}
      <ray><scan><horizontal>{horizontal}</horizontal>
      {f'<vertical>{vertical}</vertical>' if vertical else ''}</scan>
      <range>{ranges}</range></ray>
      <plugin name="scan" filename="libgazebo_ros_ray_sensor.so">
        <output_type>sensor_msgs/LaserScan</output_type></plugin>
    </sensor></gazebo>'''


@st.composite
def cameras(draw) -> str:
    """Draw a camera with hostile image sizes, fields of view and clip planes."""
    sizes = ('1', '2', '64', '3840', '100000', '0', '-5', '2.5', '1e300')
    image = draw(_tags({'width': ('32', *sizes), 'height': ('24', *sizes)}))
    camera = draw(_tags({'horizontal_fov': ('1.047', '0', '3.2', '-1', '1e-300', 'nan')}))
    clip = draw(_tags({'near': ('0.1', '0', '-1', '1e-300', '1e300'),
                       'far': ('100', '0.05', '1e300', 'inf')}))
    kind = draw(st.sampled_from(('camera', 'depth')))
    return f'''<gazebo reference="base_link"><sensor type="{kind}" name="camera">
      <update_rate>10</update_rate>
      <camera>{camera}<image>{image}</image><clip>{clip}</clip></camera>
      <plugin name="camera" filename="libgazebo_ros_camera.so"/>
    </sensor></gazebo>'''


@st.composite
def plugin_and_sensor_inputs(draw, steps: int) -> dict[str, Any]:
    """Draw the rover with a hostile drive plugin, lidar and camera (no controllers file)."""
    parts = [f'<gazebo>{draw(drive_plugins())}</gazebo>']
    if draw(st.booleans()):
        parts.append(draw(lidars()))
    if draw(st.booleans()):
        parts.append(draw(cameras()))
    return plugin_request(parts, draw(requests()), steps)


def plugin_request(parts: list[str], requests_: dict[str, Any], steps: int) -> dict[str, Any]:
    """Return the worker's request: the rover with the ``<gazebo>`` ``parts``, no controllers."""
    return {'kind': 'plugins', 'urdf': ROBOT_URDF_HEAD + ''.join(parts) + '</robot>\n',
            'controllers': None, 'requests': requests_, 'steps': steps}


def inputs(steps: int) -> st.SearchStrategy:
    """Draw either kind of input: a fuzzed controller, or fuzzed plugin and sensor tags."""
    return st.one_of(controller_inputs(steps), plugin_and_sensor_inputs(steps))
