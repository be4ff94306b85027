# shellcheck shell=bash
# Sourced by run_sim.sh and run_tests.sh: bring the repo's venv up to date.
#
#   prepare_venv runtime|test
#
# * creates $VENV (default <repo>/.venv) on first use with the machine's
#   default Python, 3.12 or else 3.11 (see _find_python.sh), or with
#   PAN_TILT_SIM_PYTHON; an existing venv on a supported version is kept
#   unless PAN_TILT_SIM_PYTHON names another version;
# * installs PyBullet 3.2.7's source as one distribution (requirements.txt,
#   docs/install.md): upstream's wheel where PyPI has one (3.11), else
#   pybullet-arm64's wheel (3.12), else upstream's built from its source
#   (several minutes, once) into PAN_TILT_SIM_WHEELS (default
#   ~/.cache/pan_tilt_sim/wheels), which every later install, in any venv
#   or clone, takes it from; again when PAN_TILT_SIM_PYBULLET or those
#   requirement lines change;
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
#   packages, built for the system's Python and libraries, must not shadow
#   the venv's).
#
# Environment: PAN_TILT_SIM_VENV (venv path), PAN_TILT_SIM_PYTHON
# (interpreter to create it with, default: the machine's default Python),
# PAN_TILT_SIM_WHEELS (where wheels built from source are kept),
# PAN_TILT_SIM_PYBULLET: auto (default) or upstream (never pybullet-arm64),
# PAN_TILT_SIM_INTERFACES: auto (default: `test` builds the interface
# packages, `runtime` uses whatever is built), build (`runtime` builds them
# too, installing requirements-build.txt) or skip (never build);
# PAN_TILT_SIM_INTERFACES_FORCE=1 rebuilds them even when up to date.

REPO=$(cd -- "$(dirname -- "${BASH_SOURCE[0]}")/.." && pwd)
VENV=${PAN_TILT_SIM_VENV:-$REPO/.venv}
_PTS_WHEELS=${PAN_TILT_SIM_WHEELS:-${XDG_CACHE_HOME:-${HOME:-$REPO}/.cache}/pan_tilt_sim/wheels}
# What setup.py installs from; a change to any of these reinstalls.
_PTS_SOURCES=(setup.py setup.cfg package.xml resource pan_tilt_sim urdf config launch)

# shellcheck source=scripts/_find_python.sh
source "$REPO/scripts/_find_python.sh"

_pts_say() { echo "[pan_tilt_sim] $*" >&2; }
_pts_die() { _pts_say "error: $*"; exit 1; }

# Make $VENV with the chosen Python unless it already runs a supported one
# (and PAN_TILT_SIM_PYTHON, when set, names that same version).
_pts_ensure_venv() {
    local have=
    if [[ -x $VENV/bin/python && -x $VENV/bin/pip ]]; then
        have=$(pts_python_version "$VENV/bin/python") || have=
    fi
    if [[ -n $have ]] && pts_is_supported "$have" && [[ -z ${PAN_TILT_SIM_PYTHON:-} ]]; then
        return 0
    fi
    pts_choose_python || _pts_die 'no Python to create the venv with (see above)'
    [[ $have == "$PTS_PYTHON_VERSION" ]] && return 0
    if [[ -n $have ]]; then
        _pts_say "$VENV runs Python $have; recreating it with $PTS_PYTHON (Python $PTS_PYTHON_VERSION)"
    else
        _pts_say "creating $VENV with $PTS_PYTHON (Python $PTS_PYTHON_VERSION)"
    fi
    # --clear: a half-made venv (e.g. ensurepip was missing) is redone.
    "$PTS_PYTHON" -m venv --clear "$VENV" \
        || _pts_die "cannot create a venv; on Debian/Ubuntu: sudo apt-get install python$PTS_PYTHON_VERSION-venv"
}

# What building C/C++ extensions for the venv's Python lacks: the Debian/Ubuntu
# packages to install, on one line (empty when nothing is missing).
_pts_missing_build_packages() {
    local version missing=()
    version=$(pts_python_version "$VENV/bin/python")
    command -v g++ >/dev/null || command -v c++ >/dev/null || missing+=(g++)
    "$VENV/bin/python" -c 'import os, sys, sysconfig
sys.exit(not os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")))' \
        || missing+=("python$version-dev")
    echo "${missing[*]}"
}

# The requirement line for a package in requirements.txt, comment, environment
# marker and spaces stripped (none: fail).
_pts_requirement() {
    local line
    line=$(grep -E -m1 "^[[:space:]]*$1([^[:alnum:]_.-]|\$)" "$REPO/requirements.txt") || return 1
    line=${line%%#*}
    line=${line%%;*}
    echo "${line//[[:space:]]/}"
}

# PyBullet's two distributions (requirements.txt, docs/install.md): both
# install the module `pybullet`, into the same files, so a venv holds one.
_PTS_PYBULLET_DISTRIBUTIONS=(pybullet pybullet-arm64)

# What PAN_TILT_SIM_PYBULLET asks for: auto (default) or upstream.
_pts_pybullet_wish() {
    local want=${PAN_TILT_SIM_PYBULLET:-auto}
    case $want in
        auto|upstream) echo "$want" ;;
        *) _pts_die "PAN_TILT_SIM_PYBULLET is auto or upstream, not '$want'" ;;
    esac
}

