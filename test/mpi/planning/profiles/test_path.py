"""The path motion types (mpi_ros/mpi/planning/profiles/path.py) against independent implementations.

Every kind is checked at every sample of a 2 kHz grid and at both ends of every segment against
numpy / scipy: PT against numpy.interp, PVT against CubicHermiteSpline, SPLINE against
CubicSpline(bc_type="natural"), BESSEL against CubicHermiteSpline with tangents from
numpy.polyfit parabolas, BSPLINE / BSPLINE2 against scipy's BSpline on knots built here from the
rule in docs/paths.md. Segment i is compared with the reference's piece i on its closed interval,
so a quantity that jumps at a knot (PVT's acceleration, say) is compared on both sides of the jump.

Tolerances: position, velocity and acceleration within RTOL = 1e-12 times the largest magnitude
of that quantity anywhere on the path (or of the terms that cancel in it, see assert_matches).
The errors reached are around 1e-15 to 1e-13 of that: scipy solves the same equations in
another order, and the acceleration of a cubic Hermite piece is a difference of terms of size
dx/dt^2, so it loses the most.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline, CubicHermiteSpline, CubicSpline, PPoly

from mpi_ros.mpi.planning.profiles.path import PathKind, feedforward_segments, path_segments, peaks
from mpi_ros.mpi.planning.profiles.segment import Segment, SegmentTable, total_duration

RATE = 2000.0
RTOL = 1e-12  # of the largest |value| of that quantity on the path
ROUNDING = 1e-11  # of the magnitudes of the terms that make up a value (contiguity, knots)
SETTINGS = dict(derandomize=True, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])
INTERPOLATING = (PathKind.PT, PathKind.PVT, PathKind.SPLINE, PathKind.BESSEL)
BSPLINES = {PathKind.BSPLINE: 3, PathKind.BSPLINE2: 2}


def case(seed: int, count: int):
    """A path in counts and seconds: a random walk of up to 2e4 counts per point, 1 ms to 0.4 s
    between points (uneven on purpose), velocities up to 2e5 counts/s."""
    rng = np.random.default_rng(seed)
    start = 1234.5
    times = rng.uniform(0.001, 0.4, count).tolist()
    positions = (start + np.cumsum(rng.uniform(-2e4, 2e4, count))).tolist()
    velocities = rng.uniform(-2e5, 2e5, count).tolist()
    return start, float(rng.uniform(-2e5, 2e5)), positions, times, velocities


# one to three points exercise the degree drops of the B-splines and the short Bessel/spline cases;
# the last case has its knots on the 2 kHz grid (up to the rounding of their sums)
CASES = [case(seed, count) for seed, count in enumerate((1, 2, 3, 4, 5, 8, 30))]
CASES.append((-50.0, 0.0, [0.0, 100.0, 100.0, -20.0, 35.0, 35.5, 400.0, 0.0], [0.01] * 8, [0.0] * 8))


def knot_times(times) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(times)])


def knot_values(start, positions) -> np.ndarray:
    return np.concatenate([[start], positions])


def pieces_of(poly: PPoly) -> list[PPoly]:
    """The reference's non-empty pieces, each on its own (a B-spline's PPoly has empty ones at
    the repeated end knots)."""
    keep = np.nonzero(np.diff(poly.x) > 0.0)[0]
    return [PPoly(poly.c[:, i:i + 1], poly.x[i:i + 2]) for i in keep]


def assert_matches(segments: list[Segment], pieces, values: np.ndarray, times) -> list[float]:
    """Segment i against reference piece i (a callable (t, derivative) -> values) at every 2 kHz
    sample of its closed interval and at its ends; returns the worst relative error per quantity.
    The scale of the k-th derivative is its largest magnitude on the path, or the largest
    |x_{i+1} - x_i| / dt_i^k if that is larger: a quantity that is zero everywhere (a straight
    line's acceleration) is then judged by the size of the terms that cancel in it."""
    assert len(segments) == len(pieces)
    starts = knot_times([s.duration for s in segments])
    grid = np.arange(int(starts[-1] * RATE) + 1) / RATE
    mine: list[list[np.ndarray]] = [[], [], []]
    theirs: list[list[np.ndarray]] = [[], [], []]
    for seg, piece, t0, t1 in zip(segments, pieces, starts, starts[1:], strict=False):
        t = np.concatenate([[t0], grid[(grid >= t0) & (grid <= t1)], [t1]])
        for order, value in enumerate(seg.state_at(t - t0)):
            mine[order].append(np.broadcast_to(value, t.shape))
            theirs[order].append(np.broadcast_to(piece(t, order), t.shape))
    worst = []
    for order in range(3):
        got, want = np.concatenate(mine[order]), np.concatenate(theirs[order])
        step = float(np.max(np.abs(np.diff(values)) / np.asarray(times) ** order))
        scale = max(float(np.max(np.abs(want))), step, 1e-300)
        np.testing.assert_allclose(got, want, rtol=0.0, atol=RTOL * scale, err_msg=f"derivative {order}")
        worst.append(float(np.max(np.abs(got - want))) / scale)
    return worst


def polynomial_pieces(poly: PPoly):
    return [lambda t, order, p=p: p(t, order) for p in pieces_of(poly)]


def parabola_tangents(x: np.ndarray, y: np.ndarray) -> list[float]:
    """The slope at each knot of the parabola through it and its neighbours (the end ones: the
    first or last three knots), by least squares on exactly three points, i.e. interpolation."""
    if len(x) == 2:
        slope = (y[1] - y[0]) / (x[1] - x[0])
        return [slope, slope]
    tangents = []
    for i in range(len(x)):
        lo = min(max(i - 1, 0), len(x) - 3)
        coefficients = np.polyfit(x[lo:lo + 3] - x[i], y[lo:lo + 3], 2)
        tangents.append(float(coefficients[1]))  # d/dt of c0 t^2 + c1 t + c2 at t = 0
    return tangents


def reference_knot_vector(times, degree: int) -> np.ndarray:
    """Clamped, with inner knots by knot averaging (Piegl & Tiller, The NURBS Book, eq. 9.8)."""
    t = knot_times(times)
    n = len(t) - 1
    k = min(degree, n)
    inner = [np.mean(t[j:j + k]) for j in range(1, n - k + 1)]
    return np.concatenate([[0.0] * (k + 1), inner, [t[-1]] * (k + 1)])


# --- each kind against an independent implementation -------------------------------------


@pytest.mark.parametrize(("start", "start_velocity", "positions", "times", "velocities"), CASES)
def test_pt_is_numpy_interp(start, start_velocity, positions, times, velocities):
    # MPI 000, Streaming Point Motion Type Calculations, PT Moves: "constant velocity segments"
    segments = path_segments(PathKind.PT, start, start_velocity, positions, times)
    x, y = knot_times(times), knot_values(start, positions)
    slopes = np.diff(y) / np.diff(x)

    def piece(i):
        return lambda t, order: (np.interp(t, x, y), np.full(t.shape, slopes[i]), np.zeros(t.shape))[order]

    assert_matches(segments, [piece(i) for i in range(len(times))], y, times)


@pytest.mark.parametrize(("start", "start_velocity", "positions", "times", "velocities"), CASES)
def test_pvt_is_the_cubic_hermite_spline(start, start_velocity, positions, times, velocities):
    # MPI 000, Streaming Point Motion Type Calculations, PVT Moves: position and velocity at both ends
    segments = path_segments(PathKind.PVT, start, start_velocity, positions, times, velocities)
    reference = CubicHermiteSpline(knot_times(times), knot_values(start, positions),
                                   knot_values(start_velocity, velocities))
    assert_matches(segments, polynomial_pieces(reference), knot_values(start, positions), times)


@pytest.mark.parametrize(("start", "start_velocity", "positions", "times", "velocities"), CASES)
def test_spline_is_the_natural_cubic_spline(start, start_velocity, positions, times, velocities):
    # MPI 000, Streaming Point Motion Type Calculations, Cubic Spline Moves: "a natural cubic spline"
    segments = path_segments(PathKind.SPLINE, start, start_velocity, positions, times)
    reference = CubicSpline(knot_times(times), knot_values(start, positions), bc_type="natural")
    assert_matches(segments, polynomial_pieces(reference), knot_values(start, positions), times)
    assert segments[0].a == 0.0
    assert segments[-1].end_state()[2] == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize(("start", "start_velocity", "positions", "times", "velocities"), CASES)
def test_bessel_is_hermite_with_parabola_tangents(start, start_velocity, positions, times, velocities):
    # MPI 000, MPIMotionTypeBESSEL BESSEL "fits a Bessel spline"; de Boor's Bessel tangents and end condition
    segments = path_segments(PathKind.BESSEL, start, start_velocity, positions, times)
    x, y = knot_times(times), knot_values(start, positions)
    reference = CubicHermiteSpline(x, y, parabola_tangents(x, y))
    assert_matches(segments, polynomial_pieces(reference), knot_values(start, positions), times)


@pytest.mark.parametrize("kind", list(BSPLINES))
@pytest.mark.parametrize(("start", "start_velocity", "positions", "times", "velocities"), CASES)
def test_bspline_is_scipys_bspline(kind, start, start_velocity, positions, times, velocities):
    # MPI 000, MPIMotionTypeBSPLINE / BSPLINE2: "3rd order" / "2nd order B spline"
    segments = path_segments(kind, start, start_velocity, positions, times)
    knots = reference_knot_vector(times, BSPLINES[kind])
    degree = min(BSPLINES[kind], len(positions))
    reference = BSpline(knots, knot_values(start, positions), degree)
    pieces = polynomial_pieces(PPoly.from_spline(reference))
    assert_matches(segments, pieces, knot_values(start, positions), times)
    assert len(segments) == len(positions) - degree + 1  # one per knot interval


# --- the reference's equations, literally ---------------------------------------------------


def test_pvt_uses_the_reference_equations_to_the_bit():
    # MPI 000, Streaming Point Motion Type Calculations, PVT Moves: a0 and j of each interval
    x_start, v_start = 0.1, 0.7
    positions, velocities, times = [3.3, -2.45], [-1.9, 11.0 / 3.0], [0.37, 0.0123]
    segments = path_segments(PathKind.PVT, x_start, v_start, positions, times, velocities)
    ends = [(x_start, v_start), *list(zip(positions, velocities, strict=True))]
    for seg, (x0, v0), (x1, v1), dt in zip(segments, ends, ends[1:], times, strict=False):
        assert (seg.duration, seg.p, seg.v) == (dt, x0, v0)
        assert seg.a == 6 * ((x1 - x0) / dt**2) - (2 * v1 + 4 * v0) / dt
        assert seg.j == -12 * ((x1 - x0) / dt**3) + 6 * ((v1 + v0) / dt**2)


def test_spline_velocity_is_the_or_form_not_the_typo():
    # MPI 000, Cubic Spline Moves: v0 = dx/dt - (3a + da) dt / 6; its first form writes v_i for a_i
    times, positions = [0.2, 0.05, 0.3], [10.0, 4.0, 30.0]
    segments = path_segments(PathKind.SPLINE, 0.0, 0.0, positions, times)
    x, y = knot_times(times), knot_values(0.0, positions)
    acc = CubicSpline(x, y, bc_type="natural")(x, 2)
    for i, (seg, dt) in enumerate(zip(segments, times, strict=True)):
        dx, da = y[i + 1] - y[i], acc[i + 1] - acc[i]
        assert seg.v == pytest.approx(dx / dt - (3 * acc[i] + da) * dt / 6, rel=1e-12)
        assert seg.a == pytest.approx(acc[i], abs=1e-9)
        assert seg.j == pytest.approx(da / dt, rel=1e-9)


# --- shapes a user should know about ---------------------------------------------------------


@pytest.mark.parametrize("kind", list(PathKind))
def test_one_point_is_a_straight_line_except_pvt(kind):
    # two knots: the natural spline, Bessel (no parabola) and both B-splines (degree 1) are the line
    segments = path_segments(kind, 10.0, 0.0, [30.0], [0.5], [0.0])
    if kind is PathKind.PVT:
        assert segments[0].v == 0.0
        assert segments[0].end_state()[1] == pytest.approx(0.0, abs=1e-12)
        return
    assert segments == [Segment(0.5, 10.0, 40.0, 0.0, 0.0)]


def test_bspline_passes_near_not_through_the_inner_points():
    # docs/paths.md: the points are control points; only the start and the last point are on the path
    times, positions = [0.1] * 4, [100.0, 0.0, 100.0, 0.0]
    for kind in BSPLINES:
        table = SegmentTable(path_segments(kind, 0.0, 0.0, positions, times))
        at_points = table.evaluate(knot_times(times))[0]
        assert at_points[0] == 0.0
        assert at_points[-1] == pytest.approx(0.0, abs=1e-9)
        assert all(abs(p - x) > 1.0 for p, x in zip(at_points[1:-1], positions[:-1], strict=True))


def test_bspline_timing_is_not_the_points_timing():
    # docs/paths.md: points on a line at a constant 1 count/s; only the Greville-placed ones keep time
    positions, times = [float(i) for i in range(1, 9)], [1.0] * 8
    cubic = path_segments(PathKind.BSPLINE, 0.0, 0.0, positions, times)
    quadratic = path_segments(PathKind.BSPLINE2, 0.0, 0.0, positions, times)
    assert [s.v for s in cubic] == pytest.approx([1.5, 5 / 6, 7 / 8, 1.0, 7 / 8, 5 / 6], rel=1e-12)
    assert [s.v for s in quadratic] == pytest.approx([4 / 3, 0.8, 1.0, 1.0, 1.0, 1.0, 0.8], rel=1e-12)


def test_spline_and_bspline_start_with_a_velocity_step():
    # MPI 000, Cubic Spline Moves: "there may be instantaneous changes in velocity when starting"
    for kind in (PathKind.SPLINE, PathKind.BSPLINE, PathKind.BSPLINE2, PathKind.BESSEL):
        assert path_segments(kind, 0.0, 0.0, [10.0, 30.0], [0.1, 0.1])[0].v != 0.0


# --- properties over random paths -----------------------------------------------------------


@st.composite
def paths(draw):
    count = draw(st.integers(1, 8))

    # No subnormals: the relative rounding bounds below do not hold for them (halving 5e-324
    # gives 0 or 5e-324), and a position or velocity of 1e-310 counts means nothing.
    def floats(low, high):
        return st.floats(low, high, allow_subnormal=False)

    def values(bound):
        return draw(st.lists(floats(-bound, bound), min_size=count, max_size=count))

    times = draw(st.lists(floats(1e-3, 1.0), min_size=count, max_size=count))
    return draw(floats(-1e4, 1e4)), draw(floats(-1e5, 1e5)), values(1e4), times, values(1e5)


def term_sizes(seg: Segment, t: float) -> tuple[float, float, float]:
    """The sum of the magnitudes of the terms that make up position, velocity and acceleration
    ``t`` into the segment: what rounding is proportional to."""
    p, v, a, j = abs(seg.p), abs(seg.v), abs(seg.a), abs(seg.j)
    return (p + t * (v + t * (a / 2 + t * j / 6)), v + t * (a + t * j / 2), a + t * j)


def close(x: float, y: float, size: float) -> bool:
    return abs(x - y) <= ROUNDING * size


@settings(max_examples=120, **SETTINGS)
@given(paths(), st.sampled_from(list(PathKind)))
def test_paths_are_contiguous_finite_and_cover_the_times(path, kind):
    start, start_velocity, positions, times, velocities = path
    segments = path_segments(kind, start, start_velocity, positions, times, velocities)
    assert all(seg.duration > 0.0 for seg in segments)
    assert all(math.isfinite(x) for seg in segments for x in (seg.duration, seg.p, seg.v, seg.a, seg.j))
    if kind in BSPLINES:  # inner knots are averages, not sums of the dts (docs/paths.md)
        assert abs(total_duration(segments) - sum(times)) <= math.ulp(sum(times))
    else:
        assert total_duration(segments) == sum(times)
    # which of position, velocity, acceleration are continuous at the joints
    continuous = {PathKind.PT: 1, PathKind.PVT: 2, PathKind.BESSEL: 2, PathKind.BSPLINE2: 2}.get(kind, 3)
    for before, after in itertools.pairwise(segments):
        sizes = [s + n for s, n in zip(term_sizes(before, before.duration), term_sizes(after, 0.0), strict=True)]
        for order in range(continuous):
            assert close(before.end_state()[order], (after.p, after.v, after.a)[order], sizes[order])


@settings(max_examples=80, **SETTINGS)
@given(paths(), st.sampled_from(INTERPOLATING))
def test_interpolating_paths_pass_through_every_point_at_its_time(path, kind):
    start, start_velocity, positions, times, velocities = path
    segments = path_segments(kind, start, start_velocity, positions, times, velocities)
    assert len(segments) == len(times)
    assert segments[0].p == start
    for i, seg in enumerate(segments):
        p, v, _ = seg.end_state()
        assert close(p, positions[i], term_sizes(seg, seg.duration)[0])
        if kind is PathKind.PVT:
            assert close(v, velocities[i], term_sizes(seg, seg.duration)[1])
        if i + 1 < len(segments):
            assert segments[i + 1].p == positions[i]  # the next one starts exactly on the point


@settings(max_examples=60, **SETTINGS)
@given(paths(), st.sampled_from(list(BSPLINES)))
def test_bsplines_start_at_the_start_and_end_on_the_last_point(path, kind):
    start, start_velocity, positions, times, _velocities = path
    segments = path_segments(kind, start, start_velocity, positions, times)
    assert segments[0].p == start
    last = segments[-1]
    assert close(last.end_state()[0], positions[-1], term_sizes(last, last.duration)[0])


@settings(max_examples=80, **SETTINGS)
@given(paths(), st.sampled_from(list(PathKind)))
def test_peaks_bound_and_match_dense_sampling(path, kind):
    # MPI 000, Streaming Point Motion Type Calculations: the maxima from the segment ends (and the
    # velocity's vertex), checked against 400 samples per segment including both ends
    start, start_velocity, positions, times, velocities = path
    segments = path_segments(kind, start, start_velocity, positions, times, velocities)
    v_peak, a_peak = peaks(segments)
    v_sampled = a_sampled = 0.0
    between = 0.0  # how far the largest |v| can hide between two samples: |j| (step/2)^2 / 2
    rounding = 0.0  # the rounding of one velocity
    for seg in segments:
        t = np.linspace(0.0, seg.duration, 400)
        _, v, a = seg.state_at(t)
        v_sampled = max(v_sampled, float(np.max(np.abs(v))))
        a_sampled = max(a_sampled, float(np.max(np.abs(a))))
        between = max(between, abs(seg.j) * (seg.duration / 399) ** 2 / 8)
        rounding = max(rounding, ROUNDING * term_sizes(seg, seg.duration)[1])
    assert a_peak == a_sampled  # the ends are sampled: the very same numbers
    assert v_peak >= v_sampled - rounding  # never below
    assert v_peak <= v_sampled + between + rounding


def test_peaks_of_known_segments():
    # the vertex inside a segment, and a jump of acceleration between segments
    rise = Segment(1.0, 0.0, 0.0, 2.0, -4.0)  # v = 2t - 2t^2: 0.5 at t = 0.5, a from 2 to -2
    jump = Segment(1.0, 0.0, 0.0, 3.0, 0.0)  # a jumps from -2 to 3
    assert peaks([rise]) == (0.5, 2.0)
    assert peaks([rise, jump]) == (3.0, 3.0)
    assert peaks([Segment(1.0, 0.0, 1.0, 1.0, 1.0)]) == (2.5, 2.0)  # vertex outside: the ends
    assert peaks([]) == (0.0, 0.0)


# --- feedforward -----------------------------------------------------------------------------


@settings(max_examples=60, **SETTINGS)
@given(paths())
def test_feedforward_reaches_each_value_at_its_point_and_is_linear_between(path):
    # MPI 000, MPIMotionPTF: "When the motion reaches a specified position ... the interpolated
    # feedforward value will be equal to what is specified"; it starts from the value it holds
    start, _, values, times, _ = path
    segments = feedforward_segments(start, values, times)
    assert total_duration(segments) == sum(times)
    for seg, before, value, dt in zip(segments, [start, *values], values, times, strict=False):
        assert (seg.duration, seg.p, seg.a, seg.j) == (dt, before, 0.0, 0.0)
        assert close(seg.end_state()[0], value, abs(before) + abs(seg.v) * dt)
        middle = seg.state_at(dt / 2)[0]
        assert close(middle, (before + value) / 2, abs(before) + abs(value))
