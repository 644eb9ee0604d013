"""Compile a validated start/modify request into a Move: per-axis frames.

Multi-axis rules (MPI 000 MPIMotionAttrMask remarks, MPIMotionSCurve):
- without SYNC_START/SYNC_END the first trajectory is the vector's: the axes move on a
  straight line with one profile along it;
- with SYNC_START/SYNC_END each axis uses its own trajectory; SYNC_END inserts wait
  frames before the shorter profiles so all end together, SYNC_START adds delay frames
  after them;
- DELAY inserts a wait frame of delay[i] seconds before axis i's profile.
Quirks kept from the firmware (MPI 000 mpiMotionStart): a frame may not last more than
16,384,000 samples (the axis stops abruptly there), and the fraction of a RELATIVE
distance is truncated. Both are reported through ``notes``.

Decision (the spec is silent): a vector modify whose current velocity is not along the new
line cannot stay on one line; the vector first comes to rest along its current line, then
moves on a straight line to the new targets (docs/decisions.md).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal, overload

from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Refused
from mpi_ros.mpi.base.params import (
    ID_BITS,
    VELOCITY_FRAME_LIMIT_SAMPLES,
    AxisMaster,
    Hold,
    MotionParams,
    Output,
    Trajectory,
)
from mpi_ros.mpi.base.types import HOLD_ATTRS, MotionAttr, MPIMotionType
from mpi_ros.mpi.planning import cams
from mpi_ros.mpi.planning.families import FAMILIES, Kind
from mpi_ros.mpi.planning.frames import AxisPlan, Listed, Move, Scaled, Stream
from mpi_ros.mpi.planning.paths import PathStart, compile_path
from mpi_ros.mpi.planning.profiles.jerk import point_to_point_jerk, velocity_change, velocity_jerk
from mpi_ros.mpi.planning.profiles.point_to_point import reverses, velocity_move
from mpi_ros.mpi.planning.profiles.ramps import ProfileError, ramp_rows, trapezoid_rows
from mpi_ros.mpi.planning.profiles.scurve import reshape, reshaped
from mpi_ros.mpi.planning.profiles.segment import (
    Row,
    Segment,
    chain,
    end_time,
    scaled_profile,
)
from mpi_ros.mpi.planning.start import AxisStart

A = MotionAttr
# The attributes planning tests, as plain ints: an IntFlag's `in` and `&` run Python code, an
# int's do not.
_RELATIVE, _FINAL_VEL, _NO_REVERSAL, _DELAY, _OUTPUT, _ID, _ELEMENT_ID, _EVENT = map(
    int, (A.RELATIVE, A.FINAL_VEL, A.NO_REVERSAL, A.DELAY, A.OUTPUT, A.ID, A.ELEMENT_ID, A.EVENT))
_SYNC_START, _SYNC_END, _HOLDS = int(A.SYNC_START), int(A.SYNC_END), int(HOLD_ATTRS)
_SYNC = _SYNC_START | _SYNC_END
# Unions the planning tests, made once
_IN_MOTION_REFUSED = _DELAY | _HOLDS  # a move that starts in motion may not wait first
_PADDED = _SYNC | _DELAY  # profiles with wait frames: not reshape's chain of pieces
_AXIS_BY_AXIS = _DELAY | _NO_REVERSAL  # a vector's axes made and checked one by one
_HOLD_OR_OUTPUT = _HOLDS | _OUTPUT
# The attributes that change a point-to-point axis' plan: without them one axis is planned by
# _lone_axis_plan, the general path's lists and tests left out
_GENERAL = _RELATIVE | _FINAL_VEL | _SYNC | _DELAY | _NO_REVERSAL | _HOLD_OR_OUTPUT
# Each type's family and ramps (families.py), looked up here once, not for every move
_KIND = {t: family.kind for t, family in FAMILIES.items()}
_LINE = {t: family.line for t, family in FAMILIES.items() if family.line is not None}
_STOP = {t: family.stop for t, family in FAMILIES.items() if family.stop is not None}
_POINT_TO_POINT, _VELOCITY, _CAM = Kind.POINT_TO_POINT, Kind.VELOCITY, Kind.CAM
_NO_EVENTS = MPIEventType.NONE


@dataclass(slots=True)
class PlanNotes:
    """Quirks that applied, as (event type, detail) to report."""

    events: list[tuple[MPIEventType, str]] = field(default_factory=list)


def _truncate_id(value: int, notes: PlanNotes) -> int:
    half = 1 << (ID_BITS - 1)
    truncated = ((int(value) + half) % (1 << ID_BITS)) - half
    if truncated != value:
        notes.events.append(
            (MPIEventType.ID_TRUNCATED, f"id {value} stored as {truncated} (16-bit on the controller)")
        )
    return truncated


def _targets(params: MotionParams, bits: int, starts: list[AxisStart], notes: PlanNotes) -> list[float]:
    """Raw target positions; RELATIVE distances lose their fraction (firmware quirk)."""
    positions = params.position
    targets: list[float] = []
    if not bits & _RELATIVE:  # (the usual case)
        for position, start in zip(positions, starts, strict=True):
            targets.append(position + start.origin)
        return targets
    for value, start in zip(positions, starts, strict=True):
        distance = float(math.trunc(value))
        if distance != value:
            notes.events.append(
                (MPIEventType.RELATIVE_TRUNCATED,
                 f"axis {start.axis}: relative distance {value!r} truncated to {distance:g}")
            )
        targets.append(start.position + distance)
    return targets


def _sound(segment: Row, limit: float) -> bool:
    """A segment (or row) lasts from 0 to ``limit`` seconds and all its values are finite."""
    return 0.0 <= segment[0] <= limit and all(map(math.isfinite, segment))


def _check_finite(segments: list[Segment], axis: int) -> None:
    """A profile that overflowed (absurd distances or limits) cannot be calculated."""
    for segment in segments:
        if not _sound(segment, math.inf):
            raise ProfileError(f"axis {axis}: the profile cannot be calculated with these values (overflow)")


def _on_target(end: float, start: AxisStart, target: float) -> bool:
    """The plan's end is on the target within the rounding of the positions alone."""
    if not math.isfinite(end):
        return False
    return abs(end - target) <= 1e-9 * max(1.0, abs(target), abs(start.position))