# What decides which PyBullet the venv gets: the wish and both requirement
# lines. A change to it reinstalls PyBullet (the stamp below).
_pts_pybullet_key() {
    { _pts_pybullet_wish; grep -E '^[[:space:]]*pybullet' "$REPO/requirements.txt"; } | _pts_hash
}

# _pts_pybullet_wheel SPEC [FIND_LINKS]: install SPEC from a wheel, on PyPI
# (or in FIND_LINKS), in place of whichever PyBullet distributions the venv
# has: both are removed first (with both installed, removing one would take
# the module's files from the other). Fails, leaving none installed, when
# there is no wheel for this Python and platform; any other failure (no
# network, say) ends the script.
_pts_pybullet_wheel() {
    local spec=$1 links=() errors
    [[ -n ${2:-} ]] && links=(--find-links "$2")
    "$VENV/bin/python" -m pip uninstall --quiet --disable-pip-version-check --yes \
        "${_PTS_PYBULLET_DISTRIBUTIONS[@]}" >/dev/null 2>&1 || true
    errors=$("$VENV/bin/python" -m pip install --quiet --disable-pip-version-check --no-deps \
        --only-binary=:all: "${links[@]}" "$spec" 2>&1) && return 0
    grep -q 'No matching distribution' <<<"$errors" && return 1
    echo "$errors" >&2
    _pts_die "installing $spec failed"
}

