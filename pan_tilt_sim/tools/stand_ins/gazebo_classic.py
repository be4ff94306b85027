"""gazebo_ros's ``gazebo.launch.py`` (classic): its launch arguments as sim_node's start.

``world`` (a path, else found in ``GAZEBO_RESOURCE_PATH``; ``worlds/empty.world``,
gzserver's default, is the ground), ``pause``, ``verbose``, ``server`` (false: nothing
to start), ``server_required`` (the launch ends with sim_node), ``gui`` (sim_node is
headless) and ``extra_gazebo_args`` (``-u``/``--pause`` and ``--verbose`` honoured; any
other gzserver option is named with its value in one warning).  ``init``, ``factory``
and ``force_system`` need nothing: sim_node serves its spawn service anyway.  Any other
argument given a value is named in one warning.  sim_node starts with no robot:
``spawn_entity.py`` brings it.
"""

from __future__ import annotations

import os
import pathlib
import shlex

from pan_tilt_sim.tools.stand_ins.gz_sim import GzArgsError, Server

NODE_NAME = 'gazebo'  # gazebo_ros's node
BUILT_IN_WORLDS = {'': 'ground', 'empty.world': 'ground', 'worlds/empty.world': 'ground'}
RESOURCE_PATH = 'GAZEBO_RESOURCE_PATH'
# Launch arguments and the value that means "not used" (gzserver.launch.py's defaults).
ARGUMENTS = {
    'world': '', 'gui': 'true', 'server': 'true', 'version': 'false', 'verbose': 'false',
    'lockstep': 'false', 'help': 'false', 'pause': 'false', 'initial_sim_time': '',
    'physics': '', 'play': '', 'record': 'false', 'record_encoding': '', 'record_path': '',
    'record_period': '', 'record_filter': '', 'seed': '', 'iters': '',
    'minimal_comms': 'false', 'profile': '', 'extra_gazebo_args': '', 'params_file': '',
    'gdb': 'false', 'valgrind': 'false', 'init': 'true', 'factory': 'true',
    'force_system': 'true', 'server_required': 'false', 'gdbserver': 'false',
    'gdbserver_port': '', 'gui_required': 'false',
}
# gzserver's options that take a value (the next word), as gazebo 11's --help lists them.
WITH_VALUE = ('-e', '--physics', '-p', '--play', '-s', '--server-plugin', '-o', '--profile',
              '--record_encoding', '--record_path', '--record_period', '--record_filter',
              '--seed', '--iters', '--initial_sim_time')
HONOURED = ('world', 'gui', 'server', 'verbose', 'pause', 'extra_gazebo_args', 'init',
            'factory', 'force_system', 'server_required', 'gui_required')


def server(arguments: dict[str, str], environ: dict[str, str] | None = None,
           cwd: pathlib.Path | None = None) -> Server:
    """Return sim_node's start for gazebo.launch.py's launch arguments (see the module)."""
    environ = os.environ if environ is None else environ
    warnings = [f"gazebo.launch.py: {name}:='{value}' is not honoured by sim_node"
                for name, value in arguments.items()
                if name in ARGUMENTS and name not in HONOURED and value != ARGUMENTS[name]]
    paused = truth(arguments.get('pause', 'false'))
    verbose = truth(arguments.get('verbose', 'false'))
    words = shlex.split(arguments.get('extra_gazebo_args', ''))
    index = 0
    while index < len(words):
        word = words[index]
        index += 1
        if word in ('-u', '--pause'):
            paused = True
        elif word == '--verbose':
            verbose = True
        else:
            if word in WITH_VALUE and index < len(words):
                word, index = f'{word} {words[index]}', index + 1
            warnings.append(f"extra_gazebo_args: '{word}' is not honoured by sim_node")
    if not truth(arguments.get('server', 'true')):
        return Server({}, [], warnings, run=False)
    parameters = {'world': find_world(arguments.get('world', ''), environ,
                                      cwd or pathlib.Path.cwd()),
                  'robot_from_spawn': True, 'paused': paused,
                  'autostart_controllers': False, 'publish_tf': False}
    # gzserver says little unless --verbose, as sim_node at 'warn'.
    return Server(parameters, [] if verbose else ['--log-level', 'warn'], warnings,
                  shutdown_on_exit=truth(arguments.get('server_required', 'false')))


def truth(text: str) -> bool:
    """Return a launch argument's truth, as launch's conditions read it."""
    return text.strip().lower() in ('true', '1')


def find_world(world: str, environ: dict[str, str], cwd: pathlib.Path) -> str:
    """Return the ``world`` parameter for gzserver's world argument."""
    candidates = [pathlib.Path(world).expanduser()] if world else []
    if world and not candidates[0].is_absolute():
        candidates = [cwd / world] + [
            pathlib.Path(folder) / world
            for folder in environ.get(RESOURCE_PATH, '').split(os.pathsep) if folder]
    for candidate in candidates:
        if candidate.is_file():
            return str(candidate.resolve())
    if world in BUILT_IN_WORLDS:
        return BUILT_IN_WORLDS[world]
    raise GzArgsError(f"world '{world}' not found (as a path, nor in {RESOURCE_PATH}; "
                      f"built in: {', '.join(name for name in BUILT_IN_WORLDS if name)})")