def _end_position(segment: tuple[float, float, float, float, float]) -> float:
    """Where a segment ends, as Segment.end_state calculates it, without its other values."""
    t, p, v, a, j = segment
    return p + t * (v + t * (a / 2.0 + t * j / 6.0))


def _check_lands(segments: list[Segment], start: AxisStart, target: float, end: float) -> None:
    """The frames must end on the target: the executor snaps the command onto it when the
    trajectory completes, which must never be a jump (guards against overflow and any
    planning fault). Rounding grows with the positions and the distance travelled. ``end``:
    where they end, not on the target within the rounding of the positions alone (_on_target,
    which _checked asks first: the travel can only widen the tolerance)."""
    scale = max(1.0, abs(target), abs(start.position))
    # each segment's distance at the greater of its start and end speeds (its end velocity as
    # Segment.state_at calculates it, on rows as well as Segments)
    travel = sum([max(abs(v), abs(v + t * (a + t * j / 2.0))) * t for t, _, v, a, j in segments])
    scale = max(scale, travel)
    if not math.isfinite(end) or abs(end - target) > 1e-9 * scale:
        raise ProfileError(f"axis {start.axis}: the profile cannot be calculated with these values")


def _checked(segments: list[Segment], start: AxisStart, target: float, limit: float, notes: PlanNotes,
             end: float, duration: float | None) -> tuple[list[Segment], bool]:
    """An axis' plan after the landing, overflow and frame-limit checks: cut at the first frame
    longer than ``limit`` seconds (16,384,000 samples), and whether it was. ``end``: where the
    segments end (_end_position of the last; the start without any). ``duration``: their
    end_time when they are reshape's (each starting where the one before ends, so that one that
    lands is finite throughout: _finite_if_it_ends), None otherwise: then one pass over them
    finds every segment finite and within the limit, the usual case."""
    if not _on_target(end, start, target):
        _check_lands(segments, start, target, end)
    if duration is not None and _within(segments, duration, limit):
        return segments, False  # landed: finite (and reshape's pieces are positive)
    for segment in segments:
        if not _sound(segment, limit):
            _check_finite(segments, start.axis)
            return _cap_frames(segments, limit, start.axis, notes)
    return segments, False


