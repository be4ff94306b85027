#!/usr/bin/env bash
# Run the simulator: scripts/run_sim.sh [--viewer] [sim_node arguments...]
#   e.g. scripts/run_sim.sh --ros-args -p real_time_factor:=0
#        scripts/run_sim.sh --viewer     # and open the URL it prints in a browser
#
# --viewer installs the browser view's package (requirements-viewer.txt) when
# it is missing and starts sim_node with viewer:=true.
# First use creates .venv (Python 3.12 where the machine has it, else 3.11;
# PAN_TILT_SIM_PYTHON chooses) and installs the dependencies and this
# package; later runs reinstall only what changed. Then it starts sim_node the
# way `ros2 run pan_tilt_sim sim_node` does: looks the package up in the ament
# index and execs <prefix>/lib/pan_tilt_sim/sim_node, so sim_node gets this
# script's PID and signals (Ctrl-C, kill) reach it directly.
set -euo pipefail

# shellcheck source=scripts/_prepare_venv.sh
source "$(dirname -- "${BASH_SOURCE[0]}")/_prepare_venv.sh"
prepare_venv runtime

args=()
viewer=false
for arg in "$@"; do
    if [[ $arg == --viewer && $viewer == false ]]; then viewer=true; else args+=("$arg"); fi
done
if [[ $viewer == true ]]; then
    if ! "$VENV/bin/python" -c 'import viser' 2>/dev/null; then
        _pts_say "installing the browser view (requirements-viewer.txt)"
        "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check \
                -r "$REPO/requirements-viewer.txt" \
            || _pts_die "installing requirements-viewer.txt failed"
    fi
    # A second --ros-args section: ROS reads them all.
    args+=(--ros-args -p viewer:=true)
fi

# DDS on loopback only, unless the caller chose otherwise.
export ROS_AUTOMATIC_DISCOVERY_RANGE=${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}
# The venv is an ament prefix (share/ament_index/...); it goes first so this
# checkout's pan_tilt_sim wins, other prefixes stay for package:// look-ups.
export AMENT_PREFIX_PATH=$VENV${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}

prefix=$("$VENV/bin/python" -c \
    'from ament_index_python.packages import get_package_prefix as p; print(p("pan_tilt_sim"))')
exec "$prefix/lib/pan_tilt_sim/sim_node" "${args[@]}"
