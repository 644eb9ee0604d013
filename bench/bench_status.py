"""Status reads: what the status topics take of the controller at each status sample.

At every status sample the suite reads every supervisor's mpiMotionStatus and every axis'
mpiAxisStatus (once a sample, for every node: runner.add_status), under the runner's lock,
on the thread that steps the controller: at 100 Hz and 8 axes moving this was the largest piece of the suite's work
besides stepping (bench/RESULTS.md, "Status reads"). Timed here on the controller alone,
every axis in a VELOCITY move (or back-to-back S-curves), reads alternating with 20-sample
steps, side by side with the controller of a baseline commit (``--baseline``, extracted with
git archive; each case in a fresh process, alternating between the two trees, best of
``--rounds``). A tree without ``Controller.motion_snapshots`` is read as the status topics
read it then: each supervisor's snapshot, and an axis' own for the axes no supervisor maps.

    python -P bench/bench_status.py [--baseline 62f4a12] [--rounds 3]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

sys.path.insert(0, str(Path(__file__).resolve().parent))  # bench_controller, beside this file
from bench_controller import REPO, _controller, _restart_idle, _velocity, baseline_tree, measure_in

if TYPE_CHECKING:
    from mpi_ros.mpi import Controller

# (axes, supervisors, motion)
CASES = [(4, 2, "velocity"), (8, 8, "velocity"), (8, 8, "s-curves"), (32, 16, "velocity"), (32, 16, "s-curves")]
READS = 2000


def read_all(ctl: Controller) -> Any:
    """Every supervisor's and every axis' status, as the status topics read them."""
    if hasattr(ctl, "motion_snapshots"):
        return ctl.motion_snapshots()
    motions = {ms.number: ms.snapshot() for ms in ctl.supervisors}
    mapped = {axis.number for motion in motions.values() for axis in motion.axes}
    return motions, [ctl.axis_snapshot(a.number) for a in ctl.axes if a.number not in mapped]


def measure(axes: int, supervisors: int, motion: str) -> dict[str, float]:
    ctl = _controller(axes, supervisors)
    if motion == "velocity":
        _velocity(ctl)
    flips = [0] * supervisors
    spent = 0.0
    for _ in range(READS):
        if motion == "s-curves":
            _restart_idle(ctl, flips)
        ctl.step(20)
        start = time.perf_counter()
        read_all(ctl)
        spent += time.perf_counter() - start
    return {"read_us": spent / READS * 1e6}


def main(baseline: str, rounds: int) -> list[str]:
    rows = [f"| axes | supervisors | motion | a read, us | per axis, us | {baseline}: a read, us | speed-up |",
            "| --- | --- | --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory() as scratch:
        old = baseline_tree(baseline, Path(scratch))
        for case in CASES:
            new_runs, old_runs = [], []
            for _ in range(rounds):  # alternate, so both see the same load
                new_runs.append(measure_in(REPO, case, "bench_status")["read_us"])
                if old is not None:
                    old_runs.append(measure_in(old, case, "bench_status")["read_us"])
            axes, supervisors, motion = case
            row = f"| {axes} | {supervisors} | {motion} | {min(new_runs):.1f} | {min(new_runs) / axes:.1f} |"
            row += f" {min(old_runs):.1f} | {min(old_runs) / min(new_runs):.2f}x |" if old_runs else " - | - |"
            rows.append(row)
    return rows


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default="62f4a12", help="commit to measure side by side")
    parser.add_argument("--rounds", type=int, default=3, help="runs of each case on each tree (best kept)")
    options = parser.parse_args()
    print("\n".join(main(options.baseline, options.rounds)))
