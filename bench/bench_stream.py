"""A 100,000-point path streamed through ROS in real time, as a user would (issue 11).

Two processes: the suite (``mpi-ros run``, time scale 1, the default configuration) and this
one, which streams a 2-axis PVT contour with ``MotionClient.stream`` (MotionStart with the
first chunk, final false; a MotionModify with APPEND per FRAMES_LOW cue; the last chunk final
true). Reported: the motion's length, the wall time the stream took (the path ran without a
gap only if the two agree), whether it ended OK (an open path that starves is E-stopped), and
the suite's CPU over the stream (utime + stime of its process, /proc/<pid>/stat) as a share of
one core.

    python -P bench/bench_stream.py [--points 100000] [--dt 0.001] [--chunk 100]
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def cpu_seconds(pid: int) -> float:
    """utime + stime of a process (every thread), in seconds."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def contour(points: int, dt: float) -> tuple[list[tuple[float, float]], list[tuple[float, float]]]:
    """A circle of radius 10,000 counts through the start, one turn per 10 s: positions and velocities."""
    w = 2.0 * math.pi / 10.0
    pos, vel = [], []
    for k in range(1, points + 1):
        t = k * dt
        pos.append((1e4 * math.sin(w * t), 1e4 * (1.0 - math.cos(w * t))))
        vel.append((1e4 * w * math.cos(w * t), 1e4 * w * math.sin(w * t)))
    return pos, vel


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--dt", type=float, default=0.001)
    parser.add_argument("--chunk", type=int, default=100)
    args = parser.parse_args()
    env = dict(os.environ, ROS_DOMAIN_ID=str(110 + os.getpid() % 90), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
               PYTHONPATH=str(REPO))
    os.environ.update(env)
    sys.path.insert(0, str(REPO))  # this source tree, as the suite runs it
    from mpi_ros.client import MotionClient  # after the environment: the client's context reads it

    suite = subprocess.Popen([sys.executable, "-P", "-m", "mpi_ros.cli", "run"], env=env, cwd=REPO,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        with MotionClient(supervisor=0, timeout=30.0) as ms0:
            if not ms0.wait_for_server(60.0):
                raise SystemExit("the suite did not come up")
            points, velocities = contour(args.points, args.dt)
            cpu0, wall0 = cpu_seconds(suite.pid), time.monotonic()
            result = ms0.stream("PVT", points, [args.dt] * args.points, velocities=velocities, chunk=args.chunk,
                                low_count=128, timeout=60.0)
            wall, cpu = time.monotonic() - wall0, cpu_seconds(suite.pid) - cpu0
    finally:
        suite.terminate()
        suite.wait(30)
    motion = args.points * args.dt
    load = Path("/proc/loadavg").read_text().split()[:3]
    print(f"| measure | result |\n| --- | --- |\n"
          f"| points streamed (PVT, 2 axes, chunks of {args.chunk}) | {args.points:,} ({motion:.0f} s of motion) |\n"
          f"| wall time from the first goal to the result | {wall:.2f} s ({wall / motion:.4f} x the motion) |\n"
          f"| result | {result.message} ({result.detail.split(';')[0]}) |\n"
          f"| the suite's CPU over the stream | {cpu:.2f} s, {100 * cpu / wall:.1f} % of one core |\n"
          f"| load average during the run (1/5/15 min) | {' / '.join(load)} |")


if __name__ == "__main__":
    main()
