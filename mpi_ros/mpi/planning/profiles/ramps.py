"""Velocity plans: the trapezoid every TRAPEZOIDAL, S_CURVE and VELOCITY move starts from.

A plan is a list of :class:`Ramp` pieces, each a linear change of velocity (a cruise is
a ramp whose start and end velocity are equal). The firmware builds the trapezoid
first and S-curves reshape each ramp keeping its duration (docs/profiles.md, "The trapezoid
and the S-curve"), so the S-curve and trapezoid of the same limits share this plan.

Rates: a ramp that raises |v| uses the acceleration, one that lowers |v| the
deceleration; a ramp through zero is split at zero. VELOCITY moves use the
acceleration for every ramp (MPI 000 MPIMotionVelocity: "deceleration is ignored").
"""

from __future__ import annotations

import math
from typing import NamedTuple


class ProfileError(ValueError):
    """The profile cannot be calculated with the given constraints (PROFILE_ERROR)."""


class Ramp(NamedTuple):
    """One ramp of a trapezoid: a RampRow (below) with names; ``Ramp._make(row)`` makes one."""

    duration: float
    v_start: float
    v_end: float

    @property
    def is_cruise(self) -> bool:
        return self.v_start == self.v_end

    @property
    def distance(self) -> float:
        return 0.5 * (self.v_start + self.v_end) * self.duration


# A ramp as a plain tuple (duration, v_start, v_end), a Ramp without the names: the planner's
# trapezoid is made of them (trapezoid_rows) and reshaped into segments
RampRow = tuple[float, float, float]


def ramps_between(v_from: float, v_to: float, accel: float, decel: float) -> list[Ramp]:
    """The ramp(s) from one velocity to another, split at zero when the sign changes."""
    return list(map(Ramp._make, ramp_rows(v_from, v_to, accel, decel)))


def ramp_rows(v_from: float, v_to: float, accel: float, decel: float) -> list[RampRow]:
    """:func:`ramps_between`'s ramps as plain tuples (what the planner reshapes)."""
    rows: list[RampRow] = []
    _add_ramps(rows, v_from, v_to, accel, decel)
    return rows


def _add_ramps(rows: list[RampRow], v_from: float, v_to: float, accel: float, decel: float) -> None:
    """Append ramps_between's ramps to ``rows``, as plain tuples (trapezoid_rows')."""
    if v_from == v_to:
        return
    if v_from * v_to < 0.0:  # through rest: down to it, then up from it
        _add_ramps(rows, v_from, 0.0, accel, decel)
        _add_ramps(rows, 0.0, v_to, accel, decel)
        return
    rate = accel if abs(v_to) > abs(v_from) else decel  # the ramp does not cross zero
    rows.append((abs(v_to - v_from) / rate, v_from, v_to))


def _ramp_time(v_from: float, v_to: float, accel: float, decel: float) -> float:
    return sum(duration for duration, _, _ in ramp_rows(v_from, v_to, accel, decel))


def _total_time(peak: float, cruise: float, v_start: float, v_final: float, accel: float, decel: float) -> float:
    """Duration of the plan v_start -> peak, cruise, peak -> v_final."""
    return _ramp_time(v_start, peak, accel, decel) + cruise + _ramp_time(peak, v_final, accel, decel)


