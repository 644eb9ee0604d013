"""Cross-check one axis' plan (or a 1-D request) against ruckig.

:func:`check_plan` takes an :class:`~mpi_ros.mpi.planning.frames.AxisPlan` as the controller compiled
it (its ``limits`` are the Trajectory the axis' profile was planned with: for a vector move
the vector's limits scaled by the axis' share) and answers a
:class:`~mpi_ros.crosscheck.result.CrossCheck`:

1. the motion part of the profile (DELAY/SYNC waits stripped; for VELOCITY the ramp, its
   cruise checked separately) must respect every limit (limits.py);
2. the request maps to a ruckig problem (mapping.py) — exact where the models coincide,
   otherwise a bound the controller's profile satisfies;
3. exact: durations agree to DURATION_RTOL relative, the final position and velocity and the
   sampled states (sampling.py) to STATE_RTOL of their scales plus each state's derivative x
   TIME_RESOLUTION x duration (switching times are doubles); the acceleration right at the
   end is where a trapezoid steps to zero, so it is compared by the samples inside the last
   interval, not at the end point; bound: the controller is never faster than ruckig
   (BOUND_RTOL) and reaches the same final position and velocity.

Scales (what STATE_RTOL and LIMIT_RTOL are relative to): velocity max(V, |v0|, |vf|),
acceleration the largest allowed peak, position the larger of the distance and velocity
scale x duration, and never below 1e-6 of the largest |position| (float positions far from
zero carry that much rounding).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

from mpi_ros.mpi.base.types import MPIMotionType
from mpi_ros.mpi.planning.frames import AxisPlan, Listed
from mpi_ros.mpi.planning.profiles.segment import Segment

from .limits import BlendLimits, check_blend, check_profile, strip_waits
from .mapping import INF, Mapping, map_point_to_point, map_velocity, peak_acceleration
from .request import ProfileRequest
from .request import motion_type as parse_type
from .result import (
    BOUND_RTOL,
    DURATION_RTOL,
    STATE_RTOL,
    TIME_RESOLUTION,
    CrossCheck,
    Reason,
    RuckigLimits,
    StateDifference,
    Verdict,
)
from .sampling import end_state, max_difference
from .solver import RuckigFailed, solve

POSITION_FLOOR = 1e-6  # of the largest |position|: float rounding of absolute positions


def check_request(request: ProfileRequest | dict | str, sample_rate: float = 2000.0) -> CrossCheck:
    """Plan a 1-D request with the controller's planner and check the plan."""
    if isinstance(request, str):
        request = ProfileRequest.parse(request)
    elif isinstance(request, dict):
        request = ProfileRequest.from_mapping(request)
    return check_plan(request.plan(sample_rate), request.type)


def _split_velocity(segments: Sequence[Segment]) -> tuple[list[Segment], list[Segment]]:
    """(ramp, cruise) of a VELOCITY profile: the cruise is the trailing a = j = 0 part."""
    ramp = list(segments)
    cruise: list[Segment] = []
    while ramp and ramp[-1].a == 0.0 and ramp[-1].j == 0.0:
        cruise.insert(0, ramp.pop())
    return ramp, cruise


