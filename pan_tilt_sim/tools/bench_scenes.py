"""The bench's scenes: a driving base, a grasp, a six-joint arm and a TurtleBot3-like sandbox.

Each scene is a robot and a world written into the bench's folder from
package files (the bench runs from an installed package, so it makes its
own files, as it does its chains), run in two cases that differ only in the
contacts PyBullet has to solve (see the design notes).

Design notes: docs/design/tools.md#bench_scenespy.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import pathlib
import statistics
import xml.etree.ElementTree as ElementTree
from collections.abc import Callable

import yaml
from builtin_interfaces.msg import Duration
from control_msgs.action import FollowJointTrajectory
from geometry_msgs.msg import Twist, TwistStamped
from std_msgs.msg import Float64, Float64MultiArray
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from pan_tilt_sim.controllers.framework.surface import CommandTopic, StampedTwist
from pan_tilt_sim.model.base_pose import parse_initial_pose
from pan_tilt_sim.model.physics_settings import DEFAULT_PHYSICS
from pan_tilt_sim.model.world_file import world_from_parameter
from pan_tilt_sim.ros.ros_interfaces import joint_trajectory
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.sim.entities import Entities, spawn_world_objects
from pan_tilt_sim.sim.profiling import CommandRecorder, replay_step_cost
from pan_tilt_sim.sim.world import build_world, has_ground

ROVER_DESCRIPTION = pathlib.Path('urdf', 'diff_drive_rover.urdf')
ROOM_WORLD = pathlib.Path('config', 'worlds', 'room.yaml')
DRIVE_PLUGINS = ('libgazebo_ros_diff_drive.so', 'libgazebo_ros_p3d.so',
                 'libgazebo_ros_joint_state_publisher.so')
WHEELS = ('left_wheel_joint', 'right_wheel_joint')
BASE_CONTROLLER = 'base_controller'
CMD_VEL_TOPIC = f'/{BASE_CONTROLLER}/cmd_vel'
LINEAR_SPEED = 0.3  # m/s
CIRCLE_RADIUS = 0.5  # m: from the origin, the circle stays clear of the room's walls and objects
UPDATE_RATE = 100  # Hz, the controller manager's (the JointStateBroadcaster publishes at it)
FEW_SOLVER_ITERATIONS = 10  # the driving base's second world: <ode><solver><iters>

FINGER_JOINT = 'left_finger_joint'
LIFT_JOINT = 'lift_joint'
FINGER_OPEN = 0.05  # m: a finger's upper limit (its inner face from the middle)
FINGER_HEIGHT = 0.06  # m
FINGER_BOTTOM = 0.005  # m above the ground at lift 0
FINGER_MU = 2.0  # with the box's PyBullet default 0.5, a friction coefficient of 1.0
BOX_SIZE = 0.04  # m, a cube
BOX_MASS = 0.2  # kg: 1.96 N of weight
GRIP_N = 10.0  # N per finger: with friction 1.0 on two faces, five times the box's weight
LIFT_M = 0.1  # m
LIFT_CONTROLLER = 'lift_controller'
FINGER_CONTROLLER = 'finger_controller'

# The sandbox: sizes and masses of a TurtleBot3 waffle, our own geometry.
SANDBOX_STEP = 0.003  # s: the world's <physics> max_step_size, as Nav2's tb3_sandbox
WAFFLE_WHEEL_RADIUS = 0.033  # m
WAFFLE_WHEEL_SEPARATION = 0.287  # m
WAFFLE_BASE = (0.27, 0.27, 0.09)  # m: the base box, its bottom 0.01 m above the ground
WAFFLE_CASTER_RADIUS = 0.005  # m
WAFFLE_LIDAR_HEIGHT = 0.17  # m: the beam plane above the ground
SANDBOX_LIDAR = {'samples': 360, 'rate': 5.0, 'range': (0.12, 3.5)}  # beams, Hz, m
PILLAR_GRID = 1.1  # m between neighbouring cylinders, 3 x 3 about the origin
PILLAR_RADIUS = 0.15  # m
PILLAR_HEIGHT = 0.5  # m
HEXAGON_APOTHEM = 2.2  # m: the wall's inner face from the origin
HEXAGON_THICKNESS = 0.1  # m
SANDBOX_CIRCLE_CENTRE = (PILLAR_GRID / 2, PILLAR_GRID / 2)  # m: a cell between four cylinders
SANDBOX_CIRCLE_RADIUS = 0.3  # m: the robot stays clear of the four cylinders
SANDBOX_SPEED = 0.2  # m/s

# The arm: UR5e's published figures (Universal Robots' DH parameters and its ROS 2
# description's physical_parameters.yaml and joint_limits.yaml); the geometry is ours.
UR5E_JOINTS = ('shoulder_pan_joint', 'shoulder_lift_joint', 'elbow_joint',
               'wrist_1_joint', 'wrist_2_joint', 'wrist_3_joint')
UR5E_MASSES = {'base_link': 4.0, 'shoulder_link': 3.761, 'upper_arm_link': 8.058,
               'forearm_link': 2.846, 'wrist_1_link': 1.37, 'wrist_2_link': 1.3,
               'wrist_3_link': 0.365}  # kg
UR5E_DH = {'d1': 0.1625, 'a2': -0.425, 'a3': -0.3922, 'd4': 0.1333, 'd5': 0.0997,
           'd6': 0.0996}  # m
UR5E_EFFORT = (150.0, 150.0, 150.0, 28.0, 28.0, 28.0)  # N m
UR5E_VELOCITY = math.pi  # rad/s, every joint
UR5E_UPDATE_RATE = 500  # Hz, UR's controller manager
ARM_CONTROLLER = 'joint_trajectory_controller'
ARM_ACTION = f'/{ARM_CONTROLLER}/follow_joint_trajectory'
ARM_HOME = (0.0, -1.57, 1.57, -1.57, -1.57, 0.0)  # rad: upright, the wrist level
ARM_AMPLITUDE = 0.5  # rad, each joint's sine about its home position
ARM_PERIOD = 8.0  # s
ARM_POINT_S = 0.5  # s between the goal's points
ARM_GOAL_S = 2000.0  # sim s the goal lasts: beyond any bench window

CONTACT_SETTLE_S = 2.0  # sim s before the recording: the grasp closed, the lift up
CONTACT_COUNT_S = 5.0  # sim s recorded: contacts counted, accuracy judged, replayed


@dataclasses.dataclass(frozen=True)
class SceneCase:
    """One case of a scene: the files sim_node runs, its parameters, what the bench sends.

    ``messages``: topic -> message, each sent again every command period (a
    node's command subscriptions keep the newest only).
    """

    description_file: pathlib.Path
    controllers_file: pathlib.Path | None  # None: the robot has no controller YAML
    parameters: dict[str, str]
    messages: dict[str, object]
    joint_states_topic: str = '/joint_states'
    watched: tuple[str, str] | None = None  # (topic, type) a subscriber process reads
    # Action name -> a FollowJointTrajectory goal, sent once when the node runs.
    goals: dict[str, object] = dataclasses.field(default_factory=dict)
    # What in_process_figures checks the physics by: 'odometry', 'box_held',
    # 'box_on_ground', 'tracking' or ''.
    accuracy: str = ''


def _write(folder: pathlib.Path, name: str, text: str) -> pathlib.Path:
    """Write ``text`` to ``folder``/``name`` in UTF-8; return the path."""
    path = folder / name
    path.write_text(text, encoding='utf-8')
    return path


def rover_urdf(shipped: str) -> str:
    """Return the shipped rover's URDF driven by ros2_control instead of Gazebo plugins.

    The ``<gazebo>`` block of the diff drive, ground truth and joint state
    plugins goes; a ``<ros2_control>`` block gives each wheel a velocity
    command interface and position and velocity states.  The lidar stays.
    """
    robot = ElementTree.fromstring(shipped)
    for block in robot.findall('gazebo'):
        if any(plugin.get('filename') in DRIVE_PLUGINS for plugin in block.iter('plugin')):
            robot.remove(block)
    control = ElementTree.SubElement(robot, 'ros2_control', name='rover', type='system')
    hardware = ElementTree.SubElement(control, 'hardware')
    ElementTree.SubElement(hardware, 'plugin').text = 'gz_ros2_control/GazeboSimSystem'
    for wheel in WHEELS:
        joint = ElementTree.SubElement(control, 'joint', name=wheel)
        ElementTree.SubElement(joint, 'command_interface', name='velocity')
        for state in ('position', 'velocity'):
            ElementTree.SubElement(joint, 'state_interface', name=state)
    return ElementTree.tostring(robot, encoding='unicode')


def rover_controllers(wheel_separation: float, wheel_radius: float) -> str:
    """Return the rover's controllers: a JointStateBroadcaster and ``base_controller``.

    ``cmd_vel_timeout`` 0 keeps the last command: the bench sends it every
    wall command period, which at real_time_factor 0 is many sim seconds.
    """
    return yaml.safe_dump({
        'controller_manager': {'ros__parameters': {
            'update_rate': UPDATE_RATE,
            'joint_state_broadcaster': {'type': 'joint_state_broadcaster/JointStateBroadcaster'},
            BASE_CONTROLLER: {'type': 'diff_drive_controller/DiffDriveController'}}},
        BASE_CONTROLLER: {'ros__parameters': {
            'left_wheel_names': [WHEELS[0]], 'right_wheel_names': [WHEELS[1]],
            'wheel_separation': wheel_separation, 'wheel_radius': wheel_radius,
            'cmd_vel_timeout': 0.0}},
    }, sort_keys=False)


def _rover_geometry(urdf: str) -> tuple[float, float]:
    """Return (wheel separation, wheel radius) of the rover's URDF, in m."""
    robot = ElementTree.fromstring(urdf)
    joints = {joint.get('name'): joint for joint in robot.findall('joint')}
    lateral = [float(joints[wheel].find('origin').get('xyz').split()[1]) for wheel in WHEELS]
    links = {link.get('name'): link for link in robot.findall('link')}
    child = joints[WHEELS[0]].find('child').get('link')
    radius = float(links[child].find('collision/geometry/cylinder').get('radius'))
    return abs(lateral[0] - lateral[1]), radius


def driving_base(share: pathlib.Path, folder: pathlib.Path) -> dict[str, SceneCase]:
    """Write the driving base's files into ``folder``; return its cases (on_ground, base_fixed)."""
    urdf = rover_urdf((share / ROVER_DESCRIPTION).read_text(encoding='utf-8'))
    description = _write(folder, 'rover.urdf', urdf)
    controllers = _write(folder, 'rover_controllers.yaml',
                         rover_controllers(*_rover_geometry(urdf)))
    twist = TwistStamped()
    twist.twist.linear.x = LINEAR_SPEED
    twist.twist.angular.z = LINEAR_SPEED / CIRCLE_RADIUS
    world = str(share / ROOM_WORLD)
    few = _write(folder, 'room_10_iterations.sdf',
                 room_sdf(world_from_parameter(world), FEW_SOLVER_ITERATIONS))
    return {case: SceneCase(description, controllers, {'world': path, 'fixed_base': fixed},
                            {CMD_VEL_TOPIC: twist}, accuracy=accuracy)
            for case, path, fixed, accuracy in (
                ('on_ground', world, 'false', 'odometry'),
                ('base_fixed', world, 'true', ''),
                ('on_ground_10_iterations', str(few), 'false', 'odometry'))}


def room_sdf(room: object, iterations: int) -> str:
    """Return the room world (``config/worlds/room.yaml``) as an SDF world.

    ``room``: the room read as a :class:`~pan_tilt_sim.model.world_file.World`;
    its objects become SDF models with the same shapes, poses, masses and
    statics; ``<physics>`` asks for ``iterations`` solver iterations.
    """
    models = []
    for entity in room.entities:
        robot = ElementTree.fromstring(entity.resource_string)
        link = robot.find('link')
        shape = _sdf_geometry(link.find('collision/geometry'))
        static = robot.findtext('gazebo/static', 'false').strip()
        inertia = link.find('inertial/inertia')
        moments = ''.join(f'<{axis}>{inertia.get(axis)}</{axis}>'
                          for axis in ('ixx', 'iyy', 'izz'))
        mass = (f'<inertial><mass>{link.find("inertial/mass").get("value")}</mass>'
                f'<inertia>{moments}</inertia></inertial>')
        x, y, z = entity.position
        roll, pitch, yaw = _rpy(entity.orientation)
        models.append(f'<model name="{entity.name}"><static>{static}</static>'
                      f'<pose>{x} {y} {z} {roll} {pitch} {yaw}</pose><link name="link">{mass}'
                      f'<collision name="c"><geometry>{shape}</geometry></collision>'
                      f'<visual name="v"><geometry>{shape}</geometry></visual></link></model>')
    return f'''<?xml version="1.0"?>
<sdf version="1.6">
  <world name="room">
    <physics name="1ms" type="ode"><max_step_size>0.001</max_step_size>
      <ode><solver><iters>{iterations}</iters></solver></ode></physics>
    <model name="ground_plane"><static>true</static><link name="link">
      <collision name="c"><geometry><plane><normal>0 0 1</normal><size>20 20</size></plane>
      </geometry></collision></link></model>
    {''.join(models)}
  </world>
</sdf>
'''


def _sdf_geometry(geometry: ElementTree.Element) -> str:
    """Return a URDF ``<geometry>``'s box, cylinder or sphere as SDF."""
    box, cylinder, sphere = (geometry.find(kind) for kind in ('box', 'cylinder', 'sphere'))
    if box is not None:
        return f'<box><size>{box.get("size")}</size></box>'
    if cylinder is not None:
        return (f'<cylinder><radius>{cylinder.get("radius")}</radius>'
                f'<length>{cylinder.get("length")}</length></cylinder>')
    return f'<sphere><radius>{sphere.get("radius")}</radius></sphere>'


def _rpy(q: tuple[float, float, float, float]) -> tuple[float, float, float]:
    """Roll, pitch, yaw (rad) of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


def _finger(name: str, side: float) -> str:
    """Return a finger link, its inner face at its joint's origin (``side``: which way is out)."""
    centre = f'0 {side * 0.005} {-FINGER_HEIGHT / 2}'
    return (f'<link name="{name}"><inertial><origin xyz="{centre}"/><mass value="0.05"/>'
            '<inertia ixx="2e-5" ixy="0" ixz="0" iyy="2e-5" iyz="0" izz="2e-6"/></inertial>'
            f'<collision><origin xyz="{centre}"/>'
            f'<geometry><box size="0.03 0.01 {FINGER_HEIGHT}"/></geometry></collision></link>'
            f'<gazebo reference="{name}"><mu1>{FINGER_MU}</mu1><mu2>{FINGER_MU}</mu2></gazebo>')


def gripper_urdf() -> str:
    """Return the lift arm with its parallel gripper (see the module)."""
    carriage = FINGER_BOTTOM + FINGER_HEIGHT
    finger_limit = f'lower="0" upper="{FINGER_OPEN}" effort="40" velocity="0.2"'
    return (
        '<?xml version="1.0"?><robot name="gripper_arm">'
        '<link name="base_link"><inertial><mass value="10"/>'
        '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>'
        '<link name="carriage"><inertial><mass value="1.0"/>'
        '<inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>'
        '</link>'
        f'<joint name="{LIFT_JOINT}" type="prismatic">'
        '<parent link="base_link"/><child link="carriage"/>'
        f'<origin xyz="0 0 {carriage}"/><axis xyz="0 0 1"/>'
        '<limit lower="0" upper="0.3" effort="200" velocity="0.2"/></joint>'
        + _finger('left_finger', 1.0) + _finger('right_finger', -1.0) +
        f'<joint name="{FINGER_JOINT}" type="prismatic">'
        '<parent link="carriage"/><child link="left_finger"/><axis xyz="0 1 0"/>'
        f'<limit {finger_limit}/></joint>'
        '<joint name="right_finger_joint" type="prismatic">'
        '<parent link="carriage"/><child link="right_finger"/><axis xyz="0 -1 0"/>'
        f'<limit {finger_limit}/><mimic joint="{FINGER_JOINT}" multiplier="1" offset="0"/>'
        '</joint>'
        '<ros2_control name="GripperArm" type="system">'
        '<hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>'
        f'<joint name="{LIFT_JOINT}"><command_interface name="effort"/>'
        '<state_interface name="position"/><state_interface name="velocity"/></joint>'
        f'<joint name="{FINGER_JOINT}"><command_interface name="effort"/>'
        '<state_interface name="position"/><state_interface name="velocity"/></joint>'
        '</ros2_control></robot>\n')


def gripper_controllers() -> str:
    """Return the arm's controllers: a broadcaster, a lift position PID, a finger effort.

    The lift is a ``position_controllers/JointPositionController`` with PID
    gains (its command on ``lift_controller/command``), the finger an
    ``effort_controllers/JointGroupEffortController``: both are laws that
    step in C between two JointState samples (docs/performance.md).
    """
    return yaml.safe_dump({
        'controller_manager': {'ros__parameters': {
            'update_rate': UPDATE_RATE,
            'joint_state_broadcaster': {'type': 'joint_state_broadcaster/JointStateBroadcaster'},
            LIFT_CONTROLLER: {'type': 'effort_controllers/JointPositionController'},
            FINGER_CONTROLLER: {'type': 'effort_controllers/JointGroupEffortController'}}},
        LIFT_CONTROLLER: {'ros__parameters': {
            'joint': LIFT_JOINT, 'pid': {'p': 2000.0, 'i': 500.0, 'd': 100.0}}},
        FINGER_CONTROLLER: {'ros__parameters': {'joints': [FINGER_JOINT]}},
    }, sort_keys=False)


def grasp_world() -> str:
    """Return a world file: the ground and the box, between the open fingers, at rest."""
    return yaml.safe_dump({
        'scenery': 'ground',
        'entities': [{'name': 'box', 'shape': 'box', 'size': [BOX_SIZE] * 3,
                      'static': False, 'mass': BOX_MASS,
                      'pose': {'position': [0.0, 0.0, BOX_SIZE / 2]}}]}, sort_keys=False)


def grasp(folder: pathlib.Path) -> dict[str, SceneCase]:
    """Write the grasp's files into ``folder``; return its cases (holding, open)."""
    description = _write(folder, 'gripper_arm.urdf', gripper_urdf())
    controllers = _write(folder, 'gripper_controllers.yaml', gripper_controllers())
    world = _write(folder, 'grasp_world.yaml', grasp_world())
    # The lift's setpoint ramps at its velocity limit, so the fingers close on the
    # box long before the lift has risen by a millimetre or two.
    return {case: SceneCase(description, controllers, {'world': str(world)}, {
        f'/{FINGER_CONTROLLER}/commands': Float64MultiArray(data=[grip]),
        f'/{LIFT_CONTROLLER}/command': Float64(data=LIFT_M)}, accuracy=accuracy)
        for case, grip, accuracy in (('holding', -GRIP_N, 'box_held'),
                                     ('open', GRIP_N, 'box_on_ground'))}


def _cylinder_inertia(mass: float, radius: float, length: float) -> str:
    """Return a solid cylinder's inertia about its centre, its axis along z."""
    side = mass * (3.0 * radius ** 2 + length ** 2) / 12.0
    return (f'<inertia ixx="{side:.6g}" ixy="0" ixz="0" iyy="{side:.6g}" iyz="0" '
            f'izz="{mass * radius ** 2 / 2.0:.6g}"/>')


def ur5e_like_urdf() -> str:
    """Return the six-joint arm: UR5e's masses, lengths and limits on cylinders of our own.

    Joint frames follow the UR5e's DH parameters (:data:`UR5E_DH`): every
    joint turns about its frame's z axis.  Each link is a cylinder whose mass
    (:data:`UR5E_MASSES`) sits at its middle.
    """
    dh = UR5E_DH
    half_pi = math.pi / 2
    # (joint origin xyz, rpy) in the parent's frame; (link cylinder centre xyz, rpy, length).
    joints = [((0.0, 0.0, dh['d1']), (0.0, 0.0, 0.0)),
              ((0.0, 0.0, 0.0), (half_pi, 0.0, 0.0)),
              ((dh['a2'], 0.0, 0.0), (0.0, 0.0, 0.0)),
              ((dh['a3'], 0.0, dh['d4']), (0.0, 0.0, 0.0)),
              ((0.0, -dh['d5'], 0.0), (half_pi, 0.0, 0.0)),
              ((0.0, dh['d6'], 0.0), (-half_pi, 0.0, 0.0))]
    links = [((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.12),
             ((dh['a2'] / 2, 0.0, 0.0), (0.0, half_pi, 0.0), abs(dh['a2'])),
             ((dh['a3'] / 2, 0.0, 0.0), (0.0, half_pi, 0.0), abs(dh['a3'])),
             ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.1),
             ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.1),
             ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.04)]
    radius = 0.045
    names = list(UR5E_MASSES)

    def triple(values: tuple[float, float, float]) -> str:
        return ' '.join(f'{value:.6g}' for value in values)

    def link(name: str, centre: tuple, rpy: tuple, length: float) -> str:
        mass = UR5E_MASSES[name]
        origin = f'<origin xyz="{triple(centre)}" rpy="{triple(rpy)}"/>'
        shape = f'<geometry><cylinder radius="{radius}" length="{length:.6g}"/></geometry>'
        return (f'<link name="{name}"><inertial>{origin}<mass value="{mass}"/>'
                f'{_cylinder_inertia(mass, radius, length)}</inertial>'
                f'<visual>{origin}{shape}</visual><collision>{origin}{shape}</collision></link>')

    parts = [link(names[0], (0.0, 0.0, 0.025), (0.0, 0.0, 0.0), 0.05)]
    control = []
    for index, (joint, effort) in enumerate(zip(UR5E_JOINTS, UR5E_EFFORT, strict=True)):
        (xyz, rpy), (centre, link_rpy, length) = joints[index], links[index]
        limit = math.pi if joint == 'elbow_joint' else 2 * math.pi
        parts.append(
            f'<joint name="{joint}" type="revolute"><parent link="{names[index]}"/>'
            f'<child link="{names[index + 1]}"/><origin xyz="{triple(xyz)}" '
            f'rpy="{triple(rpy)}"/><axis xyz="0 0 1"/><limit lower="{-limit:.6g}" '
            f'upper="{limit:.6g}" effort="{effort}" velocity="{UR5E_VELOCITY:.6g}"/></joint>')
        parts.append(link(names[index + 1], centre, link_rpy, length))
        control.append(f'<joint name="{joint}"><command_interface name="position"/>'
                       f'<state_interface name="position"><param name="initial_value">'
                       f'{ARM_HOME[index]}</param></state_interface>'
                       '<state_interface name="velocity"/></joint>')
    return ('<?xml version="1.0"?><robot name="ur5e_like">' + ''.join(parts)
            + '<ros2_control name="ur5e_like" type="system"><hardware><plugin>'
            'gz_ros2_control/GazeboSimSystem</plugin></hardware>' + ''.join(control)
            + '</ros2_control></robot>\n')


