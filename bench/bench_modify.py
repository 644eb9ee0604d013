"""The core's CPU per MotionModify: applying it, and the stepping it adds.

Issue 14's soak target: 8 motion supervisors, each sent 100 modifies a second (800/s),
with the suite in real time. Here the ROS-free core alone: 8 one-axis supervisors in
S_CURVE moves, each modified every ``--every`` samples (20: 100/s at 2 kHz) toward the
other end of its stroke (AUTO_START), the controller stepped in batches of each size in
``--batches`` (20 is what the clock thread steps every 10 ms). Per modify:

- apply: CPU in commands.apply (parsing, checks, planning, loading the move);
- stepping extra: CPU stepping the run minus CPU stepping the same samples without any
  modify (the moves then run to their end and settle), per modify.

The machine is shared, so every case runs in a fresh process, alternating between this tree
and the package at ``--baseline`` (git archive), best of ``--rounds`` per figure. Both trees
must give the same bits: each run digests every axis' values after every step (outside the
timed calls) and the table says whether the digests agree.

``--ruckig N`` (issue 35) times instead N modifies of a moving one-axis S-curve through the
controller's public API (MotionSupervisor.modify: validation, planning, loading), each beside
ruckig's calculate() for the same problem (the cross-check's mapping of the plan the modify
loaded, bench_planning.ruckig_input), in one process, the two calls alternating; a fresh
process per run, ``--rounds`` runs of this tree and of ``--baseline`` ("none": this tree only)
alternating. Beside them, the step(20) that follows each modify (what the new plan costs the
stepping: its bank refresh, the pieces it starts inside the stretch) and the two together, as
a user sees a modify; "values" says whether the axis values after every step agree with
the first run's.

    python -P bench/bench_modify.py [--baseline b39be10] [--rounds 3] [--batches 1 2 5 20]
    python -P bench/bench_modify.py --ruckig 2000 [--baseline none] [--rounds 3]
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_controller import REPO, baseline_tree, measure_in

if TYPE_CHECKING:
    from mpi_ros.mpi import Controller

SUPERVISORS = 8
TRAJECTORY = [{"velocity": 5000.0, "acceleration": 100000.0, "deceleration": 100000.0, "jerk_percent": 50.0}]


# -- the measuring process ------------------------------------------------------------------
def _controller() -> Controller:
    from mpi_ros.commands import Command, Operation, apply
    from mpi_ros.mpi import Controller, ControllerConfig, MPIAction

    ctl = Controller(ControllerConfig(axis_count=SUPERVISORS, supervisor_count=SUPERVISORS))
    for n in range(SUPERVISORS):
        _, ms = ctl.create_motion(n)
        ms.axis_list_set([n])
        ms.action(MPIAction.MAP)
        apply(ctl, Command(Operation.MOTION_START, n, request={"type": "S_CURVE", "position": [2000.0],
                                                      "trajectory": TRAJECTORY}))
    ctl.step(100)
    return ctl


def measure(batch: int, every: int, samples: int, modify: bool) -> dict:
    """CPU seconds stepping and applying over ``samples`` samples, the modifies applied, and a
    digest of every axis' values after every step."""
    from mpi_ros.commands import Command, Operation, apply

    ctl = _controller()
    digest = hashlib.sha256()
    stepping = applying = 0.0
    mods = flips = 0
    end, due = ctl.sample + samples, ctl.sample + every
    while ctl.sample < end:
        t0 = time.process_time()
        ctl.step(min(end, ctl.sample + batch) - ctl.sample)
        stepping += time.process_time() - t0
        digest.update(ctl.bank.values.tobytes())
        if modify and ctl.sample >= due:
            due += every
            flips += 1
            request = {"type": "S_CURVE", "position": [2000.0 if flips % 2 else -2000.0],
                       "attributes": ["AUTO_START"], "trajectory": TRAJECTORY}
            t0 = time.process_time()
            for n in range(SUPERVISORS):
                apply(ctl, Command(Operation.MOTION_MODIFY, n, request=request))
            applying += time.process_time() - t0
            mods += SUPERVISORS
    return {"stepping": stepping, "applying": applying, "mods": mods, "digest": digest.hexdigest()}