def check_plan(plan: AxisPlan, motion_type: MPIMotionType | str, axis: int | None = None) -> CrossCheck:
    """Check ``plan`` (one axis of a TRAPEZOIDAL, S_CURVE or VELOCITY move) against ruckig."""
    kind = parse_type(motion_type)
    traj = plan.limits
    if traj is None:
        raise ValueError("the plan does not record its limits")
    axis = plan.axis if axis is None else axis
    jerk_percent = traj.jerk_percent if kind is not MPIMotionType.TRAPEZOIDAL else 0.0
    f = jerk_percent / 100.0
    velocity_type = kind is MPIMotionType.VELOCITY
    leading = 0.0
    for seg in plan.segments:
        if seg.v == 0.0 and seg.a == 0.0 and seg.j == 0.0:
            leading += seg.duration
        else:
            break
    motion = strip_waits(plan.segments)
    p0, v0, a0 = plan.start_position, plan.start_velocity, plan.start_acceleration
    problems: list[str] = []

    if velocity_type:
        v_cmd = plan.velocity_target if plan.velocity_target is not None else traj.velocity
        ramp, cruise = _split_velocity(motion)
        mapping = map_velocity(p0, v0, a0, v_cmd, traj.acceleration, jerk_percent)
        speed = max(abs(v0), abs(v_cmd))
        acc_scale = peak_acceleration(traj.acceleration, f)
        target = None
        compared = ramp
        checked = motion
        limit_v, accel, decel, final_v = v_cmd, traj.acceleration, traj.acceleration, v_cmd
    else:
        if plan.truncated:
            return CrossCheck(kind.name, axis, Verdict.DIFFER_EXPLAINED, False, _duration(motion), None,
                              (Reason.TRUNCATED,), ("not compared: the profile was cut at the frame limit",))
        if plan.blended_from is not None:
            return _check_blended(plan, kind, axis)
        if plan.composite:
            return CrossCheck(kind.name, axis, Verdict.DIFFER_EXPLAINED, False, _duration(motion), None,
                              (Reason.COMPOSITE,), (f"not compared: {plan.composite}",))
        mapping = map_point_to_point(p0, v0, a0, plan.target, plan.final_velocity, traj.velocity,
                                     traj.acceleration, traj.deceleration, jerk_percent)
        speed = max(traj.velocity, abs(v0), abs(plan.final_velocity))
        acc_scale = peak_acceleration(max(traj.acceleration, traj.deceleration), f)
        target = plan.target
        compared = checked = motion
        limit_v, accel, decel, final_v = traj.velocity, traj.acceleration, traj.deceleration, plan.final_velocity

    duration = _duration(compared)
    extent = max([abs(p0)] + [abs(s.p) for s in motion] + [abs(target or 0.0)])
    span = abs(target - p0) if target is not None else 0.0
    scales = StateDifference(max(span, speed * duration, POSITION_FLOOR * extent), speed, acc_scale)
    problems += check_profile(
        checked, velocity_type=velocity_type, start_position=p0, start_velocity=v0, target=target,
        final_velocity=final_v, velocity=limit_v, acceleration=accel, deceleration=decel,
        jerk_percent=jerk_percent, scales=scales)
    if velocity_type:
        expected_end = leading + duration
        if abs(plan.ramp_end - expected_end) > STATE_RTOL * max(expected_end, 1.0):
            problems.append(f"ramp_end {plan.ramp_end!r} s, but the ramp ends at {expected_end!r} s")
        for seg in cruise:
            if abs(seg.v - v_cmd) > STATE_RTOL * speed:
                problems.append(f"cruises at {seg.v!r}, not at the commanded {v_cmd!r}")
                break

    mapping = mapping.with_jerk(_bound_jerk(compared, duration))  # a bound's max_jerk (if it needs one)
    return _compare(kind, axis, mapping, compared, duration, scales, problems, (p0, v0, 0.0), a0)


def _check_blended(plan: AxisPlan, kind: MPIMotionType, axis: int) -> CrossCheck:
    """A blended corner (planning/blend.py): the appended move's own profile is checked as
    any plan (limits and ruckig); the blend, that profile plus the rest of the move before,
    against the limits the reference gives a blend (limits.check_blend)."""
    parts = plan.blended_from
    assert parts is not None and plan.limits is not None  # (check_plan's caller: a blended plan)
    alone = replace(plan, source=Listed(list(parts.own), plan.limits), composite="", blended_from=None)
    own = check_plan(alone, kind, axis)
    own_f = plan.limits.jerk_percent / 100.0 if kind is not MPIMotionType.TRAPEZOIDAL else 0.0
    before = parts.tail_limits or plan.limits  # (a move before without recorded limits: the same)
    tail_f = before.jerk_percent / 100.0 if any(s.j != 0.0 for s in parts.tail) else 0.0
    limits = BlendLimits(plan.limits.velocity, peak_acceleration(max(plan.limits.acceleration,
                                                                     plan.limits.deceleration), own_f),
                         before.velocity, peak_acceleration(before.deceleration, tail_f))
    scales = StateDifference(max(own.scales.position, POSITION_FLOOR * abs(plan.target)),
                             max(own.scales.velocity, limits.tail_velocity),
                             max(own.scales.acceleration, limits.tail_peak))
    problems = check_blend(plan.segments, parts.own, parts.tail, limits, scales)
    verdict = Verdict.DISAGREE if problems or own.verdict is Verdict.DISAGREE else Verdict.DIFFER_EXPLAINED
    return replace(own, verdict=verdict, reasons=(*own.reasons, Reason.BLENDED), problems=(*own.problems, *problems),
                   controller_duration=_duration(plan.segments))


def _bound_jerk(segments: Sequence[Segment], duration: float) -> float:
    """The largest jerk of the profile, or inf if a jerk phase is shorter than the time
    resolution (indistinguishable from a step; ruckig mishandles jerks like 1e279)."""
    phases = [s for s in segments if s.j != 0.0]
    if not phases or min(s.duration for s in phases) < TIME_RESOLUTION * duration:
        return INF
    return max(abs(s.j) for s in phases)


def _duration(segments: Sequence[Segment]) -> float:
    return float(sum(s.duration for s in segments))


def _tolerance(scales: StateDifference, duration: float, segments: Sequence[Segment]) -> StateDifference:
    """STATE_RTOL of the scales, plus each state's derivative x the time resolution."""
    dt = TIME_RESOLUTION * duration
    jerk = max((abs(s.j) for s in segments), default=0.0)
    return StateDifference(STATE_RTOL * scales.position + scales.velocity * dt,
                           STATE_RTOL * scales.velocity + scales.acceleration * dt,
                           STATE_RTOL * scales.acceleration + jerk * dt)