def ur5e_like_controllers() -> str:
    """Return the arm's controllers: a broadcaster and a position JointTrajectoryController."""
    return yaml.safe_dump({
        'controller_manager': {'ros__parameters': {
            'update_rate': UR5E_UPDATE_RATE,
            'joint_state_broadcaster': {'type': 'joint_state_broadcaster/JointStateBroadcaster'},
            ARM_CONTROLLER: {'type': 'joint_trajectory_controller/JointTrajectoryController'}}},
        'joint_state_broadcaster': {'ros__parameters': {'publish_rate': 100.0}},
        ARM_CONTROLLER: {'ros__parameters': {
            'joints': list(UR5E_JOINTS), 'command_interfaces': ['position'],
            'state_interfaces': ['position', 'velocity']}},
    }, sort_keys=False)


def arm_goal(duration: float = ARM_GOAL_S) -> FollowJointTrajectory.Goal:
    """Return a goal swinging every joint in a sine about :data:`ARM_HOME` for ``duration`` s.

    Points every :data:`ARM_POINT_S` with positions and velocities; it starts
    at home, at rest, and so does it end (whole periods).
    """
    omega = 2.0 * math.pi / ARM_PERIOD
    periods = max(1, round(duration / ARM_PERIOD))
    points = []
    for index in range(1, round(periods * ARM_PERIOD / ARM_POINT_S) + 1):
        t = index * ARM_POINT_S
        # (1 - cos) keeps every joint at rest at the start and the end of each period.
        swing = ARM_AMPLITUDE * (1.0 - math.cos(omega * t)) / 2.0
        speed = ARM_AMPLITUDE * omega * math.sin(omega * t) / 2.0
        seconds = math.floor(t)
        points.append(JointTrajectoryPoint(
            positions=[home + swing * (1 if joint % 2 else -1)
                       for joint, home in enumerate(ARM_HOME)],
            velocities=[speed * (1 if joint % 2 else -1) for joint in range(len(ARM_HOME))],
            time_from_start=Duration(sec=seconds, nanosec=round((t - seconds) * 1e9))))
    return FollowJointTrajectory.Goal(
        trajectory=JointTrajectory(joint_names=list(UR5E_JOINTS), points=points))


