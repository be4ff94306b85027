"""Install pan_tilt_sim in the ament layout, with colcon or with pip.

Both ways give the same prefix layout, the one ``ros2 run`` and the ament
index expect:

* ``lib/pan_tilt_sim/<executable>``: a small launcher (``resource/ros2_run``)
  that execs ``bin/<executable>``, the console script. pip ignores
  setup.cfg's ``install_scripts``, so the launchers come through
  ``data_files``, and setup.cfg deliberately leaves the console scripts in
  ``bin/`` for colcon too, so the two never land on the same path.
* ``share/pan_tilt_sim/``: package.xml, urdf/ (with any subfolders),
  config/*.yaml, launch/*.launch.py.
* ``share/ament_index/resource_index/packages/pan_tilt_sim``: the marker.

One C extension, ``pan_tilt_sim.sim._compiled_step`` (PyBullet's per-step
calls from C, see ``pan_tilt_sim/sim/compiled_step.py``), is optional: where
it cannot be compiled, the install goes on and the physics steps through
PyBullet's Python module.
"""

import os
import xml.etree.ElementTree as ElementTree

from setuptools import Extension, find_packages, setup

PACKAGE = 'pan_tilt_sim'
EXECUTABLES = {
    'sim_node': 'pan_tilt_sim.__main__:main',  # signals handled before rclpy loads
    'bench': 'pan_tilt_sim.tools.bench:main',
    'step_response': 'pan_tilt_sim.tools.step_response:main',
    'tune': 'pan_tilt_sim.tools.tune:main',
    'sweep': 'pan_tilt_sim.tools.sweep:main',
}
# The Gazebo-side stand-ins (create, parameter_bridge, ...; pan_tilt_sim.tools.stand_ins):
# launchers in lib/pan_tilt_sim/ only, all running one console script of an unmistakable
# name, so that their generic names never land on PATH.
STAND_INS = ('create', 'parameter_bridge', 'image_bridge', 'spawn_entity.py',
             'ros2_control_node')
STAND_IN_SCRIPT = 'pan_tilt_sim_stand_in'
HERE = os.path.dirname(os.path.abspath(__file__))
SHARE = os.path.join('share', PACKAGE)


def _files(folder, suffixes=None):
    """Return ``(install dir, [files])`` pairs for a source folder, recursively.

    Paths are relative to this file's folder (colcon checks them that way).
    A missing or empty folder gives no pairs.
    """
    pairs = []
    for root, dirs, names in os.walk(os.path.join(HERE, folder)):
        dirs[:] = sorted(d for d in dirs if d != '__pycache__')
        picked = sorted(
            os.path.relpath(os.path.join(root, name), HERE) for name in names
            if suffixes is None or name.endswith(suffixes))
        if picked:
            rel_dir = os.path.relpath(root, HERE)
            pairs.append((os.path.join(SHARE, rel_dir), picked))
    return pairs


def _version():
    """Return the version from package.xml, the one place it is written."""
    return ElementTree.parse(os.path.join(HERE, 'package.xml')).getroot().findtext('version')


setup(
    name=PACKAGE,
    version=_version(),
    packages=find_packages(include=[PACKAGE, PACKAGE + '.*']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + PACKAGE]),
        (SHARE, ['package.xml']),
        ('lib/' + PACKAGE, ['resource/ros2_run/' + name for name in EXECUTABLES]
         + ['resource/stand_ins/' + name for name in STAND_INS]),
        *_files('urdf'),
        *_files('config', ('.yaml', '.yml')),
        *_files('launch', ('.launch.py',)),
    ],
    # Run-time dependencies are declared in package.xml (rosdep) and, for a
    # venv without ROS, in requirements.txt; listing them here would make
    # pip fetch ROS wheels into a ROS install.
    ext_modules=[Extension(
        f'{PACKAGE}.sim._compiled_step', [f'{PACKAGE}/sim/_compiled_step.c'],
        # No fused multiply-adds: the compiled laws must round as Python does.
        extra_compile_args=['-O2', '-fvisibility=hidden', '-ffp-contract=off'],
        libraries=['dl'], optional=True)],
    install_requires=['setuptools'],
    zip_safe=False,  # an extension module is never imported from a zip
    maintainer='pan_tilt_sim maintainers',
    maintainer_email='maintainers@users.noreply.h-seed-816557ff.example',
    description='Headless PyBullet stand-in for Gazebo + gazebo_ros_control.',
    license='Apache-2.0',
    python_requires='>=3.10',
    entry_points={
        'console_scripts': [f'{name} = {target}' for name, target in EXECUTABLES.items()]
        + [f'{STAND_IN_SCRIPT} = {PACKAGE}.tools.stand_ins:main'],
        # The sim fixtures for users' tests (inert unless a test asks for them).
        'pytest11': ['pan_tilt_sim = pan_tilt_sim.tools.pytest_plugin'],
    },
)