def _peak_in_direction(
    x: float, u0: float, uf: float, vmax: float, accel: float, decel: float,
) -> tuple[float, float] | None:
    """Fastest peak velocity w in [0, vmax] and cruise time for one travel direction.

    Coordinates are along the direction: x is the distance to go, u0/uf the start and
    final velocities. Returns None when this direction cannot reach the target (the
    start velocity would overshoot it). The distance covered without cruise, F(w), is
    piecewise alpha*w^2 + beta with breakpoints at u0 and uf; the fastest profile uses
    the largest w with F(w) <= x and cruises at w for the rest.
    """
    # (conditionals for max and min, answering what they would, NaN included: a modify is
    # planned while its command waits)
    size = abs(x)
    reach = x + 1e-12 * (size if size > 1.0 else 1.0)  # F(w) may exceed x by this much (rounding)
    if u0 == 0.0 and uf == 0.0 and reach < 0.0 and 1.0 / (2.0 * accel) + 1.0 / (2.0 * decel) < math.inf:
        # From rest to rest, away from the target: F(w) = alpha*w^2 with a finite alpha is 0 at
        # w = 0 and grows, so the scan below would find every breakpoint overshooting.
        return None
    # the breakpoints, ascending: 0, u0 and uf where inside (0, vmax) (once if equal), vmax
    inner_u0, inner_uf = 0.0 < u0 < vmax, 0.0 < uf < vmax
    if inner_u0 and inner_uf:
        points = [0.0, u0, uf, vmax] if u0 < uf else [0.0, uf, u0, vmax] if uf < u0 else [0.0, u0, vmax]
    elif inner_u0:
        points = [0.0, u0, vmax]
    elif inner_uf:
        points = [0.0, uf, vmax]
    else:
        points = [0.0, vmax]
    # Scan the pieces [points[k], points[k + 1]] from the top: the first breakpoint that does not
    # overshoot bounds w. F at vmax is the top piece's, at any other breakpoint the piece above's.
    top = len(points) - 2
    twice_accel, twice_decel = 2.0 * accel, 2.0 * decel
    for k in range(top, -1, -1):
        lo, hi = points[k], points[k + 1]
        # F on this piece, alpha*w^2 + beta: the first ramp's (u0 -> w) alpha and beta plus the
        # last's (w -> uf), at the rates a w inside the piece gives them
        w = 0.5 * (lo + hi)
        if u0 < 0.0:
            a1, b1 = 1.0 / twice_accel, -u0 * u0 / twice_decel
        elif w >= u0:
            a1, b1 = 1.0 / twice_accel, -u0 * u0 / twice_accel
        else:
            a1, b1 = -1.0 / twice_decel, u0 * u0 / twice_decel
        if uf < 0.0:
            a2, b2 = 1.0 / twice_decel, -uf * uf / twice_accel
        elif w >= uf:
            a2, b2 = 1.0 / twice_decel, -uf * uf / twice_decel
        else:
            a2, b2 = -1.0 / twice_accel, uf * uf / twice_accel
        alpha, beta = a1 + a2, b1 + b2
        if k == top:
            f_top = alpha * vmax * vmax + beta
            if not f_top > reach:  # even the top speed leaves distance: cruise at vmax
                return _cruise_at(x, f_top, vmax)
        f_lo = alpha * lo * lo + beta
        if f_lo > reach:
            continue
        return _peak_on(x, lo, hi, alpha, beta), 0.0
    return None


def _cruise_at(x: float, f_top: float, vmax: float) -> tuple[float, float]:
    """The peak and cruise where even the top speed leaves distance (F(vmax) = f_top <= x): the
    cruise at vmax covers the rest."""
    cruise = (x - f_top) / vmax if vmax > 0.0 else 0.0
    return vmax, cruise if cruise > 0.0 else 0.0


def _peak_on(x: float, lo: float, hi: float, alpha: float, beta: float) -> float:
    """The largest w in the piece [lo, hi] where F(w) = alpha*w^2 + beta reaches x (F(lo) does
    not overshoot, F(hi) does): lo where F does not grow on the piece."""
    if alpha > 0.0:
        square = (x - beta) / alpha
        w = math.sqrt(square if square > 0.0 else 0.0)
    else:
        w = lo
    w = lo if lo > w else w
    return hi if hi < w else w


