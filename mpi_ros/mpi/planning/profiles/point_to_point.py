"""1-D TRAPEZOIDAL, S_CURVE and VELOCITY profiles as constant-jerk segments.

One function per motion type family; all return segments in profile time starting at
the given position. Start/modify alike: the standard algorithm starts from the current
position and velocity with zero acceleration (docs/profiles.md, "Modify: from the current state").
"""

from __future__ import annotations

from mpi_ros.mpi.planning.profiles.ramps import Ramp, plan_velocity, trapezoid_rows
from mpi_ros.mpi.planning.profiles.scurve import reshape
from mpi_ros.mpi.planning.profiles.segment import Segment


def point_to_point(
    p0: float,
    v0: float,
    target: float,
    v_final: float,
    velocity: float,
    acceleration: float,
    deceleration: float,
    jerk_percent: float,
) -> list[Segment]:
    """S_CURVE (jerk_percent > 0) or TRAPEZOIDAL (jerk_percent = 0) from (p0, v0)."""
    # (the trapezoid as plain rows: reshape reads them as they are, no Ramp made for each)
    plan = trapezoid_rows(target - p0, v0, v_final, velocity, acceleration, deceleration)
    return reshape(plan, p0, jerk_percent)


def velocity_move(
    p0: float, v0: float, v_target: float, acceleration: float, jerk_percent: float, cruise: float
) -> tuple[list[Segment], float]:
    """VELOCITY: S-curve ramp to ``v_target`` then ``cruise`` seconds at it.

    Returns the segments and the profile time at which the ramp is done.
    """
    ramps = plan_velocity(v0, v_target, acceleration)
    ramp_time = sum(r.duration for r in ramps)
    if cruise > 0.0:
        ramps = [*ramps, Ramp(cruise, v_target, v_target)]
    return reshape(ramps, p0, jerk_percent), ramp_time


def reverses(segments: list[Segment], v0: float) -> bool:
    """True if the profile's velocity changes sign (NO_REVERSAL forbids it)."""
    signs = {1 if v0 > 0 else -1} if v0 != 0.0 else set()
    for seg in segments:
        for v in (seg.v, seg.end_state()[1]):
            if abs(v) > 1e-9 * (1.0 + abs(v0)):
                signs.add(1 if v > 0 else -1)
        if len(signs) > 1:
            return True
    return False
