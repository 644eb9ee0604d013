#!/usr/bin/env bash
# Load and soak (issue 14): bench/soak.sh [MINUTES] [more bench/soak.py options]
# 8 supervisors, modify goals at --modify-rate per supervisor (default 100/s), status at
# --status-rate (default 1000 Hz), for MINUTES (default 10); RSS, CPU, status gaps and what the
# suite holds every minute; the report is appended to bench/RESULTS.md.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
MPI_ROS_SETUP_QUIET=1 scripts/setup.sh
minutes="${1:-10}"
shift || true
exec .venv/bin/python -P bench/soak.py --minutes "$minutes" --append "$@"
