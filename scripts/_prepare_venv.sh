# shellcheck shell=bash
# Sourced by run_sim.sh and run_tests.sh: bring the repo's venv up to date.
#
#   prepare_venv runtime|test
#
# * creates $VENV (default <repo>/.venv) with python3.11 on first use;
# * pip-installs requirements.txt (runtime) or requirements-test.txt (test)
#   only when those files changed since the last install (hash in a stamp);
# * installs this package (not editable) from a throw-away copy of the
#   source, only when the source changed since the last install, so the
#   venv's ament layout (lib/pan_tilt_sim/, share/pan_tilt_sim/, ament index
#   marker) always matches the tree and the tree gets no build/ or egg-info;
#   also when a C compiler appeared or went (the compiled step is optional);
# * builds the interface packages of interfaces/ (tf2_msgs, control_msgs,
#   controller_manager_msgs, simulation_interfaces: not on PyPI) into the
#   venv with scripts/build_interfaces.py, in test mode (or when asked), only
#   when interfaces/, that script, the requirements or AMENT_PREFIX_PATH /
#   PYTHONPATH changed since the last build; the script itself skips a
#   package that a ROS install (or anything else) already provides and
#   rebuilds only the packages whose definitions changed;
# * leaves REPO and VENV set, PYTHONPATH unset (a sourced ROS install's
#   Python 3.12 packages must not shadow the venv's).
#
# Environment: PAN_TILT_SIM_VENV (venv path), PAN_TILT_SIM_PYTHON
# (interpreter to create it with, default python3.11),
# PAN_TILT_SIM_INTERFACES: auto (default: `test` builds the interface
# packages, `runtime` uses whatever is built), build (`runtime` builds them
# too, installing requirements-build.txt) or skip (never build);
# PAN_TILT_SIM_INTERFACES_FORCE=1 rebuilds them even when up to date.

REPO=$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd)
VENV=${PAN_TILT_SIM_VENV:-$REPO/.venv}
_PTS_PYTHON=${PAN_TILT_SIM_PYTHON:-python3.11}
# What setup.py installs from; a change to any of these reinstalls.
_PTS_SOURCES=(setup.py setup.cfg package.xml resource pan_tilt_sim urdf config launch)
_PTS_PY311='import sys; sys.exit(sys.version_info[:2] != (3, 11))'

_pts_say() { echo "[pan_tilt_sim] $*" >&2; }
_pts_die() { _pts_say "error: $*"; exit 1; }

_pts_create_venv() {
    command -v "$_PTS_PYTHON" >/dev/null \
        || _pts_die "$_PTS_PYTHON not found; this project needs Python 3.11"
    "$_PTS_PYTHON" -c "$_PTS_PY311" \
        || _pts_die "$_PTS_PYTHON is not Python 3.11 (the ROS Jazzy wheels are built for 3.11)"
    _pts_say "creating $VENV with $_PTS_PYTHON"
    # --clear: a half-made venv (e.g. ensurepip was missing) is redone.
    "$_PTS_PYTHON" -m venv --clear "$VENV" \
        || _pts_die "cannot create a venv; on Debian/Ubuntu: sudo apt-get install python3.11-venv"
}

_pts_hash() { sha256sum | cut -d' ' -f1; }

# tar of the given repo paths, names, modes and contents only, for hashing.
_pts_tar() {
    tar -C "$REPO" --sort=name --owner=0 --group=0 --numeric-owner --mtime=@0 \
        --exclude=__pycache__ --exclude='*.pyc' --exclude='*.egg-info' -cf - "$@"
}

# Hash of the source files setup.py installs: names, modes and contents.
_pts_source_hash() {
    local present=() item
    for item in "${_PTS_SOURCES[@]}"; do
        [[ -e $REPO/$item ]] && present+=("$item")
    done
    _pts_tar "${present[@]}" | _pts_hash
}

_pts_install_package() {
    local tmp present=() item
    tmp=$(mktemp -d "${TMPDIR:-/tmp}/pan_tilt_sim-src.XXXXXX")
    for item in "${_PTS_SOURCES[@]}"; do
        [[ -e $REPO/$item ]] && present+=("$item")
    done
    tar -C "$REPO" --exclude=__pycache__ --exclude='*.pyc' --exclude='*.egg-info' \
        -cf - "${present[@]}" | tar -C "$tmp" -xf -
    _pts_say "installing pan_tilt_sim from the source tree into $VENV"
    if ! "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check \
            --no-deps --no-build-isolation --force-reinstall "$tmp"; then
        rm -rf -- "$tmp"
        _pts_die "installing pan_tilt_sim failed"
    fi
    rm -rf -- "$tmp"
}

