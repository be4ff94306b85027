"""ros_gz_sim's ``create``: hand a robot to the running simulation; exit 0 once it is in.

Arguments as ros_gz_sim's (jazzy): the flags ``-world -file -param -string -topic
-name -allow_renaming -x -y -z -R -P -Y``, gflags' own (``--flagfile``, ``--undefok``,
``--help``, ...), and the same names as ROS parameters (which win, as there).  The
description goes to sim_node's SpawnEntity service
(:mod:`pan_tilt_sim.tools.stand_ins.spawning`); exit codes as create's: 0 in, 1
refused, 255 no description.  ``-world`` is not honoured (one world per sim_node):
a warning names it.  ``-R -P -Y`` are the pose's fixed-axis angles, as gz's.
"""

from __future__ import annotations

import math
import sys

from pan_tilt_sim.tools.stand_ins.flags import FlagError, FlagExitError, parse_flags
from pan_tilt_sim.tools.stand_ins.launcher import exit_with, run_node
from pan_tilt_sim.tools.stand_ins.spawning import call_spawn, description_from_topic

NODE_NAME = 'ros_gz_sim'
FLAGS = {'world': '', 'file': '', 'param': '', 'string': '', 'topic': '', 'name': '',
         'allow_renaming': False, 'x': 0.0, 'y': 0.0, 'z': 0.0, 'R': 0.0, 'P': 0.0, 'Y': 0.0}
# The ROS parameters create declares (not 'param').
PARAMETERS = ('world', 'file', 'string', 'topic', 'name', 'allow_renaming',
              'x', 'y', 'z', 'R', 'P', 'Y')
POSE = ('x', 'y', 'z', 'R', 'P', 'Y')
EXIT_REFUSED = 1
EXIT_NO_DESCRIPTION = 255  # create's return -1
USAGE = ('create: Usage: create -world [arg] [-file FILE] [-param PARAM] [-topic TOPIC]\n'
         '                       [-string STRING] [-name NAME] [-allow_renaming RENAMING] '
         '[-x X] [-y Y] [-z Z]\n                       [-R ROLL] [-P PITCH] [-Y YAW]\n')


def quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """Return (x, y, z, w) of fixed-axis roll, pitch, yaw (rad), as gz::math::Quaternion."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def main(argv: list[str] | None = None) -> None:
    """Run create with ``argv`` (program name first); exit with create's code."""
    exit_with(run, argv)


def run(argv: list[str]) -> int:
    """Spawn as create does; return the exit code."""
    return run_node(argv, NODE_NAME, _create)


def _create(node, words: list[str]) -> int:
    from simulation_interfaces.srv import SpawnEntity

    logger = node.get_logger()
    try:
        flags, _leftover, _given = parse_flags(words, FLAGS)
    except FlagError as err:
        sys.stderr.write(f'{err}\n')
        return EXIT_REFUSED
    except FlagExitError as ended:  # gflags' --help* print the usage, --version the name
        sys.stdout.write(USAGE if ended.flag != 'version' else 'create\n')
        return ended.code
    values = {name: node.declare_parameter(name, FLAGS[name]).value for name in PARAMETERS}
    world = values['world'] or flags['world']
    if world:
        logger.warning(f"-world '{world}' is not honoured: the robot goes to the one "
                       "simulation running (sim_node's SpawnEntity service)")
    request = SpawnEntity.Request()
    if values['file']:
        request.uri = values['file']
    elif values['string']:
        request.resource_string = values['string']
    elif values['topic']:
        request.resource_string = _from_topic(node, values['topic'])
    elif words:
        if flags['file']:
            request.uri = flags['file']
        elif flags['param']:
            text = node.declare_parameter(flags['param'], '').value
            if not text:
                logger.error(f"Failed to get XML from param [{flags['param']}].")
                return EXIT_NO_DESCRIPTION
            request.resource_string = text
        elif flags['string']:
            request.resource_string = flags['string']
        elif flags['topic']:
            request.resource_string = _from_topic(node, flags['topic'])
        else:
            logger.error('Must specify either -file, -param, -string or -topic')
            return EXIT_NO_DESCRIPTION
    else:
        logger.error('Must specify either file, string or topic as ROS 2 parameters')
        return EXIT_NO_DESCRIPTION
    if not request.uri and not request.resource_string:
        return 0  # interrupted while waiting for the topic, as create returns
    # A parameter other than 0 wins over its flag, as in create.
    pose = {name: values[name] if values[name] != 0.0 else flags[name] for name in POSE}
    target = request.initial_pose
    target.header.frame_id = 'world'
    target.pose.position.x, target.pose.position.y, target.pose.position.z = (
        pose['x'], pose['y'], pose['z'])
    (target.pose.orientation.x, target.pose.orientation.y, target.pose.orientation.z,
     target.pose.orientation.w) = quaternion(pose['R'], pose['P'], pose['Y'])
    request.name = values['name'] or flags['name']
    request.allow_renaming = bool(values['allow_renaming'] or flags['allow_renaming'])
    response = call_spawn(node, request, None, lambda: logger.warning(
        'Waiting for service [spawn_entity] (simulation_interfaces/srv/SpawnEntity) to '
        'become available ...'))
    if response is None:
        logger.info('Entity creation was interrupted.')
        return 0
    if response.result.result == 1:  # RESULT_OK
        logger.info('Entity creation successfull.')
        return 0
    logger.error(f'Entity creation failed: {response.result.error_message}')
    return EXIT_REFUSED


def _from_topic(node, topic: str) -> str:
    """Return the description on ``topic``, waited for as create waits; '' if interrupted."""
    logger = node.get_logger()
    text = description_from_topic(
        node, topic, None, lambda name: logger.info(f'Waiting messages on topic [{name}].'))
    return text or ''
