"""Random requests and agreement statistics (``mpi-ros crosscheck --random N``, the tests).

Categories, each a seeded draw (numpy ``default_rng(seed)``, so a survey is reproducible):

* ``TRAPEZOIDAL`` / ``S_CURVE``: from rest to rest, distance ±1e-2..1e6 counts (at most 4000 s
  at the velocity, below the frame time limit), velocity 10..1e5, acceleration 1e2..1e7,
  deceleration equal to it half the time, jerkPercent 0..100 (S_CURVE; 0 and 100 included,
  and 5 % tiny ones, 1e-300..1e-3);
* ``VELOCITY``: start velocity and commanded velocity of either sign (or zero);
* ``MODIFY``: TRAPEZOIDAL or S_CURVE from a moving state: start velocity up to 1.5x the limit
  either way, a start acceleration half the time (the controller steps it to zero), a final
  velocity (FINAL_VEL) a quarter of the time.

Draws the controller refuses are counted as refused and not checked. At these magnitudes
they are PROFILE_ERRORs of the planner's landing check (the frames must end within
1e-9 x max(1, |target|, |start|) of the target), which the rounding of a long reversing
modify near position 0 exceeds (about 1e-16 of the distance travelled).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from mpi_ros.mpi.base.types import MPIMotionType

from .check import check_request
from .request import ProfileRequest, RequestInvalid
from .result import CrossCheck, Reason, StateDifference, Verdict

CATEGORIES = ("TRAPEZOIDAL", "S_CURVE", "VELOCITY", "MODIFY")


def _log(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(10.0 ** rng.uniform(np.log10(lo), np.log10(hi)))


def _signed(rng: np.random.Generator, lo: float, hi: float) -> float:
    return _log(rng, lo, hi) * (1.0 if rng.random() < 0.5 else -1.0)


def _jerk_percent(rng: np.random.Generator) -> float:
    r = rng.random()
    if r < 0.1:
        return 0.0
    if r < 0.2:
        return 100.0
    if r < 0.25:  # tiny: jerk phases down to below the time resolution
        return float(10.0 ** rng.uniform(-300.0, -3.0))
    return float(rng.uniform(0.0, 100.0))


def random_request(rng: np.random.Generator, category: str) -> ProfileRequest:
    velocity = _log(rng, 10.0, 1e5)
    acceleration = _log(rng, 1e2, 1e7)
    deceleration = acceleration if rng.random() < 0.5 else _log(rng, 1e2, 1e7)
    start = float(rng.uniform(-1e6, 1e6)) if rng.random() < 0.3 else 0.0
    # At most ~4000 s of cruise: longer frames hit the 16,384,000-sample limit (TRUNCATED).
    distance = max(-4000.0 * velocity, min(4000.0 * velocity, _signed(rng, 1e-2, 1e6)))
    if category == "TRAPEZOIDAL":
        return ProfileRequest(MPIMotionType.TRAPEZOIDAL, velocity, acceleration, deceleration,
                              target=start + distance, start_position=start)
    if category == "S_CURVE":
        return ProfileRequest(MPIMotionType.S_CURVE, velocity, acceleration, deceleration, _jerk_percent(rng),
                              target=start + distance, start_position=start)
    if category == "VELOCITY":
        v0 = 0.0 if rng.random() < 0.3 else _signed(rng, 1.0, 1e5)
        v = 0.0 if rng.random() < 0.2 else _signed(rng, 1.0, 1e5)
        a0 = 0.0 if rng.random() < 0.5 else _signed(rng, 1.0, 1e7)
        return ProfileRequest(MPIMotionType.VELOCITY, v, acceleration, None, _jerk_percent(rng),
                              start_position=start, start_velocity=v0, start_acceleration=a0)
    if category == "MODIFY":
        kind = MPIMotionType.TRAPEZOIDAL if rng.random() < 0.4 else MPIMotionType.S_CURVE
        v0 = float(rng.uniform(-1.5, 1.5)) * velocity
        a0 = 0.0 if rng.random() < 0.5 else float(rng.uniform(-1.0, 1.0)) * acceleration
        vf = 0.0 if rng.random() < 0.75 else float(rng.uniform(-1.0, 1.0)) * velocity
        return ProfileRequest(kind, velocity, acceleration, deceleration,
                              _jerk_percent(rng) if kind is MPIMotionType.S_CURVE else 0.0,
                              target=start + distance, start_position=start, start_velocity=v0,
                              start_acceleration=a0, final_velocity=vf)
    raise ValueError(f"unknown category {category!r} (known: {', '.join(CATEGORIES)})")


@dataclass
class CategoryStats:
    cases: int = 0
    refused: int = 0
    verdicts: Counter = field(default_factory=Counter)
    reasons: Counter = field(default_factory=Counter)
    max_duration_relative: float = 0.0  # where compared exactly
    max_relative: StateDifference = field(default_factory=StateDifference)  # sampled / scales, exact
    max_tolerance_used: float = 0.0  # largest sampled or final difference / its tolerance (exact)
    min_bound_margin: float = float("inf")  # bound cases: (controller - ruckig) / ruckig
    disagreements: list = field(default_factory=list)

    def add(self, request: ProfileRequest, result: CrossCheck) -> None:
        self.verdicts[result.verdict] += 1
        for reason in result.reasons:
            self.reasons[reason] += 1
        if result.exact and result.ruckig_duration is not None:
            self.max_duration_relative = max(self.max_duration_relative, result.duration_relative)
            self.max_relative = self.max_relative.max(result.max_difference.relative_to(result.scales))
            final = result.final_difference  # its acceleration is not compared (check.py)
            worst = result.max_difference.max(StateDifference(final.position, final.velocity, 0.0))
            ratio = worst.relative_to(result.tolerance)
            self.max_tolerance_used = max(self.max_tolerance_used, ratio.position, ratio.velocity,
                                          ratio.acceleration)
        elif result.ruckig_duration:
            self.min_bound_margin = min(self.min_bound_margin, result.duration_difference / result.ruckig_duration)
        if result.verdict is Verdict.DISAGREE:
            self.disagreements.append((request, result))


def survey(count: int, seed: int = 0, categories=CATEGORIES) -> dict[str, CategoryStats]:
    """``count`` random requests per category, checked; statistics per category."""
    stats: dict[str, CategoryStats] = {}
    for index, category in enumerate(categories):
        rng = np.random.default_rng([seed, index])
        entry = stats.setdefault(category, CategoryStats())
        for _ in range(count):
            request = random_request(rng, category)
            entry.cases += 1
            try:
                result = check_request(request)
            except RequestInvalid:
                entry.refused += 1
                continue
            entry.add(request, result)
    return stats


def format_summary(stats: dict[str, CategoryStats]) -> str:
    """One line per category. Where the models coincide: max |dT|/T, the largest sampled
    differences relative to their scales (dp/P, dv/V, da/A), and "tol used", the largest
    sampled or final difference as a fraction of its tolerance (< 1 passes). Elsewhere:
    "bound margin", the smallest (controller - ruckig)/ruckig duration (>= -1e-9 passes)."""
    lines = [f"{'category':<12} {'cases':>6} {'refused':>7} {'AGREE':>6} {'EXPLAINED':>9} {'DISAGREE':>8} "
             f"{'max |dT|/T':>10} {'max dp/P':>9} {'max dv/V':>9} {'max da/A':>9} {'tol used':>8} "
             f"{'bound margin':>12}"]
    for name, s in stats.items():
        margin = "-" if s.min_bound_margin == float("inf") else f"{s.min_bound_margin:.3g}"
        lines.append(
            f"{name:<12} {s.cases:>6} {s.refused:>7} {s.verdicts[Verdict.AGREE]:>6} "
            f"{s.verdicts[Verdict.DIFFER_EXPLAINED]:>9} {s.verdicts[Verdict.DISAGREE]:>8} "
            f"{s.max_duration_relative:>10.2e} {s.max_relative.position:>9.2e} {s.max_relative.velocity:>9.2e} "
            f"{s.max_relative.acceleration:>9.2e} {s.max_tolerance_used:>8.2g} {margin:>12}")
    reasons: Counter[Reason] = Counter()
    for s in stats.values():
        reasons.update(s.reasons)
    if reasons:
        lines.append("reasons: " + ", ".join(f"{r.name} {n}" for r, n in reasons.most_common()))
    return "\n".join(lines)
