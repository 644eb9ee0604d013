"""Compile a validated start/modify request into a Move: per-axis frames.

Multi-axis rules (spec 000 MPIMotionAttrMask remarks, MPIMotionSCurve):
- without SYNC_START/SYNC_END the first trajectory is the vector's: the axes move on a
  straight line with one profile along it;
- with SYNC_START/SYNC_END each axis uses its own trajectory; SYNC_END inserts wait
  frames before the shorter profiles so all end together, SYNC_START adds delay frames
  after them;
- DELAY inserts a wait frame of delay[i] seconds before axis i's profile.
Quirks kept from the firmware (spec 000 mpiMotionStart): a frame may not last more than
16,384,000 samples (the axis stops abruptly there), and the fraction of a RELATIVE
distance is truncated. Both are reported through ``notes``.

Decision (the spec is silent): a vector modify whose current velocity is not along the new
line cannot stay on one line; the vector first comes to rest along its current line, then
moves on a straight line to the new targets (docs/decisions.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from operator import attrgetter

from . import cams
from .events import MPIEventType
from .frames import AxisPlan, Move, Stream
from .messages import Message
from .outcome import Refused
from .params import ID_BITS, VELOCITY_FRAME_LIMIT_SAMPLES, AxisMaster, MotionParams, Trajectory
from .paths import STREAMED_TYPES, PathStart, compile_path
from .profiles.jerk import point_to_point_jerk, velocity_change, velocity_jerk
from .profiles.point_to_point import point_to_point, reverses, velocity_move
from .profiles.ramps import ProfileError, ramps_between
from .profiles.scurve import reshape
from .profiles.segment import Segment, chain, scaled_profile, segment_values
from .types import CAM_TYPES, HOLD_ATTRS, MotionAttr, MPIMotionType

A = MotionAttr
# The attributes planning tests, as plain ints: IntFlag's `in` and `&` run Python code (0.2 to
# 1 us each, a dozen per move), an int's & does not.
_RELATIVE, _FINAL_VEL, _NO_REVERSAL, _DELAY, _OUTPUT, _ID, _ELEMENT_ID, _EVENT = map(
    int, (A.RELATIVE, A.FINAL_VEL, A.NO_REVERSAL, A.DELAY, A.OUTPUT, A.ID, A.ELEMENT_ID, A.EVENT))
_SYNC, _HOLDS = int(A.SYNC_START | A.SYNC_END), int(HOLD_ATTRS)
_duration_of = attrgetter("duration")


@dataclass(slots=True)
class AxisStart:
    """Where an axis' new profile starts: raw position and velocity in profile time."""

    axis: int
    position: float
    velocity: float = 0.0
    origin: float = 0.0
    acceleration: float = 0.0  # used by the jerk types only (they plan from the full state)


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


def _targets(params: MotionParams, attrs: MotionAttr, starts: list[AxisStart], notes: PlanNotes) -> list[float]:
    """Raw target positions; RELATIVE distances lose their fraction (firmware quirk)."""
    targets = []
    relative = int(attrs) & _RELATIVE
    for start, value in zip(starts, params.position, strict=True):
        if relative:
            distance = float(math.trunc(value))
            if distance != value:
                notes.events.append(
                    (MPIEventType.RELATIVE_TRUNCATED,
                     f"axis {start.axis}: relative distance {value!r} truncated to {distance:g}")
                )
            targets.append(start.position + distance)
        else:
            targets.append(value + start.origin)
    return targets


def _check_finite(segments: list[Segment], axis: int) -> None:
    """A profile that overflowed (absurd distances or limits) cannot be calculated."""
    for d, p, v, a, j in map(segment_values, segments):
        # x - x is 0 for a finite x, NaN for an infinite or NaN one: one comparison for all five
        if not (d >= 0.0 and (d - d) + (p - p) + (v - v) + (a - a) + (j - j) == 0.0):
            raise ProfileError(f"axis {axis}: the profile cannot be calculated with these values (overflow)")


