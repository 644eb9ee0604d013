"""Planning time of a start: S-curve, trapezoid and S_CURVE_JERK, one axis and a 2-axis vector.

Targets (docs/quality.md, "Fast"): planning an S-curve < 100 us median; within 10x of ruckig's calculate()
for the equivalent problem, timed side by side in the same run (issue 10: a modify is planned
while the command waits for its sample, so planning is command latency).

Measured on compile_move, the whole request-to-frames path (validation excluded). The side by
side part times, interleaved problem by problem:

* ours: compile_move for S_CURVE, one axis and a 2-axis vector, from rest and from a moving
  start (a modify: the vector moving along its line, toward or away from the target);
* ruckig: ``Ruckig(dofs).calculate(InputParameter, Trajectory)`` on the problem the cross-check
  makes of our plan (mpi_ros.crosscheck: exact from rest with A = D, a bound with the profile's
  own jerk from a moving start), posed as its solver first poses it (from position 0, in units
  where the velocity and acceleration limits are 1); the Ruckig and Trajectory objects are
  made once, as an online generator keeps them (and, for comparison, made for every call);
* with ``--baseline REV``: compile_move of that commit (git archive, imported in the same
  process under another package name), whose plans must be bit-identical to ours;
* "+ first evaluation": compile_move and then every plan's SegmentTable (``plan.table``), which
  the stepping builds when it first evaluates a plan: work a plan leaves for later (a vector
  axis' segments, made when first asked for) is paid there, and a command's latency is both.

    python -P bench/bench_planning.py [--baseline ca83577] [--count 1000] [--rounds 3]
"""

from __future__ import annotations

import argparse
import gc
import importlib
import importlib.util
import math
import random
import re
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

# This source tree, not the copy scripts/setup.sh last installed into the venv (run with -P).
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mpi_ros.crosscheck import check_plan
from mpi_ros.crosscheck.result import RuckigLimits
from mpi_ros.mpi.base.params import MotionParams, Trajectory
from mpi_ros.mpi.base.types import MotionAttr, MPIMotionType
from mpi_ros.mpi.planning.planner import compile_move
from mpi_ros.mpi.planning.start import AxisStart

REPO = Path(__file__).resolve().parent.parent
SAMPLE_RATE = 2000.0


# -- the existing table: every standard type, our planner alone ------------------------------
def timings(motion_type: MPIMotionType, axes: int, count: int = 3000) -> list[float]:
    rng = random.Random(7)
    out = []
    for _ in range(count):
        traj = Trajectory(rng.uniform(100, 5000), rng.uniform(1e3, 1e5), rng.uniform(1e3, 1e5), rng.uniform(0, 100),
                          rng.uniform(1e4, 1e7), rng.uniform(1e4, 1e7))
        params = MotionParams(trajectory=[traj], position=[rng.uniform(-1e5, 1e5) for _ in range(axes)])
        starts = [AxisStart(n, 0.0) for n in range(axes)]
        t0 = time.perf_counter()
        compile_move(0, motion_type, MotionAttr.NONE, params, starts, SAMPLE_RATE)
        out.append(time.perf_counter() - t0)
    return out


def _median_p99(t: list[float]) -> tuple[float, float]:
    t = sorted(t)
    return statistics.median(t) * 1e6, t[int(len(t) * 0.99)] * 1e6


def type_rows() -> list[str]:
    rows = ["| type | axes | median us | p99 us |", "| --- | --- | --- | --- |"]
    for motion_type in (MPIMotionType.S_CURVE, MPIMotionType.TRAPEZOIDAL, MPIMotionType.S_CURVE_JERK):
        for axes in (1, 2):
            median, p99 = _median_p99(timings(motion_type, axes))
            rows.append(f"| {motion_type.name} | {axes} | {median:.1f} | {p99:.1f} |")
    return rows


# -- side by side with ruckig ------------------------------------------------------------------
@dataclass(frozen=True)
class Problem:
    """One S_CURVE request: plain numbers, so each planner builds it from its own classes."""

    velocity: float
    acceleration: float  # = deceleration: from rest the cross-check's mapping is then exact
    jerk_percent: float
    positions: tuple[float, ...]
    targets: tuple[float, ...]
    velocities: tuple[float, ...]  # along the line to the targets (a vector modify stays on its line)


@dataclass(frozen=True)
class Case:
    label: str
    axes: int
    moving: bool


