"""The path (streaming point) motion types, one axis at a time: PT, PVT, SPLINE, BESSEL,
BSPLINE and BSPLINE2 as constant-jerk segments.

MPI 000, Streaming Point Motion Type Calculations: "all motion is specified by constant-jerk
segments of motion", and "Any given dt defining a point also specifies how long it will take to
arrive at that point". A path starts from the axis' position (and, for PVT, its velocity) at time
0 and reaches point i at T_i = dt_0 + ... + dt_i. Every kind is a piecewise polynomial of degree
at most three in time, so each piece is exactly one ``Segment``.

docs/paths.md explains each definition, the reference it follows and where the reference is
silent or wrong. This module is pure mathematics: it validates nothing (the caller does: every
dt > 0, every value finite, as many times as positions, at least one point).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from mpi_ros.mpi.planning.profiles.segment import Segment

if TYPE_CHECKING:
    import numpy as np


class PathKind(enum.Enum):
    """The path motion types. PTF plans as PT and PVTF as PVT (the caller maps them): the
    feedforward is a separate signal (``feedforward_segments``), the path is the same."""

    PT = enum.auto()
    PVT = enum.auto()
    SPLINE = enum.auto()
    BESSEL = enum.auto()
    BSPLINE = enum.auto()
    BSPLINE2 = enum.auto()


def path_segments(kind: PathKind, start_position: float, start_velocity: float,
                  positions: Sequence[float] | np.ndarray, times: Sequence[float] | np.ndarray,
                  velocities: Sequence[float] | np.ndarray | None = None) -> list[Segment]:
    """One axis' path: from (start_position, start_velocity) through the points.

    times[i] is dt_i, the seconds from point i-1 to point i (the first, from the start)
    (MPI 000 "Any given dt defining a point also specifies how long it will take to arrive at
    that point"). velocities: PVT only (one per point). start_velocity is used by PVT only
    (the velocity the first interval leaves with); the other kinds ignore it.
    Returns contiguous segments covering exactly [0, sum(times)], no zero-length segments
    (the caller validates: every dt > 0, every value finite, len(positions) == len(times) >= 1).
    """
    # the path's value at each knot: the start, then every point
    values = [float(start_position)] + [float(x) for x in positions]
    dts = [float(dt) for dt in times]
    if kind is PathKind.PT:
        return _linear(values, dts)
    if kind is PathKind.PVT:
        if velocities is None or len(velocities) != len(dts):
            raise ValueError("PVT needs one velocity per point")
        return _hermite(values, [float(start_velocity)] + [float(v) for v in velocities], dts)
    if kind is PathKind.SPLINE:
        return _natural_spline(values, dts)
    if kind is PathKind.BESSEL:
        return _hermite(values, _bessel_tangents(values, dts), dts)
    if kind in _DEGREE:
        return _bspline(values, dts, _DEGREE[kind])
    raise ValueError(f"not a path kind: {kind!r}")


def peaks(segments: Sequence[Segment]) -> tuple[float, float]:
    """(max |velocity|, max |acceleration|) over the segments, as MPI 000 Streaming Point Motion
    Type Calculations explains: acceleration is linear in a segment, so its extremes are at the
    segment ends (two comparisons per segment: accelerations need not be continuous); velocity
    is quadratic: its ends and, where the acceleration crosses zero inside, the vertex."""
    v_peak = a_peak = 0.0
    for seg in segments:
        _, v_end, a_end = seg.end_state()
        a_peak = max(a_peak, abs(seg.a), abs(a_end))
        v_peak = max(v_peak, abs(seg.v), abs(v_end))
        if seg.j != 0.0:
            vertex = -seg.a / seg.j  # where the acceleration is zero
            if 0.0 < vertex < seg.duration:
                # evaluated like every other state, so a sample near the vertex cannot beat it
                v_peak = max(v_peak, abs(seg.state_at(vertex)[1]))
    return v_peak, a_peak


def feedforward_segments(start_value: float, values: Sequence[float], times: Sequence[float]) -> list[Segment]:
    """PTF/PVTF feedforward, linearly interpolated over each interval (MPI 000 MPIMotionPTF:
    "When the motion reaches a specified position ... the interpolated feedforward value will be
    equal to what is specified"): segments whose 'p' is the feedforward value (v = slope, a = j = 0),
    starting from start_value (the feedforward the axis holds: it is kept between moves)."""
    return _linear([float(start_value)] + [float(f) for f in values], [float(dt) for dt in times])


# --- PT and the feedforward: straight lines between the knots ------------------------------


def _linear(values: list[float], dts: list[float]) -> list[Segment]:
    """MPI 000, Streaming Point Motion Type Calculations, PT Moves: "interpolate all points
    using constant velocity segments". Each segment starts exactly on its knot's value."""
    return [Segment(dt, values[i], (values[i + 1] - values[i]) / dt, 0.0, 0.0) for i, dt in enumerate(dts)]


# --- PVT and BESSEL: a cubic per interval from its end positions and velocities ----------------


def _hermite_interval(x0: float, v0: float, x1: float, v1: float, dt: float) -> Segment:
    """The cubic leaving (x0, v0) that arrives at (x1, v1) dt later, with the reference's own
    equations (MPI 000, Streaming Point Motion Type Calculations, PVT Moves) evaluated exactly as
    written here: this operation order is part of the interface (its results are compared to
    the bit), so do not rearrange it."""
    a0 = 6 * ((x1 - x0) / dt**2) - (2 * v1 + 4 * v0) / dt
    j = -12 * ((x1 - x0) / dt**3) + 6 * ((v1 + v0) / dt**2)
    return Segment(dt, x0, v0, a0, j)


def _hermite(values: list[float], tangents: list[float], dts: list[float]) -> list[Segment]:
    """One cubic Hermite piece per interval: each starts exactly on its knot and tangent, so
    position and velocity are continuous (up to rounding of the previous piece's end)."""
    return [
        _hermite_interval(values[i], tangents[i], values[i + 1], tangents[i + 1], dt)
        for i, dt in enumerate(dts)
    ]


def _bessel_tangents(values: list[float], dts: list[float]) -> list[float]:
    """Velocities at the knots for BESSEL: at an inner knot the slope there of the parabola
    through it and its two neighbours; at an end the slope of the end parabola at the end knot
    (de Boor, A Practical Guide to Splines, Bessel end condition); a straight line for one point.

    With slopes s and interval lengths h, the parabola through three knots has at its middle knot
    the slope (h_right * s_left + h_left * s_right) / (h_left + h_right): each side's slope
    weighted by the other side's length. Its slope at an outer knot is the adjacent chord slope
    pushed away from the other one by the chord's share of the two lengths.
    """
    slopes = [(values[i + 1] - values[i]) / dt for i, dt in enumerate(dts)]
    count = len(dts)
    if count == 1:
        return [slopes[0], slopes[0]]
    tangents = [0.0] * (count + 1)
    for i in range(1, count):
        h_left, h_right = dts[i - 1], dts[i]
        tangents[i] = (h_right * slopes[i - 1] + h_left * slopes[i]) / (h_left + h_right)
    tangents[0] = slopes[0] - (slopes[1] - slopes[0]) * dts[0] / (dts[0] + dts[1])
    tangents[count] = slopes[-1] + (slopes[-1] - slopes[-2]) * dts[-1] / (dts[-2] + dts[-1])
    return tangents


# --- SPLINE: the natural cubic spline -------------------------------------------------------


def _natural_accelerations(values: list[float], dts: list[float]) -> list[float]:
    """Second derivatives a_i of the natural cubic spline at every knot (a = 0 at both ends).

    MPI 000, Streaming Point Motion Type Calculations, Cubic Spline Moves: Numerical Recipes in C
    section 3.3 spline() "outputs identical results to MEI's algorithm". That is the tridiagonal
    elimination below, 0-based. Continuity of velocity at inner knot i gives, divided by
    (h_{i-1} + h_i) with w = h_{i-1} / (h_{i-1} + h_i):

        w * a_{i-1} + 2 * a_i + (1 - w) * a_{i+1} = 6 * (s_i - s_{i-1}) / (h_{i-1} + h_i)

    Sweeping forward, each row is reduced to a_i = factor_i * a_{i+1} + offset_i (with
    factor_0 = offset_0 = 0, the natural start); then a_n = 0 and the sweep back fills the rest.
    The interval lengths are the dts themselves, not differences of cumulative times, which
    are the same numbers but lose digits on a long path.
    """
    count = len(dts)
    factor = [0.0] * (count + 1)
    offset = [0.0] * (count + 1)
    for i in range(1, count):
        h_left, h_right = dts[i - 1], dts[i]
        span = h_left + h_right
        w = h_left / span
        pivot = w * factor[i - 1] + 2.0
        factor[i] = (w - 1.0) / pivot
        curvature = (values[i + 1] - values[i]) / h_right - (values[i] - values[i - 1]) / h_left
        offset[i] = (6.0 * curvature / span - w * offset[i - 1]) / pivot
    accelerations = [0.0] * (count + 1)
    for i in range(count - 1, 0, -1):
        accelerations[i] = factor[i] * accelerations[i + 1] + offset[i]
    return accelerations


def _natural_spline(values: list[float], dts: list[float]) -> list[Segment]:
    """The segments of the natural cubic spline: the reference's equations per interval, in its
    "or" form (its first form writes v_i where a_i is meant): x0 = x_i,
    v0 = dx/dt - (3*a + da)*dt/6, a0 = a_i, j = da/dt."""
    acc = _natural_accelerations(values, dts)
    segments = []
    for i, dt in enumerate(dts):
        da = acc[i + 1] - acc[i]
        v0 = (values[i + 1] - values[i]) / dt - (3.0 * acc[i] + da) * dt / 6.0
        segments.append(Segment(dt, values[i], v0, acc[i], da / dt))
    return segments


# --- BSPLINE and BSPLINE2: clamped B-splines with the start and the points as control points ---

_DEGREE = {PathKind.BSPLINE: 3, PathKind.BSPLINE2: 2}  # docs/paths.md: "3rd order" read as the degree
_KNOT_TOLERANCE = 1e-9  # seconds: knots computed by other sums of the same dts agree far closer


@dataclass(frozen=True, slots=True)
class SplineHistory:
    """A B-spline path's control points (the start, then every point so far, raw) and the dts
    of its points, and the profile time ``begin`` at which the curve starts: enough to plan the
    one B-spline of these points and of any appended to them."""

    kind: PathKind
    begin: float
    values: tuple[float, ...]
    dts: tuple[float, ...]

    def continued(self, shift: float, values: Sequence[float], dts: Sequence[float]) -> SplineHistory:
        """With more points, the curve starting ``shift`` later (a path that ran out waited)."""
        return SplineHistory(self.kind, self.begin + shift, self.values + tuple(values), self.dts + tuple(dts))

    def pieces(self, after: float, final: bool) -> list[Segment]:
        """The curve's segments from profile time ``after`` (one of its knots) to its end, or,
        while more points may come (``final`` false), to where it is settled."""
        until = math.inf if final else self.settled_until() - _KNOT_TOLERANCE
        out, t = [], self.begin
        for segment in path_segments(self.kind, self.values[0], 0.0, self.values[1:], self.dts):
            if after - _KNOT_TOLERANCE <= t < until:
                out.append(segment)
            t += segment.duration
        return out

    def end_time(self) -> float:
        """Profile time of the last point."""
        return self.begin + math.fsum(self.dts)

    def settled_until(self) -> float:
        """The profile time up to which the curve stays what it is whatever points are appended.

        The piece on knot interval i depends on the knots u_{i-k+1} .. u_{i+k} and the control
        points c_{i-k} .. c_i (de Boor). Appended points leave the control points and the inner
        knots u_{k+1} .. u_n of n points as they are and replace the end knots, so the pieces up
        to interval n-k are final: the curve is settled up to u_{n-k+1}. With fewer points than
        the degree needs, more points raise the degree and change all of it."""
        degree, count = _DEGREE[self.kind], len(self.dts)
        if count < degree:
            return self.begin
        knot_times = [0.0]
        for dt in self.dts:
            knot_times.append(knot_times[-1] + dt)
        knots = _clamped_knots(knot_times, degree)
        return self.begin + knots[count - degree + 1]


def _clamped_knots(knot_times: list[float], degree: int) -> list[float]:
    """The knot vector: the first and last time repeated degree+1 times (so the path starts on the
    start and ends on the last point), the inner knots by knot averaging (Piegl & Tiller, The NURBS
    Book, eq. 9.8): u_{j+k} = (T_j + ... + T_{j+k-1}) / k, j = 1..n-k. n+1 control points leave
    room for only n-k inner knots, so they cannot all be point times."""
    last = len(knot_times) - 1
    inner = [sum(knot_times[j:j + degree]) / degree for j in range(1, last - degree + 1)]
    return [knot_times[0]] * (degree + 1) + inner + [knot_times[last]] * (degree + 1)


def _derivative(knots: list[float], control: list[float], degree: int) -> tuple[list[float], list[float]]:
    """The derivative of a B-spline: degree-1 on the knots without their first and last, with
    control points degree * (c_{i+1} - c_i) / (u_{i+degree+1} - u_{i+1}). A zero span (only
    where knots coincide) belongs to a basis function that is zero everywhere: its point is 0."""
    points = []
    for i in range(len(control) - 1):
        span = knots[i + degree + 1] - knots[i + 1]
        points.append(degree * (control[i + 1] - control[i]) / span if span > 0.0 else 0.0)
    return knots[1:-1], points


def _de_boor(knots: list[float], control: list[float], degree: int, interval: int, t: float) -> float:
    """The B-spline's value at t in knot interval ``interval`` (knots[interval] <= t <=
    knots[interval+1]): repeated convex combinations of the degree+1 control points that act
    there (de Boor's algorithm): convex combinations, so rounding stays at the size of the points."""
    base = interval - degree
    points = control[base:interval + 1]
    for level in range(1, degree + 1):
        for r in range(degree, level - 1, -1):
            left = knots[base + r]
            span = knots[base + r + degree + 1 - level] - left
            weight = (t - left) / span if span > 0.0 else 0.0
            points[r] = (1.0 - weight) * points[r - 1] + weight * points[r]
    return points[degree]


def _bspline(values: list[float], dts: list[float], degree: int) -> list[Segment]:
    """One constant-jerk segment per non-empty knot interval of the clamped B-spline whose control
    points are the start and the points. With fewer than degree+1 control points the degree drops
    to what they allow (one point: a straight line). Each piece's position, velocity,
    acceleration and jerk at its start come from the spline and its derivative splines, so no
    error accumulates from piece to piece."""
    knot_times = [0.0]
    for dt in dts:
        knot_times.append(knot_times[-1] + dt)
    knot_times[-1] = sum(dts)  # the path ends at sum(times), however sum() adds
    used = min(degree, len(values) - 1)  # the degree the control points allow
    # the spline and its derivatives up to the jerk (those above the degree are zero)
    splines = [(_clamped_knots(knot_times, used), list(values))]
    for r in range(1, used + 1):
        splines.append(_derivative(*splines[-1], used - r + 1))
    knot_vector = splines[0][0]
    segments = []
    elapsed = 0.0  # the segments' durations added up, as a caller adds them
    for interval in range(used, len(values)):
        start, end = knot_vector[interval], knot_vector[interval + 1]
        # measured from where the previous durations add up to, not from the knot: the sum of
        # the durations then lands on the last knot (sum(times)) exactly, or within one ulp in
        # the rare case where rounding to even cannot get there
        duration = end - elapsed
        if not (end > start and duration > 0.0):
            continue
        state = [0.0] * 4
        for r, (r_knots, r_control) in enumerate(splines):
            # the r-th derivative's knots drop r at each end: this interval is number interval - r
            state[r] = _de_boor(r_knots, r_control, used - r, interval - r, start)
        segments.append(Segment(duration, *state))
        elapsed += duration
    return segments


__all__ = ["PathKind", "SplineHistory", "feedforward_segments", "path_segments", "peaks"]
