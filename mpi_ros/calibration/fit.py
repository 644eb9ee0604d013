"""Fit an axis' servo plant to a recording, and measure how far the twin is from it.

The parameters fitted are those of ``axes.overrides.<k>.plant``: bandwidth_hz, damping,
velocity_feedforward and acceleration_feedforward by bounded least squares
(scipy.optimize.least_squares, bounded to PlantConfig.validate's ranges) on the residual
recorded actual - twin actual at every recorded sample, from several starts; and
encoder_resolution from the recorded actual positions where they sit on a lattice.

The starts: a grid of bandwidths and dampings, each with the feed-forwards that fit best
for it (the twin's actual position is affine in the two feed-forwards, so three runs of
the plant and a linear solve give them), the best few of which (and the configured plant)
are then refined, each on its own. A long recording is searched on a coarse twin first
(every m-th sample, the twin run at rate / m: a quarter of the work at 60 s of 2 kHz), and
the best of its refinements is then polished on the whole recording at the full rate.

The verdict is honest by construction: the twin "matches" only where what is left of the
residual is no more than the recording's noise. Noise is white from sample to sample, what
a model cannot represent is not: the white part is estimated from the residual's differences
between neighbouring samples (a smooth error hardly changes from one sample to the next), and
the rest, sqrt(RMS^2 - white^2), is the structured part, the twin's own error. The twin
matches when that is no larger than the noise, or than the encoder's rounding (a position
held at rest reads the same rounded value every sample: a constant, not white, error of up
to half a step).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import least_squares

from mpi_ros.mpi.base.params import BANDWIDTH_MAX_HZ, BANDWIDTH_MIN_HZ, DAMPING_MAX, FEEDFORWARD_MAX, PlantConfig

from .recording import AxisRecording
from .twin import AxisTwin

MATCH_FLOOR = 0.01  # counts RMS: a structured residual this small matches whatever the noise
DAMPING_MIN = 1e-3  # the validator's range is (0, 1]: open at 0
GRID_BANDWIDTHS = 8  # starts: bandwidths spaced evenly in log from 1 Hz to GRID_TOP
GRID_TOP = 500.0  # Hz: (a quarter of the default rate) beyond it a loop follows any command closely
COARSE_POINTS = 30_000  # a longer recording is searched on a coarse twin first (_scout)
GRID_DAMPINGS = (0.25, 0.55, 0.9)
# Relative change of cost and parameters at which a refinement stops: the recording's noise
# bounds what more iterations could find (1e-6 of the cost moves a parameter by ~0.1 % at most).
TOLERANCE = 1e-6
REFINED = 2  # the best grid starts refined (besides the configured plant)


@dataclass(frozen=True, slots=True)
class Residual:
    """How far the twin's actual position is from the recording's (counts)."""

    rms: float
    max: float
    at: float  # time of the largest (s, from the recording's start)

    @classmethod
    def of(cls, time: np.ndarray, difference: np.ndarray) -> Residual:
        i = int(np.argmax(np.abs(difference)))
        return cls(_rms(difference), float(abs(difference[i])), float(time[i] - time[0]))


@dataclass(frozen=True, slots=True)
class AxisFit:
    axis: int
    samples: int
    duration: float
    rate: float
    configured: PlantConfig
    fitted: PlantConfig
    before: Residual  # with the configured plant
    after: Residual  # with the fitted plant
    following_error: Residual  # the recording's own (command - actual)
    resolution: float | None  # the encoder's step, where the recording shows one
    noise: float  # the white part of the residual with the fit (counts RMS)
    structured: float  # the rest of it: what the fitted twin does not reproduce (counts RMS)
    starts: int
    evaluations: int

    @property
    def matched(self) -> bool:
        """The fitted twin's error is within the recording's noise (or encoder rounding)."""
        rounding = (self.resolution or 0.0) / math.sqrt(12.0)
        return self.structured <= max(self.noise, rounding, MATCH_FLOOR)

    @property
    def explained(self) -> float:
        """Share of the recorded following error's power the fitted twin reproduces."""
        power = self.following_error.rms ** 2
        return 1.0 - self.after.rms ** 2 / power if power > 0.0 else 0.0


def residual(twin: AxisTwin, config: PlantConfig, read: bool = True) -> np.ndarray:
    """Recorded actual - twin actual, at every recorded sample."""
    return twin.recording.actual - twin.actual(config, read=read)


def compare(recording: AxisRecording, config: PlantConfig, rate: float) -> tuple[Residual, Residual, Residual]:
    """(recorded following error, the twin's, recorded - twin actual) with ``config``."""
    twin = AxisTwin(recording, rate)
    actual = twin.actual(config)
    t = recording.time
    return (Residual.of(t, recording.command - recording.actual), Residual.of(t, recording.command - actual),
            Residual.of(t, recording.actual - actual))


def fit_axis(recording: AxisRecording, rate: float, configured: PlantConfig) -> AxisFit:
    recording.validate()
    twin = AxisTwin(recording, rate)
    top = min(BANDWIDTH_MAX_HZ, rate / 2.0)
    search = _Search(twin, configured, top)
    scout = _scout(recording, rate, configured, top)
    if scout is None:
        best = min((search.refine(x) for x in search.starts()), key=lambda result: result.cost)
    else:  # the starts refined on the coarse twin, the best of them polished on the whole recording
        rough = min((scout.refine(x) for x in scout.starts()), key=lambda result: result.cost)
        best = search.refine(rough.x)
    resolution = encoder_step(recording.actual)
    fitted = search.config(best.x)
    if resolution is not None:
        fitted = replace(fitted, encoder_resolution=resolution)
    after = residual(twin, fitted)
    before = residual(twin, configured)
    if _rms(before) <= _rms(after):
        # The configured plant explains the recording at least as well: kept. (A recording whose
        # following error is near the encoder's step leaves the plant undetermined, and the
        # search on unrounded positions can land on any of many plants that round alike.)
        fitted, after = configured, before
    t = recording.time
    noise, structured = split_noise(after)
    runs = search.evaluations + (scout.evaluations if scout is not None else 0)
    return AxisFit(recording.number, len(t), recording.duration, rate, configured, fitted,
                   Residual.of(t, before), Residual.of(t, after),
                   Residual.of(t, recording.command - recording.actual), resolution,
                   noise, structured, (scout or search).started, runs)


