"""A client process that is killed mid-goal (test_robustness.py, test_watchdog.py): it starts a
long S-curve on one supervisor, prints "sent" and waits on stdin until the test kills it.

    python -P test/ros/doomed_client.py SUPERVISOR TARGET
"""

from __future__ import annotations

import sys

from mpi_ros.client import MotionClient


def main() -> None:
    supervisor, target = int(sys.argv[1]), float(sys.argv[2])
    client = MotionClient(supervisor, timeout=20.0)
    client.wait_for_server()
    client.start({"type": "S_CURVE", "position": [target, 0.0],
                  "trajectory": [{"velocity": 1000.0, "acceleration": 10000.0, "deceleration": 10000.0}]})
    print("sent", flush=True)
    sys.stdin.readline()  # wait to be killed


if __name__ == "__main__":
    main()
