"""sim_node's parameters: declared with descriptions, read, type-coerced and validated.

Users type ``-p real_time_factor:=0`` and ``-p time_step:=1e-3`` without
thinking about types, so a double parameter also takes an integer (rclpy
would otherwise raise InvalidParameterTypeException).  Every parameter is
declared with dynamic typing, and this module checks and converts the type
itself, naming the parameter and the type it wants when it is wrong -- at
start-up (a one-line error) and when it is set at run time (a refusal).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from rcl_interfaces.msg import ParameterDescriptor, ParameterType
from rclpy.node import Node
from rclpy.parameter import Parameter

from pan_tilt_sim.errors import ParameterError
from pan_tilt_sim.model.base_pose import (
    AUTO,
    FIXED_BASE,
    INITIAL_POSE,
    BasePose,
    parse_fixed_base,
    parse_initial_pose,
)
from pan_tilt_sim.model.initial_positions import parse_initial_positions
from pan_tilt_sim.model.naming import check_namespace
from pan_tilt_sim.model.physics_settings import (
    DEFAULT_PHYSICS,
    DESCRIPTIONS,
    PhysicsSettings,
    setting_problem,
)
from pan_tilt_sim.ros.pacing import MAX_REAL_TIME_FACTOR
from pan_tilt_sim.share import DEFAULT_DESCRIPTION, package_share

BOOL = ParameterType.PARAMETER_BOOL
INTEGER = ParameterType.PARAMETER_INTEGER
DOUBLE = ParameterType.PARAMETER_DOUBLE
STRING = ParameterType.PARAMETER_STRING
STRING_ARRAY = ParameterType.PARAMETER_STRING_ARRAY
DOUBLE_ARRAY = ParameterType.PARAMETER_DOUBLE_ARRAY
# A string parameter that also takes a bool (`-p fixed_base:=true` arrives as one).
BOOL_OR_STRING = -1

DEFAULT_TIME_STEP = 0.001  # s, PyBullet's recommended range is 1/1000 .. 1/240
MAX_TIME_STEP = 0.1  # s; beyond this the PID loop is meaningless
# s; below it a second of sim time is over a million steps, and pacing's steps per
# wall second (real_time_factor / time_step) would leave the range of floats.
MIN_TIME_STEP = 1e-6
DEFAULT_REAL_TIME_FACTOR = 1.0
# The solver settings among the parameters, and their types.
PHYSICS_PARAMETERS = ('solver_iterations', 'erp', 'contact_erp', 'cfm', 'contact_slop',
                      'split_impulse')
PHYSICS_TYPES = {'solver_iterations': ParameterType.PARAMETER_INTEGER,
                 'split_impulse': ParameterType.PARAMETER_BOOL,
                 **{name: ParameterType.PARAMETER_DOUBLE
                    for name in ('erp', 'contact_erp', 'cfm', 'contact_slop')}}


@dataclasses.dataclass(frozen=True)
class _Spec:
    name: str
    type: int
    default: Any
    description: str
    read_only: bool = True


_TYPE_NAMES = {
    ParameterType.PARAMETER_BOOL: 'bool',
    ParameterType.PARAMETER_INTEGER: 'integer',
    ParameterType.PARAMETER_DOUBLE: 'double',
    ParameterType.PARAMETER_STRING: 'string',
    ParameterType.PARAMETER_STRING_ARRAY: 'string array',
    ParameterType.PARAMETER_DOUBLE_ARRAY: 'double array',
}


def _specs(controller_manager: bool = False) -> tuple[_Spec, ...]:
    """Return the parameters; ``controller_manager``: sim_node runs as ros2_control_node would."""
    share = package_share()
    return (
        # Named controller_manager, sim_node takes the robot from robot_description by default.
        _Spec('robot_description_file', ParameterType.PARAMETER_STRING,
              '' if controller_manager else str(share / DEFAULT_DESCRIPTION),
              'A .urdf or .xacro file describing the robot; empty = the robot_description '
              'topic (as ros2_control_node takes it).'),
        # No default: rclpy cannot declare an empty string array, so "not set" means none.
        _Spec('xacro_args', ParameterType.PARAMETER_STRING_ARRAY, None,
              "xacro mappings for a .xacro description, each 'name:=value'."),
        # Empty: the file the URDF's control plugin names, else (pan/tilt model) the default.
        _Spec('controllers_file', ParameterType.PARAMETER_STRING, '',
              'Controller YAML (ROS 1 rosparam style or ros2_control style); empty = the one '
              "the URDF's gz_ros2_control/gazebo_ros2_control plugin names in <parameters>."),
        _Spec('controllers_args', ParameterType.PARAMETER_STRING_ARRAY, None,
              "Values of the controller YAML's $(var name) substitutions, each 'name:=value'."),
        _Spec('active_controllers', ParameterType.PARAMETER_STRING_ARRAY, None,
              'The controllers to activate (as spawners would); unset or empty = all of them. '
              'The others are loaded but inactive.'),
        _Spec('autostart_controllers', ParameterType.PARAMETER_BOOL, not controller_manager,
              "true: the controllers file's controllers are loaded and active from the start "
              "(or those in 'active_controllers'); false: none is loaded until ros2_control's "
              'spawner loads, configures and activates it through /<ns>/controller_manager, '
              'as with gz_ros2_control.'),
        _Spec('time_step', ParameterType.PARAMETER_DOUBLE, DEFAULT_TIME_STEP,
              f'Physics step in seconds of sim time ({MIN_TIME_STEP:g} <= time_step <= '
              f'{MAX_TIME_STEP:g}).'),
        _Spec('real_time_factor', ParameterType.PARAMETER_DOUBLE, DEFAULT_REAL_TIME_FACTOR,
              'Sim seconds per wall second (0 <= real_time_factor <= '
              f'{MAX_REAL_TIME_FACTOR:g}); 0 runs as fast as the machine allows.',
              read_only=False),
        _Spec('paused', ParameterType.PARAMETER_BOOL, False,
              'Hold the physics (topics stay alive).', read_only=False),
        _Spec('gui', ParameterType.PARAMETER_BOOL, False,
              'Open a PyBullet window (needs a display); false is headless DIRECT mode.'),
        _Spec('robot_namespace', ParameterType.PARAMETER_STRING, '',
              "Namespace of the robot's topics; empty = derived from the node namespace, "
              'the controllers file or the gazebo_ros_control plugin.'),
        _Spec('initial_positions', ParameterType.PARAMETER_STRING_ARRAY, None,
              "Start positions, each 'joint:=value' (rad or m); they override the URDF's "
              '<ros2_control> initial_value, and the reset services return to them.'),
        _Spec(FIXED_BASE, BOOL_OR_STRING, AUTO,
              "Weld the robot's root link to the world: auto (welded unless a controller "
              'that drives the base, such as diff_drive_controller, will be active or, '
              'waiting for spawners, the robot stands on wheels), true or false. A robot '
              "hung on a 'world' link by a fixed joint is always welded."),
        _Spec(INITIAL_POSE, ParameterType.PARAMETER_DOUBLE_ARRAY, None,
              '[x, y, z, yaw] (m, m, m, rad) of the base: a free base rests on the ground, '
              'its lowest collision point z above it; a welded one has its root link frame '
              'there. Unset: the origin. The reset services return to it.'),
        _Spec('record', ParameterType.PARAMETER_STRING, '',
              'Record the run as a rosbag2 bag (MCAP storage) in this new folder: /clock, '
              'joint_states, /tf, /tf_static, robot_description, controller states and the '
              'commands received; empty = no recording. Needs the mcap package.'),
        _Spec('record_sensors', ParameterType.PARAMETER_BOOL, False,
              "With 'record': record the sensors' topics too (camera, depth, lidar, IMU, "
              'force-torque).'),
        # PyBullet's solver settings (pan_tilt_sim.model.physics_settings), settable live.
        *(_Spec(name, PHYSICS_TYPES[name], getattr(DEFAULT_PHYSICS, name),
                DESCRIPTIONS[name] + " An SDF world's <physics> sets the default.",
                read_only=False) for name in PHYSICS_PARAMETERS),
    )


@dataclasses.dataclass(frozen=True)
class SimParameters:
    """sim_node's parameters, checked."""

    robot_description_file: str
    xacro_args: tuple[str, ...]
    controllers_file: str
    controllers_args: tuple[str, ...]
    # None: every controller active (unset, or set to an empty list).
    active_controllers: tuple[str, ...] | None
    autostart_controllers: bool
    time_step: float
    real_time_factor: float
    paused: bool
    gui: bool
    robot_namespace: str
    initial_positions: dict[str, float]
    # True, False, or None for auto (see pan_tilt_sim.model.base_pose).
    fixed_base: bool | None
    initial_pose: BasePose
    record: str  # '' = no recording
    record_sensors: bool
    # PyBullet's solver settings (see physics_settings).
    solver_iterations: int
    erp: float
    contact_erp: float
    cfm: float
    contact_slop: float
    split_impulse: bool

    @property
    def physics_settings(self) -> PhysicsSettings:
        """The solver settings the parameters give."""
        return PhysicsSettings(**{name: getattr(self, name) for name in PHYSICS_PARAMETERS})