def _scout(recording: AxisRecording, rate: float, configured: PlantConfig, top: float) -> _Search | None:
    """For a long recording, a coarse twin to search from the starts with: every m-th sample,
    the twin run at rate / m, about COARSE_POINTS of each. None when the recording is short."""
    grid = recording.duration * rate
    m = math.ceil(max(grid, len(recording.time)) / COARSE_POINTS)
    if m <= 1:
        return None
    every = max(1, math.ceil(len(recording.time) / COARSE_POINTS))
    coarse = AxisRecording(recording.number, recording.time[::every], recording.command[::every],
                           recording.actual[::every])
    return _Search(AxisTwin(coarse, rate / m), configured, top)


class _Search:
    """The parameters as x = (log bandwidth, damping, velocity ff, acceleration ff)."""

    def __init__(self, twin: AxisTwin, configured: PlantConfig, top: float):
        self.twin = twin
        self.base = replace(configured, encoder_resolution=0.0)  # the fit compares unrounded positions
        self.lower = np.array([math.log(BANDWIDTH_MIN_HZ), DAMPING_MIN, -FEEDFORWARD_MAX, -FEEDFORWARD_MAX])
        self.upper = np.array([math.log(top), DAMPING_MAX, FEEDFORWARD_MAX, FEEDFORWARD_MAX])
        self.evaluations = 0
        self.started = 0

    def config(self, x: np.ndarray) -> PlantConfig:
        return replace(self.base, bandwidth_hz=float(math.exp(x[0])), damping=float(x[1]),
                       velocity_feedforward=float(x[2]), acceleration_feedforward=float(x[3]))

    def residual(self, x: np.ndarray) -> np.ndarray:
        self.evaluations += 1
        return residual(self.twin, self.config(x), read=False)

    def starts(self) -> list[np.ndarray]:
        """The best grid points (feed-forwards solved for each) and the configured plant."""
        top = min(GRID_TOP, math.exp(self.upper[0]))
        graded = []
        for bandwidth in np.geomspace(1.0, top, GRID_BANDWIDTHS):
            for damping in GRID_DAMPINGS:
                x, cost = self._feedforwards(math.log(bandwidth), damping)
                graded.append((cost, x))
        graded.sort(key=lambda item: item[0])
        c = self.base
        own = np.array([math.log(c.bandwidth_hz), c.damping, c.velocity_feedforward, c.acceleration_feedforward])
        return [x for _, x in graded[:REFINED]] + [np.clip(own, self.lower, self.upper)]

    def _feedforwards(self, log_bandwidth: float, damping: float) -> tuple[np.ndarray, float]:
        """The feed-forwards that fit best at this bandwidth and damping (linear least squares:
        the residual is affine in them), kept within their range, and the cost."""
        r00 = self.residual(np.array([log_bandwidth, damping, 0.0, 0.0]))
        d_kv = self.residual(np.array([log_bandwidth, damping, 1.0, 0.0])) - r00
        d_ka = self.residual(np.array([log_bandwidth, damping, 0.0, 1.0])) - r00
        basis = np.column_stack((d_kv, d_ka))
        solved, *_ = np.linalg.lstsq(basis, -r00, rcond=None)
        kv, ka = np.clip(solved, -FEEDFORWARD_MAX, FEEDFORWARD_MAX)
        left = r00 + basis @ np.array([kv, ka])
        return np.array([log_bandwidth, damping, kv, ka]), float(left @ left)

    def refine(self, x0: np.ndarray):
        self.started += 1
        return least_squares(self.residual, np.clip(x0, self.lower, self.upper), bounds=(self.lower, self.upper),
                             method="trf", x_scale=np.array([0.1, 0.05, 0.05, 0.05]), ftol=TOLERANCE, xtol=TOLERANCE)


def encoder_step(actual: np.ndarray) -> float | None:
    """The step of the lattice the actual positions sit on (an encoder's resolution), or None
    where they do not sit on one (not quantised, or noise added after the encoder)."""
    levels = np.unique(actual)
    if len(levels) < 3:
        return None
    gaps = np.diff(levels)
    smallest = float(gaps.min())
    if smallest <= 1e-9 * max(1.0, float(np.abs(levels).max())):
        return None  # closer than float positions resolve: not a lattice
    for divisor in (1, 2, 3, 4):  # the smallest gap may span a few steps
        step = smallest / divisor
        units = (levels - levels[0]) / step
        if np.all(np.abs(units - np.rint(units)) < 1e-6):
            return _tidy(step)
    return None


def _tidy(step: float) -> float:
    """A step read from float positions, rounded to 9 significant digits (0.1 rather than 0.1000000000001)."""
    return float(f"{step:.9g}")


def split_noise(left: np.ndarray) -> tuple[float, float]:
    """(white, structured) parts of a residual, RMS: the white part from the differences of
    neighbouring samples (white noise of RMS n gives differences of RMS n sqrt 2), the
    structured part what remains of the residual's power."""
    white = _rms(np.diff(left)) / math.sqrt(2.0) if len(left) > 1 else 0.0
    total = _rms(left)
    return min(white, total), math.sqrt(max(total * total - white * white, 0.0))


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(values)))) if len(values) else 0.0
