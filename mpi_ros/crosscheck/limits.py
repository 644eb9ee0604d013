"""Does the controller's profile respect every limit of its request?

Checked on the profile's constant-jerk segments, independently of how the controller
planned them (docs/quality.md, "Correct motion": |v| <= velocity, |a| <= acceleration /
deceleration, jerk as configured; docs/profiles.md, "The trapezoid and the S-curve" for the
S-curve's shape):

* the profile is continuous in position and velocity, starts at the plan's start position
  and velocity (with zero acceleration when f > 0: checked per ramp below; a trapezoid steps),
  and (point to point) ends at the target and final velocity;
* |v| never exceeds the velocity limit (nor a higher start velocity, which may only come
  down), and the velocity changes sign only when the move must reverse
  (:func:`~mpi_ros.crosscheck.mapping.reverses`);
* the profile splits into cruises (a = 0, j = 0) and ramps (maximal runs between points of
  zero or discontinuous acceleration); every ramp's average acceleration is the acceleration
  (raising |v|) or the deceleration (lowering |v|; VELOCITY ramps always use the
  acceleration), its peak |a| is at most rate/(1-f/2), it spends the share f of its time
  with non-zero jerk, its jerk is at most 4 rate^2/(f(2-f)|dv|), and with f > 0 it starts and
  ends at zero acceleration (unless its jerk phases, f*Ta/2, are shorter than the time
  resolution: then a step is the same profile, as the controller plans it for a jerkPercent
  whose jerk would overflow).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mpi_ros.mpi.planning.profiles.segment import Segment

from .mapping import peak_acceleration, ramp_jerk, reverses
from .result import LIMIT_RTOL, STATE_RTOL, TIME_RESOLUTION, StateDifference
from .sampling import UNIFORM_SAMPLES, sample, switching_times


def strip_waits(segments: Sequence[Segment]) -> list[Segment]:
    """The motion part: leading/trailing segments with v = a = j = 0 are DELAY/SYNC waits."""
    out = list(segments)
    while out and _is_wait(out[0]):
        out.pop(0)
    while out and _is_wait(out[-1]):
        out.pop()
    return out


def _is_wait(seg: Segment) -> bool:
    return seg.v == 0.0 and seg.a == 0.0 and seg.j == 0.0


@dataclass(frozen=True, slots=True)
class RampShape:
    """One ramp of the profile (a run of segments between zero/discontinuous acceleration)."""

    segments: tuple[Segment, ...]
    v_start: float
    v_end: float
    a_start: float
    a_end: float

    @property
    def duration(self) -> float:
        return sum(s.duration for s in self.segments)

    @property
    def jerk_time(self) -> float:
        return sum(s.duration for s in self.segments if s.j != 0.0)

    @property
    def peak(self) -> float:
        return max(max(abs(s.a), abs(s.end_state()[2])) for s in self.segments)

    @property
    def max_jerk(self) -> float:
        return max(abs(s.j) for s in self.segments)


def split_ramps(segments: Sequence[Segment], acc_tol: float) -> tuple[list[RampShape], list[Segment]]:
    """(ramps, cruises) of a motion profile."""
    ramps: list[RampShape] = []
    cruises: list[Segment] = []
    current: list[Segment] = []

    def close() -> None:
        if current:
            first, last = current[0], current[-1]
            end = last.end_state()
            ramps.append(RampShape(tuple(current), first.v, end[1], first.a, end[2]))
            current.clear()

    for seg in segments:
        if abs(seg.a) <= acc_tol and seg.j == 0.0:
            close()
            cruises.append(seg)
            continue
        if current:
            prev_a = current[-1].end_state()[2]
            if abs(prev_a) <= acc_tol or abs(seg.a - prev_a) > acc_tol:
                close()
        current.append(seg)
    close()
    return ramps, cruises


def velocity_range(seg: Segment) -> tuple[float, float]:
    """(min, max) velocity over a segment (ends and the interior extremum)."""
    values = [seg.v, seg.end_state()[1]]
    if seg.j != 0.0:
        t = -seg.a / seg.j
        if 0.0 < t < seg.duration:
            values.append(seg.state_at(t)[1])
    return min(values), max(values)


def _expected_ramp_time(v1: float, v2: float, accel: float, decel: float, velocity_type: bool) -> float:
    if velocity_type:
        return abs(v2 - v1) / accel
    if v1 * v2 < 0.0:  # through zero: down at the deceleration, up at the acceleration
        return abs(v1) / decel + abs(v2) / accel
    return abs(v2 - v1) / (accel if abs(v2) > abs(v1) else decel)


def check_profile(  # noqa: C901 - one check per limit in a row; to be split by limit (issue 33)
    segments: Sequence[Segment],
    *,
    velocity_type: bool,
    start_position: float,
    start_velocity: float,
    target: float | None,
    final_velocity: float,
    velocity: float,
    acceleration: float,
    deceleration: float,
    jerk_percent: float,
    scales: StateDifference,
) -> list[str]:
    """Every limit the profile breaks, as sentences (empty: it respects them all).

    ``segments``: the motion part (waits stripped; for VELOCITY the ramp and its cruise).
    ``target``: the end position of a point-to-point move (None for VELOCITY).
    ``velocity``: the limit V (point to point) or the commanded velocity (VELOCITY).
    """
    problems: list[str] = []
    f = jerk_percent / 100.0
    p_tol = LIMIT_RTOL * scales.position
    v_tol = LIMIT_RTOL * scales.velocity
    a_tol = LIMIT_RTOL * scales.acceleration
    if not segments:
        moved = target is not None and (target != start_position or final_velocity != 0.0)
        if moved or (velocity_type and velocity != start_velocity):
            problems.append("the profile is empty but the move is not")
        return problems

    first = segments[0]
    if abs(first.p - start_position) > p_tol or abs(first.v - start_velocity) > v_tol:
        problems.append(f"starts at (p={first.p!r}, v={first.v!r}), not at (p={start_position!r}, "
                        f"v={start_velocity!r})")
    for k in range(1, len(segments)):
        p, v, _ = segments[k - 1].end_state()
        seg = segments[k]
        if abs(seg.p - p) > p_tol or abs(seg.v - v) > v_tol:
            problems.append(f"segment {k} jumps: p {p!r} -> {seg.p!r}, v {v!r} -> {seg.v!r}")
            break
    if any(s.duration < 0.0 for s in segments):
        problems.append("a segment has a negative duration")

    # Velocity: never above the limit (point to point), or outside v0..v (VELOCITY).
    if velocity_type:
        lo, hi = min(start_velocity, velocity), max(start_velocity, velocity)
        for k, seg in enumerate(segments):
            vmin, vmax = velocity_range(seg)
            if vmin < lo - v_tol or vmax > hi + v_tol:
                problems.append(f"segment {k}: velocity {vmin!r}..{vmax!r} leaves {lo!r}..{hi!r}")
                break
    else:
        ceiling = max(velocity, abs(start_velocity))
        for k, seg in enumerate(segments):
            vmin, vmax = velocity_range(seg)
            speed = max(abs(vmin), abs(vmax))
            v_end = abs(seg.end_state()[1])
            if speed > ceiling + v_tol or (v_end > velocity + v_tol and v_end > abs(seg.v) + v_tol):
                problems.append(f"segment {k}: |v| reaches {speed!r}, above the velocity {velocity!r}")
                break
        assert target is not None  # a point-to-point move has one
        lowest = min(velocity_range(s)[0] for s in segments)
        highest = max(velocity_range(s)[1] for s in segments)
        reversed_ = lowest < -v_tol and highest > v_tol
        should = reverses(target - start_position, start_velocity, final_velocity, acceleration, deceleration)
        if reversed_ != should:
            problems.append("the velocity changes sign although the move need not reverse" if reversed_
                            else "the move must reverse but the velocity never changes sign")

    # Ramps: rate, peak, jerk share and jerk.
    ramps, cruises = split_ramps(segments, a_tol)
    total = sum(s.duration for s in segments)
    for seg in cruises:
        if seg.a != 0.0 and abs(seg.a) > a_tol:
            problems.append(f"cruise with acceleration {seg.a!r}")
    for n, ramp in enumerate(ramps):
        v1, v2 = ramp.v_start, ramp.v_end
        dv = v2 - v1
        raising = abs(v2) > abs(v1)
        rate = acceleration if velocity_type or raising else deceleration
        crossing = v1 * v2 < 0.0 and not velocity_type
        peak_limit = peak_acceleration(max(acceleration, deceleration) if crossing else rate, f)
        expected = _expected_ramp_time(v1, v2, acceleration, deceleration, velocity_type)
        time_tol = LIMIT_RTOL * (ramp.duration + scales.velocity / min(acceleration, deceleration))
        name = f"ramp {n} ({v1:.9g} -> {v2:.9g})"
        if abs(ramp.duration - expected) > time_tol:
            problems.append(f"{name}: lasts {ramp.duration!r} s, its average rate gives {expected!r} s")
        if ramp.peak > peak_limit * (1.0 + LIMIT_RTOL):
            problems.append(f"{name}: |a| reaches {ramp.peak!r} > {peak_limit!r}")
        if f > 0.0:
            if abs(ramp.jerk_time - f * ramp.duration) > time_tol:
                problems.append(f"{name}: {ramp.jerk_time / ramp.duration:.12g} of its time with jerk, "
                                f"jerkPercent asks {f:.12g}")
            visible = 0.5 * f * ramp.duration >= TIME_RESOLUTION * total  # else a step is the same profile
            if visible and (abs(ramp.a_start) > a_tol or abs(ramp.a_end) > a_tol):
                problems.append(f"{name}: starts/ends at acceleration {ramp.a_start!r}/{ramp.a_end!r}, not 0")
            if not crossing:
                jerk_limit = ramp_jerk(rate, f, dv)
                if ramp.max_jerk > jerk_limit * (1.0 + LIMIT_RTOL) + 0.0:
                    problems.append(f"{name}: jerk {ramp.max_jerk!r} > {jerk_limit!r}")
        elif ramp.max_jerk != 0.0:
            problems.append(f"{name}: jerk {ramp.max_jerk!r} with jerkPercent 0")

    if target is not None:
        p, v, _ = segments[-1].end_state()
        if abs(p - target) > p_tol or abs(v - final_velocity) > v_tol:
            problems.append(f"ends at (p={p!r}, v={v!r}), not at (p={target!r}, v={final_velocity!r})")
    return problems


@dataclass(frozen=True, slots=True)
class BlendLimits:
    """What a blended corner's two profiles were planned with (crosscheck of a blend):
    each one's velocity limit and peak acceleration (rate/(1-f/2) of its jerk share)."""

    own_velocity: float
    own_peak: float
    tail_velocity: float
    tail_peak: float


