"""The package's layers: data flows one way, PyBullet and rclpy stay in their layer, no cycles.

model -> controllers -> plugins -> sim -> ros -> tools; ``errors``, ``schedule``
and ``share`` are shared by all; viser (the browser view) only in
``ros/viewer.py``.  Inside controllers/, each family (commands, trajectory,
drives, grippers, broadcasters) uses the framework and the toolbox, never
another family; only the registry (and the manager, through it) knows every
family.  A plugin uses the controllers' framework and toolbox pieces and the
plugins' framework, never a controller family or another plugin.  Read from
the installed package's source with ``ast`` (every import, also those inside
functions), and checked once more by importing: loading model/, controllers/
and plugins/ pulls in neither rclpy nor PyBullet.
"""

import ast
import pathlib
import subprocess
import sys

import pytest
import sim_process

import pan_tilt_sim

PACKAGE = pathlib.Path(pan_tilt_sim.__file__).resolve().parent
SHARED = {'errors', 'schedule', 'share'}
# What each layer may import from the package, besides itself and SHARED.
ALLOWED = {
    'model': set(),
    'controllers': {'model'},
    'plugins': {'model', 'controllers'},
    'sim': {'model', 'controllers', 'plugins'},
    'ros': {'model', 'controllers', 'plugins', 'sim'},
    'tools': {'model', 'controllers', 'plugins', 'sim', 'ros'},
}
# The controllers' modules a plugin may use: the framework and the toolbox (by folder once
# the controllers are sorted into families; by module until then), not a controller family.
CONTROLLER_PIECES = {'framework', 'toolbox', 'base', 'surface', 'odometry', 'odometry_outputs',
                     'rate_limiter', 'parameter_spec', 'hardware_interfaces', 'limits', 'pid'}
PLUGIN_FOLDERS = ('gazebo_classic', 'gz')  # the plugins, one module each
ROS_PACKAGE_SUFFIXES = ('_msgs', '_srvs', '_interfaces')
ROS_PACKAGES = {'rclpy', 'builtin_interfaces'}
VIEWER_MODULE = 'pan_tilt_sim.ros.viewer'  # the browser view: an optional dependency's adapter
CONTROLLERS = 'pan_tilt_sim.controllers'
# Shared by every controller family and plugin: what a new one builds on.
COMMON = {'framework', 'toolbox'}
FAMILIES = {'commands', 'trajectory', 'drives', 'grippers', 'broadcasters'}
REGISTRY = 'pan_tilt_sim.controllers.framework.registry'  # maps YAML types to every family


def modules() -> dict[str, pathlib.Path]:
    """Return every module of the package by dotted name."""
    found = {}
    for path in PACKAGE.rglob('*.py'):
        parts = path.relative_to(PACKAGE.parent).with_suffix('').parts
        name = '.'.join(parts[:-1] if parts[-1] == '__init__' else parts)
        found[name] = path
    return found


