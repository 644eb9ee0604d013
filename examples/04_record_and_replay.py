"""04: record a scripted run to a bag and replay it exactly (no ROS graph needed).

    .venv/bin/python examples/04_record_and_replay.py /tmp/example_bag
"""

import sys
import tempfile
from pathlib import Path

from mpi_ros.bag import scenario
from mpi_ros.bag.replay import replay
from mpi_ros.commands import Command

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp()) / "bag"
move = {"type": "S_CURVE", "position": [3000.0, -1000.0],
        "trajectory": [{"velocity": 2000.0, "acceleration": 10000.0, "deceleration": 10000.0, "jerk_percent": 40.0}]}
plan = scenario.Scenario("example", samples=6000, steps=[
    scenario.Step(10, Command("motion_start", 0, request=move)),
    scenario.Step(1500, Command("action", 0, request={"action": "STOP"})),
    scenario.Step(3000, Command("action", 0, request={"action": "RESUME"})),
])
scenario.record(plan, out)
print("recorded", out)
print(replay(out).summary())
print(replay(out, overrides={"axes": {"defaults": {"plant": {"damping": 0.5}}}}).summary())