def check_blend(blended: Sequence[Segment], own: Sequence[Segment], tail: Sequence[Segment],
                limits: BlendLimits, scales: StateDifference) -> list[str]:
    """Every limit a blended corner breaks (MEIMotionConfig.blendLimit, MPI 000).

    ``blended``: the profile the axis runs; ``own``: the appended move's profile alone (checked
    on its own by check_profile and ruckig); ``tail``: the rest of the move before it, less its
    target. The reference bounds a blend's acceleration by what the two moves allow together:
    "the acceleration resulting from the blending can exceed the acceleration limit specified
    in the motion parameters (180 degrees = acceleration*2.0)". So: the blend is the sum of the
    two profiles; the tail is a deceleration to rest within its own limits; the sum's |v| stays
    within the larger velocity limit and its |a| within the two peaks added (twice the limit at
    an about-face of equal moves)."""
    problems = _superposition(blended, own, tail, scales)
    v_tol = LIMIT_RTOL * scales.velocity
    a_tol = LIMIT_RTOL * scales.acceleration
    if tail:
        p, v, _ = tail[-1].end_state()
        if abs(p) > LIMIT_RTOL * scales.position or abs(v) > v_tol:
            problems.append(f"the move before does not end at rest on its target: {p!r} counts, {v!r} counts/s left")
        problems += _within(tail, "the move before", limits.tail_velocity, limits.tail_peak, v_tol, a_tol)
    ceiling = max(limits.own_velocity, limits.tail_velocity)
    problems += _within(blended, "the blend", ceiling, limits.own_peak + limits.tail_peak, v_tol, a_tol)
    return problems


