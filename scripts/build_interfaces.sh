#!/usr/bin/env bash
# Build the interface packages of interfaces/ into .venv now:
#   scripts/build_interfaces.sh            build what is missing or out of date
#   scripts/build_interfaces.sh --force    rebuild all of them
#   scripts/build_interfaces.sh --status   print what is built, build nothing
#
# scripts/run_tests.sh builds them by itself; scripts/run_sim.sh does not (its
# first start would take minutes longer) but uses them once built, so this is
# the command for a simulator-only venv. It brings .venv up to date as
# run_sim.sh does, installs requirements-build.txt and runs
# scripts/build_interfaces.py (about 1.5 min on 2 cores the first time).
# Packages a ROS install on AMENT_PREFIX_PATH / PYTHONPATH provides are not
# built (see interfaces/README.md).
set -euo pipefail

case ${1:-} in
    '') ;;
    --force) export PAN_TILT_SIM_INTERFACES_FORCE=1 ;;
    --status)
        venv=${PAN_TILT_SIM_VENV:-$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd)/.venv}
        [[ -x $venv/bin/python ]] || { echo "no venv at $venv: nothing built" >&2; exit 1; }
        exec "$venv/bin/python" "$(dirname -- "${BASH_SOURCE[0]}")/build_interfaces.py" \
            --prefix "$venv" --status ;;
    *) sed -n '2,5p' "${BASH_SOURCE[0]}" >&2; exit 2 ;;
esac

# shellcheck source=scripts/_prepare_venv.sh
source "$(dirname -- "${BASH_SOURCE[0]}")/_prepare_venv.sh"
export PAN_TILT_SIM_INTERFACES=build
prepare_venv runtime
"$VENV/bin/python" "$REPO/scripts/build_interfaces.py" --prefix "$VENV" --status
