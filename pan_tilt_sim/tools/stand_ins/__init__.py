"""Stand-ins for the Gazebo-side packages' entry points, with their own arguments.

ros_gz_sim's ``create`` and ``gz_sim.launch.py``, ros_gz_bridge's ``parameter_bridge``,
ros_gz_image's ``image_bridge``, gazebo_ros's ``spawn_entity.py`` and
``gazebo.launch.py``, controller_manager's ``ros2_control_node``: a launch file that
names ``pan_tilt_sim`` in their package's place runs on sim_node.  They are
installed in ``<prefix>/lib/pan_tilt_sim/`` only (``ros2 run``, launch's ``Node``),
never on PATH: ``<prefix>/bin/pan_tilt_sim_stand_in NAME ARGS`` runs one.
docs/launch-files.md is the user's reference.
"""

from __future__ import annotations

import importlib
import sys

# Executable name -> module of this package whose main(argv) runs it.
STAND_INS = {
    'create': 'create',
    'parameter_bridge': 'parameter_bridge',
    'image_bridge': 'image_bridge',
    'spawn_entity.py': 'spawn_entity',
    'ros2_control_node': 'ros2_control_node',
}


def main(argv: list[str] | None = None) -> None:
    """Run the stand-in ``argv[1]`` names with the rest of ``argv`` as its command line."""
    argv = list(sys.argv if argv is None else argv)
    if len(argv) < 2 or argv[1] not in STAND_INS:
        sys.stderr.write(f"usage: pan_tilt_sim_stand_in {{{','.join(STAND_INS)}}} ARGS...\n")
        sys.exit(2)
    module = importlib.import_module(f'{__name__}.{STAND_INS[argv[1]]}')
    module.main([argv[1], *argv[2:]])