def _compare(kind, axis, mapping: Mapping, compared, duration, scales, problems, start, a0) -> CrossCheck:
    reasons = mapping.reasons
    tol = _tolerance(scales, duration, compared)
    limits = mapping.limits
    if limits is None:  # nothing to do for ruckig either
        if compared:
            problems.append(f"nothing should move, but the profile lasts {duration!r} s")
        return _result(kind, axis, mapping, duration, 0.0, problems, scales=scales, tol=tol)
    try:
        reference = solve(limits)
    except RuckigFailed as exc:
        if mapping.exact or not math.isfinite(limits.max_jerk):
            problems.append(f"ruckig failed: {exc}")
            return _result(kind, axis, mapping, duration, None, problems, scales=scales, tol=tol)
        # A bound stays a bound with unlimited jerk (a weaker one): ruckig failed on the jerk.
        mapping = mapping.unlimited_jerk(f"ruckig failed with max_jerk {limits.max_jerk:.6g} ({exc}); "
                                         "bound with unlimited jerk")
        assert mapping.limits is not None  # the same problem, with unlimited jerk
        limits = mapping.limits
        try:
            reference = solve(limits)
        except RuckigFailed as exc2:
            problems.append(f"ruckig failed: {exc2}")
            return _result(kind, axis, mapping, duration, None, problems, scales=scales, tol=tol)
    full_state = _full_state_duration(limits, a0) if Reason.ACCELERATION_STEP in reasons else None
    ours = end_state(compared, start)
    theirs = end_state(reference.segments, (limits.current_position, limits.current_velocity, 0.0))
    final = StateDifference(abs(ours[0] - theirs[0]), abs(ours[1] - theirs[1]), abs(ours[2] - theirs[2]))
    window = tol.velocity / scales.acceleration if scales.acceleration > 0.0 else 0.0
    sampled = max_difference(compared, reference.segments, window)
    if mapping.exact:
        scale = max(duration, reference.duration)
        if scale > 0.0 and abs(duration - reference.duration) > DURATION_RTOL * scale:
            problems.append(f"duration {duration!r} s differs from ruckig's {reference.duration!r} s "
                            f"by more than {DURATION_RTOL:g} relative")
        if final.position > tol.position or final.velocity > tol.velocity:
            problems.append(f"final state differs from ruckig's by {_fmt(final)} (tolerance {_fmt(tol)})")
        if not sampled.within(tol):
            problems.append(f"sampled states differ from ruckig's by up to {_fmt(sampled)} (tolerance {_fmt(tol)})")
    else:
        if duration < reference.duration * (1.0 - BOUND_RTOL):
            problems.append(f"faster than ruckig's time-optimal profile: {duration!r} s < {reference.duration!r} s")
        if final.position > tol.position or final.velocity > tol.velocity:
            problems.append(f"final position/velocity differ from ruckig's by {_fmt(final)} (tolerance {_fmt(tol)})")
    return _result(kind, axis, mapping, duration, reference.duration, problems, final, sampled, scales, full_state,
                   tol)


def _full_state_duration(limits: RuckigLimits, a0: float) -> float | None:
    """ruckig's duration from the full state (p, v, a0): information for ACCELERATION_STEP."""
    values = {name: getattr(limits, name) for name in RuckigLimits.__slots__}
    values["current_acceleration"] = a0
    if not math.isfinite(values["max_jerk"]):
        return None  # a0 means nothing to a trapezoid (infinite jerk)
    try:
        return solve(RuckigLimits(**values)).duration
    except RuckigFailed:
        return None


def _fmt(d: StateDifference) -> str:
    return f"p {d.position:.3g}, v {d.velocity:.3g}, a {d.acceleration:.3g}"


def _result(kind, axis, mapping: Mapping, duration, ruckig_duration, problems, final=None, sampled=None,
            scales=None, full_state=None, tol=None) -> CrossCheck:
    if problems:
        verdict = Verdict.DISAGREE
    elif mapping.reasons:
        verdict = Verdict.DIFFER_EXPLAINED
    else:
        verdict = Verdict.AGREE
    return CrossCheck(
        motion_type=kind.name, axis=axis, verdict=verdict, exact=mapping.exact,
        controller_duration=duration, ruckig_duration=ruckig_duration, reasons=mapping.reasons,
        notes=mapping.notes, problems=tuple(problems), final_difference=final or StateDifference(),
        max_difference=sampled or StateDifference(), scales=scales or StateDifference(),
        tolerance=tol or StateDifference(), ruckig=mapping.limits,
        ruckig_full_state_duration=full_state)
