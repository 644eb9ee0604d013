"""The one representation every profile compiles into: constant-jerk segments.

MPI 000 (Streaming Point Motion Type Calculations): "all motion is specified by
constant-jerk segments of motion". A segment starts at (p, v, a) and runs ``duration``
seconds of profile time with jerk ``j``. A 1-D profile is a contiguous tuple of them.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from itertools import chain as _chain_iterables
from typing import NamedTuple

import numpy as np


class Segment(NamedTuple):
    """One constant-jerk piece of an axis' profile, immutable and compared by value. A Row
    (below) holds the same five values as a plain tuple; ``Segment._make(row)`` makes one of it."""

    duration: float
    p: float
    v: float
    a: float
    j: float

    def state_at(self, t: float) -> tuple[float, float, float]:
        """(position, velocity, acceleration) ``t`` seconds into the segment."""
        return (
            self.p + t * (self.v + t * (self.a / 2.0 + t * self.j / 6.0)),
            self.v + t * (self.a + t * self.j / 2.0),
            self.a + t * self.j,
        )

    def end_state(self) -> tuple[float, float, float]:
        return self.state_at(self.duration)

    def scaled(self, factor: float, offset: float) -> Segment:
        """The segment of an axis that moves ``factor`` times this 1-D profile."""
        return Segment(self.duration, offset + factor * self.p, factor * self.v, factor * self.a, factor * self.j)


# A segment's values as a plain tuple, (duration, p, v, a, j): a vector's 1-D profile is made of
# them (its axes' Segments are made from it, scaled), and a Segment is one too
Row = tuple[float, float, float, float, float]


def scaled_profile(segments: Iterable[Row], factor: float, offset: float) -> list[Segment]:
    """``[seg.scaled(factor, offset) for seg in segments]``: the same operations, without a
    method call per segment (a vector move scales its profile for every axis)."""
    return [Segment(d, offset + factor * p, factor * v, factor * a, factor * j) for d, p, v, a, j in segments]


def chain(p0: float, v0: float, a0: float, moves: Iterable[tuple[float, float]]) -> list[Segment]:
    """Integrate ``(duration, jerk)`` pieces from (p0, v0, a0) into contiguous segments.

    Zero-length pieces are dropped. The caller passes the acceleration a piece starts
    with implicitly: it is the end acceleration of the previous piece, or ``a0``.
    """
    out: list[Segment] = []
    p, v, a = p0, v0, a0
    for duration, jerk in moves:
        if duration <= 0.0:
            continue
        seg = Segment(duration, p, v, a, jerk)
        out.append(seg)
        p, v, a = seg.end_state()
    return out


def total_duration(segments: Sequence[Segment]) -> float:
    return float(sum(s.duration for s in segments))


def end_time(segments: Sequence[Row], t0: float = 0.0) -> float:
    """``SegmentTable(segments, t0).end[-1]`` without the arrays: the same additions in the
    same order as the table's cumulative sum (``segments`` must not be empty)."""
    # Added one by one in order (as the table's cumsum adds them; not sum(), whose float
    # summation may change between Python versions); segment[0] is the duration of a Row or a
    # Segment alike. -0.0 + d is d for every d, as the cumsum's first term is.
    total = -0.0
    for segment in segments:
        total += segment[0]
    return t0 + total


def end_state(segments: Sequence[Segment], start: tuple[float, float, float]) -> tuple[float, float, float]:
    return segments[-1].end_state() if segments else start


class SegmentTable:
    """A profile as arrays, for evaluating many sample times at once."""

    __slots__ = ("a", "count", "end", "ends", "j", "p", "start", "v")

    def __init__(self, segments: Sequence[Row], t0: float = 0.0):
        # One array of every segment's fields in a row, whose columns are the fields: one
        # np.fromiter rather than five np.array calls, for the few segments a plan has.
        values = np.fromiter(_chain_iterables.from_iterable(segments), float, 5 * len(segments))
        d, self.p, self.v, self.a, self.j = values.reshape(-1, 5).T
        self.end = t0 + np.cumsum(d)
        self.ends = self.end.tolist()  # for one time at a time (bisect: no numpy call for a scalar)
        self.start = self.end - d
        self.count = len(segments)

    def index(self, t: np.ndarray) -> np.ndarray:
        """Segment index of each time (times past the end map to the last segment)."""
        idx = np.searchsorted(self.end, t, side="right")
        return np.minimum(idx, self.count - 1)

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity, acceleration, jerk at times ``t`` within the table."""
        i = self.index(t)
        dt = t - self.start[i]
        j = self.j[i]
        a = self.a[i]
        v = self.v[i]
        pos = self.p[i] + dt * (v + dt * (a / 2.0 + dt * j / 6.0))
        vel = v + dt * (a + dt * j / 2.0)
        acc = a + dt * j
        return pos, vel, acc, j