def ur5e_like(folder: pathlib.Path) -> dict[str, SceneCase]:
    """Write the arm's files into ``folder``; return its case (follow_trajectory)."""
    description = _write(folder, 'ur5e_like.urdf', ur5e_like_urdf())
    controllers = _write(folder, 'ur5e_like_controllers.yaml', ur5e_like_controllers())
    return {'follow_trajectory': SceneCase(
        description, controllers, {'world': 'empty'}, {}, goals={ARM_ACTION: arm_goal()},
        accuracy='tracking')}


def waffle_sdf() -> str:
    """Return the sandbox's robot: a waffle-sized base on two wheels and two ball casters.

    Its model frame is on the ground under the wheel axle; gz-sim's DiffDrive
    takes ``cmd_vel`` and publishes ``odom`` and ``tf``, its
    JointStatePublisher ``joint_states``, its ``gpu_lidar`` ``scan``.
    """
    bx, by, bz = WAFFLE_BASE
    radius = WAFFLE_WHEEL_RADIUS
    samples, rate = SANDBOX_LIDAR['samples'], SANDBOX_LIDAR['rate']
    near, far = SANDBOX_LIDAR['range']
    inertia = '<inertia><ixx>{0}</ixx><iyy>{0}</iyy><izz>{0}</izz></inertia>'

    def wheel(side: str, y: float) -> str:
        pose = f'<pose>0 {y} {radius} -1.5707963 0 0</pose>'
        shape = f'<cylinder><radius>{radius}</radius><length>0.018</length></cylinder>'
        return (f'<link name="wheel_{side}_link"><inertial>{pose}<mass>0.03</mass>'
                f'{inertia.format(1.2e-5)}</inertial>'
                f'<collision name="tyre">{pose}<geometry>{shape}</geometry><surface><friction>'
                '<ode><mu>1.0</mu><mu2>1.0</mu2></ode></friction></surface></collision>'
                f'<visual name="tyre">{pose}<geometry>{shape}</geometry></visual></link>'
                f'<joint name="wheel_{side}_joint" type="revolute"><parent>base_link</parent>'
                f'<child>wheel_{side}_link</child>{pose}<axis><xyz>0 0 1</xyz></axis></joint>')

    def caster(side: str, y: float) -> str:
        pose = f'<pose>-0.18 {y} {WAFFLE_CASTER_RADIUS} 0 0 0</pose>'
        shape = f'<sphere><radius>{WAFFLE_CASTER_RADIUS}</radius></sphere>'
        return (f'<link name="caster_{side}_link">{pose}<inertial><mass>0.005</mass>'
                f'{inertia.format(1e-7)}</inertial>'
                f'<collision name="ball"><geometry>{shape}</geometry><surface><friction><ode>'
                '<mu>0.05</mu><mu2>0.05</mu2></ode></friction></surface></collision></link>'
                f'<joint name="caster_{side}_joint" type="ball"><parent>base_link</parent>'
                f'<child>caster_{side}_link</child></joint>')

    box = f'<box><size>{bx} {by} {bz}</size></box>'
    return f'''<?xml version="1.0"?>
<sdf version="1.6">
  <model name="waffle_like">
    <link name="base_link">
      <inertial><pose>-0.06 0 0.05 0 0 0</pose><mass>1.4</mass>
        <inertia><ixx>0.0095</ixx><iyy>0.0095</iyy><izz>0.017</izz></inertia></inertial>
      <collision name="base"><pose>-0.06 0 {0.01 + bz / 2} 0 0 0</pose>
        <geometry>{box}</geometry></collision>
      <visual name="base"><pose>-0.06 0 {0.01 + bz / 2} 0 0 0</pose>
        <geometry>{box}</geometry></visual>
    </link>
    <link name="base_scan">
      <pose>-0.06 0 {WAFFLE_LIDAR_HEIGHT - 0.02} 0 0 0</pose>
      <inertial><mass>0.11</mass>{inertia.format(1e-4)}</inertial>
      <collision name="head"><geometry><cylinder><radius>0.035</radius><length>0.04</length>
        </cylinder></geometry></collision>
      <sensor name="hls_lfcd_lds" type="gpu_lidar">
        <pose>0 0 0.02 0 0 0</pose><always_on>true</always_on>
        <update_rate>{rate}</update_rate><topic>scan</topic><gz_frame_id>base_scan</gz_frame_id>
        <lidar><scan><horizontal><samples>{samples}</samples><resolution>1</resolution>
          <min_angle>0</min_angle><max_angle>6.28</max_angle></horizontal></scan>
          <range><min>{near}</min><max>{far}</max><resolution>0.015</resolution></range>
          <noise><type>gaussian</type><mean>0</mean><stddev>0.01</stddev></noise></lidar>
      </sensor>
    </link>
    <joint name="base_scan_joint" type="fixed"><parent>base_link</parent>
      <child>base_scan</child></joint>
    {wheel('left', WAFFLE_WHEEL_SEPARATION / 2)}
    {wheel('right', -WAFFLE_WHEEL_SEPARATION / 2)}
    {caster('left', 0.064)}
    {caster('right', -0.064)}
    <plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">
      <left_joint>wheel_left_joint</left_joint><right_joint>wheel_right_joint</right_joint>
      <wheel_separation>{WAFFLE_WHEEL_SEPARATION}</wheel_separation>
      <wheel_radius>{radius}</wheel_radius>
      <topic>cmd_vel</topic><odom_topic>odom</odom_topic><tf_topic>tf</tf_topic>
      <frame_id>odom</frame_id><child_frame_id>base_link</child_frame_id>
      <odom_publish_frequency>30</odom_publish_frequency>
    </plugin>
    <plugin filename="gz-sim-joint-state-publisher-system"
            name="gz::sim::systems::JointStatePublisher">
      <topic>joint_states</topic>
    </plugin>
  </model>
</sdf>
'''


