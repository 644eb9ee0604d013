#!/usr/bin/env bash
# Run the tests: set-up first (scripts/setup.sh: venv, pinned wheels, build, install), then
# pytest over test/ with the venv's interpreter. Extra arguments go to pytest, e.g.
#   scripts/test.sh -k roundtrip -x
# Tests import the INSTALLED mpi_ros (it has the generated interfaces; the source folder has
# not): `python -P` keeps the repo root off sys.path, pyproject.toml sets --import-mode=importlib.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$repo/scripts/setup.sh"
cd "$repo"
exec "$repo/.venv/bin/python" -P -m pytest "$@"