def _within(segments: Sequence[Segment], name: str, velocity: float, peak: float, v_tol: float,
            a_tol: float) -> list[str]:
    """``segments``' |v| within ``velocity`` and |a| within ``peak`` (a is piecewise linear: ends suffice)."""
    problems = []
    speed = max(max(abs(lo), abs(hi)) for lo, hi in map(velocity_range, segments))
    if speed > velocity + v_tol:
        problems.append(f"{name}: |v| reaches {speed!r}, above the velocity {velocity!r}")
    reached = max(max(abs(s.a), abs(s.end_state()[2])) for s in segments)
    if reached > peak * (1.0 + LIMIT_RTOL) + a_tol:
        problems.append(f"{name}: |a| reaches {reached!r} > {peak!r}")
    return problems


def _superposition(blended: Sequence[Segment], own: Sequence[Segment], tail: Sequence[Segment],
                   scales: StateDifference) -> list[str]:
    """The blend is own(t) + tail(t) (the tail at rest on 0 after its end), sampled on a grid
    and inside every interval between the three profiles' switching times."""
    if not blended or not own:
        return ["a blended plan without a profile"]
    horizon = float(switching_times(blended)[-1])
    breaks = np.concatenate([switching_times(x) for x in (blended, own, tail) if x])
    edges = np.unique(np.concatenate(([0.0, horizon], breaks[(breaks > 0.0) & (breaks < horizon)])))
    inner = np.concatenate([edges[:-1] + q * np.diff(edges) for q in (0.25, 0.5, 0.75)])
    times = np.concatenate((np.linspace(0.0, horizon, UNIFORM_SAMPLES), inner))
    pb, vb, ab, _ = sample(blended, times)
    po, vo, ao = _held(own, times)
    pt, vt, at = _held(tail, times) if tail else (np.zeros_like(times),) * 3
    dt = TIME_RESOLUTION * horizon
    tol = (STATE_RTOL * scales.position + scales.velocity * dt, STATE_RTOL * scales.velocity + scales.acceleration * dt)
    worst = (float(np.max(np.abs(pb - po - pt))), float(np.max(np.abs(vb - vo - vt))))
    if worst[0] > tol[0] or worst[1] > tol[1]:
        return [f"the blend is not the sum of the two moves' profiles: off by {worst[0]:.3g} counts, "
                f"{worst[1]:.3g} counts/s"]
    inside = np.abs(ab - ao - at)[UNIFORM_SAMPLES:]
    if inside.size and float(inside.max()) > STATE_RTOL * scales.acceleration:
        return [f"the blend's acceleration is not the sum of the two moves': off by {float(inside.max()):.3g}"]
    return []


def _held(segments: Sequence[Segment], times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity and acceleration of a profile at ``times``; after its end it goes on at
    its end velocity with no acceleration (as the controller holds a plan's end state)."""
    end = float(switching_times(segments)[-1])
    p, v, a, _ = sample(segments, np.minimum(times, end))
    after = times > end
    return np.where(after, p + v * (times - end), p), v, np.where(after, 0.0, a)
