#!/usr/bin/env bash
# Check the colcon route: build mpi_ros with colcon (from PyPI, requirements/colcon.txt,
# installed into .venv) in a scratch workspace, as a ROS user would, and check what it installed.
#   scripts/colcon-check.sh [--keep]     (--keep: leave the workspace and print its path)
# Not part of the test suite (a full build takes about a minute).
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$repo/.venv"
keep=0
[[ "${1:-}" == "--keep" ]] && keep=1
say() { printf '[colcon-check] %s\n' "$*"; }
fail() { printf '[colcon-check] FAIL: %s\n' "$*" >&2; exit 1; }

"$repo/scripts/setup.sh"
vpy="$venv/bin/python"

# colcon, pinned, on top of the other locks (skipped when already installed from this lock).
stamp="$venv/.mpi_ros-colcon.stamp"
want="$(cat "$repo"/requirements/{runtime,test,colcon}.txt | sha256sum | cut -d' ' -f1)"
if [[ "$(cat "$stamp" 2>/dev/null || true)" != "$want" ]]; then
    say "installing colcon (requirements/colcon.txt)"
    "$vpy" -m pip install --quiet --disable-pip-version-check \
        -r "$repo/requirements/colcon.txt" \
        -c "$repo/requirements/runtime.txt" -c "$repo/requirements/test.txt"
    printf '%s' "$want" > "$stamp"
fi

ws="$(mktemp -d "${TMPDIR:-/tmp}/mpi_ros-colcon.XXXXXX")"
if [[ $keep == 0 ]]; then trap 'rm -rf "$ws"' EXIT; fi
mkdir -p "$ws/src"
ln -s "$repo" "$ws/src/mpi_ros"
say "workspace $ws"

export AMENT_PREFIX_PATH="$venv${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
export CMAKE_PREFIX_PATH="$venv${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}"
export PATH="$venv/bin:$PATH"
unset PYTHONPATH

start=$SECONDS
if ! (cd "$ws" && colcon build --packages-select mpi_ros \
        --cmake-args "-DPython3_EXECUTABLE=$vpy" -DBUILD_TESTING=OFF); then
    tail -n 60 "$ws/log/latest_build/mpi_ros/stdout_stderr.log" >&2 || true
    fail "colcon build failed (log: $ws/log/latest_build)"
fi
say "colcon build took $((SECONDS - start)) s"

inst="$ws/install/mpi_ros"
site="$inst/$("$vpy" -c 'import sys, sysconfig; print(sysconfig.get_path("purelib", vars={"base": "", "platbase": ""}).lstrip("/"))')"
for f in lib/mpi_ros/mpi-ros lib/mpi_ros/suite; do
    [[ -x "$inst/$f" ]] || fail "missing executable $f"
done
for f in share/mpi_ros/config/default.yaml share/mpi_ros/launch/mpi_ros.launch.py \
         share/mpi_ros/package.xml share/ament_index/resource_index/packages/mpi_ros \
         share/mpi_ros/action/MotionStart.action share/mpi_ros/srv/MotionAction.srv \
         share/mpi_ros/msg/AxisStatus.msg; do
    [[ -f "$inst/$f" ]] || fail "missing $f"
done
for d in msg srv action cli; do
    [[ -f "$site/mpi_ros/$d/__init__.py" ]] || fail "missing Python package mpi_ros.$d in $site"
done

# Use the workspace as a ROS user would: source it, then import from it and run its executable.
set +u
# shellcheck disable=SC1091
source "$ws/install/setup.bash"
set -u
"$vpy" -P - "$inst" <<'PY' || fail "the colcon-installed interfaces do not work"
import os, sys
import mpi_ros
from mpi_ros.action import MotionStart
from mpi_ros.msg import AxisStatus
from mpi_ros.srv import MotionAction
from rclpy.serialization import deserialize_message, serialize_message
inst = os.path.realpath(sys.argv[1])
assert os.path.realpath(mpi_ros.__file__).startswith(inst), f"imported {mpi_ros.__file__}, not from {inst}"
goal = MotionStart.Goal(type="S_CURVE", position=[1000.0, 0.0])
assert deserialize_message(serialize_message(goal), MotionStart.Goal) == goal
assert goal.final and not goal.retain and goal.empty_count == 5
print("[colcon-check] interfaces OK from", os.path.dirname(mpi_ros.__file__))
PY
"$inst/lib/mpi_ros/mpi-ros" version -v | sed 's/^/[colcon-check] /' || fail "lib/mpi_ros/mpi-ros does not run"
"$vpy" - <<'PY' || fail "ament_index does not find mpi_ros's share directory"
from ament_index_python.packages import get_package_share_directory
print("[colcon-check] ament_index: share/mpi_ros =", get_package_share_directory("mpi_ros"))
PY
say "OK"
[[ $keep == 1 ]] && say "kept workspace $ws"
exit 0
