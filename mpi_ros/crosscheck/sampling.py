"""Sampling two constant-jerk profiles against each other.

Position and velocity are continuous and are compared on a uniform grid and inside every
interval between the two profiles' switching times. Acceleration may step (a trapezoid's
infinite jerk), and two correct profiles may place a step a few ulps apart; so acceleration
is compared only inside those intervals — at their quarter, middle and three-quarter
points — after merging switching times closer than a window into one. Both profiles are
polynomials there, so a difference found is a real one. The window is ``1e-9`` of the
duration, or the time in which the largest acceleration changes the velocity by the velocity
tolerance if that is longer: a phase that short is below the velocity resolution of the
comparison (ruckig, for one, may end its brake with a 1e-12 s correction phase).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from mpi_ros.mpi.planning.profiles.segment import Segment, SegmentTable

from .result import StateDifference

MERGE_RTOL = 1e-9
UNIFORM_SAMPLES = 101


def end_state(segments: Sequence[Segment], start: tuple[float, float, float]) -> tuple[float, float, float]:
    return segments[-1].end_state() if segments else start


def sample(segments: Sequence[Segment], times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity, acceleration, jerk of a profile (starting at t = 0) at ``times``."""
    return SegmentTable(list(segments)).evaluate(np.asarray(times, dtype=float))


def switching_times(segments: Sequence[Segment]) -> np.ndarray:
    return np.cumsum([s.duration for s in segments]) if segments else np.zeros(0)


def _interval_points(breaks: np.ndarray, horizon: float, window: float) -> np.ndarray:
    points = np.unique(np.concatenate(([0.0, horizon], breaks[(breaks > 0.0) & (breaks < horizon)])))
    merged = [points[0]]
    window = max(window, MERGE_RTOL * horizon)
    for t in points[1:]:
        if t - merged[-1] > window:
            merged.append(t)
    merged[-1] = horizon
    edges = np.array(merged)
    if len(edges) < 2:
        return np.zeros(0)
    lo, width = edges[:-1], np.diff(edges)
    return np.concatenate([lo + q * width for q in (0.25, 0.5, 0.75)])


def max_difference(a: Sequence[Segment], b: Sequence[Segment], window: float = 0.0,
                   uniform: int = UNIFORM_SAMPLES) -> StateDifference:
    """Largest |difference| in p, v (everywhere) and a (away from steps) over the common time.

    ``window``: switching times closer than this (or MERGE_RTOL of the duration) are one."""
    if not a or not b:
        return StateDifference()
    horizon = min(float(switching_times(a)[-1]), float(switching_times(b)[-1]))
    if horizon <= 0.0:
        return StateDifference()
    inner = _interval_points(np.concatenate((switching_times(a), switching_times(b))), horizon, window)
    grid = np.linspace(0.0, horizon, uniform)
    pa, va, aa, _ = sample(a, inner)
    pb, vb, ab, _ = sample(b, inner)
    pa2, va2, _, _ = sample(a, grid)
    pb2, vb2, _, _ = sample(b, grid)
    return StateDifference(
        float(max(np.max(np.abs(pa - pb), initial=0.0), np.max(np.abs(pa2 - pb2), initial=0.0))),
        float(max(np.max(np.abs(va - vb), initial=0.0), np.max(np.abs(va2 - vb2), initial=0.0))),
        float(np.max(np.abs(aa - ab), initial=0.0)),
    )
