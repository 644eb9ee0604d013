#!/usr/bin/env bash
# Run the tests: set-up first (scripts/setup.sh: venv, pinned wheels, build, install), then
# pytest over test/ with the venv's interpreter. Extra arguments go to pytest, e.g.
#   scripts/test.sh -k roundtrip -x
#   scripts/test.sh --fast       the edit loop: no ROS, no processes, nothing slow (markers in
#                                pyproject.toml); CI runs everything
# Tests run the source tree (pyproject: pythonpath = ["."]); mpi_ros/__init__.py extends the
# package to the installed copy for the generated interfaces. `-P`: nothing else from cwd.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$repo/scripts/setup.sh"
cd "$repo"
args=()
for arg in "$@"; do
    if [[ "$arg" == "--fast" ]]; then
        args+=(-m "not ros and not process and not slow")
    else
        args+=("$arg")
    fi
done
exec "$repo/.venv/bin/python" -P -m pytest "${args[@]}"
