"""The modify path compiled with mypyc, side by side with the same source interpreted (issue 35).

Builds a scratch copy of this tree's package (git archive of ``--revision``) and compiles the
modules a modify runs through (``MODULES``) with the mypyc that comes with the mypy in the
venv, timing the build (wall and CPU of the compiler). Then, in fresh processes alternating
between the interpreted tree and the compiled copy (``--rounds`` each, the medians' least
kept), it times per modify of a moving one-axis S-curve:

- modify: MotionSupervisor.modify (validation, planning, loading), as bench_modify --ruckig;
- planning: planner.compile_move alone for the same problem (the axis' state then as its start);

and digests every plan's segments (their float bits), so that the table says whether the
compiled planner gives the same plans bit for bit.

Modules left out: mypyc compiles them, but they fail at import or run time as they are written
(axes/axis.py's descriptors, families.py's Enum with __init__, outcome.py's dataclass over a
class with an annotated attribute, and frames.py at the revisions measured in bench/RESULTS.md,
whose Move.planned filled an object.__new__).

    python -P bench/bench_mypyc.py [--revision HEAD] [--count 2000] [--rounds 3] [--keep DIR]
"""

from __future__ import annotations

import argparse
import hashlib
import resource
import shutil
import struct
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_controller import REPO, measure_in

MYPYC = Path(sys.executable).parent / "mypyc"
MODULES = [f"mpi_ros/mpi/{name}.py" for name in (
    "planning/profiles/segment", "planning/profiles/ramps", "planning/profiles/scurve",
    "planning/profiles/point_to_point", "planning/profiles/jerk", "planning/planner", "planning/validate",
    "planning/start", "base/params", "base/clock", "supervisor/motion", "supervisor/moves",
    "supervisor/state", "supervisor/axis_list", "axes/plant",
)]


# -- the measuring process ------------------------------------------------------------------
def measure(count: int) -> dict:
    """Median microseconds of ``count`` modifies and of planning each one alone, the digest
    of every plan, and whether the planner ran compiled."""
    import statistics

    from mpi_ros.mpi import Controller, ControllerConfig, MotionAttr, MotionParams, MPIMotionType, Trajectory
    from mpi_ros.mpi.planning import planner
    from mpi_ros.mpi.planning.start import AxisStart

    ctl = Controller(ControllerConfig(axis_count=1, supervisor_count=1))
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0])
    trajectory = [Trajectory(5000.0, 100000.0, 100000.0, 50.0)]
    scurve, none = MPIMotionType.S_CURVE, MotionAttr.NONE
    assert ms.start(scurve, none, MotionParams(trajectory=trajectory, position=[2000.0])).ok
    axis, digest, clock = ctl.axes[0], hashlib.sha256(), time.perf_counter
    modifies, plans = [], []
    for i in range(count):
        ctl.step(20)  # moving: each modify starts from the velocity and acceleration of the last one
        params = MotionParams(trajectory=trajectory, position=[2000.0 if i % 2 else -2000.0])
        # (the feedrate is 1: the axis' values are its profile's)
        starts = [AxisStart(0, axis.cmd_p, axis.cmd_v, axis.turn_origin(axis.cmd_p), axis.cmd_a)]
        t0 = clock()
        move, _ = planner.compile_move(0, scurve, none, params, starts, ctl.rate)
        plans.append(clock() - t0)
        t0 = clock()
        done = ms.modify(scurve, none, params)
        modifies.append(clock() - t0)
        assert done.ok, done
        loaded = axis.plan
        assert loaded is not None and loaded.segments == move.plans[0].segments, "modify and planner differ"
        for segment in loaded.segments:
            digest.update(struct.pack("5d", *segment))
    return {"modify": statistics.median(modifies) * 1e6, "planning": statistics.median(plans) * 1e6,
            "digest": digest.hexdigest(), "compiled": not planner.__file__.endswith(".py")}


# -- the build ------------------------------------------------------------------------------
def scratch_tree(revision: str, into: Path) -> Path:
    """The package and its mypy settings at ``revision`` (git archive), in ``into``."""
    archive = subprocess.run(["git", "-C", str(REPO), "archive", revision, "mpi_ros", "pyproject.toml"],
                             check=True, capture_output=True).stdout
    (into / "tree.tar").write_bytes(archive)
    with tarfile.open(into / "tree.tar") as tar:
        tar.extractall(into / "tree", filter="data")
    return into / "tree"


def build(tree: Path) -> tuple[float, float]:
    """Compile MODULES in place in ``tree``; the build's wall and CPU seconds (the compiler's
    processes, gcc included)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([str(MYPYC), *MODULES], cwd=tree, check=True, capture_output=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main(revision: str, count: int, rounds: int, keep: Path | None) -> list[str]:
    with tempfile.TemporaryDirectory() as scratch:
        interpreted = scratch_tree(revision, Path(scratch))
        compiled = Path(scratch) / "compiled"
        shutil.copytree(interpreted, compiled)
        wall, cpu = build(compiled)
        runs: dict[str, list[dict]] = {"interpreted": [], "compiled": []}
        for _ in range(rounds):  # alternating, so that both see the same load
            runs["interpreted"].append(measure_in(interpreted, [count], "bench_mypyc"))
            runs["compiled"].append(measure_in(compiled, [count], "bench_mypyc"))
        if keep is not None:
            shutil.copytree(compiled, keep, dirs_exist_ok=True)
    assert all(run["compiled"] for run in runs["compiled"]) and not any(run["compiled"] for run in
                                                                       runs["interpreted"])
    best = {name: {key: min(run[key] for run in found) for key in ("modify", "planning")}
            for name, found in runs.items()}
    same = len({run["digest"] for found in runs.values() for run in found}) == 1
    return [f"mypyc build of {len(MODULES)} modules: {wall:.1f} s wall, {cpu:.1f} s CPU",
            "| tree | modify median us | planning median us |", "| --- | --- | --- |",
            *(f"| {name} | {best[name]['modify']:.1f} | {best[name]['planning']:.1f} |" for name in best),
            f"| interpreted / compiled | {best['interpreted']['modify'] / best['compiled']['modify']:.2f}x | "
            f"{best['interpreted']['planning'] / best['compiled']['planning']:.2f}x |",
            f"plans bit-identical: {'yes' if same else '**NO**'}"]


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--revision", default="HEAD", help="commit whose package is built and measured")
    parser.add_argument("--count", type=int, default=2000, help="modifies per run")
    parser.add_argument("--rounds", type=int, default=3, help="runs of each tree (least median kept)")
    parser.add_argument("--keep", type=Path, help="copy the compiled tree here")
    options = parser.parse_args()
    print("\n".join(main(options.revision, options.count, options.rounds, options.keep)))
