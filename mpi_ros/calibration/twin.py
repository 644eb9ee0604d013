"""The twin's own servo plant run on a recorded command.

The controller drives each axis' plant (mpi_ros.mpi.axes.plant) with the command as
polynomial pieces: ``Plant.prepare`` makes the loop's steady response to a piece, its
velocity and acceleration feed-forward taken from the piece's exact derivatives, and
``Plant.advance`` carries the motor's state across it. A recording has the command only at
its samples, so here it becomes pieces the same way a path does: the natural cubic spline
through the recorded command (C2: position, velocity and acceleration continuous, so the
acceleration feed-forward sees the command's acceleration; straight lines between samples,
as a cam's slave gets them in ``Plant.sample_step``, would have none and leave
``acceleration_feedforward`` unobservable).

The pieces are taken on a uniform grid at the controller's sample rate (one cubic per sample:
the spline's Taylor polynomial at the grid point), whatever the recording's spacing, so every
piece lasts one sample. The plant is linear, so one sample of any cubic piece is a fixed
linear map of (position, velocity, the cubic's four coefficients); this module gets that map
from ``Plant.prepare`` and ``Plant.advance`` themselves (their response to each input alone)
and applies it sample after sample as a recursive filter (scipy.signal.lfilter), which gives
what ``Plant.advance`` gives piece by piece, up to rounding, in a small fraction of the time.
The twin's actual position at the recorded times is then read off the grid: directly where
the recording is on the grid, else by cubic Hermite interpolation of position and velocity.

The twin starts settled on the command (the steady response of its first piece), as a
controller at rest or in steady motion is; a recording that starts in a transient differs
from it for the loop's first few time constants.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import CubicHermiteSpline, CubicSpline
from scipy.signal import lfilter

from mpi_ros.mpi.axes.plant import Plant, PlantState
from mpi_ros.mpi.base.params import PlantConfig

from .recording import AxisRecording

_ON_GRID = 1e-6  # samples: a recorded time this close to a grid point is that point


def step_map(config: PlantConfig, rate: float) -> tuple[np.ndarray, np.ndarray]:
    """(A, B): over one sample of a cubic command piece c0 + c1 s + c2 s^2 + c3 s^3, the
    motor's (y, y') goes to A (y, y') + B (c0, c1, c2, c3), as Plant.advance computes it."""
    plant = Plant(config)
    h = 1.0 / rate

    def after(y: float, dy: float, piece: list[float]) -> tuple[float, float]:
        state = plant.advance(PlantState(0.0, y, dy), plant.prepare(piece), h)
        return state.y, state.dy

    zero = [0.0, 0.0, 0.0, 0.0]
    a = np.array([after(1.0, 0.0, zero), after(0.0, 1.0, zero)]).T
    # Each coefficient scaled to move the command by about one count over the sample, so that
    # no response is small enough for the plant's quiet threshold to drop its transient.
    columns = []
    for m in range(4):
        unit = [0.0] * 4
        unit[m] = rate**m
        columns.append(np.array(after(0.0, 0.0, unit)) / rate**m)
    return a, np.array(columns).T


def steady_state(config: PlantConfig, piece: np.ndarray) -> tuple[float, float]:
    """The motor's (y, y') settled on the command piece (its steady response at the piece's start)."""
    forced = Plant(config).prepare([float(c) for c in piece])
    return forced.y[0], forced.dy[0]


class AxisTwin:
    """One recorded axis and the twin's plant run on its command."""

    def __init__(self, recording: AxisRecording, rate: float):
        if not (math.isfinite(rate) and rate > 0.0):
            raise ValueError(f"sample rate must be positive, got {rate!r}")
        self.recording = recording
        self.rate = rate
        t = recording.time - recording.time[0]
        self._t = t
        n = math.floor(t[-1] * rate + _ON_GRID) + 1
        if (n - 1) / rate < t[-1]:
            n += 1  # a last grid point past the end (the spline extrapolates one piece)
        self.grid = np.arange(n) / rate
        spline = CubicSpline(t, recording.command, bc_type="natural")
        g = self.grid
        # (4, n), one row per coefficient: each a contiguous run for the products below
        self.pieces = np.array([spline(g), spline(g, 1), spline(g, 2) / 2.0, spline(g, 3) / 6.0])
        position = t * rate
        index = np.rint(position).astype(np.int64)
        self._index = index if np.all(np.abs(position - index) < _ON_GRID) else None

    def motor(self, config: PlantConfig) -> tuple[np.ndarray, np.ndarray]:
        """The motor's position and velocity at every grid point (not read by the encoder)."""
        a, b = step_map(config, self.rate)
        y0, dy0 = steady_state(config, self.pieces[:, 0])
        # x[k] = A x[k-1] + w[k] with w[0] = x0 and w[k] what piece k-1 adds: x[0] = x0 exactly.
        w = np.empty((2, self.pieces.shape[1]))
        w[:, 0] = (y0, dy0)
        w[:, 1:] = b @ self.pieces[:, :-1]
        den = [1.0, -(a[0, 0] + a[1, 1]), a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]]
        # (I - A z^-1)^-1 = adj(I - A z^-1) / det(I - A z^-1), one row per state component.
        y = lfilter([1.0], den, _mix(w[0], -a[1, 1], w[1], a[0, 1]))
        if self._index is not None:
            return y, np.empty(0)
        dy = lfilter([1.0], den, _mix(w[1], -a[0, 0], w[0], a[1, 0]))
        return y, dy

    def actual(self, config: PlantConfig, read: bool = True) -> np.ndarray:
        """The twin's actual position at the recorded times; ``read``: through its encoder."""
        y, dy = self.motor(config)
        # On the grid: its values; between grid points: the cubic through position and velocity.
        out = y[self._index] if self._index is not None else CubicHermiteSpline(self.grid, y, dy)(self._t)
        return Plant(config).read(out) if read else out


def _mix(own: np.ndarray, own_delay: float, other: np.ndarray, other_delay: float) -> np.ndarray:
    """own[k] + own_delay own[k-1] + other_delay other[k-1]: the numerator of one state's filter."""
    out = own.copy()
    out[1:] += own_delay * own[:-1] + other_delay * other[:-1]
    return out
