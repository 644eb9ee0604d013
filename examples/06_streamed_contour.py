"""06: stream a contour of a few thousand points through ROS, as the controller asks for them.

    scripts/run.sh                                   # terminal 1: the suite
    .venv/bin/python examples/06_streamed_contour.py # terminal 2

A lemniscate (a figure eight) on ms0's two axes, 3000 PVT points 4 ms apart: 12 s of motion,
more than a frame buffer (128 frames per axis) holds. `MotionClient.stream` opens the path
with the first 100 points (MotionStart, final false) and appends 100 more (MotionModify with
APPEND) each time the controller asks: a FRAMES_LOW event on /mpi/events (fewer than
`low_count` points left: stream() opens the path with the LOW_COUNT attribute), or a
MotionStatus showing fewer than `low_count` frames in an axis' buffer (frame_count; here 128,
the whole buffer: a chunk goes out as soon as the buffer is not full, which keeps 0.5 s of
points ahead of the axes).
The last chunk closes the path (final true); the MotionStart goal ends when the whole contour
is done. Were the points to run out while the path is open, the controller would E_STOP
(emptyCount, 5 points by default).

Why PVT: each chunk continues from the position and velocity where the path ends, and the
velocities given are the contour's own, so the motion is exactly the one planned, across
chunks too. BESSEL streams as well (no velocities needed: it takes each point's from its
neighbours, at a chunk's first point from that chunk's points alone).

Why not SPLINE: a natural cubic spline is computed from all of its points at once, so the
MPI reference does not let it be appended to (no APPEND); a SPLINE goal with final false is
refused with MPIMotionMessagePATH_ERROR.
"""

import math
import time

from mpi_ros.client import MotionClient, MotionType

SIZE = 2000.0  # counts: half the width of the figure eight
COUNT, DT = 3000, 0.004  # points, seconds between them
DURATION = COUNT * DT


def lemniscate(t: float) -> tuple[float, float]:
    """The contour at time t (0..DURATION): from the crossing, once around, back to it, starting
    and ending at rest (the angle follows a cycloidal ramp)."""
    u = t / DURATION
    angle = math.pi / 2 + 2 * math.pi * (u - math.sin(2 * math.pi * u) / (2 * math.pi))
    s, c = math.sin(angle), math.cos(angle)
    return SIZE * c / (1 + s * s), SIZE * s * c / (1 + s * s)


def velocity(t: float, h: float = 1e-5) -> tuple[float, float]:
    (x0, y0), (x1, y1) = lemniscate(t - h), lemniscate(t + h)
    return (x1 - x0) / (2 * h), (y1 - y0) / (2 * h)


with MotionClient(supervisor=0) as ms0:
    if not ms0.wait_for_server(10.0):
        raise SystemExit("no suite on the graph: start it with scripts/run.sh")
    # 1. to the crossing of the figure eight, where the contour starts (a path starts where the axes are)
    ms0.move(lemniscate(0.0), velocity=2000.0, acceleration=20000.0, deceleration=20000.0,
             jerk_percent=50.0, timeout=30.0)
    # 2. the points and their velocities (zero at the last point: the contour ends at rest)
    times = [DT * k for k in range(1, COUNT + 1)]
    points = [lemniscate(t) for t in times]
    velocities = [velocity(t) for t in times[:-1]] + [(0.0, 0.0)]
    # 3. streamed 100 points at a time, a chunk whenever the buffer is not full
    began = time.monotonic()
    result = ms0.stream(MotionType.PVT, points, [DT] * COUNT, velocities=velocities, chunk=100, low_count=128)
    print(result.message, result.state_name, f"after {time.monotonic() - began:.1f} s at",
          [round(p, 3) for p in result.command_position])
    print(f"{COUNT} points in {math.ceil(COUNT / 100)} goals; peaks:", result.detail.split("path peaks ", 1)[-1])