def _within(segments: Sequence[Row], duration: float, limit: float) -> bool:
    """No segment of a 1-D profile (reshape's: finite if it lands, no duration below 0) lasts
    longer than ``limit``; ``duration``: theirs. Durations of at least 0 add up to at least each
    of them, in floating point too (rounding is monotonic), so one comparison answers the usual
    case; a profile that lasts longer than the limit is asked segment by segment."""
    return duration <= limit or not any(segment[0] > limit for segment in segments)  # (segment[0]: its duration)


def _finite_if_it_ends(end: float) -> bool:
    """Whether ``end``, the end position of reshape's segments (each starts at the position where
    the one before ends, as Segment.end_state calculates it), is finite, which makes every value
    of every segment finite: each enters that end position through +, -, * and division by a
    constant, where an infinite or NaN operand gives an infinite or NaN result (a product too:
    the pieces last more than 0 s). This is what _check_finite's pass would find."""
    return math.isfinite(end)


def _line_passes(line: RowLine, limit: float, chained: bool) -> bool:
    """Whether a vector's 1-D profile is not empty, all its values are finite and no frame exceeds
    ``limit``. An axis' share of it, with a factor of at most 1 and a start ``offset``, is then
    finite and within the limit too when abs(offset) + its largest |position| is finite
    (_no_overflow): rounding to nearest is monotonic, so no product or sum of the scaling
    exceeds that in magnitude. ``chained``: the profile is reshape's (_checked)."""
    segments, end, duration = line
    if not segments:
        return False
    if chained:
        return _finite_if_it_ends(end) and _within(segments, duration, limit)
    return all(_sound(segment, limit) for segment in segments)


# Half a unit in the last place of the largest float: a finite x plus any |y| below it rounds to
# at most the largest float, finite (a tie rounds to even, up: hence below)
_HALF_ULP_OF_MAX = math.ulp(sys.float_info.max) / 2.0


def _no_overflow(offset: float, segments: Sequence[Row]) -> bool:
    """abs(offset) + the largest |position| of ``segments`` (finite: _line_passes) is finite. For
    any offset below _HALF_ULP_OF_MAX it is, whatever that position (every offset a controller
    holds), so the positions are looked at for a larger one only."""
    if abs(offset) < _HALF_ULP_OF_MAX:
        return True
    bound = 0.0
    for segment in segments:
        if abs(segment[1]) > bound:  # (its position)
            bound = abs(segment[1])
    return math.isfinite(abs(offset) + bound)


def _passes_checks(scaled: Scaled, start: AxisStart, target: float) -> bool:
    """True when the vector axis' share ``scaled`` of a 1-D profile that passed its checks
    (_line_passes) passes _checked as it is, without making its segments: finite, no frame
    beyond the limit, and its last segment, scaled as scaled_profile scales it, ends on the
    target (within the rounding of the positions: otherwise _checked decides)."""
    line, factor, offset = scaled.values, scaled.factor, scaled.offset
    # (_no_overflow's first answer, the usual one, without its call)
    if not (abs(factor) <= 1.0 and (abs(offset) < _HALF_ULP_OF_MAX or _no_overflow(offset, line))):
        return False
    t, p, v, a, j = line[-1]
    p, v, a, j = offset + factor * p, factor * v, factor * a, factor * j  # (scaled_profile's operations)
    return _on_target(p + t * (v + t * (a / 2.0 + t * j / 6.0)), start, target)  # (_end_position's)


def _cap_frames(segments: list[Segment], limit: float, axis: int, notes: PlanNotes) -> tuple[list[Segment], bool]:
    """Cut the (finite) plan at the first frame longer than ``limit`` seconds. (Its segments by
    index: Segments or Rows, a lone axis': _lone_axis_plan.)"""
    for i, (duration, p, v, a, j) in enumerate(segments):
        if duration > limit:
            notes.events.append(
                (MPIEventType.FRAME_TIME_LIMIT,
                 f"axis {axis}: a frame of {duration:.1f} s exceeds {VELOCITY_FRAME_LIMIT_SAMPLES} samples;"
                 " the axis will stop abruptly after it")
            )
            return [*segments[:i], Segment(limit, p, v, a, j)], True
    return segments, False


def _wait(position: float, duration: float) -> list[Segment]:
    return [Segment(duration, position, 0.0, 0.0, 0.0)] if duration > 0.0 else []


def _scalar_profile(
    motion_type: MPIMotionType, start: AxisStart, target: float, v_final: float, traj: Trajectory,
) -> list[Segment]:
    return _profile_from(motion_type, start.position, start.velocity, start.acceleration, target, v_final, traj)[0]


