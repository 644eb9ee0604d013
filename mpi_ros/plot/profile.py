"""Plot a profile request: the controller's position, velocity, acceleration and jerk with
ruckig's profile for the same request overlaid (dashed), the limits dotted. Writes a PNG.

ruckig's profile is the one the cross-check compares against (mpi_ros.crosscheck.mapping):
the equivalent problem where the models coincide, the bound otherwise; the title gives the
verdict, both durations and the reasons. DELAY/SYNC waits are left out; a VELOCITY move is
drawn through its ramp and a little of its cruise. A trapezoid's jerk is unbounded at its
acceleration steps and is drawn as zero between them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from mpi_ros.mpi.base.types import MPIMotionType
from mpi_ros.mpi.planning.profiles.segment import Segment

from ..crosscheck.check import check_plan
from ..crosscheck.limits import strip_waits
from ..crosscheck.mapping import peak_acceleration
from ..crosscheck.request import ProfileRequest
from ..crosscheck.result import CrossCheck
from ..crosscheck.solver import RuckigFailed, solve

POINTS_PER_SEGMENT = 60


def _curves(segments: Sequence[Segment], start: tuple[float, float, float], horizon: float):
    """Dense (t, p, v, a, j) of a profile, held at its end state until ``horizon``."""
    ts, ps, vs, accs, js = [], [], [], [], []
    t0 = 0.0
    for seg in segments:
        local = np.linspace(0.0, seg.duration, POINTS_PER_SEGMENT)
        t = t0 + local
        ts.append(t)
        ps.append(seg.p + local * (seg.v + local * (seg.a / 2.0 + local * seg.j / 6.0)))
        vs.append(seg.v + local * (seg.a + local * seg.j / 2.0))
        accs.append(seg.a + local * seg.j)
        js.append(np.full_like(local, seg.j))
        t0 += seg.duration
    p_end, v_end, _ = segments[-1].end_state() if segments else start
    if horizon > t0:  # after the end: cruise at the final velocity, no acceleration
        local = np.linspace(0.0, horizon - t0, 20)
        ts.append(t0 + local)
        ps.append(p_end + v_end * local)
        vs.append(np.full_like(local, v_end))
        accs.append(np.zeros_like(local))
        js.append(np.zeros_like(local))
    if not ts:
        return (np.zeros(1), *tuple(np.array([x]) for x in (start[0], start[1], 0.0, 0.0)))
    return tuple(np.concatenate(x) for x in (ts, ps, vs, accs, js))


def plot_profile(request: ProfileRequest, output: str | Path,  # noqa: C901 - panel by panel; to be split
                 sample_rate: float = 2000.0) -> tuple[Path, CrossCheck]:
    """Draw ``request`` (controller vs ruckig) into the PNG ``output``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plan = request.plan(sample_rate)
    result = check_plan(plan, request.type)
    motion = strip_waits(plan.segments)
    velocity_type = request.type is MPIMotionType.VELOCITY
    if velocity_type:  # the ramp, and a cruise of a fifth of it
        ramp = [s for s in motion if s.a != 0.0 or s.j != 0.0]
        cruise_time = 0.25 * sum(s.duration for s in ramp) or 0.1
        motion = ramp + ([Segment(cruise_time, *ramp[-1].end_state()[:2], 0.0, 0.0)] if ramp else [])
    reference: Sequence[Segment] = ()
    if result.ruckig is not None:
        try:
            reference = solve(result.ruckig).segments
        except RuckigFailed:
            reference = ()
    start = (plan.start_position, plan.start_velocity, 0.0)
    horizon = max(sum(s.duration for s in motion), sum(s.duration for s in reference)) or 1.0
    ours = _curves(motion, start, horizon)
    theirs = _curves(reference, start, horizon) if reference else None

    fig, rows = plt.subplots(4, 1, figsize=(10, 10), sharex=True)
    labels = ("position [counts]", "velocity [counts/s]", "acceleration [counts/s²]", "jerk [counts/s³]")
    for k, (ax, label) in enumerate(zip(rows, labels, strict=True)):
        if k == 3:
            ax.step(ours[0], ours[4], where="post", lw=1.6, color="C0", label="controller")
        else:
            ax.plot(ours[0], ours[k + 1], lw=1.6, color="C0", label="controller")
        if theirs is not None:
            if k == 3:
                ax.step(theirs[0], theirs[4], where="post", lw=1.2, ls="--", color="C3", label="ruckig")
            else:
                ax.plot(theirs[0], theirs[k + 1], lw=1.2, ls="--", color="C3", label="ruckig")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    traj = request.trajectory()
    f = (request.jerk_percent if request.type is not MPIMotionType.TRAPEZOIDAL else 0.0) / 100.0
    if not velocity_type:
        for sign in (1.0, -1.0):
            rows[1].axhline(sign * traj.velocity, color="grey", ls=":", lw=1.0)
        rows[0].axhline(request.target, color="grey", ls=":", lw=1.0)
        peaks: tuple[float, ...] = (peak_acceleration(traj.acceleration, f), peak_acceleration(traj.deceleration, f))
    else:
        rows[1].axhline(traj.velocity, color="grey", ls=":", lw=1.0)
        peaks = (peak_acceleration(traj.acceleration, f),)
    for peak in peaks:
        for sign in (1.0, -1.0):
            rows[2].axhline(sign * peak, color="grey", ls=":", lw=1.0)
    if f == 0.0:
        rows[3].text(0.5, 0.8, "trapezoid: jerk unbounded at the acceleration steps", transform=rows[3].transAxes,
                     ha="center", va="center", fontsize=9, color="grey")
    rows[0].legend(loc="best", fontsize=8)
    rows[-1].set_xlabel("profile time [s]")
    ruckig = "n/a" if result.ruckig_duration is None else f"{result.ruckig_duration:.6g} s"
    subtitle = f"{result.verdict.name}: controller {result.controller_duration:.6g} s, ruckig {ruckig}"
    if result.reasons:
        subtitle += "\n" + ", ".join(r.name for r in result.reasons)
    if result.problems:
        subtitle += "\n" + "; ".join(result.problems)[:200]
    fig.suptitle(f"{request.label()}\n{subtitle}", fontsize=10)
    fig.tight_layout()
    path = Path(output)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    if math.isnan(horizon):  # pragma: no cover - defensive: never draw NaN silently
        raise ValueError("profile duration is not a number")
    return path, result
