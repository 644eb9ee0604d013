"""Velocity plans: the trapezoid every TRAPEZOIDAL, S_CURVE and VELOCITY move starts from.

A plan is a list of :class:`Ramp` pieces, each a linear change of velocity (a cruise is
a ramp whose start and end velocity are equal). The firmware builds the trapezoid
first and S-curves reshape each ramp keeping its duration (DESIGN.md, "Facts about the
libraries"), so the S-curve and trapezoid of the same limits share this plan.

Rates: a ramp that raises |v| uses the acceleration, one that lowers |v| the
deceleration; a ramp through zero is split at zero. VELOCITY moves use the
acceleration for every ramp (spec 000 MPIMotionVelocity: "deceleration is ignored").
"""

from __future__ import annotations

import math
from dataclasses import dataclass


class ProfileError(ValueError):
    """The profile cannot be calculated with the given constraints (PROFILE_ERROR)."""


@dataclass(frozen=True, slots=True)
class Ramp:
    duration: float
    v_start: float
    v_end: float

    @property
    def is_cruise(self) -> bool:
        return self.v_start == self.v_end

    @property
    def distance(self) -> float:
        return 0.5 * (self.v_start + self.v_end) * self.duration


def _ramp_rate(v_from: float, v_to: float, accel: float, decel: float) -> float:
    """Rate of a ramp that does not cross zero."""
    return accel if abs(v_to) > abs(v_from) else decel


def ramps_between(v_from: float, v_to: float, accel: float, decel: float) -> list[Ramp]:
    """The ramp(s) from one velocity to another, split at zero when the sign changes."""
    if v_from == v_to:
        return []
    if v_from * v_to < 0.0:
        return ramps_between(v_from, 0.0, accel, decel) + ramps_between(0.0, v_to, accel, decel)
    rate = _ramp_rate(v_from, v_to, accel, decel)
    return [Ramp(abs(v_to - v_from) / rate, v_from, v_to)]


def _ramp_time(v_from: float, v_to: float, accel: float, decel: float) -> float:
    return sum(r.duration for r in ramps_between(v_from, v_to, accel, decel))


def _first_ramp_coefficients(u0: float, w: float, accel: float, decel: float) -> tuple[float, float]:
    """Distance of the ramp u0 -> w as alpha*w^2 + beta (directional coordinates)."""
    if u0 < 0.0:
        return 1.0 / (2.0 * accel), -u0 * u0 / (2.0 * decel)
    if w >= u0:
        return 1.0 / (2.0 * accel), -u0 * u0 / (2.0 * accel)
    return -1.0 / (2.0 * decel), u0 * u0 / (2.0 * decel)


def _last_ramp_coefficients(w: float, uf: float, accel: float, decel: float) -> tuple[float, float]:
    """Distance of the ramp w -> uf as alpha*w^2 + beta (directional coordinates)."""
    if uf < 0.0:
        return 1.0 / (2.0 * decel), -uf * uf / (2.0 * accel)
    if w >= uf:
        return 1.0 / (2.0 * decel), -uf * uf / (2.0 * decel)
    return -1.0 / (2.0 * accel), uf * uf / (2.0 * accel)


