"""ros_gz_sim's ``gz_sim.launch.py``: ``gz_args`` read as ``gz sim`` reads its command line.

:func:`server` turns the words of ``gz_args`` into sim_node's start: the world (a
file, found as gz-sim finds it: the path, then ``GZ_SIM_RESOURCE_PATH``; ``empty.sdf``
built in, as the ground; a path not there yet is read when sim_node starts), ``-r``
(run; without it the simulation starts paused, as gz-sim's does), ``-v N`` (sim_node's
log level; ``-v4`` too), ``-s`` and ``--headless-rendering`` (sim_node is always a
headless server).  sim_node starts with no robot (``robot_from_spawn``): ``create``
brings it.  Any other option is named in one warning (an option's value is optional
and never a word starting with ``-``, as gz sim's OptionParser reads it); of several
worlds the last is loaded, as by gz sim.  A world not found is a :class:`GzArgsError`.
"""

from __future__ import annotations

import dataclasses
import os
import pathlib
import shlex
from typing import Any

NODE_NAME = 'gzserver'  # ros_gz_sim's server node
BUILT_IN_WORLDS = {'empty.sdf': 'ground', 'empty': 'ground'}
WORLD_SUFFIXES = ('.sdf', '.world', '.sdf.xacro')
RESOURCE_PATHS = ('GZ_SIM_RESOURCE_PATH', 'IGN_GAZEBO_RESOURCE_PATH')
# gz sim's options that take a value (the next word), and those that take none.
WITH_VALUE = ('--iterations', '-z', '--network-role', '--network-secondaries',
              '--record-path', '--record-topic', '--playback', '--physics-engine',
              '--render-engine', '--render-engine-gui', '--render-engine-server',
              '--render-engine-api-backend', '--render-engine-gui-api-backend',
              '--render-engine-server-api-backend', '--seed', '--initial-sim-time',
              '--gui-config', '--force-version', '--record-period')
# gz sim's -v levels (0..4) as ROS log levels; 4 (debug) stays info: sim_node's debug
# output is its own developers'.
VERBOSITY = {0: 'fatal', 1: 'error', 2: 'warn', 3: 'info', 4: 'info'}
DEFAULT_VERBOSITY_FLAG = 3  # `-v` alone, as gz sim takes it


class GzArgsError(ValueError):
    """gz_args that name no world sim_node can load (one line)."""


@dataclasses.dataclass
class Server:
    """What to start: sim_node's parameters and extra ROS arguments, or nothing (``-g``)."""

    parameters: dict[str, Any]
    ros_arguments: list[str]
    warnings: list[str]
    run: bool = True  # False: a GUI-only gz sim, nothing to start
    shutdown_on_exit: bool = False  # the launch ends when sim_node ends


def server(gz_args: str, environ: dict[str, str] | None = None,
           cwd: pathlib.Path | None = None) -> Server:
    """Return sim_node's start for ``gz_args`` (see the module)."""
    environ = os.environ if environ is None else environ
    words = shlex.split(gz_args)
    warnings: list[str] = []
    world: str | None = None
    running = gui_only = False
    verbosity: int | None = None
    index = 0
    while index < len(words):
        word = words[index]
        index += 1
        option, has_value, value = word.partition('=')
        if word.startswith('-v') and word[2:].isdigit():  # `-v4`, as OptionParser reads it
            option, has_value, value = '-v', '=', word[2:]
        if word == '-r':
            running = True
        elif word in ('-s', '--headless-rendering'):
            pass  # sim_node is a headless server already
        elif word == '-g':
            gui_only = True
        elif option in ('-v', '--verbose'):
            if not has_value and index < len(words) and words[index].isdigit():
                value, index = words[index], index + 1
            verbosity = int(value) if value.isdigit() else DEFAULT_VERBOSITY_FLAG
        elif option in WITH_VALUE:
            if not has_value and index < len(words) and not words[index].startswith('-'):
                value, index = words[index], index + 1
            named = f'{option} {value}' if value else option
            warnings.append(f"gz_args: '{named}' is not honoured by sim_node")
        elif word.startswith('-'):
            warnings.append(f"gz_args: '{word}' is not honoured by sim_node")
        else:
            if world is not None:
                warnings.append(f"gz_args: '{world}' is not honoured by sim_node (gz sim "
                                'loads the last world given)')
            world = word
    if gui_only:
        return Server({}, [], warnings + [
            "gz_args: '-g' starts only Gazebo's GUI: nothing to start (sim_node is headless; "
            "the server is the include with '-s')"], run=False)
    parameters = {'world': find_world(world, environ, cwd or pathlib.Path.cwd()),
                  'robot_from_spawn': True, 'paused': not running,
                  'autostart_controllers': False, 'publish_tf': False}
    ros_arguments = [] if verbosity is None else [
        '--log-level', VERBOSITY[max(0, min(4, verbosity))]]
    return Server(parameters, ros_arguments, warnings)


def find_world(world: str | None, environ: dict[str, str], cwd: pathlib.Path) -> str:
    """Return the ``world`` parameter for a gz sim world argument (None: gz's empty world)."""
    if world is None:
        return BUILT_IN_WORLDS['empty.sdf']
    candidates = [pathlib.Path(world).expanduser()]
    if not candidates[0].is_absolute():
        candidates = [cwd / world] + [
            pathlib.Path(folder) / world for name in RESOURCE_PATHS
            for folder in environ.get(name, '').split(os.pathsep) if folder]
    for candidate in candidates:
        if candidate.is_file():
            return str(candidate.resolve())
    if world in BUILT_IN_WORLDS:
        return BUILT_IN_WORLDS[world]
    if os.sep in world:
        # A path gz sim reads when it starts (nav2_bringup's `xacro -o` writes it meanwhile);
        # sim_node's `world` says so in one line if it is not there by then.
        return str(candidates[0])
    raise GzArgsError(
        f"gz_args: world '{world}' not found (as a path, nor in {' or '.join(RESOURCE_PATHS)}"
        f"; built in: {', '.join(BUILT_IN_WORLDS)})")