CASES = (Case("1 axis, from rest", 1, False), Case("1 axis, moving (a modify)", 1, True),
         Case("2-axis vector, from rest", 2, False), Case("2-axis vector, moving (a modify)", 2, True))


def problems(case: Case, count: int, seed: int = 7) -> list[Problem]:
    rng = random.Random(seed)
    out = []
    for _ in range(count):
        velocity, acceleration = rng.uniform(1e3, 1e5), rng.uniform(1e3, 1e5)
        distance = rng.uniform(100.0, 5000.0)
        angle = rng.uniform(0.0, 2.0 * math.pi) if case.axes == 2 else rng.choice((0.0, math.pi))
        unit = (math.cos(angle), math.sin(angle))[:case.axes]
        positions = tuple(rng.uniform(-1e5, 1e5) for _ in range(case.axes))
        speed = rng.uniform(-velocity, velocity) if case.moving else 0.0
        out.append(Problem(velocity, acceleration, rng.uniform(1.0, 100.0), positions,
                           tuple(p + distance * u for p, u in zip(positions, unit, strict=True)),
                           tuple(speed * u for u in unit)))
    return out


@dataclass(frozen=True)
class Planner:
    """compile_move and the classes its requests are made of, from one source tree."""

    name: str
    compile_move: Callable
    params: type
    trajectory: type
    start: type
    attrs: object
    s_curve: object

    @classmethod
    def of(cls, name: str, package: str) -> Planner:
        # (the layout of mpi_ros.mpi's subpackages: the baseline must have it too)
        planner = importlib.import_module(f"{package}.mpi.planning.planner")
        params = importlib.import_module(f"{package}.mpi.base.params")
        types = importlib.import_module(f"{package}.mpi.base.types")
        return cls(name, planner.compile_move, params.MotionParams, params.Trajectory, planner.AxisStart,
                   types.MotionAttr.NONE, types.MPIMotionType.S_CURVE)

    def request(self, problem: Problem) -> tuple:
        traj = self.trajectory(problem.velocity, problem.acceleration, problem.acceleration, problem.jerk_percent)
        params = self.params(trajectory=[traj], position=list(problem.targets))
        starts = [self.start(n, p, v)
                  for n, (p, v) in enumerate(zip(problem.positions, problem.velocities, strict=True))]
        return params, starts

    def plan(self, request: tuple):
        params, starts = request
        return self.compile_move(0, self.s_curve, self.attrs, params, starts, SAMPLE_RATE)[0]


