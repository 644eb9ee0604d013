"""Path motion: planning a 1,000-point path, and a 100,000-point stream executed by the controller.

Planning: compile_move (validation excluded) of a 2-axis path of 1,000 points for each kind,
median and p99 over repeated runs, and milliseconds per 1,000 points.

Streaming: a 2-axis PVT path of 100,000 points (1 ms apart: 100 s of motion), fed in chunks of
50 points with APPEND whenever the points left fall below 40, the controller stepped in
real-time-sized batches (20 samples = 10 ms at 2 kHz). Reported: the process CPU time it took
as a share of the 100 s of motion (what a real-time run of it costs the core), and that it ran
without an E_STOP (the stream never starved).
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

# This source tree, not the copy scripts/setup.sh last installed into the venv (run with -P).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mpi_ros.mpi import Controller, MotionParams, MPIAction, MPIMotionType, MPIState
from mpi_ros.mpi.base.types import MotionAttr
from mpi_ros.mpi.planning.planner import compile_move
from mpi_ros.mpi.planning.start import AxisStart

POINTS = 1000
KINDS = (MPIMotionType.PT, MPIMotionType.PVT, MPIMotionType.SPLINE, MPIMotionType.BESSEL, MPIMotionType.BSPLINE,
         MPIMotionType.BSPLINE2)


def contour(first: int, count: int, dt: float) -> MotionParams:
    """``count`` points of a circle of radius 10,000 counts, ``dt`` apart, from point ``first``."""
    k = np.arange(first + 1, first + count + 1)
    w = 2.0 * math.pi / 5000.0  # one turn in 5,000 points
    position = np.column_stack([1e4 * np.sin(w * k), 1e4 * (1.0 - np.cos(w * k))]).ravel()
    velocity = np.column_stack([1e4 * w / dt * np.cos(w * k), 1e4 * w / dt * np.sin(w * k)]).ravel()
    return MotionParams(position=position.tolist(), point_velocity=velocity.tolist(), time=[dt] * count)


def planning(kind: MPIMotionType, runs: int = 30) -> list[float]:
    params = contour(0, POINTS, 0.005)
    starts = [AxisStart(0, 0.0), AxisStart(1, 0.0)]
    out = []
    for _ in range(runs):
        t0 = time.perf_counter()
        compile_move(0, kind, MotionAttr.NONE, params, starts, 2000.0)
        out.append(time.perf_counter() - t0)
    return out


def stream(points: int = 100_000, chunk: int = 50, dt: float = 0.001) -> tuple[float, float, bool]:
    """(seconds of motion, CPU seconds, ran without E_STOP)."""
    ctl = Controller()
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0, 1])
    ms.action(MPIAction.MAP)
    first = contour(0, chunk, dt)
    first.final = False
    cpu0 = time.process_time()
    assert ms.start(MPIMotionType.PVT, MotionAttr.NONE, first).ok
    sent = chunk
    while ms.state is MPIState.MOVING:
        ctl.step(20)
        if sent < points and ctl.frame_count(0) < 40:
            more = contour(sent, min(chunk, points - sent), dt)
            sent += len(more.time)
            more.final = sent >= points
            assert ms.modify(MPIMotionType.PVT, MotionAttr.APPEND, more).ok
    cpu = time.process_time() - cpu0
    return points * dt, cpu, ms.state is MPIState.IDLE


def main() -> list[str]:
    rows = [f"Planning a 2-axis path of {POINTS} points (compile_move):", "",
            "| type | median ms | p99 ms | ms per 1,000 points |", "| --- | --- | --- | --- |"]
    for kind in KINDS:
        t = sorted(planning(kind))
        median = statistics.median(t) * 1e3
        p99 = t[int(len(t) * 0.99)] * 1e3
        rows.append(f"| {kind.name} | {median:.2f} | {p99:.2f} | {median * 1000 / POINTS:.2f} |")
    motion, cpu, clean = stream()
    rows += ["", f"A 100,000-point PVT stream on 2 axes (chunks of 50, 20-sample steps): {motion:.0f} s of motion "
                 f"took {cpu:.2f} s of CPU ({100 * cpu / motion:.1f} % of a core in real time); "
                 f"{'ended IDLE, no E_STOP' if clean else 'did NOT end cleanly'}."]
    return rows


if __name__ == "__main__":
    print("\n".join(main()))
