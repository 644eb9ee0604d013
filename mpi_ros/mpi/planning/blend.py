"""Blending of appended point-to-point moves (MEIMotionConfig.blendLimit, MPI 000).

"If the change direction is greater than 90 degrees (0 degrees = no change, 180 degrees =
about face) the acceleration resulting from the blending can exceed the acceleration limit
specified in the motion parameters (180 degrees = acceleration*2.0)." The blend chosen
(docs/decisions.md, "blendLimit"): the appended move starts before the one ahead of it has
stopped, as its deceleration begins or as late as its own acceleration allows, whichever is
later, and the two profiles add up while they overlap. Each keeps its own limits, so their
sum has at most the larger velocity and, at an about-face, twice the acceleration.

Which turns blend: the reference says a turn blends "if cosine (turn angle) is greater than
the blendLimit", and also that 1.0 blends every move, -1.0 none and 0 excludes turns sharper
than 90 degrees. The three examples hold with the cosine compared against -blendLimit: a turn
blends when blendLimit > -1 and cos(turn) >= -blendLimit.
"""

from __future__ import annotations

import math

from mpi_ros.mpi.base.params import Trajectory
from mpi_ros.mpi.base.types import MotionAttr
from mpi_ros.mpi.planning.families import FAMILIES, Kind
from mpi_ros.mpi.planning.frames import AxisPlan, BlendParts, Listed, Move
from mpi_ros.mpi.planning.profiles.segment import Segment

_WAITS = MotionAttr.DELAY | MotionAttr.HOLD | MotionAttr.HOLD_LESS | MotionAttr.HOLD_GREATER
_STILL = 1e-9  # counts/s: a segment this slow at both ends is a pause, not part of a ramp


def blends(blend_limit: float, cosine: float) -> bool:
    """Does a turn of this cosine blend under ``blend_limit``?"""
    return blend_limit > -1.0 and cosine >= -blend_limit


def overlap(previous: Move, move: Move, blend_limit: float) -> float:
    """Seconds by which ``move`` (appended) starts before ``previous`` ends; 0: no blend."""
    if not _eligible(previous, move):
        return 0.0
    before, after = _direction(previous), _direction(move)
    if before is None or after is None:
        return 0.0
    cosine = sum(x * y for x, y in zip(before, after, strict=True))
    if not blends(blend_limit, cosine):
        return 0.0
    return min(min(_ramp(p.segments, last=True) for p in previous.plans),
               min(_ramp(p.segments, last=False) for p in move.plans))


def _eligible(previous: Move, move: Move) -> bool:
    """Point-to-point moves on the same axes, the first ending at rest, the second not waiting."""
    return (FAMILIES[previous.type].kind is Kind.POINT_TO_POINT and FAMILIES[move.type].kind is Kind.POINT_TO_POINT
            and previous.stream is None and not previous.ends_moving and not move.attributes & _WAITS
            and previous.plan_axes == move.plan_axes and all(p.hold is None for p in move.plans))


def _direction(move: Move) -> list[float] | None:
    """The unit vector from where the move starts to its target (None: it goes nowhere)."""
    travel = [p.target - p.start_position for p in move.plans]
    length = math.hypot(*travel)
    return None if length == 0.0 else [x / length for x in travel]


def _ramp(segments: list[Segment], last: bool) -> float:
    """The duration of the profile's first acceleration (``last``: final deceleration): the
    segments up to the first (from the last) at constant velocity or past the speed's peak.
    An axis that does not move ramps for the whole profile."""
    ordered = reversed(segments) if last else iter(segments)
    total = 0.0
    for seg in ordered:
        if seg.a == 0.0 and seg.j == 0.0 and abs(seg.v) > _STILL:
            break  # cruising
        _, v_end, _ = seg.end_state()
        near, far = (v_end, seg.v) if last else (seg.v, v_end)  # near: at the move's end (start)
        if abs(far) + _STILL < abs(near):
            break  # the speed falls away from that end: past the peak, the other ramp
        total += seg.duration
    return total


def blended(plan: AxisPlan, tail: list[Segment], rest: float, tail_limits: Trajectory | None = None) -> AxisPlan:
    """``plan`` with ``tail`` (the rest of the previous move's profile, ending at rest at
    position ``rest``, its target; planned with ``tail_limits``) added while it lasts: the
    overlapping profiles summed. The plan keeps both parts (``blended_from``)."""
    extra = [Segment(s.duration, s.p - rest, s.v, s.a, s.j) for s in tail]
    own = list(plan.segments)
    return AxisPlan(axis=plan.axis, source=Listed(superpose(own, extra), plan.limits),
                    start_position=plan.start_position, target=plan.target, final_velocity=plan.final_velocity,
                    outputs=plan.outputs, start_velocity=plan.start_velocity,
                    start_acceleration=plan.start_acceleration, composite="blended with the move before",
                    blended_from=BlendParts(tuple(own), tuple(extra), tail_limits))


def tail(segments: list[Segment], t: float) -> list[Segment]:
    """The profile from ``t`` on, as segments from 0."""
    out, start = [], 0.0
    for seg in segments:
        end = start + seg.duration
        if end > t:
            if start >= t:
                out.append(seg)
            else:
                p, v, a = seg.state_at(t - start)
                out.append(Segment(end - t, p, v, a, seg.j))
        start = end
    return out


def superpose(base: list[Segment], extra: list[Segment]) -> list[Segment]:
    """The profile base(t) + extra(t), extra ending at rest (zero after its end): a
    constant-jerk piece wherever both are."""
    cuts = sorted({*_ends(base), *(t for t in _ends(extra))})
    span = sum(s.duration for s in extra)
    out, t0 = [], 0.0
    for t1 in cuts:
        if t1 <= t0:
            continue
        if t0 >= span:
            break
        pb, vb, ab, jb = _state(base, t0)
        pe, ve, ae, je = _state(extra, t0)
        out.append(Segment(t1 - t0, pb + pe, vb + ve, ab + ae, jb + je))
        t0 = t1
    for seg, end in zip(base, _ends(base), strict=True):
        start = end - seg.duration
        if end <= t0:
            continue
        if start >= t0:
            out.append(seg)
        else:
            p, v, a = seg.state_at(t0 - start)
            out.append(Segment(end - t0, p, v, a, seg.j))
    return out


def _ends(segments: list[Segment]) -> list[float]:
    out, t = [], 0.0
    for seg in segments:
        t += seg.duration
        out.append(t)
    return out


def _state(segments: list[Segment], t: float) -> tuple[float, float, float, float]:
    """Position, velocity, acceleration and jerk at ``t`` (the end state, jerk 0, past the end)."""
    start = 0.0
    for seg in segments:
        if t < start + seg.duration:
            p, v, a = seg.state_at(t - start)
            return p, v, a, seg.j
        start += seg.duration
    if not segments:
        return 0.0, 0.0, 0.0, 0.0
    p, v, a = segments[-1].end_state()
    return p, v, a, 0.0
