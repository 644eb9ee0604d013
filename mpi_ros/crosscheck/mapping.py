"""How a controller request maps to a ruckig problem (a 1-DoF ``InputParameter``).

The controller's profiles (docs/profiles.md, "The trapezoid and the S-curve"): the trapezoid is built from velocity V,
acceleration A and deceleration D (a ramp raising |v| uses A, one lowering |v| uses D; A and
D are the ramps' *average* accelerations), then each ramp is reshaped keeping its duration Ta:
with f = jerkPercent/100 each jerk phase lasts f*Ta/2 and the peak acceleration is A/(1-f/2).
A ramp changing the velocity by dv at rate R therefore has jerk

    J = peak / (f*Ta/2) = 4 R^2 / (f (2-f) |dv|)        (infinite at f = 0: a trapezoid)

so its jerk depends on the ramp's own velocity change. ruckig (docs/profiles.md, "The cross-check
against ruckig") reproduces the profile exactly when every ramp shares one peak and one jerk, given

* ``max_velocity``      = V
* ``max_acceleration``  = A/(1-f/2), ``min_acceleration`` = -D/(1-f/2) for a move in the
  positive direction (the signs swap for a negative move: there the raising ramps
  accelerate negatively), ±A/(1-f/2) when A = D
* ``max_jerk``          = 4 A^2 / (f (2-f) w), w the peak velocity actually reached
  (w = V, or sqrt(2|x|AD/(A+D)) for a move too short to reach V);
  ``inf`` at f = 0 (never left at ruckig's default by accident: docs/profiles.md, "ruckig's
  pitfalls"), and
  when the jerk phases f*Ta/2 are shorter than the time resolution of the comparison
  (TIME_RESOLUTION of the duration: a jerkPercent like 1e-200 gives a jerk ruckig cannot
  handle, and a profile indistinguishable from the trapezoid).

The models coincide (an *exact* mapping, compared tightly) for

* TRAPEZOIDAL (and S_CURVE at jerkPercent 0) from any start velocity, to any final velocity,
  when A = D or when the velocity never changes sign (:func:`reverses`);
* S_CURVE with jerkPercent > 0 from rest to rest with A = D (both ramps change the velocity
  by w at the same rate), short moves included;
* VELOCITY: one ramp v0 -> v at A for any sign (MPI 000 MPIMotionVelocity: deceleration is
  ignored), with ``control_interface = Velocity``, ±A/(1-f/2) and J = 4A^2/(f(2-f)|v-v0|).

Standard types start from zero acceleration: the ruckig problem starts from (p, v, 0), the
state the controller plans from (docs/profiles.md, "Modify: from the current state"); a non-zero current acceleration
is :attr:`Reason.ACCELERATION_STEP`.

Elsewhere (:class:`~mpi_ros.crosscheck.result.Reason`) there is no exact ruckig equivalent and
the problem built is a *bound*: limits the controller's profile satisfies (velocity
max(V, |v0|), the signed peaks, and the largest jerk of the controller's ramps — inf if one of
its jerk phases is shorter than the time resolution, or if ruckig fails on the finite jerk),
so ruckig's time-optimal duration is a lower bound on the controller's.

Never used (docs/profiles.md, "ruckig's pitfalls"): intermediate waypoints; ruckig's position
extrema — profiles are sampled instead.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .result import TIME_RESOLUTION, Reason, RuckigLimits

INF = math.inf
TOO_SHORT_TO_SEE = ("jerk phases shorter than the time resolution (a tiny jerkPercent): "
                    "compared as the trapezoid, max_jerk = inf")


def jerk_fraction(jerk_percent: float) -> float:
    """f = jerkPercent/100, the share of each ramp's time with non-zero jerk."""
    return jerk_percent / 100.0


def peak_acceleration(rate: float, f: float) -> float:
    """Peak acceleration of a ramp of average rate ``rate``: rate/(1 - f/2)."""
    return rate / (1.0 - 0.5 * f)


def ramp_jerk(rate: float, f: float, dv: float) -> float:
    """Jerk of a ramp changing the velocity by ``dv`` at average rate ``rate``."""
    if f <= 0.0 or dv == 0.0:
        return INF
    return 4.0 * rate * rate / (f * (2.0 - f) * abs(dv))


def reached_velocity(distance: float, velocity: float, acceleration: float, deceleration: float) -> float:
    """Peak speed of the rest-to-rest trapezoid over ``distance``: V, or less if too short."""
    x = abs(distance)
    return min(velocity, math.sqrt(2.0 * x * acceleration * deceleration / (acceleration + deceleration)))


def reverses(distance: float, v0: float, vf: float, acceleration: float, deceleration: float) -> bool:
    """True if the time-optimal move must change the sign of its velocity.

    In the direction s of travel (the start velocity's, else the distance's, else the final
    velocity's), with u0 = s*v0 >= 0 and uf = s*vf, no reversal is needed iff uf >= 0 and the
    shortest distance from u0 to uf without reversing, (u0^2-uf^2)/(2D) when slowing or
    (uf^2-u0^2)/(2A) when speeding up, fits in s*distance.
    """
    s = _sign(v0) or _sign(distance) or _sign(vf)
    if s == 0:
        return False  # nothing moves
    u0, uf, x = s * v0, s * vf, s * distance
    if uf < 0.0:
        return True
    shortest = (u0 * u0 - uf * uf) / (2.0 * deceleration) if uf <= u0 else (uf * uf - u0 * u0) / (2.0 * acceleration)
    return x < shortest


def direction(distance: float, v0: float, vf: float) -> int:
    """The direction of travel (+1/-1; 0 if nothing moves) of a move that does not reverse."""
    return _sign(v0) or _sign(distance) or _sign(vf)


