"""Where the package's data files are: ``share/pan_tilt_sim`` (no ROS imports).

Tools that run without a ROS graph (``step_response``) and launch files need
the default model and controllers as much as sim_node does.
"""

from __future__ import annotations

import pathlib
import sys

PACKAGE_NAME = 'pan_tilt_sim'
DEFAULT_DESCRIPTION = pathlib.Path('urdf', 'pan_tilt.xacro')
DEFAULT_CONTROLLERS = pathlib.Path('config', 'pan_tilt_control.yaml')
# The default model's robot name: the default controllers file is for this robot only.
DEFAULT_ROBOT_NAME = 'ex_urdf_pan_tilt'


def package_share() -> pathlib.Path:
    """Locate ``share/pan_tilt_sim`` (ament index, this prefix, or the source tree)."""
    try:
        from ament_index_python.packages import get_package_share_directory

        return pathlib.Path(get_package_share_directory(PACKAGE_NAME))
    except (ImportError, LookupError, OSError):
        # Not indexed (AMENT_PREFIX_PATH unset or without us): try where pip
        # puts data files, then the source checkout this module lives in.
        installed = pathlib.Path(sys.prefix, 'share', PACKAGE_NAME)
        if installed.is_dir():
            return installed
        return pathlib.Path(__file__).resolve().parents[1]
