#!/usr/bin/env bash
# One command for all set-up, on a fresh machine or an old one:
#   1. find a CPython 3.11 (the ROS 2 Jazzy wheels on PyPI are cp311 only);
#   2. create the virtual environment .venv in the repo;
#   3. install the pinned requirements (requirements/runtime.txt + test.txt) with uv (pinned in
#      requirements/setup.txt; pip only when uv cannot be installed) and point the ROS wheels'
#      CMake files at this venv's Python (scripts/fix-ros-wheel-paths.py);
#   4. build the interfaces and install the package: pip install . (setup.py drives CMake with
#      Ninja, build dir build/cmake is kept, so a Python-only change rebuilds nothing).
# docs/setup.md has what each step costs and why it is done this way.
# Each step is skipped when its inputs did not change (hash stamps in .venv/), so a re-run with
# nothing changed takes well under a second. Safe to run concurrently (a lock serialises runs).
#
# Environment: MPI_ROS_PYTHON=/path/to/python3.11 to choose the interpreter;
#              MPI_ROS_SETUP_QUIET=1 to print nothing when nothing changed.
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$repo/.venv"
req="$repo/requirements"
say() { printf '[setup] %s\n' "$*"; }
die() { printf '[setup] ERROR: %s\n' "$*" >&2; exit 1; }

# Progress of the long steps, one line at a time (a CI log shows them as they come): the whole
# output goes to a log under build/, the lines that show progress to the terminal, and on a
# failure the log's last lines follow.
logged() {  # logged NAME FILTER COMMAND...: run COMMAND, its output to build/setup-NAME.log
    local name="$1" filter="$2"; shift 2
    local log="$repo/build/setup-$name.log"
    if ! "$@" 2>&1 | tee "$log" | "$filter"; then
        printf '[setup] %s failed; the end of %s:\n' "$name" "$log" >&2
        tail -n 40 "$log" >&2
        exit 1
    fi
}
# Debian's awk (mawk) reads a pipe in blocks, so progress came in bursts minutes apart (the
# issue's "9 of them silent"): -W interactive makes it read line by line.
if awk -W version 2>/dev/null | grep -q mawk; then lines_awk() { awk -W interactive "$@"; }
else lines_awk() { awk "$@"; }; fi
uv_progress() {  # uv's summary lines, and a line every 25 wheel downloads started (its -v log)
    lines_awk '/^(Resolved|Prepared|Installed|Uninstalled) [0-9]+ package/ { printf "[setup]   %s\n", $0; fflush(); next }
         /Sending fresh GET request for: .*\.whl$/ { n++; if (n % 25 == 0) { printf "[setup]   %d wheel downloads started\n", n; fflush() } }'
}
pip_progress() {  # pip's lines, condensed: a line every 25 packages resolved, then the install
    lines_awk '/^Collecting / { n++; if (n % 25 == 1) { printf "[setup]   %d packages resolved\n", n; fflush() } next }
         /^Installing collected packages/ { printf "[setup]   installing %d packages\n", n; fflush() }'
}
build_progress() {  # setup.py's own lines and the build's progress every 10 % (pip indents them)
    lines_awk '{ sub(/^ +/, "") }
         /^\[mpi_ros setup.py\]/ { sub(/^\[mpi_ros setup.py\] /, ""); if (length($0) > 96) $0 = substr($0, 1, 93) "..."
                                  printf "[setup]   %s\n", $0; fflush(); next }
         / Generating .* for ROS interfaces| Generating .* type support / {   # the rosidl generators,
             sub(/^[^]]*\] /, ""); printf "[setup]   %s\n", $0; fflush() }       # a long step each
         /^\[ *[0-9]+%\]/ { show(substr($0, 2, index($0, "%") - 2) + 0); next }   # make: [ 42%]
         /^\[[0-9]+\/[0-9]+\]/ { split(substr($0, 2, index($0, "]") - 2), f, "/")   # ninja: [12/93]
                                show(int(100 * f[1] / f[2])) }
         function show(p) { if (p >= last + 10) { printf "[setup]   building the interfaces: %d%%\n", p; fflush(); last = p } }'
}

mkdir -p "$repo/build"
exec 9>"$repo/build/.setup.lock"
flock 9

export PIP_DISABLE_PIP_VERSION_CHECK=1
# Never let a caller's Python environment leak into the venv's tools.
unset PYTHONPATH PYTHONHOME VIRTUAL_ENV 2>/dev/null || true