# Build interfaces/ into the venv when due (see the top of this file).
_pts_interfaces() {
    local mode=$1 deps_hash=$2 want=${PAN_TILT_SIM_INTERFACES:-auto} key stamp force=()
    case $want in
        auto) [[ $mode == test ]] || return 0 ;;
        build) ;;
        skip) return 0 ;;
        *) _pts_die "PAN_TILT_SIM_INTERFACES is auto, build or skip, not '$want'" ;;
    esac
    # What a ROS install on these paths provides is not built (the script
    # checks), so they are part of the key.
    key=$({ echo "$deps_hash"; printf '%s\n' "${AMENT_PREFIX_PATH:-}" "${PYTHONPATH:-}"
            _pts_tar interfaces scripts/build_interfaces.py; } | _pts_hash)
    stamp=$VENV/.pan_tilt_sim-interfaces
    if [[ -n ${PAN_TILT_SIM_INTERFACES_FORCE:-} ]]; then
        force=(--force)
    elif [[ "$(cat "$stamp" 2>/dev/null)" == "$key" ]]; then
        return 0
    fi
    if [[ "$(cat "$VENV/.pan_tilt_sim-deps-test" 2>/dev/null)" != "$deps_hash" \
            && "$(cat "$VENV/.pan_tilt_sim-deps-build" 2>/dev/null)" != "$deps_hash" ]]; then
        _pts_say "installing requirements-build.txt (the rosidl generators)"
        "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check \
                -r "$REPO/requirements-build.txt" \
            || _pts_die "installing requirements-build.txt failed"
        echo "$deps_hash" >"$VENV/.pan_tilt_sim-deps-build"
    fi
    "$VENV/bin/python" "$REPO/scripts/build_interfaces.py" --prefix "$VENV" "${force[@]}" \
        || _pts_die "building the interface packages failed (PAN_TILT_SIM_INTERFACES=skip does without them)"
    echo "$key" >"$stamp"
}

prepare_venv() {
    local mode=$1 reqs deps_hash deps_stamp src_hash src_stamp
    case $mode in
        runtime) reqs=$REPO/requirements.txt ;;
        test) reqs=$REPO/requirements-test.txt ;;
        *) _pts_die "prepare_venv: unknown mode $mode" ;;
    esac

    mkdir -p -- "$(dirname -- "$VENV")"
    # One script at a time may change the venv (run_sim and run_tests may
    # start together); the lock is dropped before the caller runs anything.
    if command -v flock >/dev/null; then
        exec {_PTS_LOCK_FD}<"$(dirname -- "$VENV")"
        flock "$_PTS_LOCK_FD"
    fi

    if ! { [[ -x $VENV/bin/python && -x $VENV/bin/pip ]] \
            && "$VENV/bin/python" -c "$_PTS_PY311" 2>/dev/null; }; then
        _pts_create_venv
    fi

    # The test set includes the runtime set, so a current test stamp is
    # enough for runtime use too.
    deps_hash=$(cat "$REPO/requirements.txt" "$REPO/requirements-test.txt" \
        "$REPO/requirements-build.txt" "$REPO/requirements-viewer.txt" | _pts_hash)
    deps_stamp=$VENV/.pan_tilt_sim-deps-$mode
    if [[ "$(cat "$deps_stamp" 2>/dev/null)" != "$deps_hash" \
            && "$(cat "$VENV/.pan_tilt_sim-deps-test" 2>/dev/null)" != "$deps_hash" ]]; then
        _pts_say "installing dependencies from ${reqs#"$REPO"/} (first run: about a minute)"
        "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check -r "$reqs" \
            || _pts_die "installing dependencies failed"
        echo "$deps_hash" >"$deps_stamp"
    fi

    # Which C compiler there is, too: the compiled step (an optional C extension)
    # is built on the first install after one appears.
    src_hash=$({ echo "$deps_hash"; _pts_source_hash; command -v cc gcc || true; } | _pts_hash)
    src_stamp=$VENV/.pan_tilt_sim-source
    if [[ "$(cat "$src_stamp" 2>/dev/null)" != "$src_hash" \
            || ! -x $VENV/lib/pan_tilt_sim/sim_node ]]; then
        _pts_install_package
        echo "$src_hash" >"$src_stamp"
    fi

    _pts_interfaces "$mode" "$deps_hash"

    if [[ -n ${_PTS_LOCK_FD:-} ]]; then
        exec {_PTS_LOCK_FD}<&-
        unset _PTS_LOCK_FD
    fi
    unset PYTHONPATH
}
