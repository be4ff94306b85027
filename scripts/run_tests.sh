#!/usr/bin/env bash
# Lint and test: scripts/run_tests.sh [pytest arguments...]
#   e.g. scripts/run_tests.sh -k packaging -x
#
# Brings .venv up to date (creates it on first use; reinstalls dependencies
# when requirements*.txt changed and this package when its source changed),
# runs ruff over the tree, then pytest on test/ against the INSTALLED package
# (the tests must see the ament layout a user gets, not the source folder).
# Exit status: non-zero if ruff or pytest failed; pytest's own code (5 = no
# tests collected counts as failure) wins when pytest failed.
set -euo pipefail

# shellcheck source=scripts/_prepare_venv.sh
source "$(dirname -- "${BASH_SOURCE[0]}")/_prepare_venv.sh"
prepare_venv test

export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
# Only this venv: the tests must find this checkout's install and nothing else.
export AMENT_PREFIX_PATH=$VENV
# No script or current folder first on sys.path (`python -m ...` in a test,
# run from the repo root, would otherwise import the source tree).
export PYTHONSAFEPATH=1

cd "$REPO"
lint=0
echo '== ruff check' >&2
"$VENV/bin/ruff" check --no-cache . || lint=$?

echo '== pytest' >&2
tests=0
# The console script, not `python -m pytest`: the latter would put the
# repo root (and its pan_tilt_sim/) first on sys.path.
"$VENV/bin/pytest" "$@" || tests=$?

if (( tests != 0 )); then
    exit "$tests"
elif (( lint != 0 )); then
    echo 'ruff found problems (see above); `.venv/bin/ruff check --fix .` fixes some' >&2
    exit 1
fi