def declare_parameters(node: Node, *, controller_manager: bool = False,
                       world_physics: Any = None) -> SimParameters:
    """Declare every parameter on ``node`` and return their checked values.

    ``world_physics`` (an SDF world's :class:`~pan_tilt_sim.model.sdf_world.WorldPhysics`)
    gives ``time_step`` and ``real_time_factor`` their defaults where it sets them.

    ``controller_manager``: the node runs in ros2_control_node's place
    (see :mod:`pan_tilt_sim.ros.drop_in`): other defaults, and the
    parameters that ros2_control_node's own ones replace are refused.
    """
    defaults = {}
    if world_physics is not None:
        defaults = {name: value for name, value in (
            ('time_step', world_physics.time_step),
            ('real_time_factor', world_physics.real_time_factor)) if value is not None}
        defaults.update(world_physics.settings())
    values = {spec.name: declare(node, spec.name, spec.type,
                                 defaults.get(spec.name, spec.default), spec.description,
                                 read_only=spec.read_only)
              for spec in _specs(controller_manager)}
    values['xacro_args'] = tuple(values['xacro_args'])
    values['initial_positions'] = parse_initial_positions(values['initial_positions'])
    values['controllers_args'] = tuple(values['controllers_args'])
    values['active_controllers'] = tuple(values['active_controllers']) or None
    values[FIXED_BASE] = parse_fixed_base(values[FIXED_BASE])
    values[INITIAL_POSE] = parse_initial_pose(values[INITIAL_POSE])
    checked = SimParameters(**values)
    check_time_step(checked.time_step)
    check_real_time_factor(checked.real_time_factor)
    for name in PHYSICS_PARAMETERS:
        check_physics_setting(name, getattr(checked, name))
    check_namespace('robot_namespace', checked.robot_namespace)
    if controller_manager:
        for name, instead in (('controllers_file', "the controller_manager's own parameters "
                               '(parameters=[controllers.yaml])'),
                              ('robot_namespace', "the node's namespace")):
            if getattr(checked, name):
                raise ParameterError(
                    f"parameter '{name}' is not used by sim_node named "
                    f"'{node.get_name()}' (in ros2_control_node's place): give {instead}, as "
                    'ros2_control_node takes it')
    if not checked.autostart_controllers and checked.active_controllers is not None:
        raise ParameterError(
            "parameter 'active_controllers' is set but 'autostart_controllers' is false: with "
            'spawners, the spawners choose the active controllers; leave one of them out')
    return checked