# -- beside ruckig ---------------------------------------------------------------------------------
def measure_ruckig(count: int) -> dict:
    """Median and p90 of ``count`` modifies (MotionSupervisor.modify) and of ruckig's
    calculate() on each one's problem, microseconds."""
    import importlib
    import statistics

    # the package measured first: importing bench_planning puts this tree's source ahead of it
    importlib.import_module("mpi_ros")
    from bench_planning import ruckig_input, ruckig_limits
    from ruckig import Result, Ruckig
    from ruckig import Trajectory as RuckigTrajectory

    from mpi_ros.mpi import Controller, ControllerConfig, MotionAttr, MotionParams, MPIMotionType, Trajectory

    ctl = Controller(ControllerConfig(axis_count=1, supervisor_count=1))
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0])
    trajectory = [Trajectory(5000.0, 100000.0, 100000.0, 50.0)]
    assert ms.start(MPIMotionType.S_CURVE, MotionAttr.NONE, MotionParams(trajectory=trajectory, position=[2000.0])).ok
    otg, solved = Ruckig(1), RuckigTrajectory(1)
    ours, theirs, after, clock = [], [], [], time.perf_counter
    digest = hashlib.sha256()
    for i in range(count):
        t0 = clock()
        ctl.step(20)  # moving: each modify starts from the velocity and acceleration of the last one
        after.append(clock() - t0)
        digest.update(ctl.bank.values.tobytes())
        params = MotionParams(trajectory=trajectory, position=[2000.0 if i % 2 else -2000.0])
        t0 = clock()
        done = ms.modify(MPIMotionType.S_CURVE, MotionAttr.NONE, params)
        ours.append(clock() - t0)
        assert done.ok, done
        plan = ctl.axes[0].plan
        assert plan is not None
        inp, _ = ruckig_input(ruckig_limits([plan])[0])
        t0 = clock()
        result = otg.calculate(inp, solved)
        theirs.append(clock() - t0)
        assert result in (Result.Working, Result.Finished), result

    def figures(times: list[float]) -> list[float]:
        return [statistics.median(times) * 1e6, statistics.quantiles(times, n=10)[-1] * 1e6]

    # the stepping after a modify: each step but the first follows one
    with_step = [mod + step for mod, step in zip(ours, after[1:], strict=False)]
    return {"modify": figures(ours), "ruckig": figures(theirs), "after": figures(after[1:]),
            "with_step": figures(with_step), "digest": digest.hexdigest()}