def baseline_planner(revision: str, scratch: Path) -> Planner | None:
    """compile_move of ``revision``, imported beside ours as the package ``baseline_mpi_ros``,
    or None where there is no git history."""
    try:
        archive = subprocess.run(["git", "-C", str(REPO), "archive", revision, "mpi_ros"],
                                 check=True, capture_output=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    (scratch / "tree.tar").write_bytes(archive)
    with tarfile.open(scratch / "tree.tar") as tar:
        tar.extractall(scratch / "tree", filter="data")
    root = scratch / "tree" / "mpi_ros"
    # The core imports itself absolutely (from mpi_ros.mpi...): point those imports at the copy,
    # or the baseline would run our modules under its name.
    for source in root.rglob("*.py"):
        text = source.read_text()
        source.write_text(re.sub(r"^(\s*)(from|import) mpi_ros([. ])", r"\1\2 baseline_mpi_ros\3", text,
                                 flags=re.MULTILINE))
    spec = importlib.util.spec_from_file_location("baseline_mpi_ros", root / "__init__.py",
                                                  submodule_search_locations=[str(root)])
    module: ModuleType = importlib.util.module_from_spec(spec)
    sys.modules["baseline_mpi_ros"] = module
    spec.loader.exec_module(module)
    return Planner.of(revision, "baseline_mpi_ros")


def ruckig_limits(plan_axes) -> tuple[list[RuckigLimits], Counter]:
    """The cross-check's ruckig problem of each axis' plan, and its verdicts."""
    limits, verdicts = [], Counter()
    for plan in plan_axes:
        result = check_plan(plan, MPIMotionType.S_CURVE)
        verdicts[result.verdict.name] += 1
        limits.append(result.ruckig)
    return limits, verdicts


# ruckig's InputParameter fields in velocity (1), acceleration (2) or jerk (3) units
_RUCKIG_UNITS = {"current_velocity": 1, "target_velocity": 1, "max_velocity": 1, "current_acceleration": 2,
                 "max_acceleration": 2, "min_acceleration": 2, "max_jerk": 3}


def ruckig_input(limits: list[RuckigLimits]):
    """One InputParameter for all axes, as the cross-check's solver first poses a problem: from
    position 0, lengths in V^2/A and time in V/A. The axes of a vector share V/A (each has the
    vector's limits scaled by its share), so the first axis' time unit serves them all."""
    from ruckig import InputParameter

    def speed(lim: RuckigLimits) -> float:
        return max(abs(lim.max_velocity), abs(lim.current_velocity), abs(lim.target_velocity))

    def accel(lim: RuckigLimits) -> float:
        return max(abs(lim.max_acceleration), abs(lim.min_acceleration))

    tau = speed(limits[0]) / accel(limits[0])
    lengths = [speed(lim) ** 2 / accel(lim) for lim in limits]
    inp = InputParameter(len(limits))
    inp.current_position = [0.0] * len(limits)
    inp.target_position = [(lim.target_position - lim.current_position) / n
                           for lim, n in zip(limits, lengths, strict=True)]
    inp.target_acceleration = [0.0] * len(limits)
    for name, power in _RUCKIG_UNITS.items():
        setattr(inp, name, [getattr(lim, name) / (n / tau ** power) for lim, n in zip(limits, lengths, strict=True)])
    return inp, tau


def _bits(plans) -> list:
    return [(plan.duration, [tuple(map(float, (s.duration, s.p, s.v, s.a, s.j))) for s in plan.segments])
            for plan in plans]


@dataclass
class SideBySide:
    case: Case
    ours: list[float]
    ruckig: list[float]
    ruckig_made: list[float]  # Ruckig(dofs) and Trajectory(dofs) made for each calculate()
    baseline: list[float]
    ours_first: list[float]  # compile_move and every plan's table (the first evaluation)
    baseline_first: list[float]
    verdicts: Counter
    ruckig_failures: int
    duration_rtol: float  # largest relative difference of the durations where the mapping is exact
    identical: bool | None  # baseline plans bit-identical to ours (None: no baseline)


def _ruckig_problems(case: Case, ours: Planner, requests: list, found: SideBySide) -> list:
    """ruckig's input for each request (from our plan of it, by the cross-check's mapping), and
    in ``found`` the verdicts, ruckig's failures and how well the durations agree."""
    from ruckig import Result, Ruckig
    from ruckig import Trajectory as RuckigTrajectory

    otg, trajectory, inputs = Ruckig(case.axes), RuckigTrajectory(case.axes), []
    for request in requests:
        plans = ours.plan(request).plans
        limits, verdicts = ruckig_limits(plans)
        found.verdicts += verdicts
        inp, tau = ruckig_input(limits)
        inputs.append(inp)
        if otg.calculate(inp, trajectory) not in (Result.Working, Result.Finished):
            found.ruckig_failures += 1
        elif not case.moving:
            error = abs(trajectory.duration * tau - plans[0].duration) / plans[0].duration
            found.duration_rtol = max(found.duration_rtol, error)
    return inputs


def _timers(case: Case, requests: list, inputs: list, baseline: Planner | None, old_requests: list,
            found: SideBySide) -> list[Callable[[int], None]]:
    """One function per contender timing its call on problem i (each times its call alone)."""
    from ruckig import Ruckig
    from ruckig import Trajectory as RuckigTrajectory

    otg, trajectory, clock = Ruckig(case.axes), RuckigTrajectory(case.axes), time.perf_counter

    def ours(i: int) -> None:
        params, starts = requests[i]
        t0 = clock()
        compile_move(0, MPIMotionType.S_CURVE, MotionAttr.NONE, params, starts, SAMPLE_RATE)
        found.ours.append(clock() - t0)

    def ours_first(i: int) -> None:
        params, starts = requests[i]
        t0 = clock()
        for plan in compile_move(0, MPIMotionType.S_CURVE, MotionAttr.NONE, params, starts, SAMPLE_RATE)[0].plans:
            plan.table  # noqa: B018  (built on first use)
        found.ours_first.append(clock() - t0)

    def ruckig(i: int) -> None:
        inp = inputs[i]
        t0 = clock()
        otg.calculate(inp, trajectory)
        found.ruckig.append(clock() - t0)

    def ruckig_made(i: int) -> None:
        inp = inputs[i]
        t0 = clock()
        Ruckig(case.axes).calculate(inp, RuckigTrajectory(case.axes))
        found.ruckig_made.append(clock() - t0)

    def old(i: int) -> None:
        params, starts = old_requests[i]
        plan, s_curve, attrs = baseline.compile_move, baseline.s_curve, baseline.attrs
        t0 = clock()
        plan(0, s_curve, attrs, params, starts, SAMPLE_RATE)
        found.baseline.append(clock() - t0)

    def old_first(i: int) -> None:
        params, starts = old_requests[i]
        plan, s_curve, attrs = baseline.compile_move, baseline.s_curve, baseline.attrs
        t0 = clock()
        for axis_plan in plan(0, s_curve, attrs, params, starts, SAMPLE_RATE)[0].plans:
            axis_plan.table  # noqa: B018
        found.baseline_first.append(clock() - t0)

    return [ours, ruckig, ruckig_made, ours_first] + ([old, old_first] if baseline else [])


def side_by_side(case: Case, count: int, rounds: int, baseline: Planner | None) -> SideBySide:
    ours = Planner.of("ours", "mpi_ros")
    todo = problems(case, count)
    requests = [ours.request(p) for p in todo]
    old_requests = [baseline.request(p) for p in todo] if baseline else []
    found = SideBySide(case, [], [], [], [], [], [], Counter(), 0, 0.0, None)
    inputs = _ruckig_problems(case, ours, requests, found)
    if baseline:
        found.identical = all(_bits(ours.plan(new).plans) == _bits(baseline.plan(old).plans)
                              for new, old in zip(requests, old_requests, strict=True))
    order = _timers(case, requests, inputs, baseline, old_requests, found)
    for i in range(min(100, count)):  # warm up every path
        for timer in order:
            timer(i)
    for times in (found.ours, found.ruckig, found.ruckig_made, found.baseline, found.ours_first, found.baseline_first):
        times.clear()
    gc.collect()
    for r in range(rounds):
        for i in range(count):  # interleaved, in a rotating order: every contender sees the same load
            k = (i + r) % len(order)
            for timer in order[k:] + order[:k]:
                timer(i)
    return found


def ruckig_rows(count: int, rounds: int, revision: str | None) -> list[str]:
    head = ("| S_CURVE request | ruckig problem (cross-check) | ours median us | ours p99 us | ruckig median us "
            "| ruckig p99 us | ours / ruckig (medians) | ruckig incl. Ruckig(dofs), Trajectory(dofs): median us "
            "| ours / that | ours + first evaluation: median us |")
    rule = "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    if revision:
        head += (f" {revision} median us | {revision} p99 us | {revision} / ruckig | speed-up "
                 f"| {revision} + first evaluation: median us | plans identical |")
        rule += " --- | --- | --- | --- | --- | --- |"
    rows = [head, rule]
    with tempfile.TemporaryDirectory() as scratch:
        baseline = baseline_planner(revision, Path(scratch)) if revision else None
        for case in CASES:
            found = side_by_side(case, count, rounds, baseline)
            ours, theirs, made = _median_p99(found.ours), _median_p99(found.ruckig), _median_p99(found.ruckig_made)
            first = _median_p99(found.ours_first)[0]
            kind = ", ".join(f"{n} {name}" for name, n in sorted(found.verdicts.items()))
            if not case.moving:
                kind += f"; durations agree to {found.duration_rtol:.1e}"
            if found.ruckig_failures:
                kind += f"; ruckig failed {found.ruckig_failures}x"
            row = (f"| {case.label} | {kind} | {ours[0]:.1f} | {ours[1]:.1f} | {theirs[0]:.2f} | {theirs[1]:.2f} "
                   f"| {ours[0] / theirs[0]:.1f}x | {made[0]:.2f} | {ours[0] / made[0]:.1f}x | {first:.1f} |")
            if baseline:
                old = _median_p99(found.baseline)
                row += (f" {old[0]:.1f} | {old[1]:.1f} | {old[0] / theirs[0]:.1f}x | {old[0] / ours[0]:.1f}x "
                        f"| {_median_p99(found.baseline_first)[0]:.1f} | {'yes' if found.identical else 'NO'} |")
            elif revision:
                row += " - | - | - | - | - | - |"
            rows.append(row)
    return rows


def main(revision: str | None = None, count: int = 1000, rounds: int = 3) -> list[str]:
    return [*type_rows(), "", *ruckig_rows(count, rounds, revision)]


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default=None, help="commit whose compile_move is timed side by side")
    parser.add_argument("--count", type=int, default=1000, help="problems per case")
    parser.add_argument("--rounds", type=int, default=3, help="times each problem is planned by each")
    options = parser.parse_args()
    print("\n".join(main(options.baseline, options.count, options.rounds)))