# --- 1. a CPython 3.11 -------------------------------------------------------------------
is_py311() {  # usable for us: CPython 3.11 with venv and ensurepip
    "$1" -c 'import sys, venv, ensurepip; sys.exit(0 if sys.implementation.name == "cpython" and sys.version_info[:2] == (3, 11) else 1)' >/dev/null 2>&1
}
find_python() {
    local c candidates=()
    [[ -n "${MPI_ROS_PYTHON:-}" ]] && candidates+=("$MPI_ROS_PYTHON")
    candidates+=(python3.11 python3)
    if command -v pyenv >/dev/null 2>&1; then
        local root; root="$(pyenv root 2>/dev/null || true)"
        [[ -n "$root" ]] && candidates+=("$root"/versions/3.11*/bin/python3.11)
    fi
    candidates+=("$HOME"/.pyenv/versions/3.11*/bin/python3.11 /usr/bin/python3.11 /usr/local/bin/python3.11)
    for c in "${candidates[@]}"; do
        if [[ "$c" == */* ]]; then [[ -x "$c" ]] || continue
        else c="$(command -v "$c" 2>/dev/null)" || continue; fi
        if is_py311 "$c"; then
            # Resolve shims (pyenv) to the real interpreter.
            "$c" -c 'import sys; print(sys.executable)'
            return 0
        fi
    done
    return 1
}

venv_ok() {
    [[ -x "$venv/bin/python" ]] && "$venv/bin/python" -c 'import sys; sys.exit(0 if sys.version_info[:2] == (3, 11) else 1)' >/dev/null 2>&1
}

if ! venv_ok; then
    py="$(find_python)" || die "no CPython 3.11 found. The ROS 2 Jazzy wheels from PyPI are built for CPython 3.11 only.
Install Python 3.11 with venv support (Debian 12: apt-get install python3.11 python3.11-venv python3.11-dev;
or pyenv install 3.11), or point MPI_ROS_PYTHON at one, then re-run $0."
    for tool in cmake cc c++; do
        command -v "$tool" >/dev/null 2>&1 || die "$tool not found: building the ROS interfaces needs cmake, gcc and g++ (Debian: apt-get install cmake build-essential)"
    done
    "$py" - <<'PY' || die "Python.h missing for $py: install its development headers (Debian 12: apt-get install python3.11-dev)"
import os, sys, sysconfig
sys.exit(0 if os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")) else 1)
PY
    say "creating $venv with $py ($("$py" -c 'import sys; print(sys.version.split()[0])'))"
    rm -rf "$venv"
    "$py" -m venv "$venv"
fi
vpy="$venv/bin/python"

# --- stamps --------------------------------------------------------------------------------
hash_files() {  # hash of the names and contents of the given files (sorted, NUL-separated list on stdin)
    sort -z | xargs -0 -r sha256sum | sha256sum | cut -d' ' -f1
}
interp_id="$("$vpy" -c 'import sys, os; print(sys.version, os.path.realpath(sys.executable))')"

deps_hash="$( { printf '%s\0' "$req/setup.txt" "$req/runtime.txt" "$req/test.txt"; } | hash_files)"
deps_hash="$(printf '%s %s' "$deps_hash" "$interp_id" | sha256sum | cut -d' ' -f1)"
deps_stamp="$venv/.mpi_ros-deps.stamp"

# --- 2. pinned requirements ----------------------------------------------------------------
install_uv() {  # uv of requirements/setup.txt into the venv; fails when pip cannot get it
    local want; want="$(sed -n 's/^uv==//p' "$req/setup.txt")"
    [[ "$("$venv/bin/uv" --version 2>/dev/null)" == "uv $want"* ]] && return 0
    say "  installing uv $want (requirements/setup.txt) with pip"
    "$vpy" -m pip install --progress-bar off -r "$req/setup.txt" > "$repo/build/setup-uv.log" 2>&1
}
if [[ "$(cat "$deps_stamp" 2>/dev/null || true)" != "$deps_hash" ]]; then
    say "installing pinned requirements (requirements/runtime.txt, requirements/test.txt)"
    rm -f "$deps_stamp" "$venv/.mpi_ros-package.stamp"
    start=$SECONDS
    if install_uv; then
        # No .pyc compilation here (pip compiles all 5,500 modules): the first import of a module
        # writes its .pyc, and the tests import a fraction of these files (docs/setup.md).
        logged requirements uv_progress \
            "$venv/bin/uv" pip install -v --python "$vpy" -r "$req/runtime.txt" -r "$req/test.txt"
    else
        say "uv could not be installed (build/setup-uv.log): installing with pip, which is slower"
        logged requirements pip_progress \
            "$vpy" -m pip install --progress-bar off -r "$req/runtime.txt" -r "$req/test.txt"
    fi
    "$vpy" "$repo/scripts/fix-ros-wheel-paths.py" --prefix "$venv"
    printf '%s' "$deps_hash" > "$deps_stamp"
    say "requirements installed in $((SECONDS - start)) s"
fi

# --- 3. the package ------------------------------------------------------------------------
package_inputs() {
    cd "$repo"
    find CMakeLists.txt package.xml setup.py pyproject.toml MANIFEST.in README.md \
         scripts/fix-ros-wheel-paths.py scripts/ros msg srv action config launch \
         -type f ! -name '*.pyc' ! -path '*/__pycache__/*' -print0 2>/dev/null || true
    find mpi_ros -type f -name '*.py' ! -path '*/__pycache__/*' -print0
}
pkg_hash="$(cd "$repo" && package_inputs | hash_files)"
pkg_hash="$(printf '%s %s' "$pkg_hash" "$deps_hash" | sha256sum | cut -d' ' -f1)"
pkg_stamp="$venv/.mpi_ros-package.stamp"
site="$("$vpy" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"

if [[ "$(cat "$pkg_stamp" 2>/dev/null || true)" != "$pkg_hash" \
      || ! -f "$site/mpi_ros/msg/__init__.py" || ! -x "$venv/bin/mpi-ros" ]]; then
    say "building and installing mpi_ros (pip install .; CMake build dir build/cmake)"
    rm -f "$pkg_stamp"
    start=$SECONDS
    (cd "$repo" && logged build build_progress "$vpy" -m pip install -v --no-deps --no-build-isolation .)
    printf '%s' "$pkg_hash" > "$pkg_stamp"
    say "mpi_ros installed in $((SECONDS - start)) s"
elif [[ "${MPI_ROS_SETUP_QUIET:-0}" != 1 ]]; then
    say "up to date (.venv, mpi_ros $("$vpy" -c 'import mpi_ros; print(mpi_ros.__version__)' 2>/dev/null || echo '?'))"
fi
