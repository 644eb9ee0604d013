"""A 100,000-point path streamed through ROS in real time, as a user would (issue 11).

Two processes: the suite (``mpi-ros run``, time scale 1, the default configuration) and this
one, which streams a 2-axis PVT contour with ``MotionClient.stream`` (MotionStart with the
first chunk, final false; a MotionModify with APPEND per FRAMES_LOW cue; the last chunk final
true). Reported: the motion's length, the wall time the stream took (the path ran without a
gap only if the two agree), whether it ended OK (an open path that starves is E-stopped), and
the suite's CPU over the stream (utime + stime of its process, /proc/<pid>/stat) as a share of
one core.

    python -P bench/bench_stream.py [--points 100000] [--dt 0.001] [--chunk 500] [--ahead 4]
"""

from __future__ import annotations

import argparse
import gc
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
    parser.add_argument("--chunk", type=int, default=500)
    parser.add_argument("--ahead", type=int, default=4, help="appended chunks kept outstanding (stream's ahead)")
    args = parser.parse_args()
    env = dict(os.environ, ROS_DOMAIN_ID=str(110 + os.getpid() % 90), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
               PYTHONPATH=str(REPO))
    os.environ.update(env)
    sys.path.insert(0, str(REPO))  # this source tree, as the suite runs it
    from mpi_ros.client import MotionClient  # after the environment: the client's context reads it
    from mpi_ros.errors import MpiError

    suite = subprocess.Popen([sys.executable, "-P", "-m", "mpi_ros.cli", "run"], env=env, cwd=REPO,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        with MotionClient(supervisor=0, timeout=30.0) as ms0:
            if not ms0.wait_for_server(60.0):
                raise SystemExit("the suite did not come up")
            events = watch_events(ms0)
            points, velocities = contour(args.points, args.dt)
            # A real-time client keeps its garbage collector off its long-lived data (the 400,000
            # numbers of the path): unfrozen, full collections of this process took up to 97 ms,
            # most of the 123 ms the buffer leaves to send the next chunk (MotionClient.stream).
            gc.freeze()
            cpu0, wall0 = cpu_seconds(suite.pid), time.monotonic()
            try:
                result = ms0.stream("PVT", points, [args.dt] * args.points, velocities=velocities,
                                    chunk=args.chunk, low_count=128, timeout=60.0, ahead=args.ahead)
                outcome = f"{result.message} ({result.detail.split(';')[0]})"
            except MpiError as exc:  # E-stopped (a gap) or refused: reported, not hidden
                outcome = f"raised {type(exc).__name__}: {exc}"
            wall, cpu = time.monotonic() - wall0, cpu_seconds(suite.pid) - cpu0
    finally:
        suite.terminate()
        suite.wait(30)
    motion = args.points * args.dt
    load = Path("/proc/loadavg").read_text().split()[:3]
    seen = ", ".join(f"{name} {events.get(name, 0)}" for name in ("FRAMES_LOW", "FRAMES_EMPTY", "E_STOP"))
    print(f"| measure | result |\n| --- | --- |\n"
          f"| points streamed (PVT, 2 axes, chunks of {args.chunk}, {args.ahead} ahead) "
          f"| {args.points:,} ({motion:.0f} s of motion) |\n"
          f"| wall time from the first goal to the result | {wall:.2f} s ({wall / motion:.4f} x the motion) |\n"
          f"| result | {outcome} |\n"
          f"| events of ms0 (a gap shows as FRAMES_EMPTY or E_STOP) | {seen} |\n"
          f"| the suite's CPU over the stream | {cpu:.2f} s, {100 * cpu / wall:.1f} % of one core |\n"
          f"| load average at the end (1/5/15 min) | {' / '.join(load)} |")


def watch_events(client) -> dict[str, int]:
    """Counts of ms0's events by type, from <namespace>/events (as any subscriber sees them)."""
    from mpi_ros.client import EVENTS_QOS
    from mpi_ros.msg import MotionEvent

    counts: dict[str, int] = {}

    def count(event) -> None:
        if event.supervisor == 0:
            counts[event.type] = counts.get(event.type, 0) + 1

    client.node.create_subscription(MotionEvent, "/mpi/events", count, EVENTS_QOS)
    return counts


if __name__ == "__main__":
    main()
