"""scripts/_find_python.sh: which Python the scripts make a venv with.

Each case runs the real shell functions against stand-in interpreters (small
scripts that print a version, or refuse like an inactive pyenv shim) on a PATH
and a pyenv root made for it, so the machine's own Pythons never take part.
"""

import os
import pathlib
import shutil
import subprocess

import pytest

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
FIND_PYTHON = REPO_ROOT / 'scripts' / '_find_python.sh'


def _write_executable(path: pathlib.Path, body: str) -> pathlib.Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f'#!/bin/sh\n{body}\n')
    path.chmod(0o755)
    return path


def interpreter(path: pathlib.Path, version: str) -> pathlib.Path:
    """A stand-in Python that answers any ``-c`` with its X.Y."""
    return _write_executable(path, f'echo {version}')


def refusing_shim(path: pathlib.Path) -> pathlib.Path:
    """A pyenv shim for a version pyenv has not made active: on PATH, but it will not run."""
    return _write_executable(path, f'echo "pyenv: {path.name}: command not found" >&2; exit 127')


@pytest.fixture
def machine(tmp_path):
    """A bin folder for PATH, a pyenv root, and the few tools the functions use."""
    tools = tmp_path / 'tools'
    tools.mkdir()
    for tool in ('sort', 'head'):
        (tools / tool).symlink_to(shutil.which(tool))
    return {'bin': tmp_path / 'bin', 'pyenv': tmp_path / 'pyenv', 'tools': tools}


def choose(machine, chosen_by_user: str | None = None) -> subprocess.CompletedProcess:
    env = {'PATH': f'{machine["bin"]}{os.pathsep}{machine["tools"]}',
           'PYENV_ROOT': str(machine['pyenv'])}
    if chosen_by_user is not None:
        env['PAN_TILT_SIM_PYTHON'] = chosen_by_user
    script = f'source {FIND_PYTHON}; pts_choose_python && echo "$PTS_PYTHON $PTS_PYTHON_VERSION"'
    return subprocess.run([shutil.which('bash'), '-c', script], env=env, capture_output=True,
                          text=True, timeout=30, check=False)


def test_python312_on_path_is_preferred_to_python311(machine):
    interpreter(machine['bin'] / 'python3.11', '3.11')
    python312 = interpreter(machine['bin'] / 'python3.12', '3.12')
    result = choose(machine)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == [str(python312), '3.12']


def test_without_312_the_311_on_path_is_the_default(machine):
    python311 = interpreter(machine['bin'] / 'python3.11', '3.11')
    result = choose(machine)
    assert result.stdout.split() == [str(python311), '3.11']


def test_a_shim_that_refuses_is_passed_over_for_the_newest_pyenv_312_release(machine):
    refusing_shim(machine['bin'] / 'python3.12')
    interpreter(machine['bin'] / 'python3.11', '3.11')
    versions = machine['pyenv'] / 'versions'
    for release in ('3.12.1', '3.12.10', '3.12.4'):
        interpreter(versions / release / 'bin' / 'python3.12', '3.12')
    # Neither a development build nor a free-threaded one is a release to pick.
    interpreter(versions / '3.12-dev' / 'bin' / 'python3.12', '3.12')
    interpreter(versions / '3.12.11t' / 'bin' / 'python3.12', '3.12')
    result = choose(machine)
    assert result.stdout.split() == [str(versions / '3.12.10' / 'bin' / 'python3.12'), '3.12']


def test_an_interpreter_that_reports_another_version_is_not_taken(machine):
    interpreter(machine['bin'] / 'python3.12', '3.10')
    python311 = interpreter(machine['bin'] / 'python3.11', '3.11')
    assert choose(machine).stdout.split() == [str(python311), '3.11']


def test_with_neither_the_message_gives_the_apt_lines_for_ubuntu_2404_and_debian_12(machine):
    refusing_shim(machine['bin'] / 'python3.12')
    interpreter(machine['bin'] / 'python3.10', '3.10')
    result = choose(machine)
    assert result.returncode != 0
    assert result.stdout == ''
    assert 'no Python 3.12 or 3.11 found' in result.stderr
    assert 'Ubuntu 24.04: sudo apt-get install python3.12-venv python3.12-dev g++' in result.stderr
    assert 'Debian 12: sudo apt-get install python3.11-venv python3.11-dev g++' in result.stderr


def test_pan_tilt_sim_python_chooses_311_where_312_exists(machine):
    interpreter(machine['bin'] / 'python3.12', '3.12')
    python311 = interpreter(machine['bin'] / 'python3.11', '3.11')
    result = choose(machine, chosen_by_user=str(python311))
    assert result.stdout.split() == [str(python311), '3.11']


def test_pan_tilt_sim_python_of_an_unsupported_version_is_refused(machine):
    interpreter(machine['bin'] / 'python3.12', '3.12')
    python310 = interpreter(machine['bin'] / 'python3.10', '3.10')
    result = choose(machine, chosen_by_user=str(python310))
    assert result.returncode != 0
    assert f'PAN_TILT_SIM_PYTHON={python310} is Python 3.10' in result.stderr
    assert 'need 3.12 or 3.11' in result.stderr


def test_pan_tilt_sim_python_that_does_not_run_says_why(machine):
    shim = refusing_shim(machine['bin'] / 'python3.12')
    result = choose(machine, chosen_by_user='python3.12')
    assert result.returncode != 0
    assert f'PAN_TILT_SIM_PYTHON=python3.12 does not run: pyenv: {shim.name}: command not found' \
        in result.stderr