def _check_lands(segments: list[Segment], start: AxisStart, target: float) -> None:
    """The frames must end on the target: the executor snaps the command onto it when the
    trajectory completes, which must never be a jump (guards against overflow and any
    planning fault). Rounding grows with the positions and the distance travelled."""
    end = segments[-1].end_state()[0] if segments else start.position
    scale = max(1.0, abs(target), abs(start.position))
    if math.isfinite(end) and abs(end - target) <= 1e-9 * scale:
        return  # on target without the travel, which can only widen the tolerance
    # each segment's end velocity as Segment.state_at computes it, without a call per segment
    travel = sum([max(abs(v), abs(v + t * (a + t * j / 2.0))) * t for t, _, v, a, j in map(segment_values, segments)])
    scale = max(scale, travel)
    if not math.isfinite(end) or abs(end - target) > 1e-9 * scale:
        raise ProfileError(f"axis {start.axis}: the profile cannot be calculated with these values")


def _cap_frames(segments: list[Segment], sample_rate: float, axis: int, notes: PlanNotes) -> tuple[list[Segment], bool]:
    """Cut the plan at the first frame longer than 16,384,000 samples."""
    _check_finite(segments, axis)
    limit = VELOCITY_FRAME_LIMIT_SAMPLES / sample_rate
    if not segments or max(map(_duration_of, segments)) <= limit:  # (finite: checked) the usual case
        return segments, False
    for i, seg in enumerate(segments):
        if seg.duration > limit:
            notes.events.append(
                (MPIEventType.FRAME_TIME_LIMIT,
                 f"axis {axis}: a frame of {seg.duration:.1f} s exceeds {VELOCITY_FRAME_LIMIT_SAMPLES} samples;"
                 " the axis will stop abruptly after it")
            )
            cut = Segment(limit, seg.p, seg.v, seg.a, seg.j)
            return segments[:i] + [cut], True
    return segments, False


def _wait(position: float, duration: float) -> list[Segment]:
    return [Segment(duration, position, 0.0, 0.0, 0.0)] if duration > 0.0 else []


def _scalar_profile(motion_type: MPIMotionType, start: AxisStart, target: float, v_final: float, traj: Trajectory):
    if motion_type is MPIMotionType.S_CURVE_JERK:
        return point_to_point_jerk(
            start.position, start.velocity, start.acceleration, target, v_final, traj.velocity,
            (traj.acceleration, traj.acceleration_jerk), (traj.deceleration, traj.deceleration_jerk))
    jerk_percent = traj.jerk_percent if motion_type is MPIMotionType.S_CURVE else 0.0
    return point_to_point(
        start.position, start.velocity, target, v_final,
        traj.velocity, traj.acceleration, traj.deceleration, jerk_percent,
    )


def _scaled(traj: Trajectory, share: float) -> Trajectory:
    """An axis' share of the vector's limits (jerk percent is a ratio and stays)."""
    return Trajectory(traj.velocity * share, traj.acceleration * share, traj.deceleration * share,
                      traj.jerk_percent, traj.acceleration_jerk * share, traj.deceleration_jerk * share)


def _dot(a, b) -> float:
    """The exactly rounded dot product (math.fsum of the products)."""
    if len(a) == 2:
        # Two products: their sum is already exactly rounded, as fsum's is. fsum answers +0.0 for
        # a zero sum (hence + 0.0) and raises for inf - inf or an overflow (hence fsum there).
        total = a[0] * b[0] + a[1] * b[1]
        if math.isfinite(total):
            return total + 0.0
    return math.fsum([x * y for x, y in zip(a, b, strict=True)])


