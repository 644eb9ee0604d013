"""Controller stepping speed: axis-samples per second, and the multiple of real time.

Targets (docs/quality.md, "Fast"; issue 10): stepping in real-time-sized batches (20 samples, what the
clock thread steps every 10 ms) at 32 axes >= 1,000,000 axis-samples/s; with large batches
(4096, as replay and fast runs step) >= 20,000,000. Every axis runs a VELOCITY move (the
command and the servo are computed every sample), one supervisor per axis for 1, 4 and 8
axes, two-axis supervisors for 32; "S-curves" is 32 axes in 16 supervisors making
back-to-back S_CURVE moves (segment and servo breakpoints, settling, DONE every few
hundred samples), started between batches.

The machines are shared and noisy, so every figure is measured side by side with the
controller of a baseline commit (``--baseline``, extracted with git archive): each case
runs in a fresh process, alternating between the two trees, best of ``--rounds``.
Figures are per wall-clock second and per CPU second of the stepping process (the latter
moves less with the load of other processes).

Every case can run at several sample rates (``--rates 2000 4000``): the same moves at 4 kHz
cost twice the samples for the same controller time, so "x real time" is the figure to compare.

    python -P bench/bench_controller.py [--baseline dd12ae1] [--rounds 3] [--rates 2000 4000] [--stretch]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from mpi_ros.mpi import Controller

REPO = Path(__file__).resolve().parent.parent
# (axes, supervisors, motion, batch, samples)
CASES = [
    (1, 1, "velocity", 4096, 400_000), (1, 1, "velocity", 10, 20_000),
    (4, 4, "velocity", 4096, 400_000), (4, 4, "velocity", 10, 20_000),
    (8, 8, "velocity", 4096, 400_000), (8, 8, "velocity", 10, 20_000),
    (32, 16, "velocity", 4096, 400_000), (32, 16, "velocity", 20, 20_000),
    (32, 16, "s-curves", 4096, 40_000), (32, 16, "s-curves", 20, 20_000),
]
# --stretch (issue 35): a stretch's fixed cost, in the batches the live suite steps (2 and 20
# samples) at 8 axes in two-axis supervisors and at 32
STRETCH_CASES = [
    (8, 4, "velocity", 2, 20_000), (8, 4, "velocity", 20, 40_000),
    (32, 16, "velocity", 2, 20_000), (32, 16, "velocity", 20, 40_000),
    (32, 16, "s-curves", 2, 20_000), (32, 16, "s-curves", 20, 40_000),
]


# -- the measuring process ------------------------------------------------------------------
def _controller(axes: int, supervisors: int, rate: float = 2000.0) -> Controller:
    from mpi_ros.mpi import Controller, ControllerConfig, MPIAction

    ctl = Controller(ControllerConfig(axis_count=axes, supervisor_count=supervisors, sample_rate=rate))
    per = axes // supervisors
    for n in range(supervisors):
        _, ms = ctl.create_motion(n)
        ms.axis_list_set(list(range(per * n, per * n + per)))
        ms.action(MPIAction.MAP)
    return ctl


def _velocity(ctl: Controller) -> None:
    from mpi_ros.mpi import MotionAttr, MotionParams, MPIMotionType, Trajectory

    for n, ms in enumerate(ctl.supervisors):
        ms.start(MPIMotionType.VELOCITY, MotionAttr.NONE,
                 MotionParams(trajectory=[Trajectory(300.0 + n, 1000.0, 0.0, 50.0)]))
    ctl.step(2000)  # past the ramps


def _restart_idle(ctl: Controller, flips: list[int]) -> None:
    """Start the next S-curve move of every idle supervisor (back and forth)."""
    from mpi_ros.mpi import MotionAttr, MotionParams, MPIMotionType, MPIState, Trajectory

    for n, ms in enumerate(ctl.supervisors):
        if ms.state is MPIState.IDLE:
            flips[n] ^= 1
            x = (1000.0 + 37.0 * n) * (1.0 if flips[n] else -1.0)
            ms.start(MPIMotionType.S_CURVE, MotionAttr.NONE,
                     MotionParams(trajectory=[Trajectory(4000.0 + 100.0 * n, 40000.0, 40000.0, 50.0)],
                                  position=[x, -x / 2.0][: len(ms.axis_list)]))


def measure(axes: int, supervisors: int, motion: str, batch: int, samples: int,
            rate: float = 2000.0) -> dict[str, float]:
    ctl = _controller(axes, supervisors, rate)
    if motion == "velocity":
        _velocity(ctl)
    flips = [0] * supervisors
    wall, cpu = time.perf_counter(), time.process_time()
    end = ctl.sample + samples
    while ctl.sample < end:
        if motion == "s-curves":
            _restart_idle(ctl, flips)
        ctl.step(batch)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    return {"wall": axes * samples / wall, "cpu": axes * samples / cpu, "real_time": samples / ctl.rate / wall}


def measure_in(source: Path, case: tuple | list, bench: str = "bench_controller", function: str = "measure") -> dict:
    """``<bench>.<function>(*case)`` in a fresh process running the package in ``source``."""
    code = ("import sys, json; sys.dont_write_bytecode = True; sys.path.insert(0, sys.argv[1]); "
            f"sys.path.insert(0, sys.argv[2]); import {bench} as b; "
            f"print(json.dumps(b.{function}(*json.loads(sys.argv[3]))))")
    done = subprocess.run([sys.executable, "-P", "-c", code, str(source), str(REPO / "bench"), json.dumps(case)],
                          check=True, capture_output=True, text=True)
    return json.loads(done.stdout)


def least_side_by_side(trees: list[tuple[Path, str]], case: tuple | list, bench: str,
                       rounds: int) -> dict[str, dict[str, float]]:
    """``<bench>.measure(*case)`` ``rounds`` times in each tree, the trees alternating so that
    both see the same load; each figure's least over the rounds, by tree name."""
    runs: dict[str, list[dict[str, float]]] = {name: [] for _, name in trees}
    for _ in range(rounds):
        for tree, name in trees:
            runs[name].append(measure_in(tree, case, bench))
    return {name: {key: min(run[key] for run in found) for key in found[0]} for name, found in runs.items()}


