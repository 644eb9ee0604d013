"""S-curve reshaping of a trapezoid's ramps into constant-jerk segments.

With f = jerkPercent/100 and a ramp of duration Ta, the ramp becomes a jerk phase of
f*Ta/2, a constant-acceleration phase of (1-f)*Ta and a jerk phase of f*Ta/2, with peak
acceleration dv / (Ta * (1 - f/2)). The ramp keeps its duration and distance (the
velocity curve is symmetric about the ramp's midpoint), so an S-curve takes exactly as
long as the trapezoid with the same limits (DESIGN.md, "Facts about the libraries").
f = 0 is the trapezoid itself.
"""

from __future__ import annotations

import math
from typing import Sequence

from .ramps import ProfileError, Ramp
from .segment import Segment


def ramp_pieces(ramp: Ramp, fraction: float) -> list[tuple[float, float, float]]:
    """(duration, start acceleration, jerk) pieces of one ramp or cruise."""
    dv = ramp.v_end - ramp.v_start
    trapezoid = [(ramp.duration, dv / ramp.duration if ramp.duration > 0.0 else 0.0, 0.0)]
    jerk_time = 0.5 * fraction * ramp.duration
    # a cruise, f = 0, or jerk phases too short to represent (tiny jerkPercent, or a ramp of ~1e-324 s)
    if ramp.is_cruise or jerk_time <= 0.0:
        return trapezoid
    flat_time = (1.0 - fraction) * ramp.duration
    peak = dv / (ramp.duration * (1.0 - 0.5 * fraction))
    jerk = peak / jerk_time
    if not math.isfinite(jerk):
        # jerkPercent so small (~1e-308) that the jerk overflows: it would make the positions NaN.
        return trapezoid
    return [(jerk_time, 0.0, jerk), (flat_time, peak, 0.0), (jerk_time, peak, -jerk)]


def reshape(plan: Sequence[Ramp], p0: float, jerk_percent: float) -> list[Segment]:
    """Segments of a velocity plan starting at position ``p0`` with zero acceleration
    at every ramp boundary (the standard S-curve starts each ramp from a = 0)."""
    if not 0.0 <= jerk_percent <= 100.0:
        raise ProfileError("jerkPercent must be within 0..100")
    fraction = jerk_percent / 100.0
    segments: list[Segment] = []
    p = p0
    for ramp in plan:
        v = ramp.v_start
        for duration, accel, jerk in ramp_pieces(ramp, fraction):
            if duration <= 0.0:
                continue
            seg = Segment(duration, p, v, accel, jerk)
            segments.append(seg)
            p, v, _ = seg.end_state()
    return segments