def _peak_in_direction(x: float, u0: float, uf: float, vmax: float, accel: float, decel: float):
    """Fastest peak velocity w in [0, vmax] and cruise time for one travel direction.

    Coordinates are along the direction: x is the distance to go, u0/uf the start and
    final velocities. Returns None when this direction cannot reach the target (the
    start velocity would overshoot it). The distance covered without cruise, F(w), is
    piecewise alpha*w^2 + beta with breakpoints at u0 and uf; the fastest profile uses
    the largest w with F(w) <= x and cruises at w for the rest.
    """

    def coefficients(w_mid: float) -> tuple[float, float]:
        a1, b1 = _first_ramp_coefficients(u0, w_mid, accel, decel)
        a2, b2 = _last_ramp_coefficients(w_mid, uf, accel, decel)
        return a1 + a2, b1 + b2

    def distance(w: float, w_mid: float) -> float:
        alpha, beta = coefficients(w_mid)
        return alpha * w * w + beta

    points = sorted({0.0, vmax} | {u for u in (u0, uf) if 0.0 < u < vmax})
    tolerance = 1e-12 * max(1.0, abs(x))
    # Scan the breakpoints from the top: the first one that does not overshoot bounds w.
    for i in range(len(points) - 1, -1, -1):
        lo = points[i]
        upper_mid = 0.5 * (lo + points[i + 1]) if i + 1 < len(points) else lo
        lower_mid = 0.5 * (points[i - 1] + lo) if i > 0 else lo
        f_lo = distance(lo, upper_mid if i + 1 < len(points) else lower_mid)
        if f_lo > x + tolerance:
            continue
        if i == len(points) - 1:  # even the top speed leaves distance: cruise at vmax
            cruise = (x - f_lo) / vmax if vmax > 0.0 else 0.0
            return vmax, max(0.0, cruise)
        hi = points[i + 1]
        alpha, beta = coefficients(upper_mid)
        w = math.sqrt(max(0.0, (x - beta) / alpha)) if alpha > 0.0 else lo
        return min(max(w, lo), hi), 0.0
    return None


def plan_point_to_point(
    distance: float,
    v_start: float,
    v_final: float,
    vmax: float,
    accel: float,
    decel: float,
) -> list[Ramp]:
    """Time-optimal trapezoid from ``v_start`` to ``v_final`` covering ``distance``.

    Handles moves too short to reach ``vmax`` (triangular), a start velocity above the
    limit (ramps down to it) and a start velocity toward or away from the target that
    cannot stop in time (decelerates, reverses and comes back).
    """
    if vmax <= 0.0 or accel <= 0.0 or decel <= 0.0:
        raise ProfileError("velocity, acceleration and deceleration must be positive")
    if abs(v_final) > vmax * (1.0 + 1e-12):
        raise ProfileError("final velocity exceeds the trajectory velocity")
    best = None
    for direction in (1.0, -1.0):
        found = _peak_in_direction(
            direction * distance, direction * v_start, direction * v_final, vmax, accel, decel
        )
        if found is None:
            continue
        w, cruise = found
        peak = direction * w
        total = (
            _ramp_time(v_start, peak, accel, decel)
            + cruise
            + _ramp_time(peak, v_final, accel, decel)
        )
        if best is None or total < best[0] - 1e-15:
            best = (total, peak, cruise)
    if best is None:
        raise ProfileError("no profile reaches the target")
    _, peak, cruise = best
    plan = ramps_between(v_start, peak, accel, decel)
    if cruise > 0.0:
        plan.append(Ramp(cruise, peak, peak))
    plan += ramps_between(peak, v_final, accel, decel)
    return _absorb_rounding(plan, distance)


def _absorb_rounding(plan: list[Ramp], distance: float) -> list[Ramp]:
    """Let the cruise (if any) absorb the last rounding error of the distance."""
    error = distance - sum(r.distance for r in plan)
    if not math.isfinite(error):
        raise ProfileError("the profile cannot be calculated with these values (overflow)")
    for i, ramp in enumerate(plan):
        if ramp.is_cruise and ramp.v_start != 0.0:
            duration = max(0.0, ramp.duration + error / ramp.v_start)
            plan[i] = Ramp(duration, ramp.v_start, ramp.v_end)
            break
    return plan


def plan_velocity(v_start: float, v_target: float, accel: float) -> list[Ramp]:
    """The ramp of a VELOCITY move: one ramp at the acceleration, even through zero."""
    if accel <= 0.0:
        raise ProfileError("acceleration must be positive")
    if v_start == v_target:
        return []
    return [Ramp(abs(v_target - v_start) / accel, v_start, v_target)]