def hexagon_obj() -> str:
    """Return the hexagonal wall as an OBJ: a closed ring, hollow inside (a concave mesh).

    Its inner face is :data:`HEXAGON_APOTHEM` from the origin, it is
    :data:`HEXAGON_THICKNESS` thick and :data:`PILLAR_HEIGHT` tall, bottom at z = 0.
    """
    corners = []  # (inner, outer) corner radii at each of six angles
    inner = HEXAGON_APOTHEM / math.cos(math.pi / 6)
    outer = (HEXAGON_APOTHEM + HEXAGON_THICKNESS) / math.cos(math.pi / 6)
    for corner in range(6):
        angle = corner * math.pi / 3
        corners.append([(r * math.cos(angle), r * math.sin(angle)) for r in (inner, outer)])
    # Vertex 1 + 4 * corner + 0 inner bottom, 1 outer bottom, 2 inner top, 3 outer top.
    vertices = []
    for (ix, iy), (ox, oy) in corners:
        vertices += [(ix, iy, 0.0), (ox, oy, 0.0), (ix, iy, PILLAR_HEIGHT),
                     (ox, oy, PILLAR_HEIGHT)]
    faces = []
    for corner in range(6):
        a, b = 1 + 4 * corner, 1 + 4 * ((corner + 1) % 6)
        for quad in ((a + 1, b + 1, b + 3, a + 3),  # outer face
                     (b, a, a + 2, b + 2),  # inner face
                     (a + 2, a + 3, b + 3, b + 2),  # top
                     (a, b, b + 1, a + 1)):  # bottom
            faces += [(quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3])]
    return ''.join([f'v {x:.6f} {y:.6f} {z:.6f}\n' for x, y, z in vertices] +
                   [f'f {a} {b} {c}\n' for a, b, c in faces])