# A 1-D profile: its segments, where they end (the position Segment.end_state gives at the end
# of the last; the start without any) and its duration (end_time of the segments). The planner
# checks and times every profile: reshape calculates both as it makes the segments. A vector's
# line is made of Rows (its axes' Segments are made from it), an axis' own profile of Segments.
Line = tuple[list[Segment], float, float]
RowLine = tuple[list[Row], float, float]


@overload
def _profile_from(motion_type: MPIMotionType, p0: float, v0: float, a0: float, target: float, v_final: float,
                  traj: Trajectory, rows: Literal[False] = False) -> Line: ...


@overload
def _profile_from(motion_type: MPIMotionType, p0: float, v0: float, a0: float, target: float, v_final: float,
                  traj: Trajectory, rows: Literal[True]) -> RowLine: ...


def _profile_from(motion_type: MPIMotionType, p0: float, v0: float, a0: float, target: float, v_final: float,
                  traj: Trajectory, rows: bool = False) -> Line | RowLine:
    """The 1-D profile of a point-to-point type from (p0, v0, a0); a0 is read by the jerk types
    only. ``rows``: reshape's segments as Rows (scurve.reshaped; a jerk type's are Segments)."""
    line = _LINE[motion_type]
    if line.jerk_limited:
        segments = point_to_point_jerk(
            p0, v0, a0, target, v_final, traj.velocity,
            (traj.acceleration, traj.acceleration_jerk), (traj.deceleration, traj.deceleration_jerk))
        return segments, _end_position(segments[-1]) if segments else p0, end_time(segments)
    jerk_percent = traj.jerk_percent if line.reads_jerk_percent else 0.0
    # point_to_point's two steps, without its call (a modify is planned while its command waits)
    plan = trapezoid_rows(target - p0, v0, v_final, traj.velocity, traj.acceleration, traj.deceleration)
    return reshaped(plan, p0, jerk_percent, True) if rows else reshaped(plan, p0, jerk_percent)


def _limits_of(profile: Profile, limits: list[Trajectory] | None, i: int, traj: Trajectory) -> Trajectory:
    """Axis i's limits: ``limits[i]``, or where a vector's shares are not made (None: every
    profile Scaled), its share of the vector's limits, by its factor (_vector_profiles)."""
    if limits is not None:
        return limits[i]
    assert isinstance(profile, Scaled)
    return profile.limits()


# An axis' profile: its segments, or (a vector's axis) its share of the vector's 1-D profile
Profile = list[Segment] | Scaled


def _segments(profile: Profile) -> list[Segment]:
    return profile.segments() if isinstance(profile, Scaled) else profile


def _dot(a: Sequence[float], b: Sequence[float]) -> float:
    """The exactly rounded dot product (math.fsum of the products)."""
    if len(a) == 2:
        # Two products: their sum is already exactly rounded, as fsum's is. fsum answers +0.0 for
        # a zero sum (hence + 0.0) and raises for inf - inf or an overflow (hence fsum there).
        total = a[0] * b[0] + a[1] * b[1]
        if math.isfinite(total):
            return total + 0.0
    return math.fsum([x * y for x, y in zip(a, b, strict=True)])


def _along(vector: Sequence[float], unit: Sequence[float], scale: float) -> tuple[float, bool]:
    """The component of ``vector`` along ``unit``, and whether ``vector`` lies on that line."""
    if not any(vector):  # at rest (or no final velocity): what the calculation gives, without it
        return 0.0, True
    along = _dot(vector, unit)
    tolerance = 1e-9 * (1.0 + scale)
    for x, u in zip(vector, unit, strict=True):
        if not abs(x - along * u) <= tolerance + 1e-9 * abs(x):
            return along, False
    return along, True


def _accel_along(starts: list[AxisStart], unit: list[float]) -> float:
    """The component of the axes' acceleration along ``unit``: the jerk types plan from it."""
    accels = [start.acceleration for start in starts]
    return _dot(accels, unit) if any(accels) else 0.0  # (a dot product of zeros is +0.0)


