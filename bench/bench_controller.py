"""Controller stepping speed: axis-samples per second, and the multiple of real time.

Targets (DESIGN.md): >= 1,000,000 axis-samples/s on one core; 500x real time for one axis,
60x for 8. Every axis runs a VELOCITY move (the command and the servo are computed every
sample); stepped in batches of 4096 samples (as replay and fast runs do) and of 10 samples
(as the real-time clock thread does every 5 ms).
"""

from __future__ import annotations

import time

from mpi_ros.mpi import (Controller, ControllerConfig, MotionAttr, MotionParams, MPIAction, MPIMotionType,
                         Trajectory)


def controller(axes: int) -> Controller:
    ctl = Controller(ControllerConfig(axis_count=axes, supervisor_count=axes))
    for n in range(axes):
        _, ms = ctl.create_motion(n)
        ms.axis_list_set([n])
        ms.action(MPIAction.MAP)
        ms.start(MPIMotionType.VELOCITY, MotionAttr.NONE,
                 MotionParams(trajectory=[Trajectory(300.0 + n, 1000.0, 0.0, 50.0)]))
    ctl.step(2000)  # past the ramps
    return ctl


def measure(axes: int, batch: int, samples: int) -> tuple[float, float]:
    ctl = controller(axes)
    start = time.perf_counter()
    end = ctl.sample + samples
    while ctl.sample < end:
        ctl.step(batch)
    elapsed = time.perf_counter() - start
    return axes * samples / elapsed, samples / ctl.rate / elapsed


def main() -> list[str]:
    rows = ["| axes | batch | axis-samples/s | x real time |", "| --- | --- | --- | --- |"]
    for axes in (1, 4, 8):
        for batch in (4096, 10):
            samples = 400_000 if batch > 100 else 20_000
            rate, speed = max((measure(axes, batch, samples) for _ in range(3)), key=lambda r: r[0])
            rows.append(f"| {axes} | {batch} | {rate:,.0f} | {speed:,.0f} |")
    return rows


if __name__ == "__main__":
    print("\n".join(main()))