def _along(vector, unit, scale: float) -> tuple[float, bool]:
    """The component of ``vector`` along ``unit``, and whether ``vector`` lies on that line."""
    if not any(vector):  # at rest (or no final velocity): what the calculation gives, without it
        return 0.0, True
    along = _dot(vector, unit)
    tolerance = 1e-9 * (1.0 + scale)
    for x, u in zip(vector, unit, strict=True):
        if not abs(x - along * u) <= tolerance + 1e-9 * abs(x):
            return along, False
    return along, True


def _vector_profiles(motion_type, starts, targets, finals, traj) -> tuple[list[list[Segment]], list[Trajectory], str]:
    """One profile along the straight line from the start to the targets, each axis'
    effective limits (the vector's scaled by the axis' share of the line), and why the
    profiles are not one profile per axis ("" when they are). Plain floats: a vector has at
    most MEIXmpMAX_COORD_AXES components, too few for numpy to pay off."""
    p0 = [s.position for s in starts]
    v0 = [s.velocity for s in starts]
    delta = [t - p for t, p in zip(targets, p0, strict=True)]
    length = math.hypot(*delta)  # no overflow for large components, unlike a sum of squares
    speed = math.hypot(*v0)
    if not (math.isfinite(length) and math.isfinite(speed)):
        raise ProfileError("the move's length cannot be calculated (overflow)")
    if length > 0.0:
        unit = [d / length for d in delta]
    elif speed > 0.0:
        unit = [v / speed for v in v0]
    else:
        return [[] for _ in starts], [traj for _ in starts], ""
    along, parallel = _along(v0, unit, speed)
    final_along, final_parallel = _along(finals, unit, math.hypot(*finals))
    if not final_parallel:
        raise Refused(Message.MPIMessagePARAM_INVALID, "final velocities of a vector move must lie along the move")
    if not parallel:
        return _stop_then_line(motion_type, starts, p0, v0, speed, targets, finals, traj)
    accels = [s.acceleration for s in starts]
    accel = _dot(accels, unit) if any(accels) else 0.0  # (a dot product of zeros is +0.0)
    line = _scalar_profile(motion_type, AxisStart(-1, 0.0, along, 0.0, accel), length, final_along, traj)
    profiles = [scaled_profile(line, u, p) for u, p in zip(unit, p0, strict=True)]
    return profiles, [_scaled(traj, abs(u)) for u in unit], ""


STOP_THEN_LINE = "vector modify off its line: the vector stops along its line, then moves on a new one"


def _stop_then_line(motion_type, starts, p0, v0, speed, targets, finals, traj):
    """A vector modify off the current line: the vector first comes to rest along the line it
    is on (decelerating as the trajectory says), then moves on a straight line to the new
    targets. Both parts are single vector profiles, so the vector's limits hold throughout
    (docs/decisions.md)."""
    heading = [v / speed for v in v0]
    stop = _stop_profile(motion_type, speed, traj)
    stopped_after = stop[-1].end_state()[0] if stop else 0.0
    rest = [p + h * stopped_after for p, h in zip(p0, heading, strict=True)]
    go_starts = [AxisStart(s.axis, p, 0.0, s.origin) for s, p in zip(starts, rest, strict=True)]
    go, limits, _ = _vector_profiles(motion_type, go_starts, targets, finals, traj)
    profiles = [scaled_profile(stop, h, p) + tail for h, p, tail in zip(heading, p0, go, strict=True)]
    limits = [_scaled(traj, max(abs(h), lim.velocity / traj.velocity)) for h, lim in zip(heading, limits, strict=True)]
    return profiles, limits, STOP_THEN_LINE


def _stop_profile(motion_type: MPIMotionType, speed: float, traj: Trajectory) -> list[Segment]:
    """1-D: from ``speed`` to rest with the trajectory's deceleration (and its jerk)."""
    if motion_type is MPIMotionType.S_CURVE_JERK:
        return chain(0.0, speed, 0.0, velocity_change(speed, 0.0, 0.0, traj.deceleration, traj.deceleration_jerk))
    jerk_percent = traj.jerk_percent if motion_type is MPIMotionType.S_CURVE else 0.0
    return reshape(ramps_between(speed, 0.0, traj.acceleration, traj.deceleration), 0.0, jerk_percent)


