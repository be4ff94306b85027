"""The bench's two contact scenes: a driving base in the room, and a grasp.

Each scene is a robot and a world written into the bench's folder from
package files (the bench runs from an installed package, so it makes its
own files, as it does its chains), run in two cases that differ only in the
contacts PyBullet has to solve:

* ``driving_base``: the shipped ``urdf/diff_drive_rover.urdf`` with its Gazebo
  drive plugins replaced by a ``<ros2_control>`` block and a
  ``diff_drive_controller/DiffDriveController`` (``base_controller``), in
  ``config/worlds/room.yaml``, its lidar present and nobody subscribed to
  ``/scan``.  ``on_ground``: the base free, driving a circle of
  :data:`CIRCLE_RADIUS` on its wheels and caster; ``base_fixed``: the same
  robot, commands and world with ``fixed_base:=true``, which welds the base
  frame at the origin: the wheels and the caster reach into the ground, and
  links that do when welded never collide with it, so the wheels spin
  touching nothing (the room's ball resting on the ground is the one contact
  left in both cases).
* ``grasp``: a lift arm with a parallel gripper (two prismatic fingers, the
  right one a mimic of the left, as Franka's hand) and a 4 cm, 0.2 kg box
  between the fingers, spawned from a world file.  ``holding``: the fingers
  squeeze the box with :data:`GRIP_N` and the lift holds it
  :data:`LIFT_M` above the ground; ``open``: the fingers pushed open, the
  lift at the same height, the box resting on the ground.

:func:`contact_points` counts, in this process, the contact points PyBullet
reports per step in each case (the same files, commands and world).
"""

from __future__ import annotations

import dataclasses
import pathlib
import xml.etree.ElementTree as ElementTree

import yaml
from geometry_msgs.msg import TwistStamped
from std_msgs.msg import Float64, Float64MultiArray

from pan_tilt_sim.controllers.surface import StampedTwist
from pan_tilt_sim.model.world_file import world_from_parameter
from pan_tilt_sim.sim.bullet import pybullet
from pan_tilt_sim.sim.engine import make_simulation
from pan_tilt_sim.sim.entities import Entities, spawn_world_objects
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

CONTACT_SETTLE_S = 2.0  # sim s before contacts are counted: the grasp closed, the lift up
CONTACT_COUNT_S = 1.0  # sim s over which contacts are counted


@dataclasses.dataclass(frozen=True)
class SceneCase:
    """One case of a scene: the files sim_node runs, its parameters, what the bench sends.

    ``messages``: topic -> message, each sent again every command period (a
    node's command subscriptions keep the newest only).
    """

    description_file: pathlib.Path
    controllers_file: pathlib.Path
    parameters: dict[str, str]
    messages: dict[str, object]
    joint_states_topic: str = '/joint_states'


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
    description = folder / 'rover.urdf'
    description.write_text(urdf, encoding='utf-8')
    controllers = folder / 'rover_controllers.yaml'
    controllers.write_text(rover_controllers(*_rover_geometry(urdf)), encoding='utf-8')
    twist = TwistStamped()
    twist.twist.linear.x = LINEAR_SPEED
    twist.twist.angular.z = LINEAR_SPEED / CIRCLE_RADIUS
    world = str(share / ROOM_WORLD)
    return {case: SceneCase(description, controllers,
                            {'world': world, 'fixed_base': fixed}, {CMD_VEL_TOPIC: twist})
            for case, fixed in (('on_ground', 'false'), ('base_fixed', 'true'))}


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
    description = folder / 'gripper_arm.urdf'
    description.write_text(gripper_urdf(), encoding='utf-8')
    controllers = folder / 'gripper_controllers.yaml'
    controllers.write_text(gripper_controllers(), encoding='utf-8')
    world = folder / 'grasp_world.yaml'
    world.write_text(grasp_world(), encoding='utf-8')
    # The lift's setpoint ramps at its velocity limit, so the fingers close on the
    # box long before the lift has risen by a millimetre or two.
    return {case: SceneCase(description, controllers, {'world': str(world)}, {
        f'/{FINGER_CONTROLLER}/commands': Float64MultiArray(data=[grip]),
        f'/{LIFT_CONTROLLER}/command': Float64(data=LIFT_M)})
        for case, grip in (('holding', -GRIP_N), ('open', GRIP_N))}


def _command_value(message: object) -> object:
    """Return a bench message as the command value its controller takes in-process."""
    if isinstance(message, TwistStamped):
        linear, angular = message.twist.linear, message.twist.angular
        return StampedTwist(0.0, (linear.x, linear.y, linear.z),
                            (angular.x, angular.y, angular.z))
    if isinstance(message, Float64MultiArray):
        return list(message.data)
    return message.data


def contact_points(case: SceneCase, time_step: float,
                   settle_s: float = CONTACT_SETTLE_S,
                   count_s: float = CONTACT_COUNT_S) -> dict[str, float]:
    """Run ``case`` in this process as sim_node would; count PyBullet's contact points.

    The case's commands go to its controllers at the start; after
    ``settle_s`` of sim time, the contact points of every step of the next
    ``count_s`` are counted.  Returns ``contact_points`` (the mean per step)
    and, where the world has a ``box``, ``box_height_m`` (its centre's z at
    the end, m): the figures say what PyBullet solved, not how fast.
    """
    fixed = case.parameters.get('fixed_base')
    with make_simulation(str(case.description_file), str(case.controllers_file), time_step,
                         fixed_base=None if fixed is None else fixed == 'true') as simulation:
        world = world_from_parameter(case.parameters['world'])
        client = simulation.physics.client_id
        targets = build_world(world.scenery, client)
        entities = Entities(simulation.physics, simulation.description.name, targets=targets,
                            ground=has_ground(world.scenery))
        try:
            spawn_world_objects(entities, world)
            for topic, message in case.messages.items():
                controller = simulation.controller(topic.split('/')[1])
                controller.set_command(_command_value(message))
            simulation.advance(round(settle_s / time_step))
            steps = round(count_s / time_step)
            total = 0
            for _ in range(steps):
                simulation.advance(1)
                total += len(pybullet.getContactPoints(physicsClientId=client))
            heights = {name: entities.state(name).pose.translation[2]
                       for name in entities.names() if name == 'box'}
        finally:
            entities.close()
    figures = {'contact_points': total / steps}
    if heights:
        figures['box_height_m'] = heights['box']
    return figures
