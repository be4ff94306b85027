# shellcheck shell=bash
# shellcheck disable=SC2034  # PTS_PYTHON and PTS_PYTHON_VERSION are for the sourcing script
# Sourced by _prepare_venv.sh and .ci/run: which Python a venv is made with.
#
# The standalone path runs on CPython 3.12 (Ubuntu 24.04, ROS 2 Jazzy's tier-1
# platform) and 3.11 (Debian 12): the ROS 2 Jazzy wheels on PyPI exist for
# both. "The machine's default Python" is the first of these that runs:
#
#   python3.12 on PATH, a pyenv-installed 3.12, python3.11 on PATH, a
#   pyenv-installed 3.11
#
# Every candidate is run before it is taken: a pyenv shim for a version that
# pyenv does not have active exists on PATH but refuses to start.
# PAN_TILT_SIM_PYTHON (a command or a path) overrides the search; it must be
# one of the supported versions.

PTS_SUPPORTED_VERSIONS=(3.12 3.11)

# pts_python_version COMMAND: print COMMAND's X.Y if it runs, else fail.
pts_python_version() {
    "$1" -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null
}

# pts_is_supported X.Y: whether the project runs on that version.
pts_is_supported() {
    local version
    for version in "${PTS_SUPPORTED_VERSIONS[@]}"; do
        [[ $1 == "$version" ]] && return 0
    done
    return 1
}

# pts_other_version X.Y: print the supported version that is not X.Y.
pts_other_version() {
    local version
    for version in "${PTS_SUPPORTED_VERSIONS[@]}"; do
        [[ $1 != "$version" ]] && { echo "$version"; return 0; }
    done
    return 1
}

# Interpreters pyenv has installed for X.Y, newest first (none without pyenv).
_pts_pyenv_candidates() {
    local root dir
    if command -v pyenv >/dev/null; then
        root=$(pyenv root 2>/dev/null) || return 0
    else
        root=${PYENV_ROOT:-}
    fi
    [[ -n $root && -d $root/versions ]] || return 0
    for dir in "$root"/versions/"$1".*; do
        # Releases only: not 3.12-dev, 3.12.1t (free-threaded) or a virtualenv.
        [[ ${dir##*/} =~ ^[0-9]+\.[0-9]+\.[0-9]+$ && -x $dir/bin/python$1 ]] \
            && echo "$dir/bin/python$1"
    done | sort -V -r
}

# pts_find_python X.Y: print a command that runs Python X.Y, or fail.
pts_find_python() {
    local candidate
    while IFS= read -r candidate; do
        [[ -n $candidate && "$(pts_python_version "$candidate")" == "$1" ]] \
            && { echo "$candidate"; return 0; }
    done < <(command -v "python$1" || true; _pts_pyenv_candidates "$1")
    return 1
}

# How to get a supported Python on the two platforms the project targets.
pts_python_help() {
    echo 'Ubuntu 24.04: sudo apt-get install python3.12-venv python3.12-dev g++;' \
         'Debian 12: sudo apt-get install python3.11-venv python3.11-dev g++'
}

# pts_choose_python: set PTS_PYTHON (a command) and PTS_PYTHON_VERSION (X.Y)
# to PAN_TILT_SIM_PYTHON or the machine's default; fail with a message saying
# how to get one when there is none.
pts_choose_python() {
    local version
    PTS_PYTHON=
    PTS_PYTHON_VERSION=
    if [[ -n ${PAN_TILT_SIM_PYTHON:-} ]]; then
        version=$(pts_python_version "$PAN_TILT_SIM_PYTHON") || {
            # Its own words say why (not found; a pyenv shim for a version
            # pyenv has not made active: its full path works).
            echo "PAN_TILT_SIM_PYTHON=$PAN_TILT_SIM_PYTHON does not run:" \
                 "$({ "$PAN_TILT_SIM_PYTHON" --version 2>&1 || true; } | head -n 1)" >&2
            return 1
        }
        pts_is_supported "$version" || {
            echo "PAN_TILT_SIM_PYTHON=$PAN_TILT_SIM_PYTHON is Python $version; the ROS 2" \
                 "Jazzy wheels this project uses need 3.12 or 3.11" >&2
            return 1
        }
        PTS_PYTHON=$PAN_TILT_SIM_PYTHON
        PTS_PYTHON_VERSION=$version
        return 0
    fi
    for version in "${PTS_SUPPORTED_VERSIONS[@]}"; do
        if PTS_PYTHON=$(pts_find_python "$version"); then
            PTS_PYTHON_VERSION=$version
            return 0
        fi
    done
    echo "no Python 3.12 or 3.11 found (looked for python3.12 and python3.11 on PATH" \
         "and in pyenv); $(pts_python_help); or set PAN_TILT_SIM_PYTHON" >&2
    return 1
}