def _sync(profiles: list[list[Segment]], starts: list[AxisStart], targets: list[float], attrs: MotionAttr):
    durations = [sum(s.duration for s in prof) for prof in profiles]
    longest = max(durations, default=0.0)
    out = []
    for prof, start, target, duration in zip(profiles, starts, targets, durations, strict=True):
        pad = longest - duration
        if A.SYNC_END in attrs and start.velocity == 0.0:
            prof = _wait(start.position, pad) + prof
        elif A.SYNC_START in attrs:
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
    cam_masters: list[tuple[AxisMaster, float]] | None = None,
) -> tuple[Move, PlanNotes]:
    """The frames of a request for the axes ``starts`` (in the supervisor's order).

    Raises Refused with the spec's message when the profile cannot be made. A profile
    that starts while its axes move cannot wait first: a non-zero DELAY is
    MPIMotionMessageILLEGAL_DELAY (spec 000, for a modify in motion) and a HOLD
    MPIMotionMessageATTRIBUTE_INVALID (spec 000: HOLD is not permitted in modifies); either
    would stop the axes dead. A cam (``cam_masters``: each slave's master and its position
    now) is planned by cams.py.
    """
    notes = PlanNotes()
    moving = any(s.velocity != 0.0 for s in starts)
    if int(attrs) & _DELAY and moving and any(d != 0.0 for d in params.delay):
        raise Refused(Message.MPIMotionMessageILLEGAL_DELAY, "a move that starts in motion cannot be delayed")
    if int(attrs) & _HOLDS and moving:
        raise Refused(Message.MPIMotionMessageATTRIBUTE_INVALID, "a move that starts in motion cannot be held")
    stream = None
    try:
        if motion_type in CAM_TYPES:
            assert cam_masters is not None  # (the supervisor reads each slave's master)
            plans = cams.cam_plans(motion_type, attrs, params, starts, cam_masters)
        elif motion_type in STREAMED_TYPES:
            plans, stream = _path_plans(motion_type, params, attrs, starts)
        elif motion_type in (MPIMotionType.VELOCITY, MPIMotionType.VELOCITY_JERK):
            plans = _velocity_plans(motion_type, params, attrs, starts, sample_rate, notes)
        else:
            plans = _point_to_point_plans(motion_type, params, attrs, starts, sample_rate, notes)
    except ProfileError as exc:
        raise Refused(Message.MPIMotionMessagePROFILE_ERROR, str(exc)) from exc
    move = Move(
        supervisor=supervisor,
        type=motion_type,
        attributes=attrs,
        plans=plans,
        id=_truncate_id(params.id, notes) if int(attrs) & _ID else 0,
        element_id=int(params.element_id[0]) if int(attrs) & _ELEMENT_ID and params.element_id else 0,
        event_mask=params.event_mask if int(attrs) & _EVENT else MPIEventType.NONE,
        stream=stream,
    )
    return move, notes


def path_starts(starts: list[AxisStart]) -> list[PathStart]:
    return [PathStart(s.axis, s.position, s.velocity, s.origin) for s in starts]


def _path_plans(motion_type, params, attrs, starts) -> tuple[list[AxisPlan], Stream]:
    """A path's plans (paths.py) and its streaming state; the frame buffer's low count is
    the supervisor's to set (it knows the buffer's size)."""
    relative = bool(attrs & (A.RELATIVE | A.RELATIVE_MOVE))
    plans, peaks = compile_path(motion_type, attrs, params, path_starts(starts), relative)
    for plan in plans:
        _check_finite(plan.segments, plan.axis)
    return plans, Stream(open=not params.final, empty_count=params.empty_count, low_count=0, peaks=peaks)


