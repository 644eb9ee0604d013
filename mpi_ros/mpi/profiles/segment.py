"""The one representation every profile compiles into: constant-jerk segments.

spec 000 (Streaming Point Motion Type Calculations): "all motion is specified by
constant-jerk segments of motion". A segment starts at (p, v, a) and runs ``duration``
seconds of profile time with jerk ``j``. A 1-D profile is a contiguous tuple of them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Sequence

import numpy as np


@dataclass(frozen=True, slots=True)
class Segment:
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

    def scaled(self, factor: float, offset: float) -> "Segment":
        """The segment of an axis that moves ``factor`` times this 1-D profile."""
        return Segment(
            self.duration, offset + factor * self.p, factor * self.v, factor * self.a, factor * self.j
        )


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


def end_state(segments: Sequence[Segment], start: tuple[float, float, float]) -> tuple[float, float, float]:
    return segments[-1].end_state() if segments else start


class SegmentTable:
    """A profile as arrays, for evaluating many sample times at once."""

    __slots__ = ("start", "end", "p", "v", "a", "j", "count")

    def __init__(self, segments: Sequence[Segment], t0: float = 0.0):
        d = np.array([s.duration for s in segments], dtype=float)
        self.end = t0 + np.cumsum(d)
        self.start = self.end - d
        self.p = np.array([s.p for s in segments], dtype=float)
        self.v = np.array([s.v for s in segments], dtype=float)
        self.a = np.array([s.a for s in segments], dtype=float)
        self.j = np.array([s.j for s in segments], dtype=float)
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
