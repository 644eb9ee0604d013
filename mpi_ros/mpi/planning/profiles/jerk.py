"""S_CURVE_JERK and VELOCITY_JERK (firmware option 21): jerk-limited profiles that start
from the full current state (position, velocity and acceleration).

MPI 000 MPIMotionTypeS_CURVE_JERK: "specified by acceleration, velocity,
deceleration, accelerationJerk, decelerationJerk, and final position". A change of
speed that raises |v| uses the acceleration and accelerationJerk, one that lowers it
the deceleration and decelerationJerk (jerk in counts/s^3).

A velocity change from (v, a) to (v1, 0) is: jerk toward a peak acceleration p (at most
the limit), hold p, jerk back to zero. A point-to-point move is such a change to a peak
velocity, a cruise, and a change to the final velocity; the peak is the largest whose
distance still fits (found by bisection, the distance grows with the peak).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from mpi_ros.mpi.planning.profiles.ramps import ProfileError
from mpi_ros.mpi.planning.profiles.segment import Segment, chain, end_state, total_duration

_ITERATIONS = 80


def velocity_change(v: float, a: float, v1: float, amax: float, jerk: float) -> list[tuple[float, float]]:
    """(duration, jerk) pieces taking (v, a) to (v1, 0) in minimum time."""
    if amax <= 0.0 or jerk <= 0.0:
        raise ProfileError("acceleration and jerk must be positive")
    v_zero = v + a * abs(a) / (2.0 * jerk)  # velocity if the acceleration is removed now
    sign = 1.0 if v1 >= v_zero else -1.0
    a_dir = sign * a
    dv = sign * (v1 - v)
    peak = math.sqrt(max(0.0, (2.0 * jerk * dv + a_dir * a_dir) / 2.0))
    hold = 0.0
    limit = max(amax, a_dir)
    if peak > limit:
        peak = limit
        hold = (dv - (2.0 * peak * peak - a_dir * a_dir) / (2.0 * jerk)) / peak
    pieces = [((peak - a_dir) / jerk, sign * jerk), (max(0.0, hold), 0.0), (peak / jerk, -sign * jerk)]
    return [(d, j) for d, j in pieces if d > 0.0]


def _integrate(
    p: float, v: float, a: float, pieces: Iterable[tuple[float, float]],
) -> tuple[list[Segment], tuple[float, float, float], float]:
    """Segments of (duration, jerk) pieces from (p, v, a), their end state and duration."""
    segments = chain(p, v, a, pieces)
    return segments, end_state(segments, (p, v, a)), total_duration(segments)


# (acceleration, jerk): the limits of a change that raises |v| (accel) or lowers it (decel)
Limits = tuple[float, float]


def _limits_for(v_from: float, v_to: float, accel: Limits, decel: Limits) -> Limits:
    return accel if abs(v_to) >= abs(v_from) else decel


def _change(v: float, a: float, v1: float, accel: Limits, decel: Limits) -> list[tuple[float, float]]:
    amax, jerk = _limits_for(v, v1, accel, decel)
    return velocity_change(v, a, v1, amax, jerk)


def _distance(
    v0: float, a0: float, peak: float, v_final: float, accel: Limits, decel: Limits,
) -> tuple[float, float]:
    """(distance, time) of going from (v0, a0) to peak and from peak to v_final."""
    _, (p1, _, _), t1 = _integrate(0.0, v0, a0, _change(v0, a0, peak, accel, decel))
    _, (p2, _, _), t2 = _integrate(0.0, peak, 0.0, _change(peak, 0.0, v_final, accel, decel))
    return p1 + p2, t1 + t2


def point_to_point_jerk(
    p0: float, v0: float, a0: float, target: float, v_final: float,
    vmax: float, accel: Limits, decel: Limits,
) -> list[Segment]:
    """S_CURVE_JERK from (p0, v0, a0); accel/decel are (acceleration, jerk) pairs."""
    if vmax <= 0.0:
        raise ProfileError("velocity must be positive")
    distance = target - p0
    best = None
    for direction in (1.0, -1.0):
        found = _peak(direction, distance, v0, a0, v_final, vmax, accel, decel)
        if found is not None and (best is None or found[0] < best[0]):
            best = found
    if best is None:
        raise ProfileError("no profile reaches the target")
    _, peak, cruise = best
    segments, (p, _v, _a), _ = _integrate(p0, v0, a0, _change(v0, a0, peak, accel, decel))
    if cruise > 0.0:
        segments.append(Segment(cruise, p, peak, 0.0, 0.0))
        p += peak * cruise
    tail, _, _ = _integrate(p, peak, 0.0, _change(peak, 0.0, v_final, accel, decel))
    return segments + tail


def _peak(
    direction: float, distance: float, v0: float, a0: float, v_final: float, vmax: float,
    accel: Limits, decel: Limits,
) -> tuple[float, float, float] | None:
    """(time, peak velocity, cruise) of the fastest profile peaking in ``direction``."""
    x = direction * distance

    def covered(w: float) -> tuple[float, float]:
        d, t = _distance(v0, a0, direction * w, v_final, accel, decel)
        return direction * d, t

    v_zero = v0 + a0 * abs(a0) / (2.0 * accel[1])
    lo = max(0.0, direction * v_zero, direction * v_final)
    if lo > vmax:
        lo = vmax
    d_hi, t_hi = covered(vmax)
    if d_hi <= x:
        return t_hi + (x - d_hi) / vmax, direction * vmax, (x - d_hi) / vmax
    d_lo, _ = covered(lo)
    if d_lo > x + 1e-9 * (1.0 + abs(x)):
        return None
    hi = vmax
    for _ in range(_ITERATIONS):
        mid = 0.5 * (lo + hi)
        if covered(mid)[0] <= x:
            lo = mid
        else:
            hi = mid
    d, t = covered(lo)
    cruise = (x - d) / lo if lo > 0.0 else 0.0
    return t + cruise, direction * lo, max(0.0, cruise)


def velocity_jerk(
    p0: float, v0: float, a0: float, v_target: float, accel: float, jerk_up: float, jerk_down: float,
    cruise: float,
) -> tuple[list[Segment], float]:
    """VELOCITY_JERK from (p0, v0, a0): change to ``v_target``, then cruise.

    Returns the segments and the profile time at which the change is done.
    """
    jerk = jerk_up if abs(v_target) >= abs(v0) or jerk_down <= 0.0 else jerk_down
    segments, (p, _, _), elapsed = _integrate(p0, v0, a0, velocity_change(v0, a0, v_target, accel, jerk))
    if cruise > 0.0:
        segments.append(Segment(cruise, p, v_target, 0.0, 0.0))
    return segments, elapsed