def sandbox_world(mesh: pathlib.Path) -> str:
    """Return the sandbox world: ground, nine cylinders and the hexagonal wall ``mesh``."""
    pillars = []
    for index, (i, j) in enumerate(itertools.product((-1, 0, 1), repeat=2)):
        shape = (f'<cylinder><radius>{PILLAR_RADIUS}</radius>'
                 f'<length>{PILLAR_HEIGHT}</length></cylinder>')
        pillars.append(
            f'<model name="pillar_{index}"><static>true</static>'
            f'<pose>{i * PILLAR_GRID} {j * PILLAR_GRID} {PILLAR_HEIGHT / 2} 0 0 0</pose>'
            f'<link name="link"><collision name="c"><geometry>{shape}</geometry></collision>'
            f'<visual name="v"><geometry>{shape}</geometry></visual></link></model>')
    wall = f'<mesh><uri>{mesh.name}</uri></mesh>'
    return f'''<?xml version="1.0"?>
<sdf version="1.6">
  <world name="sandbox">
    <physics name="3ms" type="ode"><max_step_size>{SANDBOX_STEP}</max_step_size>
      <real_time_factor>1.0</real_time_factor></physics>
    <plugin filename="gz-sim-physics-system" name="gz::sim::systems::Physics"/>
    <plugin filename="gz-sim-sensors-system" name="gz::sim::systems::Sensors"/>
    <light name="sun" type="directional"><direction>-0.5 0.1 -0.9</direction></light>
    <model name="ground_plane"><static>true</static><link name="link">
      <collision name="c"><geometry><plane><normal>0 0 1</normal><size>20 20</size></plane>
      </geometry></collision></link></model>
    {''.join(pillars)}
    <model name="hexagon"><static>true</static><link name="link">
      <collision name="c"><geometry>{wall}</geometry></collision>
      <visual name="v"><geometry>{wall}</geometry></visual></link></model>
  </world>
</sdf>
'''


