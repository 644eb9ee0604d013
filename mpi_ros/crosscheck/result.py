"""What a cross-check found, as data: durations, differences, a verdict and its reasons.

Verdicts:

* ``AGREE`` — the two models coincide for this request (docs/profiles.md, "The cross-check
  against ruckig"): the durations agree to :data:`DURATION_RTOL` relative, the final
  position and velocity and the sampled states (acceleration away from its steps) to
  :data:`STATE_RTOL` of their scales (plus what double-precision time,
  :data:`TIME_RESOLUTION` of the duration, allows), and the controller's profile respects
  every limit.
* ``DIFFER_EXPLAINED`` — the models legitimately differ (each :class:`Reason` says why,
  docs/profiles.md, "The cross-check against ruckig"); the controller's profile still
  respects every limit, reaches the same final position and velocity, and is never faster
  than ruckig's time-optimal profile for limits the controller's profile satisfies (ruckig
  is a lower bound). Where the only reason is :attr:`Reason.ACCELERATION_STEP`, the tight
  comparison of ``AGREE`` is made as well.
* ``DISAGREE`` — anything else; ``problems`` lists what failed.

Tolerances are constants here and never widened per case: a case that does not meet them
is a finding (``DISAGREE``) or, if the models legitimately differ, classified with its
reason — never passed by loosening a comparison.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum

DURATION_RTOL = 1e-6  # where the models coincide (issue 5)
STATE_RTOL = 1e-9  # sampled/final states, relative to the move's scales (check.py)
# Both models place their switching times in double precision: a time t is known to a few
# ulps of the duration T, so a state sampled at t carries (its derivative) x T x this.
TIME_RESOLUTION = 64 * 2.0**-52
LIMIT_RTOL = 1e-9  # limits (velocity, acceleration peaks, ramp rates, jerk share)
BOUND_RTOL = 1e-9  # "never faster than ruckig": controller >= ruckig * (1 - BOUND_RTOL)


class Verdict(Enum):
    AGREE = "AGREE"
    DIFFER_EXPLAINED = "DIFFER_EXPLAINED"
    DISAGREE = "DISAGREE"


class Reason(Enum):
    """Why the controller's model and ruckig's legitimately differ for a request."""

    DECELERATION_DIFFERS = (
        "deceleration != acceleration with jerkPercent > 0: the two ramps' jerks "
        "4A^2/(f(2-f)w) and 4D^2/(f(2-f)w) differ, ruckig has one max_jerk per axis")
    REVERSAL_ASYMMETRIC = (
        "deceleration != acceleration and the velocity changes sign: the controller's rates "
        "apply to raising/lowering |v|, ruckig's max/min_acceleration are signed")
    START_VELOCITY = (
        "start velocity != 0 with jerkPercent > 0 (modify from motion): each ramp's jerk comes "
        "from its own velocity change, ruckig has one max_jerk")
    FINAL_VELOCITY = (
        "final velocity != 0 with jerkPercent > 0: the ramps' velocity changes differ, so do "
        "their jerks; ruckig has one max_jerk")
    ACCELERATION_STEP = (
        "modify from a moving state with acceleration: the controller restarts from zero "
        "acceleration (a step, as the firmware does); compared from that state")
    TRUNCATED = (
        "a frame hit the 16,384,000-sample limit: the profile stops there, not at the target")
    BLENDED = (
        "a blended corner (MEIMotionConfig.blendLimit): the appended move's own profile is "
        "compared with ruckig; the blend, its sum with the rest of the move before, is checked "
        "against the limits (velocity; acceleration up to both peaks added: twice at an about-face)")
    COMPOSITE = (
        "the plan is two profiles, not one (a vector modify off its line stops along the line, "
        "then moves on a new one): each is a vector profile; not compared")

    @property
    def description(self) -> str:
        return self.value


@dataclass(frozen=True, slots=True)
class StateDifference:
    """Largest absolute differences in position, velocity and acceleration."""

    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0

    def within(self, tolerance: StateDifference) -> bool:
        return (self.position <= tolerance.position and self.velocity <= tolerance.velocity
                and self.acceleration <= tolerance.acceleration)

    def relative_to(self, scales: StateDifference) -> StateDifference:
        def rel(x: float, s: float) -> float:
            return x / s if s > 0.0 else (0.0 if x == 0.0 else math.inf)

        return StateDifference(rel(self.position, scales.position), rel(self.velocity, scales.velocity),
                               rel(self.acceleration, scales.acceleration))

    def max(self, other: StateDifference) -> StateDifference:
        return StateDifference(max(self.position, other.position), max(self.velocity, other.velocity),
                               max(self.acceleration, other.acceleration))


@dataclass(frozen=True, slots=True)
class RuckigLimits:
    """The 1-DoF problem given to ruckig (see mapping.py for how it is derived)."""

    control: str  # "position" or "velocity"
    current_position: float
    current_velocity: float
    current_acceleration: float
    target_position: float
    target_velocity: float
    max_velocity: float
    max_acceleration: float
    min_acceleration: float
    max_jerk: float


@dataclass(frozen=True, slots=True)
class CrossCheck:
    """The outcome of checking one axis' profile against ruckig."""

    motion_type: str
    axis: int
    verdict: Verdict
    exact: bool  # the models coincide (compared tightly)
    controller_duration: float
    ruckig_duration: float | None
    reasons: tuple[Reason, ...] = ()
    notes: tuple[str, ...] = ()
    problems: tuple[str, ...] = ()
    final_difference: StateDifference = field(default_factory=StateDifference)  # acceleration: data only
    max_difference: StateDifference = field(default_factory=StateDifference)  # sampled (exact only)
    scales: StateDifference = field(default_factory=StateDifference)
    tolerance: StateDifference = field(default_factory=StateDifference)  # absolute, used for states
    ruckig: RuckigLimits | None = None
    ruckig_full_state_duration: float | None = None  # ACCELERATION_STEP: ruckig from (p, v, a)

    @property
    def duration_difference(self) -> float:
        """Controller minus ruckig (s); > 0: the controller is slower."""
        if self.ruckig_duration is None:
            return math.nan
        return self.controller_duration - self.ruckig_duration

    @property
    def duration_relative(self) -> float:
        if self.ruckig_duration is None:
            return math.nan
        scale = max(self.ruckig_duration, self.controller_duration)
        return abs(self.duration_difference) / scale if scale > 0.0 else 0.0

    @property
    def ok(self) -> bool:
        return self.verdict is not Verdict.DISAGREE

    @property
    def reason_text(self) -> str:
        return "; ".join(r.name for r in self.reasons)

    @property
    def detail(self) -> str:
        """One line: what was compared and what came out (the CROSSCHECK event's detail)."""
        ruckig = "n/a" if self.ruckig_duration is None else f"{self.ruckig_duration:.9g} s"
        text = (f"{self.motion_type} axis {self.axis}: {self.verdict.name}; controller "
                f"{self.controller_duration:.9g} s, ruckig {ruckig}")
        if self.reasons:
            text += f"; reasons: {self.reason_text}"
        if self.problems:
            text += "; problems: " + "; ".join(self.problems)
        return text