def _vector_profiles(
    motion_type: MPIMotionType, starts: list[AxisStart], targets: list[float], finals: list[float], traj: Trajectory,
) -> tuple[list[Profile], list[Trajectory] | None, str, RowLine | None]:
    """One profile along the straight line from the start to the targets, each axis'
    effective limits (the vector's scaled by the axis' share of the line: None when every
    profile is Scaled, whose factor is that share, the limits then made when asked for,
    _limits_of), why the profiles are not one profile per axis ("" when they are) and the 1-D
    profile every axis has a share of (None when they have not: no move, or not one line).
    Plain floats: a vector has at most MEIXmpMAX_COORD_AXES components, too few for numpy to
    pay off."""
    p0: list[float] = []
    v0: list[float] = []
    delta: list[float] = []
    for start, target in zip(starts, targets, strict=True):
        p0.append(start.position)
        v0.append(start.velocity)
        delta.append(target - start.position)
    length = math.hypot(*delta)  # no overflow for large components, unlike a sum of squares
    speed = math.hypot(*v0)
    if not (math.isfinite(length) and math.isfinite(speed)):
        raise ProfileError("the move's length cannot be calculated (overflow)")
    if length > 0.0:
        unit = [d / length for d in delta]
    elif speed > 0.0:
        unit = [v / speed for v in v0]
    else:
        return [[] for _ in starts], [traj for _ in starts], "", None
    along, parallel = _along(v0, unit, speed)
    # (_along's answer without a final velocity, without the length of the zeros it needs otherwise)
    final_along, final_parallel = _along(finals, unit, math.hypot(*finals)) if any(finals) else (0.0, True)
    if not final_parallel:
        raise Refused(Message.MPIMessagePARAM_INVALID, "final velocities of a vector move must lie along the move")
    if not parallel:
        return _stop_then_line(motion_type, starts, p0, v0, speed, targets, finals, traj)
    # (only a jerk-limited profile plans from the current acceleration; the others from a = 0)
    accel = _accel_along(starts, unit) if _LINE[motion_type].jerk_limited else 0.0
    line = _profile_from(motion_type, 0.0, along, accel, length, final_along, traj, True)
    segments, duration = line[0], line[2]
    profiles: list[Profile] = []
    for u, p in zip(unit, p0, strict=True):
        profiles.append(Scaled(segments, u, p, duration, traj))
    return profiles, None, "", line


STOP_THEN_LINE = "vector modify off its line: the vector stops along its line, then moves on a new one"


def _stop_then_line(
    motion_type: MPIMotionType, starts: list[AxisStart], p0: list[float], v0: list[float], speed: float,
    targets: list[float], finals: list[float], traj: Trajectory,
) -> tuple[list[Profile], list[Trajectory], str, None]:
    """A vector modify off the current line: the vector first comes to rest along the line it
    is on (decelerating as the trajectory says), then moves on a straight line to the new
    targets. Both parts are single vector profiles, so the vector's limits hold throughout
    (docs/decisions.md)."""
    heading = [v / speed for v in v0]
    stop = _stop_profile(motion_type, speed, traj)
    stopped_after = stop[-1].end_state()[0] if stop else 0.0
    rest = [p + h * stopped_after for p, h in zip(p0, heading, strict=True)]
    go_starts = [AxisStart(s.axis, p, 0.0, s.origin) for s, p in zip(starts, rest, strict=True)]
    go, go_limits, _, _ = _vector_profiles(motion_type, go_starts, targets, finals, traj)
    profiles: list[Profile] = [scaled_profile(stop, h, p) + _segments(tail)
                               for h, p, tail in zip(heading, p0, go, strict=True)]
    limits = [traj.share(max(abs(h), _limits_of(tail, go_limits, i, traj).velocity / traj.velocity))
              for i, (h, tail) in enumerate(zip(heading, go, strict=True))]
    return profiles, limits, STOP_THEN_LINE, None


def _stop_profile(motion_type: MPIMotionType, speed: float, traj: Trajectory) -> list[Segment]:
    """1-D: from ``speed`` to rest with the trajectory's deceleration (and its jerk), as the
    family's stop profile ramps."""
    stop = _STOP[motion_type]
    if stop.jerk_limited:
        return chain(0.0, speed, 0.0, velocity_change(speed, 0.0, 0.0, traj.deceleration, traj.deceleration_jerk))
    jerk_percent = traj.jerk_percent if stop.reads_jerk_percent else 0.0
    return reshape(ramp_rows(speed, 0.0, traj.acceleration, traj.deceleration), 0.0, jerk_percent)