def _holds_and_outputs(params: MotionParams, attrs: MotionAttr, index: int):
    bits = int(attrs)
    hold = params.hold[index] if bits & _HOLDS else None
    outputs = list(params.output) if bits & _OUTPUT and index == 0 else []
    return hold, outputs


def _point_to_point_plans(motion_type, params, attrs, starts, sample_rate, notes) -> list[AxisPlan]:
    bits = int(attrs)
    targets = _targets(params, attrs, starts, notes)
    finals = list(params.final_velocity) if bits & _FINAL_VEL else [0.0] * len(starts)
    composite = ""
    if bits & _SYNC:
        profiles = [
            _scalar_profile(motion_type, start, target, final, traj)
            for start, target, final, traj in zip(starts, targets, finals, params.trajectory, strict=True)
        ]
        profiles = _sync(profiles, starts, targets, attrs)
        limits = list(params.trajectory)
    elif len(starts) == 1:
        profiles = [_scalar_profile(motion_type, starts[0], targets[0], finals[0], params.trajectory[0])]
        limits = [params.trajectory[0]]
    else:
        profiles, limits, composite = _vector_profiles(motion_type, starts, targets, finals, params.trajectory[0])
    plans = []
    for i, (start, target, final, prof) in enumerate(zip(starts, targets, finals, profiles, strict=True)):
        if bits & _NO_REVERSAL and reverses(prof, start.velocity):
            raise Refused(Message.MPIMotionMessagePROFILE_ERROR,
                            f"axis {start.axis}: NO_REVERSAL, but the target is behind the motion")
        if bits & _DELAY:
            prof = _wait(start.position, params.delay[i]) + prof
        _check_lands(prof, start, target)
        prof, truncated = _cap_frames(prof, sample_rate, start.axis, notes)
        hold, outputs = _holds_and_outputs(params, attrs, i)
        plans.append(AxisPlan(
            axis=start.axis, segments=prof, start_position=start.position,
            target=prof[-1].end_state()[0] if truncated else target,  # truncated: where the cut plan ends
            final_velocity=0.0 if truncated else final,
            hold=hold, outputs=outputs, truncated=truncated,
            limits=limits[i], start_velocity=start.velocity, start_acceleration=start.acceleration,
            composite=composite,
        ))
    return plans


def _velocity_plans(motion_type, params, attrs, starts, sample_rate, notes) -> list[AxisPlan]:
    limit = VELOCITY_FRAME_LIMIT_SAMPLES / sample_rate
    trajs = params.trajectory if len(params.trajectory) == len(starts) else params.trajectory * len(starts)
    plans = []
    for i, (start, traj) in enumerate(zip(starts, trajs, strict=True)):
        delay = params.delay[i] if A.DELAY in attrs else 0.0
        cruise = limit if traj.velocity != 0.0 else 0.0
        if motion_type is MPIMotionType.VELOCITY_JERK:
            prof, ramp_time = velocity_jerk(start.position, start.velocity, start.acceleration, traj.velocity,
                                            traj.acceleration, traj.acceleration_jerk, traj.deceleration_jerk,
                                            cruise)
        else:
            prof, ramp_time = velocity_move(start.position, start.velocity, traj.velocity, traj.acceleration,
                                            traj.jerk_percent, cruise)
        prof = _wait(start.position, delay) + prof
        _check_finite(prof, start.axis)
        end = prof[-1].end_state() if prof else (start.position, 0.0, 0.0)
        hold, outputs = _holds_and_outputs(params, attrs, i)
        plans.append(AxisPlan(
            axis=start.axis, segments=prof, start_position=start.position, target=end[0],
            final_velocity=0.0, hold=hold, outputs=outputs, truncated=traj.velocity != 0.0,
            velocity_target=traj.velocity, ramp_end=delay + ramp_time,
            limits=traj, start_velocity=start.velocity, start_acceleration=start.acceleration,
        ))
    return plans