# -- the table ------------------------------------------------------------------------------
def baseline_tree(revision: str, into: Path) -> Path | None:
    """The package at ``revision`` and its config/ (git archive), or None where there is no
    git history."""
    try:
        archive = subprocess.run(["git", "-C", str(REPO), "archive", revision, "mpi_ros", "config"],
                                 check=True, capture_output=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    (into / "tree.tar").write_bytes(archive)
    with tarfile.open(into / "tree.tar") as tar:
        tar.extractall(into / "tree", filter="data")
    return into / "tree"


def compared_trees(baseline: str, into: Path, label: str = "this tree") -> list[tuple[Path, str]]:
    """This source tree, and the package at ``baseline`` where it can be extracted ("none": only
    this one): (tree, its name) each, for measurements side by side."""
    trees = [(REPO, label)]
    if baseline != "none":
        old = baseline_tree(baseline, into)
        if old is None:
            print(f"(no baseline: `git archive {baseline}` failed)")
        else:
            trees.append((old, baseline))
    return trees


def _best(source: Path, case: tuple, rounds: int) -> dict[str, float]:
    runs = [measure_in(source, case) for _ in range(rounds)]
    return {key: max(run[key] for run in runs) for key in runs[0]}


def main(baseline: str = "dd12ae1", rounds: int = 3, rates: tuple[float, ...] = (2000.0,),
         cases: list[tuple[int, int, str, int, int]] | None = None) -> list[str]:
    rows = [f"| rate | axes | supervisors | motion | batch | axis-samples/s | per CPU second | x real time | "
            f"{baseline}: axis-samples/s | {baseline}: per CPU second | speed-up (CPU) | CPU per step, us |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory() as scratch:
        old = baseline_tree(baseline, Path(scratch))
        for case in [(*case, rate) for rate in rates for case in cases or CASES]:
            new_runs, old_runs = [], []
            for _ in range(rounds):  # alternate, so both see the same load
                new_runs.append(measure_in(REPO, case))
                if old is not None:
                    old_runs.append(measure_in(old, case))
            new = {key: max(run[key] for run in new_runs) for key in new_runs[0]}
            axes, supervisors, motion, batch, _, rate = case
            row = (f"| {rate / 1000:g} kHz | {axes} | {supervisors} | {motion} | {batch} | {new['wall']:,.0f} | "
                   f"{new['cpu']:,.0f} | {new['real_time']:,.0f} |")
            step = f"{axes * batch / new['cpu'] * 1e6:.0f}"  # a step(batch)'s CPU time
            if old_runs:
                before = {key: max(run[key] for run in old_runs) for key in old_runs[0]}
                row += f" {before['wall']:,.0f} | {before['cpu']:,.0f} | {new['cpu'] / before['cpu']:.2f}x |"
                step += f" ({axes * batch / before['cpu'] * 1e6:.0f})"
            else:
                row += " - | - | - |"
            row += f" {step} |"
            rows.append(row)
    return rows


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default="dd12ae1", help="commit to measure side by side")
    parser.add_argument("--rounds", type=int, default=3, help="runs of each case on each tree (best kept)")
    parser.add_argument("--rates", type=float, nargs="+", default=[2000.0],
                        help="sample rates (Hz) to step every case at (the default 2 kHz; issue 35 asks 4 kHz too)")
    parser.add_argument("--stretch", action="store_true",
                        help="the small batches of issue 35 (a stretch's fixed cost) instead of the default cases")
    options = parser.parse_args()
    print("\n".join(main(options.baseline, options.rounds, tuple(options.rates),
                         STRETCH_CASES if options.stretch else None)))
