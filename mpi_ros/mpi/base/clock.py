"""Feedrate: a supervisor's profile time tau runs at feedrate x real time.

STOP ramps the feedrate to pauseFeedrate over decelTime.stop, so the axes slow down
along their path and RESUME continues on the same path (docs/decisions.md, "Stopping"); E_STOP ramps it to
zero over decelTime.eStop. Frames are written in profile time; the executor reads them
at tau(t). The feedrate ramps linearly, so tau(t) is piecewise quadratic:

    tau(t) = tau0 + f0 (t - t0) + rate/2 (t - t0)^2    for t0 <= t <= t_end
    tau(t) = tau(t_end) + f_end (t - t_end)             for t >= t_end
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt


@dataclass(frozen=True, slots=True)
class ProfileClock:
    t0: float = 0.0
    tau0: float = 0.0
    f0: float = 1.0
    f1: float = 1.0  # feedrate from t_end on (stored, so a finished ramp is exact)
    t_end: float = 0.0
    # Derived once: every command piece and boundary time of every axis asks for them.
    rate: float = field(init=False, repr=False, compare=False)  # the feedrate's slope in the ramp
    tau_end: float = field(init=False, repr=False, compare=False)  # profile time at t_end

    def __post_init__(self) -> None:
        span = self.t_end - self.t0
        object.__setattr__(self, "rate", (self.f1 - self.f0) / span if span > 0.0 else 0.0)
        object.__setattr__(self, "tau_end", self.tau0 + 0.5 * (self.f0 + self.f1) * (self.t_end - self.t0))

    # -- scalar queries -------------------------------------------------------------
    def ramping(self, t: float) -> bool:
        return t < self.t_end

    def feedrate(self, t: float) -> float:
        if t >= self.t_end:
            return self.f1
        return self.f0 + self.rate * (t - self.t0)

    def feedrate_slope(self, t: float) -> float:
        return self.rate if t < self.t_end else 0.0

    def tau_at(self, t: float) -> float:
        if t >= self.t_end:
            return self.tau_end + self.f1 * (t - self.t_end)
        dt = t - self.t0
        return self.tau0 + dt * (self.f0 + 0.5 * self.rate * dt)

    # -- vector queries -------------------------------------------------------------
    def tau(self, t: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        rate = self.rate
        dt = np.minimum(t, self.t_end) - self.t0
        ramp = self.tau0 + dt * (self.f0 + 0.5 * rate * dt)
        after = np.maximum(t - self.t_end, 0.0)
        return ramp + self.f1 * after

    def feedrates(self, t: npt.NDArray[np.float64]) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """Feedrate and its time derivative at each time."""
        rate = self.rate
        in_ramp = t < self.t_end
        f = np.where(in_ramp, self.f0 + rate * (t - self.t0), self.f1)
        df = np.where(in_ramp, rate, 0.0)
        return f, df

    # -- changes ------------------------------------------------------------------
    def ramp_to(self, t: float, target: float, duration: float) -> ProfileClock:
        """A clock that continues this one and ramps linearly to ``target`` from ``t``."""
        tau, f = self.tau_at(t), self.feedrate(t)
        if duration <= 0.0 or f == target:
            return ProfileClock(t, tau, target, target, t)
        return ProfileClock(t, tau, f, target, t + duration)

    def time_of_tau(self, tau: float, t_from: float) -> float:
        """Earliest time >= t_from at which profile time reaches ``tau`` (inf if never)."""
        return self.times_of_tau([tau], t_from)[0]

    def times_of_tau(self, taus: list[float], t_from: float) -> list[float]:
        """:meth:`time_of_tau` of each of ``taus`` (a plan's boundaries: what is common to
        them is worked out once)."""
        tau_from = self.tau_at(t_from)
        t0, tau0, f0, f1, rate = self.t0, self.tau0, self.f0, self.f1, self.rate
        t_end, tau_end = self.t_end, self.tau_end
        times = []
        for tau in taus:
            if tau_from >= tau:
                times.append(t_from)
            elif t_from < t_end and tau_end >= tau:
                # tau0 + f0 x + rate/2 x^2 = tau with x = t - t0, on the increasing branch.
                c = tau0 - tau
                if rate == 0.0:
                    x = -c / f0
                else:
                    root = math.sqrt(max(0.0, f0 * f0 - 2.0 * rate * c))
                    denominator = f0 + root
                    x = (-2.0 * c) / denominator if denominator > 0.0 else (root - f0) / rate
                times.append(max(t_from, t0 + x))
            elif f1 <= 0.0:
                times.append(math.inf)
            else:
                times.append(max(t_from, t_end + (tau - tau_end) / f1))
        return times

    def local_quadratic(self, t: float) -> tuple[float, float, float]:
        """tau(t + s) = q0 + q1 s + q2 s^2 for s within the current clock piece."""
        return self.tau_at(t), self.feedrate(t), 0.5 * self.feedrate_slope(t)
