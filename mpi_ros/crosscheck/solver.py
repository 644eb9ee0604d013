"""Running ruckig on a :class:`~mpi_ros.crosscheck.result.RuckigLimits` problem.

ruckig's pitfalls (docs/profiles.md, "ruckig's pitfalls") are avoided: every limit is set
explicitly (ruckig's max_velocity defaults to 0 and max_jerk to infinity), lists have exactly
one element (lengths are not checked, an empty list crashes the process), intermediate
waypoints are never used, and ruckig's errors — it raises ``RuckigError`` rather than
returning a code — become :class:`RuckigFailed`. The result is ruckig's own profile as constant-jerk segments
(its brake pre-trajectory, then its seven phases), so both models are sampled alike.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mpi_ros.mpi.planning.profiles.segment import Segment

from .result import RuckigLimits


class RuckigFailed(RuntimeError):
    """ruckig refused the problem or found no profile."""


@dataclass(frozen=True, slots=True)
class RuckigProfile:
    duration: float
    segments: tuple[Segment, ...]


SANITY_RTOL = 1e-6  # ruckig's answer must reach the target at least this well to be used

# Units tried, as multiples of (length V^2/A, time V/A): the first makes the velocity and
# acceleration limits 1; the others are fallbacks for ruckig's occasional numerical failures.
UNITS = ((1.0, 1.0), (10.0, 1.0), (1.0, 10.0), (0.1, 1.0), (1.0, 0.1), (100.0, 10.0), (3.0, 1.0), (1.0, 3.0),
         (0.3, 1.0), (1.0, 0.3), (10.0, 10.0), (0.1, 0.1), (100.0, 1.0), (0.01, 1.0), (1.0, 100.0), (1.0, 0.01),
         (3.0, 3.0), (0.3, 0.3), (1000.0, 10.0), (10.0, 100.0))


def solve(limits: RuckigLimits) -> RuckigProfile:
    """ruckig's time-optimal profile for ``limits``.

    ruckig works with absolute tolerances, so problems of very different magnitudes (a
    1e-6 s jerk phase in a 1000 s move, positions near 1e6 counts) can fail inside it
    ("error in step 1"), come back suboptimal, or — when the distance is below its absolute
    position precision in the units used — answer "already there"; changing units is the
    remedy its author suggests (pantor/ruckig#71). The problem is therefore solved from
    position 0 in units where the velocity and acceleration limits are 1, then in units of
    the distance, then in a few others, until ruckig answers a profile that reaches the
    target (a sanity check, :data:`SANITY_RTOL`; the comparisons are check.py's). Every
    attempt is exactly the same problem; the answer is converted back.
    """
    speed = max(abs(limits.max_velocity), abs(limits.current_velocity), abs(limits.target_velocity))
    accel = max(abs(limits.max_acceleration), abs(limits.min_acceleration))
    if not (speed > 0.0 and accel > 0.0 and math.isfinite(speed) and math.isfinite(accel)):
        raise RuckigFailed(f"limits out of range: velocity {speed!r}, acceleration {accel!r}")
    distance = abs(limits.target_position - limits.current_position)
    units = [(f * speed * speed / accel, g * speed / accel) for f, g in UNITS]
    if distance > 0.0 and limits.control == "position":
        units.insert(1, (distance, distance / speed))
    failures = []
    for length, tau in units:
        try:
            profile = _solve_in_units(limits, length, tau)
        except RuckigFailed as exc:
            failures.append(str(exc))
            continue
        wrong = _misses_target(limits, profile, speed, distance)
        if not wrong:
            return profile
        failures.append(wrong)
    raise RuckigFailed(failures[0])


def _misses_target(limits: RuckigLimits, profile: RuckigProfile, speed: float, distance: float) -> str:
    """A sanity check of ruckig's answer (not the comparison): does it get there at all?"""
    if profile.segments:
        p, v, _ = profile.segments[-1].end_state()
    else:
        p, v = limits.current_position, limits.current_velocity
    if abs(v - limits.target_velocity) > SANITY_RTOL * speed:
        return f"ruckig's profile ends at velocity {v!r}, not {limits.target_velocity!r}"
    if limits.control == "position" and abs(p - limits.target_position) > SANITY_RTOL * max(
            distance, speed * profile.duration):
        return f"ruckig's profile ends at {p!r}, not at the target {limits.target_position!r}"
    return ""


def _solve_in_units(limits: RuckigLimits, length: float, tau: float) -> RuckigProfile:
    from ruckig import ControlInterface, InputParameter, Result, Ruckig, RuckigError, Trajectory

    v_unit, a_unit, j_unit = length / tau, length / (tau * tau), length / (tau * tau * tau)
    inp = InputParameter(1)
    inp.control_interface = ControlInterface.Velocity if limits.control == "velocity" else ControlInterface.Position
    inp.current_position = [0.0]
    inp.current_velocity = [float(limits.current_velocity) / v_unit]
    inp.current_acceleration = [float(limits.current_acceleration) / a_unit]
    inp.target_position = [float(limits.target_position - limits.current_position) / length]
    inp.target_velocity = [float(limits.target_velocity) / v_unit]
    inp.target_acceleration = [0.0]
    inp.max_velocity = [float(limits.max_velocity) / v_unit]
    inp.max_acceleration = [float(limits.max_acceleration) / a_unit]
    inp.min_acceleration = [float(limits.min_acceleration) / a_unit]
    inp.max_jerk = [float(limits.max_jerk) / j_unit]
    trajectory = Trajectory(1)
    try:
        result = Ruckig(1).calculate(inp, trajectory)
    except RuckigError as exc:
        text = str(exc).strip()
        raise RuckigFailed(text.splitlines()[0] if text else "RuckigError") from exc
    if result not in (Result.Working, Result.Finished):
        raise RuckigFailed(f"ruckig answered {result}")
    scale = (tau, length, v_unit, a_unit, j_unit, float(limits.current_position))
    return RuckigProfile(float(trajectory.duration) * tau, tuple(_segments(trajectory, scale)))


def _segments(trajectory, scale) -> list[Segment]:
    tau, length, v_unit, a_unit, j_unit, p0 = scale
    profile = trajectory.profiles[0][0]
    pieces = []
    brake = profile.brake
    if brake.duration > 0.0:
        pieces += [(brake.t[i], brake.p[i], brake.v[i], brake.a[i], brake.j[i]) for i in range(2)]
    pieces += [(profile.t[i], profile.p[i], profile.v[i], profile.a[i], profile.j[i]) for i in range(7)]
    return [Segment(t * tau, p0 + p * length, v * v_unit, a * a_unit, _finite(j) * j_unit)
            for t, p, v, a, j in pieces if t > 0.0]


def _finite(jerk: float) -> float:
    if not math.isfinite(jerk):
        raise RuckigFailed(f"ruckig profile has a non-finite jerk phase ({jerk})")
    return float(jerk)
