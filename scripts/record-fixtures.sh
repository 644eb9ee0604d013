#!/usr/bin/env bash
# Re-record the replay regression fixtures (test/fixtures/bags) from their scenarios
# (test/fixtures/scenarios). Do this only when a change to the controller is meant to change
# its behaviour: the fixtures are what `mpi-ros replay` holds the controller to.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$repo/scripts/setup.sh"
cd "$repo"
for scenario in test/fixtures/scenarios/*.yaml; do
    name="$(basename "$scenario" .yaml)"
    rm -rf "test/fixtures/bags/$name"
    .venv/bin/mpi-ros record --scenario "$scenario" "test/fixtures/bags/$name"
done