def tb3_sandbox(folder: pathlib.Path) -> dict[str, SceneCase]:
    """Write the sandbox's robot, world and wall mesh into ``folder``; return its case (circle)."""
    description = _write(folder, 'waffle_like.sdf', waffle_sdf())
    mesh = _write(folder, 'hexagon.obj', hexagon_obj())
    world = _write(folder, 'sandbox.sdf', sandbox_world(mesh))
    cx, cy = SANDBOX_CIRCLE_CENTRE
    twist = Twist()
    twist.linear.x = SANDBOX_SPEED
    twist.angular.z = SANDBOX_SPEED / SANDBOX_CIRCLE_RADIUS
    start = f'[{cx}, {cy - SANDBOX_CIRCLE_RADIUS}, 0.0, 0.0]'  # heading +x, turning left
    return {'circle': SceneCase(description, None, {
        'world': str(world), 'initial_pose': start, 'time_step': repr(SANDBOX_STEP)},
        {'/cmd_vel': twist}, watched=('/scan', 'sensor_msgs/msg/LaserScan'))}


def _command_value(message: object) -> object:
    """Return a bench message as the command value its controller takes in-process."""
    if isinstance(message, TwistStamped | Twist):
        twist = message.twist if isinstance(message, TwistStamped) else message
        linear, angular = twist.linear, twist.angular
        return StampedTwist(0.0, (linear.x, linear.y, linear.z),
                            (angular.x, angular.y, angular.z))
    if isinstance(message, Float64MultiArray):
        return list(message.data)
    return message.data