def _peak_to_rest(x: float, u0: float, vmax: float, accel: float, decel: float) -> tuple[float, float] | None:
    """_peak_in_direction(x, u0, uf, vmax, accel, decel) for a final velocity uf of ±0 and finite
    limits (greater than 0: plan_point_to_point's checks), the usual start or modify, which ends at
    rest: the same operations on the pieces the scan looks at, for the one or two pieces there
    are, without the scan's list of breakpoints (a modify is planned while its command waits).

    With uf = ±0 the last ramp's coefficients are 1/(2 decel) and -uf*uf/(2 decel) = -0.0 on every
    piece (each piece's midpoint w is at least 0, so w >= uf), and beta + -0.0 is beta. The
    breakpoints are 0, vmax and u0 when 0 < u0 < vmax; then the top piece's midpoint
    0.5 * (u0 + vmax) is at least u0 (the first ramp accelerates from u0: rounding is monotonic)
    and the lower piece's 0.5 * u0 is below u0 (it decelerates to w)."""
    size = abs(x)
    reach = x + 1e-12 * (size if size > 1.0 else 1.0)  # F(w) may exceed x by this much (rounding)
    twice_accel, twice_decel = 2.0 * accel, 2.0 * decel
    up, down = 1.0 / twice_accel, 1.0 / twice_decel  # (-1.0 / twice_decel, the scan's, is -down)
    if u0 == 0.0 and reach < 0.0 and up + down < math.inf:
        return None  # (from rest to rest, away from the target: _peak_in_direction's first test)
    if 0.0 < u0 < vmax:
        alpha, beta = up + down, -u0 * u0 / twice_accel  # the top piece [u0, vmax]
        f_top = alpha * vmax * vmax + beta
        if not f_top > reach:  # even the top speed leaves distance: cruise at vmax
            return _cruise_at(x, f_top, vmax)
        if not alpha * u0 * u0 + beta > reach:
            return _peak_on(x, u0, vmax, alpha, beta), 0.0
        alpha, beta, hi = -down + down, u0 * u0 / twice_decel, u0  # the piece [0, u0]
    else:
        # the one piece [0, vmax], its first ramp's coefficients at its midpoint as the scan chooses them
        w = 0.5 * (0.0 + vmax)
        if u0 < 0.0:
            a1, beta = up, -u0 * u0 / twice_decel
        elif w >= u0:
            a1, beta = up, -u0 * u0 / twice_accel
        else:
            a1, beta = -down, u0 * u0 / twice_decel
        alpha = a1 + down
        f_top = alpha * vmax * vmax + beta
        if not f_top > reach:
            return _cruise_at(x, f_top, vmax)
        hi = vmax
    if alpha * 0.0 * 0.0 + beta > reach:  # (F at the piece's lo, 0, as the scan calculates it)
        return None
    return _peak_on(x, 0.0, hi, alpha, beta), 0.0


def _rest_to_rest(distance: float, vmax: float, accel: float, decel: float) -> tuple[float, float] | None:
    """(peak velocity, cruise) of a move from rest to rest (every start from rest), as
    plan_point_to_point finds them with _peak_in_direction in both directions, with the same
    operations; None where it might find something else (then it asks both directions).

    From rest to rest (u0 = uf = ±0) the direction away from the target is ruled out by
    _peak_in_direction's first test (its reach below 0, a finite alpha), and the scan toward it
    has the one piece [0, vmax] (no inner breakpoint), where its coefficients are
    alpha = 1/(2 accel) + 1/(2 decel) and beta = -0.0 (-u*u/(2 rate) of u = ±0 is -0.0 for
    positive rates; vmax >= 0 takes their branches); F at 0 is then 0, never past the reach."""
    size = abs(distance)
    margin = 1e-12 * (size if size > 1.0 else 1.0)  # (reach = x + margin, as _peak_in_direction's)
    alpha = 1.0 / (2.0 * accel) + 1.0 / (2.0 * decel)
    if not (-size + margin < 0.0 and alpha < math.inf and vmax >= 0.0):
        return None  # (the way away not ruled out, or limits that are no positive numbers)
    x, beta = size, -0.0  # toward the target, along it
    sign = 1.0 if distance > 0.0 else -1.0  # (its distance is not 0: size > margin)
    f_top = alpha * vmax * vmax + beta
    if not f_top > x + margin:  # even the top speed leaves distance: cruise at vmax
        cruise = (x - f_top) / vmax if vmax > 0.0 else 0.0
        return sign * vmax, cruise if cruise > 0.0 else 0.0
    square = (x - beta) / alpha
    w = math.sqrt(square if square > 0.0 else 0.0)  # (>= 0: the scan's max with its lo of 0 keeps it)
    return sign * (vmax if vmax < w else w), 0.0


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
    return list(map(Ramp._make, trapezoid_rows(distance, v_start, v_final, vmax, accel, decel)))