# Install PyBullet 3.2.7's source as ONE distribution (requirements.txt says
# which and why):
#  1. upstream's own wheel, where PyPI has one for this Python and platform;
#  2. else pybullet-arm64's wheel (the same source rebuilt), where PyPI has one,
#     unless PAN_TILT_SIM_PYBULLET=upstream;
#  3. else upstream's, from a wheel built here before or, where there is none
#     for this Python, built from the sdist once into $_PTS_WHEELS, saying so
#     first and showing that it goes on.
_pts_pybullet() {
    local spec fork version lock_fd build_deps=() tmp log heartbeat status=0 started missing
    local elapsed stamp=$VENV/.pan_tilt_sim-pybullet key
    spec=$(_pts_requirement pybullet) || return 0
    _pts_pybullet_wish >/dev/null
    key=$(_pts_pybullet_key)
    [[ "$(cat "$stamp" 2>/dev/null)" == "$key" ]] && return 0
    if _pts_pybullet_wheel "$spec"; then
        echo "$key" >"$stamp"
        return 0
    fi
    if [[ $(_pts_pybullet_wish) == auto ]] && fork=$(_pts_requirement pybullet-arm64) \
            && _pts_pybullet_wheel "$fork"; then
        _pts_say "$spec has no wheel for Python $(pts_python_version "$VENV/bin/python") here:" \
            "installed $fork, its source rebuilt (docs/install.md; PAN_TILT_SIM_PYBULLET=upstream" \
            "builds upstream's instead)"
        echo "$key" >"$stamp"
        return 0
    fi
    mkdir -p -- "$_PTS_WHEELS"
    # One build at a time per wheel folder (two venvs being made at once).
    exec {lock_fd}>"$_PTS_WHEELS/.lock"
    if command -v flock >/dev/null && ! flock -n "$lock_fd"; then
        _pts_say "waiting for another install to finish with $_PTS_WHEELS"
        flock "$lock_fd"
    fi
    if _pts_pybullet_wheel "$spec" "$_PTS_WHEELS"; then
        exec {lock_fd}>&-
        echo "$key" >"$stamp"
        return 0
    fi
    version=$(pts_python_version "$VENV/bin/python")
    missing=$(_pts_missing_build_packages)
    [[ -z $missing ]] || _pts_die "$spec has no wheel for Python $version and building it" \
        "from source needs a C++ compiler and Python's headers; on Debian/Ubuntu:" \
        "sudo apt-get install $missing"
    _pts_say "$spec has no wheel for Python $version: building one from source now." \
        "This takes several minutes (about 7 on 2 idle cores) and happens once: the wheel is" \
        "kept in $_PTS_WHEELS and later venvs install it in seconds."
    # PyBullet compiles its NumPy support (getCameraImage returning arrays, as
    # PyPI's wheels do) only when numpy imports at build time, so the build
    # runs in the venv, with requirements.txt's numpy and setuptools.
    build_deps+=("$(_pts_requirement numpy || echo numpy)")
    build_deps+=("$(_pts_requirement setuptools || echo setuptools)")
    "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check "${build_deps[@]}" \
        || _pts_die "installing PyBullet's build requirements (${build_deps[*]}) failed"
    rm -rf -- "$_PTS_WHEELS"/.build.*  # what an interrupted build left
    tmp=$(mktemp -d "$_PTS_WHEELS/.build.XXXXXX")
    mkdir -- "$tmp/tmp" "$tmp/wheel"
    log=$VENV/pybullet-build.log
    started=$SECONDS
    # A heartbeat every 30 s, from the background (pip stays in the
    # foreground, where Ctrl-C reaches it): the time so far and how many
    # source files are compiled. It ends with the build or with this script.
    (
        while kill -0 "$$" 2>/dev/null; do
            for _ in {1..30}; do
                sleep 1
                kill -0 "$$" 2>/dev/null || exit 0
            done
            elapsed=$((SECONDS - started))
            _pts_say "building PyBullet: $((elapsed / 60)) min $((elapsed % 60)) s," \
                "$(find "$tmp/tmp" -name '*.o' 2>/dev/null | wc -l) source files compiled" \
                "(pip's output: $log)"
        done
    ) &
    heartbeat=$!
    # Its own TMPDIR: the heartbeat counts the object files compiled there.
    # --no-cache-dir: a wheel pip built and cached before may lack NumPy.
    TMPDIR=$tmp/tmp "$VENV/bin/python" -m pip wheel --verbose --disable-pip-version-check \
        --no-cache-dir --no-deps --no-build-isolation --no-binary=pybullet \
        --wheel-dir "$tmp/wheel" "$spec" >"$log" 2>&1 || status=$?
    kill "$heartbeat" 2>/dev/null || true
    wait "$heartbeat" 2>/dev/null || true
    if (( status != 0 )); then
        tail -n 20 "$log" >&2
        rm -rf -- "$tmp"
        missing=$(_pts_missing_build_packages)
        _pts_die "building $spec from source failed (pip's output: $log)${missing:+; missing:" \
            "sudo apt-get install $missing}"
    fi
    mv -f -- "$tmp"/wheel/*.whl "$_PTS_WHEELS"/ || _pts_die "pip wheel left no wheel in $tmp"
    rm -rf -- "$tmp"
    elapsed=$((SECONDS - started))
    _pts_say "built PyBullet in $((elapsed / 60)) min $((elapsed % 60)) s;" \
        "kept in $_PTS_WHEELS"
    _pts_pybullet_wheel "$spec" "$_PTS_WHEELS" \
        || _pts_die "installing the PyBullet wheel built in $_PTS_WHEELS failed"
    exec {lock_fd}>&-
    echo "$key" >"$stamp"
}

# _pts_without_pybullet DIR: copy the requirements files into DIR, with
# requirements.txt's PyBullet lines left out (_pts_pybullet installs one of
# them); the files' own -r references then resolve inside DIR.
_pts_without_pybullet() {
    cp -- "$REPO"/requirements*.txt "$1"/
    grep -v -E '^[[:space:]]*pybullet([^[:alnum:]_.]|$)' "$REPO/requirements.txt" \
        >"$1/requirements.txt" || true
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
    local mode=$1 reqs deps_hash deps_stamp src_hash src_stamp tmp
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

    _pts_ensure_venv

    # The test set includes the runtime set, so a current test stamp is
    # enough for runtime use too.
    deps_hash=$(cat "$REPO/requirements.txt" "$REPO/requirements-test.txt" \
        "$REPO/requirements-build.txt" "$REPO/requirements-viewer.txt" | _pts_hash)
    deps_stamp=$VENV/.pan_tilt_sim-deps-$mode
    # PyBullet first, on its own stamp: PAN_TILT_SIM_PYBULLET changes it too.
    _pts_pybullet
    if [[ "$(cat "$deps_stamp" 2>/dev/null)" != "$deps_hash" \
            && "$(cat "$VENV/.pan_tilt_sim-deps-test" 2>/dev/null)" != "$deps_hash" ]]; then
        _pts_say "installing dependencies from ${reqs#"$REPO"/} (first run: about a minute)"
        tmp=$(mktemp -d "${TMPDIR:-/tmp}/pan_tilt_sim-requirements.XXXXXX")
        _pts_without_pybullet "$tmp"
        if ! "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check \
                -r "$tmp/${reqs##*/}"; then
            rm -rf -- "$tmp"
            _pts_die "installing dependencies failed"
        fi
        rm -rf -- "$tmp"
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