def _sync(
    profiles: list[list[Segment]], starts: list[AxisStart], targets: list[float], bits: int,
) -> list[list[Segment]]:
    durations = [sum(s.duration for s in prof) for prof in profiles]
    longest = max(durations, default=0.0)
    out = []
    for prof, start, target, duration in zip(profiles, starts, targets, durations, strict=True):
        pad = longest - duration
        if bits & _SYNC_END and start.velocity == 0.0:
            prof = _wait(start.position, pad) + prof
        elif bits & _SYNC_START:
            prof = prof + _wait(target, pad)
        out.append(prof)
    return out


def compile_move(
    supervisor: int,
    motion_type: MPIMotionType,
    attrs: MotionAttr,
    params: MotionParams,
    starts: list[AxisStart],
    sample_rate: float,
    cam_masters: list[tuple[AxisMaster, float, float]] | None = None,
) -> tuple[Move, PlanNotes]:
    """The frames of a request for the axes ``starts`` (in the supervisor's order).

    Raises Refused with the spec's message when the profile cannot be made. A profile
    that starts while its axes move cannot wait first: a non-zero DELAY is
    MPIMotionMessageILLEGAL_DELAY (MPI 000, for a modify in motion) and a HOLD
    MPIMotionMessageATTRIBUTE_INVALID (MPI 000: HOLD is not permitted in modifies); either
    would stop the axes dead. A cam (``cam_masters``: each slave's master, its position
    now and the origins it is read less) is planned by cams.py.
    """
    notes = PlanNotes([])
    bits = int(attrs)
    if bits & _IN_MOTION_REFUSED and any(s.velocity != 0.0 for s in starts):  # starts in motion
        if bits & _DELAY and any(d != 0.0 for d in params.delay):
            raise Refused(Message.MPIMotionMessageILLEGAL_DELAY, "a move that starts in motion cannot be delayed")
        if bits & _HOLDS:
            raise Refused(Message.MPIMotionMessageATTRIBUTE_INVALID, "a move that starts in motion cannot be held")
    stream = None
    try:
        kind = _KIND[motion_type]
        if kind is _POINT_TO_POINT:
            if len(starts) == 1 and not bits & _GENERAL:  # (the usual start or modify of an axis)
                plans = [_lone_axis_plan(motion_type, params, starts[0], sample_rate, notes)]
            else:
                plans = _point_to_point_plans(motion_type, params, bits, starts, sample_rate, notes)
        elif kind is _VELOCITY:
            plans = _velocity_plans(motion_type, params, attrs, starts, sample_rate, notes)
        elif kind is _CAM:
            assert cam_masters is not None  # (the supervisor reads each slave's master)
            plans = cams.cam_plans(motion_type, attrs, params, starts, cam_masters)
        else:  # (the streamed kinds, PATH and FRAME: paths.py tells them apart)
            assert kind.streamed, kind
            plans, stream = _path_plans(motion_type, params, attrs, starts)
    except ProfileError as exc:
        raise Refused(Message.MPIMotionMessagePROFILE_ERROR, str(exc)) from exc
    move = Move(
        supervisor, motion_type, attrs, plans,
        id=_truncate_id(params.id, notes) if bits & _ID else 0,
        element_id=int(params.element_id[0]) if bits & _ELEMENT_ID and params.element_id else 0,
        event_mask=params.event_mask if bits & _EVENT else _NO_EVENTS,
        stream=stream,
    )  # (serial 0: the supervisor that takes the move gives it one)
    return move, notes


def path_starts(starts: list[AxisStart]) -> list[PathStart]:
    return [PathStart(s.axis, s.position, s.velocity, s.origin) for s in starts]


def _path_plans(
    motion_type: MPIMotionType, params: MotionParams, attrs: MotionAttr, starts: list[AxisStart],
) -> tuple[list[AxisPlan], Stream]:
    """A path's plans (paths.py) and its streaming state; the frame buffer's low count is
    the supervisor's to set (it knows the buffer's size)."""
    relative = bool(attrs & (A.RELATIVE | A.RELATIVE_MOVE))
    plans, peaks = compile_path(motion_type, attrs, params, path_starts(starts), relative)
    for plan in plans:
        _check_finite(plan.segments, plan.axis)
    return plans, Stream(open=not params.final, empty_count=params.empty_count, low_count=0, peaks=peaks)


