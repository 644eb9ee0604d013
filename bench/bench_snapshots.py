"""Status snapshots: what the controller's status costs, at one sample and inside a stretch.

Every axis runs a VELOCITY move (bench_controller's _controller and _velocity), in two-axis
supervisors: 8 axes in 4 and 32 axes in 16. Per case, in microseconds a call:
``step(20)`` (the stepping alone), ``motion_snapshots()`` (the live status of every
supervisor and axis) and ``step_snapshots(20, 10 stops)`` (the same 20 samples, with the
status of every second one: what publishing at 1 kHz from a 2 kHz controller in 10 ms
batches asks), and ``pack a sample`` (wire.Packer: the CDR of every axis' and supervisor's
status of one sample, as the status topics pack them, from snapshots not packed before).
Then the stretches the suite steps (issue 35, bench_suite --phases): ``step_snapshots(20, 1
stop)`` (32 axes at 100 Hz: one status at the end of 20 samples) and ``step_snapshots(10, 5
stops)`` (8 axes at 1 kHz in 5 ms batches) beside ``step(10)``, and what their snapshots
alone cost: ``snapshots of ...``, the call minus the stepping of the same samples.

The machines are shared and noisy: each tree (this one and ``--baseline``, extracted with git
archive) runs every case in a fresh process, the trees alternating ``--rounds`` times; a
figure is the best CPU time (process_time) of its process, and the ratio compares the two
trees' figures of one case.

    python -P bench/bench_snapshots.py [--baseline main] [--rounds 3]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run with -P: the sibling bench_controller
from bench_controller import compared_trees, least_side_by_side

if TYPE_CHECKING:
    from mpi_ros.mpi import Controller

CASES = [(8, 4), (32, 16)]
CALLS = ("step(20)", "motion_snapshots()", "step_snapshots(20, 10 stops)", "pack a sample",
         "step_snapshots(20, 1 stop)", "step(10)", "step_snapshots(10, 5 stops)")
# what the snapshots alone cost: a call minus the stepping of the same samples
PARTS = {"snapshots of 1 stop in 20": ("step_snapshots(20, 1 stop)", "step(20)"),
         "snapshots of 5 stops in 10": ("step_snapshots(10, 5 stops)", "step(10)")}
BATCH, EVERY = 20, 2  # samples a call steps; a status every EVERY samples


def _best(call: Callable[[], object], number: int, repeat: int = 7) -> float:
    """The best CPU time of one call, in microseconds, over ``repeat`` runs of ``number``."""
    best = float("inf")
    for _ in range(repeat):
        start = time.process_time()
        for _ in range(number):
            call()
        best = min(best, (time.process_time() - start) / number)
    return best * 1e6


def measure(axes: int, supervisors: int) -> dict[str, float]:
    """Each of CALLS' best CPU time, in a controller with ``axes`` axes in ``supervisors``
    supervisors, every axis in a VELOCITY move."""
    from bench_controller import _controller, _velocity

    ctl = _controller(axes, supervisors)
    _velocity(ctl)
    number = max(20, 800 // axes)

    def stepping(samples: int, every: int) -> Callable[[], object]:
        """step_snapshots of ``samples`` samples, with the status of every ``every``-th."""
        return lambda: ctl.step_snapshots(samples, range(ctl.sample + every, ctl.sample + samples + 1, every))

    return {"step(20)": _best(lambda: ctl.step(BATCH), number),
            "motion_snapshots()": _best(ctl.motion_snapshots, number),
            "step_snapshots(20, 10 stops)": _best(stepping(BATCH, EVERY), number),
            "pack a sample": _packing(ctl, number),
            "step_snapshots(20, 1 stop)": _best(stepping(BATCH, BATCH), number),
            "step(10)": _best(lambda: ctl.step(10), number),
            "step_snapshots(10, 5 stops)": _best(stepping(10, EVERY), number)}


def _packing(ctl: Controller, number: int, repeat: int = 7) -> float:
    """The best CPU time of packing every status of one sample, in microseconds: each axis'
    AxisStatus, then each supervisor's MotionStatus (which holds its axes' again), as the
    controller and supervisor nodes do, each sample's snapshots new to the packer."""
    from mpi_ros.ros import wire

    samples = [ctl.step_snapshots(BATCH, range(ctl.sample + 1, ctl.sample + BATCH + 1)) for _ in range(repeat)]
    best = float("inf")
    for taken in samples:
        batch = list(taken.values())
        packer = wire.Packer(ctl.rate, 1_795_000_000_123_456_789)
        start = time.process_time()
        for _ in range(max(1, number // len(batch))):
            for motions, axes in batch:
                for axis in axes:
                    packer.axis_status(axis)
                for motion in motions.values():
                    packer.motion_status(motion)
        best = min(best, (time.process_time() - start) / (max(1, number // len(batch)) * len(batch)))
    return best * 1e6


def main(baseline: str, rounds: int) -> list[str]:
    rows = ["| axes / supervisors | call | this tree (us) | " + baseline + " (us) | this tree / " + baseline + " |",
            "| --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory() as scratch:
        trees = compared_trees(baseline, Path(scratch))
        for case in CASES:
            best = least_side_by_side(trees, case, "bench_snapshots", rounds)
            for figures in best.values():
                figures.update({part: figures[call] - figures[step] for part, (call, step) in PARTS.items()})
            for call in [*CALLS, *PARTS]:
                new = best["this tree"][call]
                old = best[baseline][call] if baseline in best else float("nan")
                rows.append(f"| {case[0]} / {case[1]} | {call} | {new:,.0f} | {old:,.0f} | {new / old:.2f} |")
    return rows


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default="main", help="commit to measure side by side ('none': only this tree)")
    parser.add_argument("--rounds", type=int, default=3, help="processes of each case on each tree (best kept)")
    options = parser.parse_args()
    print("\n".join(main(options.baseline, options.rounds)))