def _command_taker(simulation: object, topic: str) -> Callable[[object], object]:
    """Return what takes ``topic``'s commands: its controller, else a Gazebo plugin's topic."""
    try:
        return simulation.controller(topic.rsplit('/', 2)[-2]).set_command
    except KeyError:
        leaf = topic.rsplit('/', 1)[-1]
        for plugin in simulation.plugins:
            for endpoint in plugin.ros_surface():
                if isinstance(endpoint, CommandTopic) and endpoint.name.rsplit('/', 1)[-1] == leaf:
                    return endpoint.accept
        raise


def in_process_figures(case: SceneCase, time_step: float,
                       settle_s: float = CONTACT_SETTLE_S,
                       count_s: float = CONTACT_COUNT_S) -> dict[str, float]:
    """Run ``case`` in this process as sim_node would; what PyBullet solved, and alone costs.

    The case's commands (and goals, as trajectories) go to its controllers at
    the start.  After ``settle_s`` of sim time the state is saved and the
    next ``count_s`` are run with every command sent to PyBullet recorded;
    then the state is restored and the recorded commands are replayed with
    nothing else running.  Returns ``contact_points`` (PyBullet's per step,
    mean), ``raw_step_us`` (thread CPU us of one ``stepSimulation`` in the
    replay, median over windows) and the case's accuracy at the end of the
    recorded run: ``odometry_error_percent`` (the controller's odometry
    against the base's true position, % of the distance driven),
    ``box_height_m`` and ``box_height_error_m`` (the box's centre, and how far
    it is from where a held box, or one on the ground, belongs) or
    ``tracking_error_rad`` (the trajectory controller's largest position
    error over the recorded run).
    """
    fixed = case.parameters.get('fixed_base')
    world = world_from_parameter(case.parameters.get('world', 'empty'))
    pose = case.parameters.get('initial_pose')
    # The solver settings the world's <physics> asks for, as sim_node applies them.
    settings = (DEFAULT_PHYSICS if world.physics is None
                else dataclasses.replace(DEFAULT_PHYSICS, **world.physics.settings()))
    with CommandRecorder() as recorder, make_simulation(
            str(case.description_file),
            None if case.controllers_file is None else str(case.controllers_file), time_step,
            fixed_base=None if fixed is None else fixed == 'true',
            initial_pose=parse_initial_pose(None if pose is None else yaml.safe_load(pose)),
            physics_settings=settings) as simulation:
        client = simulation.physics.client_id
        targets = build_world(world.scenery, client)
        entities = Entities(simulation.physics, simulation.description.name, targets=targets,
                            ground=has_ground(world.scenery))
        try:
            spawn_world_objects(entities, world)
            for topic, message in case.messages.items():
                _command_taker(simulation, topic)(_command_value(message))
            for action, goal in case.goals.items():
                simulation.controller(action.rsplit('/', 2)[-2]).set_command(
                    joint_trajectory(goal.trajectory))
            simulation.advance(round(settle_s / time_step))
            saved = pybullet.saveState(physicsClientId=client)
            steps = round(count_s / time_step)
            tracking = case.accuracy == 'tracking'
            contacts, error = 0, 0.0
            start = _odometry_and_truth(case, simulation)
            recorder.start()
            for _ in range(steps):
                simulation.advance(1)
                contacts += len(pybullet.getContactPoints(physicsClientId=client))
                if tracking:
                    error = max(error, *map(abs, simulation.controller(
                        ARM_CONTROLLER).position_errors()))
            recorder.stop()
            figures = {'contact_points': contacts / steps,
                       **_accuracy(case, simulation, entities, start, steps * time_step)}
            if tracking:
                figures['tracking_error_rad'] = error
            pybullet.restoreState(stateId=saved, physicsClientId=client)
            figures['raw_step_us'] = replay_step_cost(client, recorder.steps)
        finally:
            entities.close()
    return figures


