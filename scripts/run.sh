#!/usr/bin/env bash
# Run the mpi_ros node suite on the built-in simulated controller with config/default.yaml,
# after doing all set-up (scripts/setup.sh). Extra arguments go to `mpi-ros run`, e.g.
#   scripts/run.sh --time-scale 10
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$repo/scripts/setup.sh"
exec "$repo/.venv/bin/mpi-ros" run --config "$repo/config/default.yaml" "$@"
