"""05: a PVT pick-and-place through ROS with the Python client, against the running suite.

    scripts/run.sh                                      # terminal 1: the suite
    .venv/bin/python examples/05_pvt_pick_and_place.py  # terminal 2

ms0's axis 0 is the horizontal axis, axis 1 the vertical one. One PVT path lifts the part
from the pick point, carries it over, lowers it onto the place point and goes back: the
velocity is zero at the pick and place points (the gripper works there) and the corners are
rounded by the velocities given at the points in between. Every point carries an element id,
so MotionStatus.element_id (and `mpi-ros status`) tells which leg runs.
"""

from mpi_ros.client import MotionClient, MotionType

PICK, PLACE, TOP = 0.0, 1000.0, 250.0  # counts
PATH = [  # (x, z), (vx, vz) in counts/s, dt in s from the point before
    ((PICK, 150.0), (0.0, 500.0), 0.35),           # 1 lift
    ((PICK + 150.0, TOP), (750.0, 0.0), 0.3),      # 2 over the top, moving across
    ((PLACE - 150.0, TOP), (750.0, 0.0), 0.95),    # 3 traverse
    ((PLACE, 150.0), (0.0, -500.0), 0.3),          # 4 round the corner, going down
    ((PLACE, 0.0), (0.0, 0.0), 0.35),              # 5 lower onto the place point: at rest
    ((PLACE, 150.0), (0.0, 500.0), 0.35),          # 6 lift again
    ((PLACE - 150.0, TOP), (-750.0, 0.0), 0.3),    # 7
    ((PICK + 150.0, TOP), (-750.0, 0.0), 0.95),    # 8 back across
    ((PICK, 150.0), (0.0, -500.0), 0.3),           # 9
    ((PICK, 0.0), (0.0, 0.0), 0.35),               # 10 down onto the pick point: at rest
]

with MotionClient(supervisor=0) as ms0:
    if not ms0.wait_for_server(10.0):
        raise SystemExit("no suite on the graph: start it with scripts/run.sh")
    # 1. to the pick point (a path starts wherever the axes are)
    ms0.move([PICK, 0.0], velocity=2000.0, acceleration=20000.0, deceleration=20000.0, jerk_percent=50.0, timeout=30.0)
    # 2. the whole cycle as one PVT path, an element id per point
    points, velocities, times = zip(*PATH, strict=True)
    result = ms0.path(MotionType.PVT, points, times, velocities=velocities, element_ids=range(1, len(PATH) + 1))
    print(result.message, result.state_name, "at", list(result.command_position))
    print("peaks:", result.detail.split("path peaks ", 1)[-1])
    # 3. the same cycle, watched while it runs: element_id names the point being run toward
    goal = ms0.path(MotionType.PVT, points, times, velocities=velocities, element_ids=range(1, len(PATH) + 1),
                    wait=False)
    seen = []
    while not goal.result_ready(0.05):
        seen.append(ms0.status().element_id)
    print("element ids seen:", sorted(set(seen)), "->", goal.wait().message)
