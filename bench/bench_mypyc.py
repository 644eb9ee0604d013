"""The core compiled with mypyc, side by side with the same source interpreted (issue 35).

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

``--suite CASE`` (repeatable; bench_suite's cases) compiles instead the modules a stretch of the
suite runs through (``SUITE_MODULES``: Controller.step_snapshots, its stepping, status templates
and snapshots) and times, in both trees: a stretch as the suite steps it (``step_snapshots`` of
32 axes in 16 supervisors, 20 samples with one status; of 8 in 4, 10 samples with five), its
snapshots digested; then the suite through ROS as bench_suite runs it (rclpy subscriber
processes, the suite's CPU from /proc), the trees alternating ``--rounds`` times. The modules it
leaves out fail as written (axes/trace.py: compiled, ``_Segments.of``'s call with ``*`` over
a generator hands ``gathered`` a list iterator where an array is due; base/params.py: the ROS
layer reads its dataclasses' ``__slots__``, which a compiled class has not; axes/plant.py: mypyc
rejects servo_effort's constrained TypeVar). One thing is adapted in the scratch copy only
(``ADAPTATIONS``): the ROS layer keeps each controller's epoch by a weak reference to it, and a
compiled Controller cannot be referenced weakly.

    python -P bench/bench_mypyc.py [--revision HEAD] [--count 2000] [--rounds 3] [--keep DIR]
    python -P bench/bench_mypyc.py --suite 32x100 --suite 8x1000 [--seconds 10] [--rounds 3]
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
SUITE_MODULES = [f"mpi_ros/mpi/{name}.py" for name in (
    "control", "snapshots", "base/snapshot", "base/events", "base/wrap", "base/clock", "supervisor/status",
    "supervisor/moves", "supervisor/motion", "supervisor/state", "supervisor/stepping", "planning/frames",
    "axes/status", "axes/bank", "axes/stretch", "axes/scratch", "faults/monitor",
)]
# (file, text as written, text in the compiled copy): see the docstring
ADAPTATIONS = [("mpi_ros/ros/convert.py", "_EPOCHS: weakref.WeakKeyDictionary[Any, int] = weakref.WeakKeyDictionary()",
                "_EPOCHS: dict[Any, int] = {}")]
STRETCHES = [(32, 16, 20, 20), (8, 4, 10, 2)]  # axes, supervisors, samples, a status every ... samples


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


def measure_stretch(count: int) -> dict:
    """The best CPU time of a stretch of each of STRETCHES (microseconds, best of 5 runs of
    ``count``), a digest of every snapshot taken, and whether the core ran compiled."""
    import hashlib

    from mpi_ros.mpi import control

    digest = hashlib.sha256()
    figures = {f"{case[0]}/{case[1]}": _stretch(*case, count, digest) for case in STRETCHES}
    return {"stretch": figures, "digest": digest.hexdigest(), "compiled": not control.__file__.endswith(".py")}


def _stretch(axes: int, supervisors: int, samples: int, every: int, count: int, digest) -> float:
    """measure_stretch's figure of one case; the snapshots of its first 20 stretches digested."""
    from bench_controller import _controller, _velocity

    ctl = _controller(axes, supervisors)
    _velocity(ctl)

    def stretch() -> dict:
        return ctl.step_snapshots(samples, range(ctl.sample + every, ctl.sample + samples + 1, every))

    for _ in range(20):
        for motions, axis_snaps in stretch().values():
            digest.update(repr((sorted(motions.items()), axis_snaps)).encode())
    best = float("inf")
    for _ in range(5):
        start = time.process_time()
        for _ in range(count):
            stretch()
        best = min(best, (time.process_time() - start) / count)
    return best * 1e6


# -- the build ------------------------------------------------------------------------------
def scratch_tree(revision: str, into: Path, *more: str) -> Path:
    """The package, its mypy settings and ``more`` paths at ``revision`` (git archive), in ``into``."""
    archive = subprocess.run(["git", "-C", str(REPO), "archive", revision, "mpi_ros", "pyproject.toml", *more],
                             check=True, capture_output=True).stdout
    (into / "tree.tar").write_bytes(archive)
    with tarfile.open(into / "tree.tar") as tar:
        tar.extractall(into / "tree", filter="data")
    return into / "tree"