def declare(node: Node, name: str, wanted: int, default: Any, description: str, *,
            read_only: bool = True) -> Any:
    """Declare parameter ``name`` on ``node``; return its value, checked for type ``wanted``.

    rclpy's own type check would end start-up with an
    InvalidParameterTypeException traceback (and refuse integers for doubles):
    the parameter is declared with dynamic typing and :func:`coerce` checks it.
    """
    descriptor = ParameterDescriptor(
        name=name, type=STRING if wanted == BOOL_OR_STRING else wanted,
        description=description, read_only=read_only, dynamic_typing=True)
    return coerce(name, wanted, node.declare_parameter(name, default, descriptor).value)


def coerce(name: str, wanted: int, value: Any) -> Any:
    """Return ``value`` as parameter type ``wanted``.

    Integers pass for doubles; otherwise the type must match.
    """
    if wanted == ParameterType.PARAMETER_DOUBLE and isinstance(value, int) and not isinstance(
            value, bool):
        return float(value)
    if wanted in (STRING_ARRAY, DOUBLE_ARRAY) and (
            value is None or (isinstance(value, list | tuple) and not value)):
        return []  # declared without a value, or empty (`-p x:=[]` reads as not set)
    if wanted == BOOL_OR_STRING and isinstance(value, bool | str):
        return value
    if wanted == DOUBLE_ARRAY and isinstance(value, list | tuple) and all(
            isinstance(item, int | float) and not isinstance(item, bool) for item in value):
        return [float(item) for item in value]  # `[1, 2, 0, 0]` arrives as integers
    ok = {
        ParameterType.PARAMETER_BOOL: lambda v: isinstance(v, bool),
        ParameterType.PARAMETER_INTEGER: lambda v: isinstance(v, int) and not isinstance(v, bool),
        ParameterType.PARAMETER_DOUBLE: lambda v: isinstance(v, float),
        ParameterType.PARAMETER_STRING: lambda v: isinstance(v, str),
        ParameterType.PARAMETER_STRING_ARRAY: lambda v: isinstance(v, list | tuple) and all(
            isinstance(item, str) for item in v),
        ParameterType.PARAMETER_DOUBLE_ARRAY: lambda v: False,  # numbers were taken above
        BOOL_OR_STRING: lambda v: False,  # bools and strings were taken above
    }[wanted](value)
    if not ok:
        wanted_name = 'bool or string' if wanted == BOOL_OR_STRING else _TYPE_NAMES[wanted]
        raise ParameterError(
            f"parameter '{name}' must be a {wanted_name}, got {_describe(value)}")
    return list(value) if wanted == STRING_ARRAY else value


