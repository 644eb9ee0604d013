"""S-curve reshaping of a trapezoid's ramps into constant-jerk segments.

With f = jerkPercent/100 and a ramp of duration Ta, the ramp becomes a jerk phase of
f*Ta/2, a constant-acceleration phase of (1-f)*Ta and a jerk phase of f*Ta/2, with peak
acceleration dv / (Ta * (1 - f/2)). The ramp keeps its duration and distance (the
velocity curve is symmetric about the ramp's midpoint), so an S-curve takes exactly as
long as the trapezoid with the same limits (docs/profiles.md, "The trapezoid and the S-curve").
f = 0 is the trapezoid itself.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, Literal, overload

from mpi_ros.mpi.planning.profiles.ramps import ProfileError, RampRow
from mpi_ros.mpi.planning.profiles.segment import Row, Segment


def reshape(plan: Sequence[RampRow], p0: float, jerk_percent: float) -> list[Segment]:
    """Segments of a velocity plan starting at position ``p0`` with zero acceleration
    at every ramp boundary (the standard S-curve starts each ramp from a = 0). Each segment
    lasts more than 0 s and starts at the position where the one before ends, as
    Segment.end_state calculates it: the planner relies on it (a profile whose end position
    is finite is finite throughout: planner._finite_if_it_ends)."""
    return reshaped(plan, p0, jerk_percent)[0]


@overload
def reshaped(plan: Sequence[RampRow], p0: float, jerk_percent: float,
             rows: Literal[False] = False) -> tuple[list[Segment], float, float]: ...


@overload
def reshaped(plan: Sequence[RampRow], p0: float, jerk_percent: float,
             rows: Literal[True]) -> tuple[list[Row], float, float]: ...


def reshaped(plan: Sequence[RampRow], p0: float, jerk_percent: float,
             rows: bool = False) -> tuple[list[Any], float, float]:
    """:func:`reshape`'s segments, where they end and how long they last: the position
    Segment.end_state gives at the end of the last one (``p0`` without segments) and
    ``end_time(segments)``, the same additions in the same order (0.0 without segments).
    The planner needs both of every profile; here they are a by-product of the loop that makes
    the segments (it calculates each segment's end to start the next), not a pass of their own.
    ``rows``: the segments as plain tuples (Rows), for a vector's line, whose axes' Segments are
    made from it (segment.scaled_profile)."""
    if not 0.0 <= jerk_percent <= 100.0:
        raise ProfileError("jerkPercent must be within 0..100")
    fraction = jerk_percent / 100.0
    # The fractions of a ramp each piece takes, the same for every ramp: computed once, as the
    # same operations give the same values (0.5 * fraction * duration is (0.5 * fraction) * duration)
    half = 0.5 * fraction  # each jerk phase
    flat = 1.0 - fraction  # the constant-acceleration phase
    kept = 1.0 - half  # peak acceleration = dv / (duration * kept)
    segments: list[Any] = []  # (Rows, made Segments at the end unless ``rows``)
    p = p0
    total = -0.0  # end_time's sum: -0.0 + d is d for every d, as its first term is
    for duration, v, v_end in plan:
        dv = v_end - v
        jerk_time = half * duration
        # The S-curve's three pieces (duration, start acceleration, jerk), unless this is a
        # cruise, f = 0, the jerk phases are too short to represent (tiny jerkPercent, or a ramp
        # of ~1e-324 s), or the jerk overflows (jerkPercent ~1e-308: the positions would be NaN).
        # Then the trapezoid's ramp.
        pieces: tuple[tuple[float, float, float], ...] | None = None
        if not (v == v_end or jerk_time <= 0.0):
            peak = dv / (duration * kept)
            jerk = peak / jerk_time
            if math.isfinite(jerk):
                pieces = ((jerk_time, 0.0, jerk), (flat * duration, peak, 0.0), (jerk_time, peak, -jerk))
        if pieces is None:
            pieces = ((duration, dv / duration if duration > 0.0 else 0.0, 0.0),)
        for t, a, j in pieces:
            if not t <= 0.0:  # (no piece of 0 s; a NaN one is kept)
                segments.append((t, p, v, a, j))
                # where it ends, as Segment.end_state calculates it: the next piece starts there
                p, v = p + t * (v + t * (a / 2.0 + t * j / 6.0)), v + t * (a + t * j / 2.0)
                total += t
    if not rows:
        segments = list(map(Segment._make, segments))
    return segments, p, 0.0 + total  # (end_time's t0 + total, with t0 = 0.0)