def imports(path: pathlib.Path) -> set[str]:
    """Return every module ``path`` imports, anywhere in it (top-level names and dotted)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
            names.update(f'{node.module}.{alias.name}' for alias in node.names)
    return names


def layer(module: str) -> str:
    """Return the layer of a package module: its first sub-package, or '' at the top."""
    parts = module.split('.')
    return parts[1] if len(parts) > 2 else ''


MODULES = modules()


def test_the_package_has_the_layer_folders():
    assert set(ALLOWED) <= {path.name for path in PACKAGE.iterdir() if path.is_dir()}


@pytest.mark.parametrize('module', sorted(MODULES))
def test_pybullet_is_imported_only_in_the_sim_layer(module):
    uses_pybullet = any(name.split('.')[0] == 'pybullet' for name in imports(MODULES[module]))
    assert not uses_pybullet or layer(module) == 'sim', module


@pytest.mark.parametrize('module', sorted(MODULES))
def test_viser_is_imported_only_by_the_browser_view(module):
    uses_viser = any(name.split('.')[0] == 'viser' for name in imports(MODULES[module]))
    assert not uses_viser or module == VIEWER_MODULE, module


@pytest.mark.parametrize('module', sorted(MODULES))
def test_rclpy_and_ros_messages_are_imported_only_in_ros_and_tools(module):
    ros = sorted(name for name in imports(MODULES[module])
                 if name.split('.')[0] in ROS_PACKAGES
                 or name.split('.')[0].endswith(ROS_PACKAGE_SUFFIXES))
    if layer(module) in ('ros', 'tools') or module == 'pan_tilt_sim.sim_node':
        return  # the top-level sim_node only re-exports the node
    assert not ros, f'{module} imports {ros}'


@pytest.mark.parametrize('module', sorted(m for m in MODULES if layer(m) in ALLOWED))
def test_each_layer_imports_only_the_layers_below_it(module):
    own = layer(module)
    for name in imports(MODULES[module]):
        if not name.startswith('pan_tilt_sim.'):
            continue
        target = name.split('.')[1]
        if target in SHARED or target == own:
            continue
        assert target in ALLOWED[own], f'{module} ({own}) imports {name} ({target})'


def test_no_module_imports_one_that_imports_it_back():
    graph = {name: {dep for dep in imports(path) if dep in MODULES and dep != name}
             for name, path in MODULES.items()}
    cycles = []

    def reaches(start: str, goal: str) -> bool:
        seen, pending = set(), [start]
        while pending:
            current = pending.pop()
            if current == goal:
                return True
            if current not in seen:
                seen.add(current)
                pending.extend(graph[current])
        return False

    for module, deps in graph.items():
        cycles.extend((module, dep) for dep in deps if reaches(dep, module))
    assert cycles == []


def plugin_modules() -> list[str]:
    """Return the plugin modules (one per plugin, in ``plugins/<generation>/``)."""
    return sorted(name for name in MODULES if layer(name) == 'plugins'
                  and len(name.split('.')) == 4 and name.split('.')[2] in PLUGIN_FOLDERS)


def test_there_are_plugin_modules():
    assert len(plugin_modules()) >= 6


@pytest.mark.parametrize('module', plugin_modules())
def test_a_plugin_uses_the_controllers_framework_and_toolbox_but_no_family(module):
    for name in imports(MODULES[module]):
        parts = name.split('.')
        if parts[:2] == ['pan_tilt_sim', 'controllers'] and len(parts) > 2:
            assert parts[2] in CONTROLLER_PIECES, f'{module} imports {name} (a controller family)'


@pytest.mark.parametrize('module', plugin_modules())
def test_a_plugin_uses_no_other_plugin_only_the_plugins_framework(module):
    for name in imports(MODULES[module]):
        parts = name.split('.')
        if parts[:2] == ['pan_tilt_sim', 'plugins'] and len(parts) > 2:
            assert parts[2] == 'framework', f'{module} imports {name} (another plugin)'


def test_importing_model_controllers_and_plugins_pulls_in_neither_rclpy_nor_pybullet():
    names = sorted(m for m in MODULES if layer(m) in ('model', 'controllers', 'plugins'))
    code = '; '.join([*(f'import {name}' for name in names),
                      'import sys',
                      "print(sorted(m for m in ('rclpy', 'pybullet') if m in sys.modules))"])
    result = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                            env=sim_process.environment(), timeout=60, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == '[]'
    assert len(names) > 20  # every module of the three layers was imported


def controller_part(module: str) -> str:
    """Return a controllers module's part: its family folder, or its own name at the top."""
    return module.split('.')[2] if module.startswith(CONTROLLERS + '.') else ''


def is_plugin(module: str) -> bool:
    """Return whether ``module`` is a Gazebo plugin (in plugins/, or still beside the families)."""
    return (layer(module) == 'plugins'
            or (module.startswith(CONTROLLERS + '.') and module.count('.') == 2
                and controller_part(module) not in COMMON | FAMILIES))


def package_imports(module: str) -> set[str]:
    """Return the package modules ``module`` imports (a name imported from a module counts
    as that module)."""
    return {name if name in MODULES else name.rpartition('.')[0]
            for name in imports(MODULES[module])
            if name in MODULES or name.rpartition('.')[0] in MODULES} - {module}


def test_the_controllers_are_sorted_into_family_folders():
    folders = {path.name for path in (PACKAGE / 'controllers').iterdir()
               if (path / '__init__.py').exists()}
    assert folders == COMMON | FAMILIES
    assert (PACKAGE / 'controllers' / 'drives' / 'steering' / '__init__.py').exists()


@pytest.mark.parametrize('module', sorted(m for m in MODULES
                                          if controller_part(m) in FAMILIES or is_plugin(m)))
def test_families_and_plugins_use_the_framework_and_toolbox_not_each_other(module):
    own = module.split('.')[:3]
    for name in package_imports(module):
        if not name.startswith(CONTROLLERS + '.'):
            continue
        part = controller_part(name)
        if part in COMMON or name.split('.')[:3] == own:
            continue  # the shared parts, or the module's own family
        if is_plugin(module) and is_plugin(name):
            continue  # plugins among themselves: the plugins' own rule
        pytest.fail(f'{module} imports {name}: a family or plugin uses only '
                    f'controllers.framework and controllers.toolbox besides itself')


@pytest.mark.parametrize('module', sorted(m for m in MODULES if controller_part(m) in COMMON))
def test_the_framework_and_toolbox_know_no_family_but_through_the_registry(module):
    for name in package_imports(module):
        if module == REGISTRY or name == REGISTRY:
            continue
        assert controller_part(name) not in FAMILIES and not is_plugin(name), (
            f'{module} imports {name}')