def check_time_step(value: float) -> None:
    """``time_step`` must lie in [MIN_TIME_STEP, MAX_TIME_STEP] seconds."""
    if not (math.isfinite(value) and 0.0 < value <= MAX_TIME_STEP):
        raise ParameterError(
            f"parameter 'time_step' must be > 0 and <= {MAX_TIME_STEP} s, got {value}")
    if value < MIN_TIME_STEP:
        raise ParameterError(
            f"parameter 'time_step' must be >= {MIN_TIME_STEP:g} s (a million steps per sim "
            f'second), got {value}')


def check_physics_setting(name: str, value: Any) -> None:
    """Refuse a solver setting PyBullet cannot take (see physics_settings): ParameterError."""
    problem = setting_problem(name, value)
    if problem is not None:
        raise ParameterError(problem)


def check_real_time_factor(value: float) -> None:
    """``real_time_factor`` must lie in [0, MAX_REAL_TIME_FACTOR] (0: as fast as possible)."""
    if not (math.isfinite(value) and value >= 0.0):
        raise ParameterError(
            f"parameter 'real_time_factor' must be a finite number >= 0, got {value}")
    if value > MAX_REAL_TIME_FACTOR:
        raise ParameterError(
            f"parameter 'real_time_factor' must be <= {MAX_REAL_TIME_FACTOR:g} (use 0 to run "
            f'as fast as the machine allows), got {value}')


def runtime_value(parameter: Parameter) -> Any:
    """Return a parameter set at run time, coerced to the type it was declared with."""
    spec = {spec.name: spec for spec in _specs()}[parameter.name]
    return coerce(parameter.name, spec.type, parameter.value)


def _describe(value: Any) -> str:
    kind = {bool: 'bool', int: 'integer', float: 'double', str: 'string'}.get(
        type(value), type(value).__name__)
    return f'{kind} {value!r}'


def given_parameters(node: Node) -> set[str]:
    """Return the names of the parameters the user set (command line, launch, overrides)."""
    # rclpy keeps them in the node; it has no public accessor.
    return set(getattr(node, '_parameter_overrides', {}) or {})



def world_physics_line(physics: Any, settings: SimParameters, given: set[str]) -> str:
    """Say, in one line, which of an SDF world's ``<physics>`` values and the parameters won.

    ``physics`` is a :class:`~pan_tilt_sim.model.sdf_world.WorldPhysics` (or
    None: '' is returned, as when the world says nothing).
    """
    if physics is None:
        return ''
    said = []
    for name, value, unit in (('time_step', physics.time_step, ' s'),
                              ('real_time_factor', physics.real_time_factor, '')):
        if value is None:
            continue
        if name in given:
            said.append(f"{name} {getattr(settings, name):g}{unit} (the parameter; the world's "
                        f'<physics> says {value:g}{unit})')
        else:
            said.append(f"{name} {value:g}{unit} (the world's <physics>)")
    for name, value in physics.settings().items():
        if name in given:
            said.append(f"{name} {getattr(settings, name)} (the parameter; the world's "
                        f'<physics> says {value})')
        else:
            said.append(f"{name} {value} (the world's <physics>)")
    if physics.unmatched:
        said.append('no PyBullet counterpart, not simulated: ' + ', '.join(physics.unmatched))
    return 'physics: ' + '; '.join(said) if said else ''