def _holds_and_outputs(params: MotionParams, bits: int, index: int) -> tuple[Hold | None, list[Output]]:
    hold = params.hold[index] if bits & _HOLDS else None
    outputs = list(params.output) if bits & _OUTPUT and index == 0 else []
    return hold, outputs


def _point_to_point_plans(motion_type: MPIMotionType, params: MotionParams, bits: int, starts: list[AxisStart],
                          sample_rate: float, notes: PlanNotes) -> list[AxisPlan]:
    """``bits``: the move's attributes as an int (compile_move's). Not a lone axis without any of
    _GENERAL's attributes: compile_move plans that with _lone_axis_plan."""
    targets = _targets(params, bits, starts, notes)
    finals = list(params.final_velocity) if bits & _FINAL_VEL else [0.0] * len(starts)
    composite = ""
    line: Line | None = None  # the 1-D profile of one axis
    vector: RowLine | None = None  # or the one of a vector's axes (_vector_profiles)
    limits: list[Trajectory] | None  # (None: a vector's shares, _limits_of)
    profiles: Sequence[Profile]
    if bits & _SYNC:
        scalar = [
            _scalar_profile(motion_type, start, target, final, traj)
            for start, target, final, traj in zip(starts, targets, finals, params.trajectory, strict=True)
        ]
        profiles = _sync(scalar, starts, targets, bits)
        limits = list(params.trajectory)
    elif len(starts) == 1:
        one = starts[0]
        line = _profile_from(motion_type, one.position, one.velocity, one.acceleration, targets[0], finals[0],
                             params.trajectory[0])
        profiles = [line[0]]
        limits = [params.trajectory[0]]
    else:
        profiles, limits, composite, vector = _vector_profiles(motion_type, starts, targets, finals,
                                                               params.trajectory[0])
    limit = VELOCITY_FRAME_LIMIT_SAMPLES / sample_rate
    # A vector's axes share one 1-D profile, checked once: an axis whose share provably passes
    # the checks is planned without making its segments (a Scaled source); any other, or with
    # DELAY or NO_REVERSAL, has them made and checked here as every other plan is.
    # reshape's profiles (_profile_from: all but a jerk-limited line's), not padded, delayed or composite
    chained = not _LINE[motion_type].jerk_limited and not bits & _PADDED and not composite
    # ``shared`` only for a vector's shares (every profile Scaled) whose 1-D profile passed its
    # checks; each such plan's duration is then the 1-D profile's.
    first = profiles[0] if profiles else None
    shared = (vector is not None and isinstance(first, Scaled) and not bits & _AXIS_BY_AXIS
              and _line_passes(vector, limit, chained))
    plans: list[AxisPlan] = []
    # (one target, final velocity and profile per start, by index: made so above from a request
    # check_params has found one value per axis in)
    for i, start in enumerate(starts):
        target, final, profile = targets[i], finals[i], profiles[i]
        hold, outputs = _holds_and_outputs(params, bits, i) if bits & _HOLD_OR_OUTPUT else (None, [])
        if isinstance(profile, Scaled):
            if shared and _passes_checks(profile, start, target):
                plans.append(AxisPlan(start.axis, profile, start.position, target, final, hold, outputs, None, 0.0,
                                      False, start.velocity, start.acceleration, composite))
                continue
            # (an axis' share of a vector's profile is no chain: each of its segments is scaled alone)
            prof, own = profile.segments(), None
        else:
            prof, own = profile, line  # (a lone axis' profile is its line; the other plain profiles have none)
        if bits & _NO_REVERSAL and reverses(prof, start.velocity):
            raise Refused(Message.MPIMotionMessagePROFILE_ERROR,
                            f"axis {start.axis}: NO_REVERSAL, but the target is behind the motion")
        if bits & _DELAY:
            prof, own = _wait(start.position, params.delay[i]) + prof, None
        plans.append(_checked_plan(prof, own, chained, start, target, final, limit, notes, hold, outputs,
                                   _limits_of(profile, limits, i, params.trajectory[0]), composite))
    return plans