def beside_ruckig(count: int, baseline: str | None, rounds: int) -> list[str]:
    """The table of :func:`measure_ruckig`, a fresh process per run, ``rounds`` runs of this tree
    and (``baseline``) of the package at that commit, alternating."""
    rows = ["| tree | modifies | modify median us | modify p90 us | ruckig median us | ruckig p90 us | "
            "modify / ruckig (medians) | next step(20) median us | modify + next step(20) median us | values |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    digests: dict[str, str] = {}
    with tempfile.TemporaryDirectory() as scratch:
        trees = [(REPO, "this tree")]
        old = baseline_tree(baseline, Path(scratch)) if baseline else None
        if old is not None:
            trees.append((old, baseline))
        for _ in range(rounds):  # alternating, so that both see the same load
            for tree, name in trees:
                run = measure_in(tree, [count], "bench_modify", "measure_ruckig")
                (ours, ours_p90), (ruckig, ruckig_p90) = run["modify"], run["ruckig"]
                first = digests.setdefault("first", run["digest"])
                rows.append(f"| {name} | {count} | {ours:.1f} | {ours_p90:.1f} | {ruckig:.2f} | {ruckig_p90:.2f} | "
                            f"{ours / ruckig:.1f}x | {run['after'][0]:.1f} | {run['with_step'][0]:.1f} | "
                            f"{'same' if run['digest'] == first else '**DIFFER**'} |")
    return rows


# -- the table ------------------------------------------------------------------------------
def per_modify(source: Path, batch: int, every: int, samples: int, rounds: int) -> dict:
    """Microseconds per modify (apply, stepping extra, sum; the least of ``rounds`` runs
    each) and the digest of the modified run."""
    with_mods = [measure_in(source, [batch, every, samples, True], "bench_modify") for _ in range(rounds)]
    without = [measure_in(source, [batch, every, samples, False], "bench_modify") for _ in range(rounds)]
    mods = with_mods[0]["mods"]
    apply_us = min(run["applying"] for run in with_mods) / mods * 1e6
    extra_us = (min(run["stepping"] for run in with_mods) - min(run["stepping"] for run in without)) / mods * 1e6
    digests = {run["digest"] for run in with_mods}
    assert len(digests) == 1, "one tree gave different values from run to run"
    return {"apply": apply_us, "extra": extra_us, "total": apply_us + extra_us, "mods": mods,
            "digest": digests.pop()}


def main(baseline: str, rounds: int, batches: list[int], every: int, seconds: float) -> list[str]:
    samples = int(seconds * 2000)
    rows = [f"| batch | modifies | apply us | stepping extra us | per modify us | {baseline}: apply us | "
            f"{baseline}: stepping extra us | {baseline}: per modify us | CPU per modify, this / {baseline} | "
            "same values |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory() as scratch:
        old = baseline_tree(baseline, Path(scratch))
        for batch in batches:
            new_runs, old_runs = [], []
            for _ in range(rounds):  # alternate, so both see the same load
                new_runs.append(per_modify(REPO, batch, every, samples, 1))
                if old is not None:
                    old_runs.append(per_modify(old, batch, every, samples, 1))
            new = _least(new_runs)
            row = f"| {batch} | {new['mods']} | {new['apply']:.0f} | {new['extra']:.0f} | {new['total']:.0f} |"
            if old_runs:
                before = _least(old_runs)
                same = "yes" if before["digest"] == new["digest"] else "**NO**"
                row += (f" {before['apply']:.0f} | {before['extra']:.0f} | {before['total']:.0f} | "
                        f"{new['total'] / before['total']:.2f} | {same} |")
            else:
                row += " - | - | - | - | - |"
            rows.append(row)
    return rows


def _least(runs: list[dict]) -> dict:
    """The least apply and stepping extra over ``runs`` (the noise of a shared machine only adds)."""
    least = {key: min(run[key] for run in runs) for key in ("apply", "extra")}
    digests = {run["digest"] for run in runs}
    assert len(digests) == 1, "one tree gave different values from run to run"
    return {**least, "total": least["apply"] + least["extra"], "mods": runs[0]["mods"], "digest": digests.pop()}


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", help="commit to measure side by side (b39be10; with --ruckig: none)")
    parser.add_argument("--rounds", type=int, default=3, help="runs of each case on each tree (least kept)")
    parser.add_argument("--batches", type=int, nargs="+", default=[1, 2, 5, 20], help="samples stepped at a time")
    parser.add_argument("--every", type=int, default=20, help="samples between modifies of each supervisor")
    parser.add_argument("--seconds", type=float, default=3.0, help="simulated seconds per run")
    parser.add_argument("--ruckig", type=int, metavar="N", help="time N modifies beside ruckig instead")
    options = parser.parse_args()
    if options.ruckig:
        baseline = None if options.baseline in (None, "none") else options.baseline
        print("\n".join(beside_ruckig(options.ruckig, baseline, options.rounds)))
        sys.exit()
    rows = main(options.baseline or "b39be10", options.rounds, options.batches, options.every, options.seconds)
    print("\n".join(rows))
