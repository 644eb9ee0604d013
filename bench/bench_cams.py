"""Cam slaves: stepping speed beside the same axes in VELOCITY moves (issue 12).

A cam's slave is computed sample by sample (its command is known only at the samples: the
table at the master's position), so it costs more than an axis on a polynomial command piece.
8 axes in two supervisors: axis 0 is the master (a VELOCITY move); axes 1..7 either run a
repeating CAM_CUBIC following axis 0's command position, or VELOCITY moves. Each case runs
``--rounds`` times alternating, best of; figures are axis-samples (all 8 axes) per CPU second.

    python -P bench/bench_cams.py [--rounds 3]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mpi_ros.mpi import (
    AxisMaster,
    AxisMasterType,
    Controller,
    ControllerConfig,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIMotionType,
    Trajectory,
)

AXES = 8
CASES = [(4096, 200_000), (20, 20_000)]  # (batch, samples)


def _controller(slaves: str) -> Controller:
    ctl = Controller(ControllerConfig(axis_count=AXES, supervisor_count=2))
    _, master = ctl.create_motion(0, 0)
    _, ms = ctl.create_motion(1)
    ms.axis_list_set(list(range(1, AXES)))
    ms.action(MPIAction.MAP)
    master.start(MPIMotionType.VELOCITY, MotionAttr.NONE, MotionParams(trajectory=[Trajectory(2000.0, 1e6, 1e6)]))
    if slaves == "cam":
        for n in range(1, AXES):
            ctl.axis_master_set(n, AxisMaster(AxisMasterType.AXIS_COMMANDED_POSITION, 0))
        count = AXES - 1
        params = MotionParams(master_distance=[200.0, 200.0, 300.0, 300.0],
                              slave_position=[100.0] * count + [200.0] * count + [150.0] * count + [-450.0] * count,
                              gear_ratio=[1.0] * count * 2 + [0.0] * count * 2, repeat_from=0)
        assert ms.start(MPIMotionType.CAM_CUBIC, MotionAttr.REPEAT, params).ok
    else:
        assert ms.start(MPIMotionType.VELOCITY, MotionAttr.NONE,
                        MotionParams(trajectory=[Trajectory(1000.0, 1e6, 1e6)])).ok
    ctl.step(100)
    return ctl


def _measure(slaves: str, batch: int, samples: int) -> float:
    ctl = _controller(slaves)
    start = time.process_time()
    for _ in range(samples // batch):
        ctl.step(batch)
    return AXES * samples / (time.process_time() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    print("| batch | VELOCITY slaves: axis-samples per CPU s | cam slaves: axis-samples per CPU s | cam / velocity |")
    print("| --- | --- | --- | --- |")
    for batch, samples in CASES:
        best = {"velocity": 0.0, "cam": 0.0}
        for _ in range(args.rounds):
            for slaves in best:
                best[slaves] = max(best[slaves], _measure(slaves, batch, samples))
        print(f"| {batch} | {best['velocity']:,.0f} | {best['cam']:,.0f} | {best['cam'] / best['velocity']:.2f} |")


if __name__ == "__main__":
    main()