def build(tree: Path, modules: list[str]) -> tuple[float, float]:
    """Compile ``modules`` in place in ``tree``; the build's wall and CPU seconds (the
    compiler's processes, gcc included)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([str(MYPYC), *modules], cwd=tree, check=True, capture_output=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main(revision: str, count: int, rounds: int, keep: Path | None) -> list[str]:
    with tempfile.TemporaryDirectory() as scratch:
        interpreted = scratch_tree(revision, Path(scratch))
        compiled = Path(scratch) / "compiled"
        shutil.copytree(interpreted, compiled)
        wall, cpu = build(compiled, MODULES)
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


def suite(revision: str, cases: list[str], seconds: float, rounds: int, count: int) -> list[str]:
    """SUITE_MODULES compiled: a stretch, then the suite through ROS (bench_suite), side by side."""
    import bench_suite

    with tempfile.TemporaryDirectory() as scratch:
        interpreted = scratch_tree(revision, Path(scratch), "config")
        compiled = Path(scratch) / "compiled"
        shutil.copytree(interpreted, compiled)
        for name, written, adapted in ADAPTATIONS:
            path = compiled / name
            text = path.read_text(encoding="utf-8")
            if written not in text:
                raise SystemExit(f"bench_mypyc: {name} no longer has {written!r}: see ADAPTATIONS")
            path.write_text(text.replace(written, adapted), encoding="utf-8")
        wall, cpu = build(compiled, SUITE_MODULES)
        trees = [(interpreted, "interpreted"), (compiled, "compiled")]
        stretches: dict[str, list[dict]] = {"interpreted": [], "compiled": []}
        for _ in range(rounds):
            for tree, name in trees:
                stretches[name].append(measure_in(tree, [count], "bench_mypyc", "measure_stretch"))
        assert all(run["compiled"] == (name == "compiled") for name, runs in stretches.items() for run in runs)
        same = len({run["digest"] for runs in stretches.values() for run in runs}) == 1
        results = [bench_suite.run_case(bench_suite.CASES[case], seconds, tree=tree, label=name)
                   for _ in range(rounds) for case in cases for tree, name in trees]
    best = {name: {key: min(run["stretch"][key] for run in runs) for key in runs[0]["stretch"]}
            for name, runs in stretches.items()}
    keys = list(best["interpreted"])
    return [f"mypyc build of {len(SUITE_MODULES)} modules: {wall:.1f} s wall, {cpu:.1f} s CPU",
            "| tree | " + " | ".join(f"stretch {key} us" for key in keys) + " |", "| --- |" + " --- |" * len(keys),
            *(f"| {name} | " + " | ".join(f"{best[name][key]:.1f}" for key in keys) + " |" for name in best),
            "| interpreted / compiled | " + " | ".join(
                f"{best['interpreted'][key] / best['compiled'][key]:.2f}x" for key in keys) + " |",
            f"snapshots the same in both trees: {'yes' if same else '**NO**'}", "",
            *bench_suite.summary(results), "", *bench_suite.report(results)]


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--revision", default="HEAD", help="commit whose package is built and measured")
    parser.add_argument("--count", type=int, default=2000, help="modifies per run")
    parser.add_argument("--rounds", type=int, default=3, help="runs of each tree (least median kept)")
    parser.add_argument("--keep", type=Path, help="copy the compiled tree here")
    parser.add_argument("--suite", action="append", metavar="CASE",
                        help="compile the stretch's modules and run this bench_suite case (repeatable)")
    parser.add_argument("--seconds", type=float, default=10.0, help="--suite: each run's window")
    options = parser.parse_args()
    if options.suite:
        print("\n".join(suite(options.revision, options.suite, options.seconds, options.rounds,
                              max(20, options.count // 10))))
    else:
        print("\n".join(main(options.revision, options.count, options.rounds, options.keep)))
