"""The installed package has the ament layout `ros2 run` and the ament index need.

Checked twice: as pip installed it into this venv (what scripts/run_tests.sh
set up) and as `colcon build` lays it out in a fresh workspace.
"""

import importlib.metadata
import importlib.util
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import textwrap
import xml.etree.ElementTree as ElementTree

import pytest
from ament_index_python.packages import get_package_prefix, get_package_share_directory

PACKAGE = 'pan_tilt_sim'
EXECUTABLES = ('sim_node', 'bench', 'step_response', 'tune', 'sweep')
# The Gazebo-side stand-ins: in lib/pan_tilt_sim/ only, run by one console script.
STAND_INS = ('create', 'parameter_bridge', 'image_bridge', 'spawn_entity.py',
             'ros2_control_node')
STAND_IN_SCRIPT = 'pan_tilt_sim_stand_in'
# What setup.py installs from; copied into the colcon workspace.
PACKAGE_SOURCES = ('setup.py', 'setup.cfg', 'package.xml', 'resource', PACKAGE,
                   'urdf', 'config', 'launch')
# Installed share/ folders and which of their files setup.py picks.
SHARE_FOLDERS = {'urdf': None, 'config': ('.yaml', '.yml'), 'launch': ('.launch.py',)}
EXEC_DEPENDS = {
    'rclpy', 'std_msgs', 'sensor_msgs', 'rosgraph_msgs', 'std_srvs', 'trajectory_msgs',
    'ament_index_python', 'xacro', 'python3-yaml', 'python3-numpy', 'python3-pybullet-pip',
}
IGNORED = shutil.ignore_patterns('__pycache__', '*.pyc', '*.egg-info', 'build')


@pytest.fixture(scope='module')
def prefix() -> pathlib.Path:
    return pathlib.Path(get_package_prefix(PACKAGE))


def _is_executable_file(path: pathlib.Path) -> bool:
    return path.is_file() and os.access(path, os.X_OK)


def _files_under(folder: pathlib.Path, suffixes) -> dict:
    """Map relative path -> bytes for the files setup.py would install."""
    if not folder.is_dir():
        return {}
    found = {}
    for path in folder.rglob('*'):
        if '__pycache__' in path.parts or not path.is_file():
            continue
        if suffixes is None or path.name.endswith(suffixes):
            found[path.relative_to(folder).as_posix()] = path.read_bytes()
    return found


def _script_interpreter(script: pathlib.Path) -> pathlib.Path:
    """Return the interpreter a console script's #! line (or sh trampoline) names."""
    lines = script.read_text().splitlines()
    assert lines[0].startswith('#!'), f'{script} has no #! line'
    if lines[0] == '#!/bin/sh':
        # pip's form for paths too long for #!: '''exec' "/path/python" "$0" "$@"
        match = re.match(r"'''exec' \"?([^\"]+?)\"? \"\$0\"", lines[1])
        assert match, lines[:2]
        return pathlib.Path(match.group(1))
    return pathlib.Path(lines[0][2:].strip())