def _sign(x: float) -> int:
    return (x > 0.0) - (x < 0.0)


def signed_accelerations(raise_peak: float, lower_peak: float, travel: int, reversal: bool) -> tuple[float, float]:
    """(max_acceleration, min_acceleration) for ramps raising |v| at ``raise_peak`` and
    lowering it at ``lower_peak``: by the direction of travel, symmetric if it reverses."""
    if reversal or raise_peak == lower_peak or travel == 0:
        peak = max(raise_peak, lower_peak)
        return peak, -peak
    if travel > 0:
        return raise_peak, -lower_peak
    return lower_peak, -raise_peak


@dataclass(frozen=True, slots=True)
class Mapping:
    """A request's ruckig problem and how far it is equivalent."""

    limits: RuckigLimits | None  # None: nothing moves (no ruckig problem)
    exact: bool
    reasons: tuple[Reason, ...]
    notes: tuple[str, ...]
    needs_profile_jerk: bool = False  # a bound whose max_jerk is the controller's largest jerk

    def with_jerk(self, jerk: float) -> Mapping:
        """The bound with ``max_jerk`` set to the controller's largest ramp jerk."""
        if self.limits is None or not self.needs_profile_jerk:
            return self
        limits = RuckigLimits(**{**_asdict(self.limits), "max_jerk": jerk if jerk > 0.0 else INF})
        return Mapping(limits, self.exact, self.reasons, self.notes, False)


    def unlimited_jerk(self, note: str) -> Mapping:
        """The same problem with max_jerk = inf (for a bound: looser, still a lower bound)."""
        assert self.limits is not None  # a problem ruckig was given
        limits = RuckigLimits(**{**_asdict(self.limits), "max_jerk": INF})
        return Mapping(limits, self.exact, self.reasons, (*self.notes, note), False)


def _asdict(limits: RuckigLimits) -> dict:
    return {name: getattr(limits, name) for name in RuckigLimits.__slots__}


def map_point_to_point(
    start_position: float,
    start_velocity: float,
    start_acceleration: float,
    target: float,
    final_velocity: float,
    velocity: float,
    acceleration: float,
    deceleration: float,
    jerk_percent: float,
) -> Mapping:
    """The ruckig problem of a TRAPEZOIDAL/S_CURVE move (jerk_percent 0 for TRAPEZOIDAL)."""
    x = target - start_position
    v0, vf = start_velocity, final_velocity
    f = jerk_fraction(jerk_percent)
    reasons: list[Reason] = []
    notes: list[str] = []
    reversal = reverses(x, v0, vf, acceleration, deceleration)
    if x == 0.0 and v0 == 0.0 and vf == 0.0:
        return Mapping(None, True, (Reason.ACCELERATION_STEP,) if start_acceleration else (), ("no motion",))
    if f > 0.0:
        if acceleration != deceleration:
            reasons.append(Reason.DECELERATION_DIFFERS)
        if v0 != 0.0:
            reasons.append(Reason.START_VELOCITY)
        if vf != 0.0:
            reasons.append(Reason.FINAL_VELOCITY)
    if acceleration != deceleration and reversal:
        reasons.append(Reason.REVERSAL_ASYMMETRIC)
    exact = not reasons
    raise_peak = peak_acceleration(acceleration, f)
    lower_peak = peak_acceleration(deceleration, f)
    max_acc, min_acc = signed_accelerations(raise_peak, lower_peak, direction(x, v0, vf), reversal)
    needs_jerk = False
    if f == 0.0:
        jerk = INF
    elif exact:
        w = reached_velocity(x, velocity, acceleration, deceleration)
        jerk = ramp_jerk(acceleration, f, w)
        if w < velocity:
            notes.append(f"too short to reach the velocity: jerk from the velocity reached, w = {w:.9g}")
        if 0.5 * f * w / acceleration < TIME_RESOLUTION * (abs(x) / w + w / acceleration):
            jerk = INF
            notes.append(TOO_SHORT_TO_SEE)
    else:
        jerk = INF  # replaced by the controller's largest ramp jerk (with_jerk)
        needs_jerk = True
    if start_acceleration != 0.0:
        reasons.append(Reason.ACCELERATION_STEP)
    max_velocity = velocity if exact else max(velocity, abs(v0))
    limits = RuckigLimits(
        control="position", current_position=start_position, current_velocity=v0, current_acceleration=0.0,
        target_position=target, target_velocity=vf, max_velocity=max_velocity,
        max_acceleration=max_acc, min_acceleration=min_acc, max_jerk=jerk)
    return Mapping(limits, exact, tuple(reasons), tuple(notes), needs_jerk)


def map_velocity(
    start_position: float, start_velocity: float, start_acceleration: float,
    velocity: float, acceleration: float, jerk_percent: float,
) -> Mapping:
    """The ruckig problem (velocity interface) of a VELOCITY move's ramp."""
    f = jerk_fraction(jerk_percent)
    reasons = (Reason.ACCELERATION_STEP,) if start_acceleration != 0.0 else ()
    if velocity == start_velocity:
        return Mapping(None, True, reasons, ("already at the velocity: no ramp",))
    peak = peak_acceleration(acceleration, f)
    jerk = ramp_jerk(acceleration, f, velocity - start_velocity)
    notes: tuple[str, ...] = ()
    if 0.5 * f < TIME_RESOLUTION:
        jerk, notes = INF, (TOO_SHORT_TO_SEE,)
    limits = RuckigLimits(
        control="velocity", current_position=start_position, current_velocity=start_velocity,
        current_acceleration=0.0, target_position=start_position, target_velocity=velocity,
        max_velocity=max(abs(velocity), abs(start_velocity)), max_acceleration=peak, min_acceleration=-peak,
        max_jerk=jerk)
    return Mapping(limits, True, reasons, notes)
