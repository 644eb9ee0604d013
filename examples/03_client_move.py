"""03: move an axis through ROS with the Python client, against the running suite.

    scripts/run.sh                               # terminal 1: the suite
    .venv/bin/python examples/03_client_move.py  # terminal 2
"""

from mpi_ros import errors
from mpi_ros.client import MotionClient

with MotionClient(supervisor=0) as ms0:
    if not ms0.wait_for_server(10.0):
        raise SystemExit("no suite on the graph: start it with scripts/run.sh")
    result = ms0.move([1000.0, 0.0], velocity=500.0, acceleration=5000.0, deceleration=5000.0, jerk_percent=50.0)
    print(result.message, result.state_name, list(result.actual_position))
    try:
        # a bad goal: the spec's message comes back
        ms0.move([0.0, 0.0], velocity=0.0, acceleration=1.0, deceleration=1.0)
    except errors.MPIMessagePARAM_INVALID as exc:
        print("refused:", exc)
    print("status:", ms0.status().state_name)