def _probe(launcher: pathlib.Path, tmp_path: pathlib.Path, extra_env=None) -> dict:
    """Start ``launcher`` in a bare environment; report the Python it became.

    A sitecustomize module (on PYTHONPATH) records the interpreter and PID and
    exits before the console script imports anything, so this tests only the
    launcher chain: no venv on PATH, no VIRTUAL_ENV, nothing activated.
    """
    probe_dir = tmp_path / 'probe'
    probe_dir.mkdir()
    out = tmp_path / 'probe.json'
    (probe_dir / 'sitecustomize.py').write_text(textwrap.dedent("""\
        import json, os, sys
        with open(os.environ['PTS_PROBE_OUT'], 'w') as f:
            json.dump({'prefix': sys.prefix, 'pid': os.getpid(),
                       'orig_argv': sys.orig_argv}, f)
        os._exit(0)
        """))
    env = {'PATH': '/usr/bin:/bin', 'HOME': str(tmp_path),
           'PYTHONPATH': str(probe_dir), 'PTS_PROBE_OUT': str(out), **(extra_env or {})}
    proc = subprocess.Popen([str(launcher), '--probe-arg'], env=env, cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    output, _ = proc.communicate(timeout=60)
    assert proc.returncode == 0, f'{launcher} failed ({proc.returncode}):\n{output}'
    report = json.loads(out.read_text())
    # exec all the way down: the PID ros2 run / launch signals is Python's.
    assert report['pid'] == proc.pid, 'the launcher forked instead of exec-ing'
    assert report['orig_argv'][-1] == '--probe-arg', report['orig_argv']
    return report


def _node_env(tmp_path: pathlib.Path) -> dict:
    return {'PATH': '/usr/bin:/bin', 'HOME': str(tmp_path),
            'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
            'ROS_DOMAIN_ID': os.environ.get('ROS_DOMAIN_ID', '0')}


# --- pip layout (this venv) -------------------------------------------------

def test_ament_index_finds_this_venv(prefix):
    assert prefix.samefile(sys.prefix)
    marker = prefix / 'share/ament_index/resource_index/packages' / PACKAGE
    assert marker.is_file()
    share = pathlib.Path(get_package_share_directory(PACKAGE))
    assert share.samefile(prefix / 'share' / PACKAGE)


def test_tests_use_installed_package_not_source(repo_root):
    import pan_tilt_sim

    location = pathlib.Path(pan_tilt_sim.__file__).resolve().parent
    assert location != (repo_root / PACKAGE).resolve(), (
        'pan_tilt_sim was imported from the source tree; run scripts/run_tests.sh')
    assert 'site-packages' in location.parts


@pytest.mark.parametrize('name', EXECUTABLES)
def test_lib_launcher_and_console_script(prefix, name):
    launcher = prefix / 'lib' / PACKAGE / name
    assert _is_executable_file(launcher), f'{launcher} missing or not executable'
    script = prefix / 'bin' / name
    assert _is_executable_file(script), f'{script} missing or not executable'
    assert _script_interpreter(script).samefile(sys.executable)


def test_ros2_run_sees_exactly_the_entry_points(prefix):
    entry_points = {
        ep.name: ep.value for ep in importlib.metadata.entry_points(group='console_scripts')
        if ep.dist is not None and ep.dist.name.replace('-', '_') == PACKAGE}
    expected = {name: f'{PACKAGE}.tools.{name}:main' for name in EXECUTABLES}
    # sim_node starts through the runner, which installs its signal handlers
    # before rclpy and PyBullet are imported (a Ctrl-C during start-up is clean).
    expected['sim_node'] = f'{PACKAGE}.__main__:main'
    expected[STAND_IN_SCRIPT] = f'{PACKAGE}.tools.stand_ins:main'
    assert entry_points == expected
    # `ros2 run` offers every executable file in lib/<package>/.
    lib = prefix / 'lib' / PACKAGE
    assert {p.name for p in lib.iterdir() if _is_executable_file(p)} == {
        *EXECUTABLES, *STAND_INS}


@pytest.mark.parametrize('name', STAND_INS)
def test_stand_ins_are_in_lib_only_never_on_path(prefix, name):
    assert _is_executable_file(prefix / 'lib' / PACKAGE / name)
    assert not (prefix / 'bin' / name).exists(), f'{name} is on PATH'


def test_a_stand_in_launcher_runs_its_stand_in(prefix):
    # parameter_bridge with no argument prints its usage and exits 255, as ros_gz_bridge's.
    done = subprocess.run([str(prefix / 'lib' / PACKAGE / 'parameter_bridge')],
                          capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 255 and 'parameter_bridge [<topic@ROS2_type@Ign_type>' in (
        done.stdout), done


def test_source_launchers_are_one_script(repo_root):
    folder = repo_root / 'resource/ros2_run'
    assert sorted(p.name for p in folder.iterdir()) == sorted(EXECUTABLES)
    assert len({(folder / name).read_bytes() for name in EXECUTABLES}) == 1


def test_share_has_the_files_the_node_needs(prefix):
    share = prefix / 'share' / PACKAGE
    for relative in ('package.xml', 'urdf/pan_tilt.xacro', 'config/pan_tilt_control.yaml'):
        assert (share / relative).is_file(), f'{share / relative} is missing'


def test_installed_share_matches_source_tree(prefix, repo_root):
    share = prefix / 'share' / PACKAGE
    assert (share / 'package.xml').read_bytes() == (repo_root / 'package.xml').read_bytes()
    for folder, suffixes in SHARE_FOLDERS.items():
        source = _files_under(repo_root / folder, suffixes)
        installed = _files_under(share / folder, suffixes)
        assert installed.keys() == source.keys(), f'share/{PACKAGE}/{folder} is stale'
        stale = [name for name in source if installed[name] != source[name]]
        assert not stale, f'installed copies differ from the source: {stale}'


def test_installed_modules_match_source_tree(repo_root):
    spec = importlib.util.find_spec(PACKAGE)
    installed_dir = pathlib.Path(spec.origin).parent
    source = _files_under(repo_root / PACKAGE, ('.py',))
    installed = _files_under(installed_dir, ('.py',))
    assert installed.keys() == source.keys()
    assert [n for n in source if installed[n] != source[n]] == []


def test_package_xml_is_format_3_ament_python(repo_root):
    root = ElementTree.parse(repo_root / 'package.xml').getroot()
    assert root.get('format') == '3'
    assert root.findtext('name') == PACKAGE
    assert root.findtext('export/build_type') == 'ament_python'
    assert root.findtext('version') == importlib.metadata.version(PACKAGE)
    exec_depends = {e.text for e in root.findall('exec_depend')}
    assert EXEC_DEPENDS <= exec_depends, EXEC_DEPENDS - exec_depends
    catkin_pkg = pytest.importorskip('catkin_pkg.package')
    # Raises InvalidPackage on anything the format-3 spec rejects.
    catkin_pkg.parse_package(str(repo_root / 'package.xml'))


def test_licence_is_apache_2_everywhere(repo_root):
    root = ElementTree.parse(repo_root / 'package.xml').getroot()
    assert root.findtext('license') == 'Apache-2.0'
    assert importlib.metadata.metadata(PACKAGE)['License'] == 'Apache-2.0'
    text = (repo_root / 'LICENSE').read_text()
    assert 'Apache License' in text and 'Version 2.0, January 2004' in text


def test_launcher_runs_venv_python_when_venv_not_activated(prefix, tmp_path):
    report = _probe(prefix / 'lib' / PACKAGE / 'sim_node', tmp_path)
    assert pathlib.Path(report['prefix']).samefile(sys.prefix)


def test_sim_node_starts_through_the_launcher(prefix, tmp_path):
    # A bad parameter ends start-up with exit code 2 before any simulation.
    proc = subprocess.run(
        [str(prefix / 'lib' / PACKAGE / 'sim_node'), '--ros-args', '-p', 'time_step:=-1'],
        env=_node_env(tmp_path), cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stdout + proc.stderr


# --- colcon layout (fresh workspace) ----------------------------------------

@pytest.mark.slow
@pytest.mark.parametrize('mode', ['install', 'symlink-install'])
def test_colcon_build_layout(repo_root, tmp_path, mode):
    if importlib.util.find_spec('colcon_core') is None:
        pytest.skip('colcon is not installed here (pip install colcon-common-extensions)')
    colcon = shutil.which('colcon', path=os.path.dirname(sys.executable))
    if colcon is None:
        pytest.skip(f'no colcon executable beside {sys.executable}')

    source = tmp_path / 'ws/src' / PACKAGE
    source.mkdir(parents=True)
    for item in PACKAGE_SOURCES:
        path = repo_root / item
        if path.is_dir():
            shutil.copytree(path, source / item, ignore=IGNORED)
        elif path.is_file():
            shutil.copy2(path, source / item)
    env = {k: v for k, v in os.environ.items()
           if k not in ('AMENT_PREFIX_PATH', 'COLCON_PREFIX_PATH', 'PYTHONSAFEPATH')}
    env['COLCON_HOME'] = str(tmp_path / 'colcon_home')  # no user defaults
    command = [colcon, '--log-base', 'log', 'build', '--base-paths', 'src',
               '--build-base', 'build', '--install-base', 'install',
               '--event-handlers', 'console_direct+']
    if mode == 'symlink-install':
        command.append('--symlink-install')
    proc = subprocess.run(command, cwd=tmp_path / 'ws', env=env,
                          capture_output=True, text=True, timeout=600)
    output = proc.stdout + proc.stderr
    assert proc.returncode == 0, output
    assert "doesn't explicitly install" not in output, output

    install = tmp_path / 'ws/install' / PACKAGE
    for name in EXECUTABLES:
        assert _is_executable_file(install / 'lib' / PACKAGE / name), name
        assert _is_executable_file(install / 'bin' / name), name
    share = install / 'share' / PACKAGE
    for relative in ('package.xml', 'urdf/pan_tilt.xacro', 'config/pan_tilt_control.yaml'):
        assert (share / relative).is_file(), relative
    assert (install / 'share/ament_index/resource_index/packages' / PACKAGE).is_file()

    # colcon builds with the interpreter that runs it: this venv's.
    report = _probe(install / 'lib' / PACKAGE / 'sim_node', tmp_path)
    assert pathlib.Path(report['prefix']).samefile(sys.prefix)

    # As `ros2 run` after sourcing the workspace: the colcon-built module.
    proc = subprocess.run(
        ['bash', '-c', 'source install/setup.bash && exec "$@"', 'bash',
         str(install / 'lib' / PACKAGE / 'sim_node'), '--ros-args', '-p', 'time_step:=-1'],
        cwd=tmp_path / 'ws', env=_node_env(tmp_path), capture_output=True, text=True,
        timeout=120)
    assert proc.returncode == 2, proc.stdout + proc.stderr

    # colcon compiled the step too, and the workspace's module is the one imported.
    proc = subprocess.run(
        ['bash', '-c', 'source install/setup.bash && exec "$@"', 'bash', sys.executable, '-P',
         '-c', 'from pan_tilt_sim.sim import _compiled_step, compiled_step; '
               'print(compiled_step.unavailable_reason() or "usable"); '
               'print(_compiled_step.__file__)'],
        cwd=tmp_path / 'ws', env=_node_env(tmp_path), capture_output=True, text=True,
        timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    usable, extension = proc.stdout.splitlines()[-2:]
    assert usable == 'usable'
    assert pathlib.Path(extension).resolve().is_relative_to((tmp_path / 'ws').resolve())