def trapezoid_rows(distance: float, v_start: float, v_final: float, vmax: float, accel: float,
                   decel: float) -> list[RampRow]:
    """plan_point_to_point's ramps as plain tuples (RampRows), which the planner reshapes."""
    if vmax <= 0.0 or accel <= 0.0 or decel <= 0.0:
        raise ProfileError("velocity, acceleration and deceleration must be positive")
    if abs(v_final) > vmax * (1.0 + 1e-12):
        raise ProfileError("final velocity exceeds the trajectory velocity")
    found = _rest_to_rest(distance, vmax, accel, decel) if v_start == 0.0 and v_final == 0.0 else None
    if found is not None:
        peak, cruise = found
    else:
        # The direction toward the target, then away from it (coordinates along each direction)
        if v_final == 0.0 and vmax + accel + decel < math.inf:  # (finite limits: not NaN nor inf)
            ahead = _peak_to_rest(distance, v_start, vmax, accel, decel)
            behind = _peak_to_rest(-distance, -v_start, vmax, accel, decel)
        else:
            ahead = _peak_in_direction(distance, v_start, v_final, vmax, accel, decel)
            behind = _peak_in_direction(-distance, -v_start, -v_final, vmax, accel, decel)
        if ahead is None:
            if behind is None:
                raise ProfileError("no profile reaches the target")
            peak, cruise = -behind[0], behind[1]
        else:
            peak, cruise = ahead
            # Both directions reach the target: the other only if it is faster. The times are
            # needed for this comparison alone, so they are not calculated otherwise.
            if behind is not None and _total_time(-behind[0], behind[1], v_start, v_final, accel,
                                                  decel) < _total_time(peak, cruise, v_start, v_final, accel,
                                                                       decel) - 1e-15:
                peak, cruise = -behind[0], behind[1]
    plan: list[RampRow] = []
    _add_ramps(plan, v_start, peak, accel, decel)
    # The cruise (if any) absorbs the last rounding error of the distance. (ramps_between makes
    # no ramp of constant velocity: a cruise can only be this one.)
    at = len(plan)
    if cruise > 0.0:
        plan.append((cruise, peak, peak))
    _add_ramps(plan, peak, v_final, accel, decel)
    # each ramp's distance (Ramp.distance's formula on the rows), added in order
    travelled = 0.0
    for duration, v0, v1 in plan:
        travelled += 0.5 * (v0 + v1) * duration
    error = distance - travelled
    if not math.isfinite(error):
        raise ProfileError("the profile cannot be calculated with these values (overflow)")
    if cruise > 0.0:
        if peak != 0.0:
            cruise = max(0.0, cruise + error / peak)
        plan[at] = (cruise, peak, peak)
    return plan


def plan_velocity(v_start: float, v_target: float, accel: float) -> list[Ramp]:
    """The ramp of a VELOCITY move: one ramp at the acceleration, even through zero."""
    if accel <= 0.0:
        raise ProfileError("acceleration must be positive")
    if v_start == v_target:
        return []
    return [Ramp(abs(v_target - v_start) / accel, v_start, v_target)]