def _odometry_and_truth(case: SceneCase, simulation: object) -> tuple | None:
    """Return the odometry's pose and the base's true pose (x, y, heading), if the case drives."""
    if case.accuracy != 'odometry':
        return None
    odometry = simulation.controller(BASE_CONTROLLER).odometry
    # The odometry follows the middle of the wheels' axle: the truth's point there too.
    robot = ElementTree.fromstring(case.description_file.read_text(encoding='utf-8'))
    joints = {joint.get('name'): joint for joint in robot.findall('joint')}
    ahead = statistics.fmean(float(joints[wheel].find('origin').get('xyz').split()[0])
                             for wheel in WHEELS)
    x, y, heading = simulation.base_state()[0]
    return ((odometry.x, odometry.y, odometry.heading),
            (x + ahead * math.cos(heading), y + ahead * math.sin(heading), heading))


def _moved(start: tuple[float, float, float], end: tuple[float, float, float]
           ) -> tuple[float, float]:
    """Return the way from pose ``start`` to ``end`` in ``start``'s own axes (m)."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    cos, sin = math.cos(start[2]), math.sin(start[2])
    return cos * dx + sin * dy, cos * dy - sin * dx


def _accuracy(case: SceneCase, simulation: object, entities: Entities, start: tuple | None,
              seconds: float) -> dict[str, float]:
    """Return the case's accuracy over the recorded ``seconds`` (see :func:`in_process_figures`).

    The odometry is compared with the truth over the recorded run: where
    each says the base went from where each said it was at the start,
    in its own axes then, so that what slipped while the wheels spun up
    does not count again at every later step.
    """
    if case.accuracy == 'odometry':
        (odometry_start, truth_start), (odometry_end, truth_end) = start, _odometry_and_truth(
            case, simulation)
        odometry, truth = _moved(odometry_start, odometry_end), _moved(truth_start, truth_end)
        return {'odometry_error_percent': math.hypot(odometry[0] - truth[0],
                                                     odometry[1] - truth[1])
                / (LINEAR_SPEED * seconds) * 100.0}
    if case.accuracy in ('box_held', 'box_on_ground'):
        height = entities.state('box').pose.translation[2]
        # Held, the box belongs where the fingers took it: lifted as far as the lift is.
        lift = simulation.joint_positions()[LIFT_JOINT] if case.accuracy == 'box_held' else 0.0
        return {'box_height_m': height, 'box_height_error_m': abs(height - BOX_SIZE / 2 - lift)}
    return {}
