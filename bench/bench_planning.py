"""Planning time of a start: S-curve, trapezoid and S_CURVE_JERK, one axis and a 2-axis vector.

Target (DESIGN.md): planning an S-curve < 100 us median. Measured on compile_move, the whole
request-to-frames path (validation excluded), over random distances and limits.
"""

from __future__ import annotations

import random
import statistics
import time

from mpi_ros.mpi.params import MotionParams, Trajectory
from mpi_ros.mpi.planner import AxisStart, compile_move
from mpi_ros.mpi.types import MotionAttr, MPIMotionType


def timings(motion_type: MPIMotionType, axes: int, count: int = 3000) -> list[float]:
    rng = random.Random(7)
    out = []
    for _ in range(count):
        traj = Trajectory(rng.uniform(100, 5000), rng.uniform(1e3, 1e5), rng.uniform(1e3, 1e5), rng.uniform(0, 100),
                          rng.uniform(1e4, 1e7), rng.uniform(1e4, 1e7))
        params = MotionParams(trajectory=[traj], position=[rng.uniform(-1e5, 1e5) for _ in range(axes)])
        starts = [AxisStart(n, 0.0) for n in range(axes)]
        t0 = time.perf_counter()
        compile_move(0, motion_type, MotionAttr.NONE, params, starts, 2000.0)
        out.append(time.perf_counter() - t0)
    return out


def main() -> list[str]:
    rows = ["| type | axes | median us | p99 us |", "| --- | --- | --- | --- |"]
    for motion_type in (MPIMotionType.S_CURVE, MPIMotionType.TRAPEZOIDAL, MPIMotionType.S_CURVE_JERK):
        for axes in (1, 2):
            t = sorted(timings(motion_type, axes))
            rows.append(f"| {motion_type.name} | {axes} | {statistics.median(t) * 1e6:.1f} | "
                        f"{t[int(len(t) * 0.99)] * 1e6:.1f} |")
    return rows


if __name__ == "__main__":
    print("\n".join(main()))
