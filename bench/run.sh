#!/usr/bin/env bash
# Run every benchmark and write bench/RESULTS.md (the figures quoted in the issues' notes).
#   bench/run.sh
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$repo/scripts/setup.sh"
py="$repo/.venv/bin/python"
out="$repo/bench/RESULTS.md"
cd "$repo/bench"
{
    echo "# Benchmark results"
    echo
    echo "Measured with \`bench/run.sh\` on $(date -u +%Y-%m-%d) ($(nproc) cores, $(uname -m), Python $("$py" -c 'import platform; print(platform.python_version())'))."
    echo "Load on the machine during the run: $(cut -d' ' -f1-3 /proc/loadavg) (1/5/15 min)."
    echo
    echo "Targets (docs/quality.md, issue 10): stepping 32 axes in 20-sample batches (what the real-time clock"
    echo "thread steps every 10 ms) >= 1,000,000 axis-samples/s, in batches of 4096 (how replay and fast"
    echo "runs step) >= 20,000,000, each measured beside the core before the rebuild; planning an"
    echo "S-curve < 100 us median; E_STOP within one sample of the request arriving; status rates within"
    echo "2 % of the configured 100 Hz and 1 kHz; 32 axes / 16 supervisors moving with status and joint"
    echo "states at 100 Hz in real time (within 1 %), every topic within 2 %, the suite under 40 % of one"
    echo "core; 8 axes moving with status at 1 kHz, every topic within 2 %."
    echo
    echo "## Controller stepping (bench/bench_controller.py)"
    echo
    "$py" -P bench_controller.py
    echo
    echo "## The faults' checks while stepping (bench/bench_faults.py)"
    echo
    "$py" -P bench_faults.py
    echo
    echo "## Planning a start (bench/bench_planning.py)"
    echo
    "$py" -P bench_planning.py
    echo
    echo "## The ROS suite in real time (bench/bench_ros.py)"
    echo
    "$py" -P bench_ros.py
    echo
    echo "## The suite under load, through ROS (bench/bench_suite.py)"
    echo
    "$py" -P bench_suite.py
    echo
    echo "## Bags: replay, write and read (bench/bench_bags.py)"
    echo
    "$py" -P bench_bags.py
    echo
    echo "## Path motion: planning, and a stream in the controller (bench/bench_paths.py)"
    echo
    "$py" -P bench_paths.py
    echo
    echo "## Cam slaves (bench/bench_cams.py)"
    echo
    "$py" -P bench_cams.py
    echo
    echo "## A 100,000-point path streamed through ROS (bench/bench_stream.py)"
    echo
    "$py" -P bench_stream.py
    echo
    echo "## E_STOP with hundreds of goals in flight (bench/goal_storm.py)"
    echo
    "$py" -P goal_storm.py
} > "$out.tmp"
mv "$out.tmp" "$out"
cat "$out"