def _lone_axis_plan(motion_type: MPIMotionType, params: MotionParams, start: AxisStart, sample_rate: float,
                    notes: PlanNotes) -> AxisPlan:
    """The plan of one axis whose attributes change nothing in it (none of _GENERAL's), as
    _point_to_point_plans makes it: the same target, profile and checks, without the lists and
    tests that further axes and those attributes need."""
    positions, traj = params.position, params.trajectory[0]
    if len(positions) != 1:  # (_targets' guard)
        raise ValueError(f"{len(positions)} positions for 1 axes")
    target = positions[0] + start.origin  # (_targets' target: not RELATIVE)
    # (its segments as Rows, the Segments made when first asked for: Listed)
    line = _profile_from(motion_type, start.position, start.velocity, start.acceleration, target, 0.0, traj, True)
    segments, end, duration = line
    limit = VELOCITY_FRAME_LIMIT_SAMPLES / sample_rate
    # (chained: reshape's profile unless a jerk-limited line's; one axis is neither padded nor composite)
    chained = not _LINE[motion_type].jerk_limited
    if chained and duration <= limit and _on_target(end, start, target):
        # _checked's first answer, the usual one: on target, and no segment lasts longer than the
        # limit (_within), so finite (_finite_if_it_ends): the plan as _checked_plan makes it
        return AxisPlan(start.axis, Listed(segments, traj, duration, True), start.position, target, 0.0, None, [],
                        None, 0.0, False, start.velocity, start.acceleration, "")
    return _checked_plan(segments, line, chained, start, target, 0.0, limit, notes, None, [],  # type: ignore[arg-type]
                         traj, "", rows=True)


def _checked_plan(prof: list[Segment], own: Line | None, chained: bool, start: AxisStart, target: float,
                  final: float, limit: float, notes: PlanNotes, hold: Hold | None, outputs: list[Output],
                  limits: Trajectory, composite: str, rows: bool = False) -> AxisPlan:
    """An axis' plan of the segments ``prof`` after _checked. ``own``: the Line they are (where
    they end and their duration, calculated with them), or None; ``chained``: they are
    reshape's (_point_to_point_plans); ``rows``: they are Rows (Listed)."""
    if own is None:
        end, duration = (_end_position(prof[-1]) if prof else start.position), None
    else:
        end, duration = own[1], own[2]
    prof, truncated = _checked(prof, start, target, limit, notes, end, duration if chained else None)
    if truncated:
        # where the cut plan ends, at rest
        return AxisPlan(start.axis, Listed(prof, limits, None, rows), start.position, prof[-1].end_state()[0], 0.0,
                        hold, outputs, None, 0.0, True, start.velocity, start.acceleration, composite)
    return AxisPlan(start.axis, Listed(prof, limits, duration, rows), start.position, target, final, hold, outputs,
                    None, 0.0, False, start.velocity, start.acceleration, composite)


def _velocity_plans(
    motion_type: MPIMotionType, params: MotionParams, attrs: MotionAttr, starts: list[AxisStart],
    sample_rate: float, notes: PlanNotes,
) -> list[AxisPlan]:
    limit = VELOCITY_FRAME_LIMIT_SAMPLES / sample_rate
    jerk_limited = _LINE[motion_type].jerk_limited
    trajs = params.trajectory if len(params.trajectory) == len(starts) else params.trajectory * len(starts)
    plans = []
    for i, (start, traj) in enumerate(zip(starts, trajs, strict=True)):
        delay = params.delay[i] if A.DELAY in attrs else 0.0
        cruise = limit if traj.velocity != 0.0 else 0.0
        if jerk_limited:
            prof, ramp_time = velocity_jerk(start.position, start.velocity, start.acceleration, traj.velocity,
                                            traj.acceleration, traj.acceleration_jerk, traj.deceleration_jerk,
                                            cruise)
        else:
            prof, ramp_time = velocity_move(start.position, start.velocity, traj.velocity, traj.acceleration,
                                            traj.jerk_percent, cruise)
        prof = _wait(start.position, delay) + prof
        _check_finite(prof, start.axis)
        end = prof[-1].end_state() if prof else (start.position, 0.0, 0.0)
        hold, outputs = _holds_and_outputs(params, int(attrs), i)
        plans.append(AxisPlan(
            axis=start.axis, source=Listed(prof, traj), start_position=start.position, target=end[0],
            final_velocity=0.0, hold=hold, outputs=outputs, truncated=traj.velocity != 0.0,
            velocity_target=traj.velocity, ramp_end=delay + ramp_time,
            start_velocity=start.velocity, start_acceleration=start.acceleration,
        ))
    return plans
