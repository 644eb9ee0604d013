"""S-curve reshaping (mpi_ros/mpi/planning/profiles/scurve.py): each trapezoid ramp keeps its duration
(docs/profiles.md, "The trapezoid and the S-curve"), cross-checked against ruckig."""

from __future__ import annotations

import math

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from mpi_ros.mpi.planning.profiles.point_to_point import point_to_point
from mpi_ros.mpi.planning.profiles.ramps import ProfileError, Ramp, plan_point_to_point, trapezoid_rows
from mpi_ros.mpi.planning.profiles.scurve import reshape, reshaped
from mpi_ros.mpi.planning.profiles.segment import Segment, end_time


def test_jerk_phases_and_peak():
    # docs/profiles.md, "The trapezoid and the S-curve": jerk phases of f*Ta/2, constant acceleration
    # for (1-f)*Ta, peak acceleration A/(1 - f/2)
    ramp = Ramp(0.1, 0.0, 1000.0)  # A = 10000
    (t1, _, _, a1, j1), (t2, _, _, a2, j2), (t3, _, _, _a3, j3) = reshape([ramp], 0.0, 50.0)
    assert (t1, t2, t3) == pytest.approx((0.025, 0.05, 0.025))
    assert a2 == pytest.approx(10_000.0 / 0.75)
    assert j2 == 0.0
    assert j1 == pytest.approx(-j3)
    assert a1 == 0.0


@pytest.mark.parametrize(("percent", "peak"), [(0.0, 1.0), (50.0, 4.0 / 3.0), (100.0, 2.0)])
def test_peak_acceleration_100_133_200_percent(percent, peak):
    # docs/profiles.md: the peak is A, 4/3 A, 2 A at f = 0, 0.5, 1
    segments = reshape([Ramp(0.1, 0.0, 1000.0)], 0.0, percent)
    accelerations = [s.a for s in segments] + [s.end_state()[2] for s in segments]
    assert max(abs(a) for a in accelerations) == pytest.approx(10_000.0 * peak)


@pytest.mark.parametrize("percent", [0.0, 10.0, 50.0, 90.0, 100.0])
def test_each_ramp_keeps_its_duration_and_distance(percent):
    # docs/profiles.md: each ramp is reshaped keeping its duration, so an S-curve move takes exactly as
    # long as the trapezoid with the same limits
    plan = plan_point_to_point(5000.0, 0.0, 0.0, 1000.0, 10_000.0, 4_000.0)
    segments = reshape(plan, 0.0, percent)
    assert sum(s.duration for s in segments) == pytest.approx(sum(r.duration for r in plan))
    p, v, a = segments[-1].end_state()
    assert p == pytest.approx(5000.0)
    assert v == pytest.approx(0.0, abs=1e-9)
    if percent > 0.0:
        assert a == pytest.approx(0.0, abs=1e-6)  # an S-curve ramp ends with zero acceleration


@pytest.mark.parametrize("percent", [10.0, 50.0, 100.0])
def test_jerk_is_4a2_over_f_2_minus_f_v(percent):
    # docs/profiles.md, "The cross-check against ruckig": the equivalent problem has
    # max_acceleration = A/(1 - f/2) and max_jerk = 4*A^2/(f*(2-f)*v)
    f, acc, v = percent / 100.0, 10_000.0, 1000.0
    segments = point_to_point(0.0, 0.0, 20_000.0, 0.0, v, acc, acc, percent)
    jerk = max(abs(s.j) for s in segments)
    assert jerk == pytest.approx(4.0 * acc * acc / (f * (2.0 - f) * v))


def test_zero_percent_is_the_trapezoid():
    # scurve.py: "f = 0 is the trapezoid itself"
    plan = plan_point_to_point(3000.0, 0.0, 0.0, 1000.0, 10_000.0, 5_000.0)
    segments = reshape(plan, 0.0, 0.0)
    assert all(s.j == 0.0 for s in segments)
    assert len(segments) == len(plan)


def test_every_ramp_starts_from_zero_acceleration():
    # docs/profiles.md, "Modify: from the current state": the standard S-curve starts from acceleration 0
    segments = point_to_point(0.0, 500.0, 3000.0, 0.0, 1000.0, 10_000.0, 10_000.0, 40.0)
    assert segments[0].a == 0.0


@pytest.mark.parametrize("percent", [-1.0, 100.5])
def test_jerk_percent_range(percent):
    with pytest.raises(ProfileError):
        reshape([Ramp(1.0, 0.0, 1.0)], 0.0, percent)


@pytest.mark.parametrize(("percent", "distance"), [(0.0, 10_000.0), (30.0, 10_000.0), (50.0, 5000.0),
                                              (100.0, 3000.0), (75.0, 20_000.0)])
def test_duration_equals_ruckig(percent, distance):
    # docs/quality.md, "Correct motion": S-curve/trapezoid durations equal ruckig's time-optimal duration
    # for the equivalent limits wherever the two models coincide (long moves, accel = decel)
    import ruckig
    f, acc, v = percent / 100.0, 10_000.0, 1000.0
    inp = ruckig.InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [distance], [0.0], [0.0]
    inp.max_velocity = [v]
    inp.max_acceleration = [acc / (1.0 - f / 2.0)]
    inp.max_jerk = [4.0 * acc * acc / (f * (2.0 - f) * v)] if f > 0.0 else [float("inf")]
    trajectory = ruckig.Trajectory(1)
    assert ruckig.Ruckig(1).calculate(inp, trajectory) in (ruckig.Result.Working, ruckig.Result.Finished)
    segments = point_to_point(0.0, 0.0, distance, 0.0, v, acc, acc, percent)
    assert sum(s.duration for s in segments) == pytest.approx(trajectory.duration, abs=1e-9)


@pytest.mark.parametrize("percent", [5e-324, 1e-310, 3.086571890462606e-308, 1e-200])
def test_tiny_jerk_percent_stays_finite(percent):
    # docs/quality.md, "Robust": no input can crash a node or leave it inconsistent; a jerk phase too short
    # to represent must not make the jerk infinite (and the positions NaN); it is a trapezoid ramp
    segments = point_to_point(0.0, 0.0, 10.0, 0.0, 50.0, 500.0, 500.0, percent)
    for seg in segments:
        assert all(math.isfinite(x) for x in (seg.p, seg.v, seg.a, seg.j, *seg.end_state()))
    assert segments[-1].end_state()[0] == pytest.approx(10.0)


@pytest.mark.parametrize(("ramp", "percent"), [(Ramp(0.0, 0.0, 5e-324), 100.0), (Ramp(5e-324, 0.0, 1e-300), 100.0),
                                          (Ramp(1e-300, 0.0, 1e-290), 1e-20)])
def test_ramp_too_short_to_reshape(ramp, percent):
    # docs/quality.md, "Robust" (no input can crash): a ramp whose duration underflows (a VELOCITY move to
    # 5e-324 counts/s) is kept as the trapezoid's ramp instead of dividing by zero
    for segment in reshape([ramp], 0.0, percent):
        assert all(math.isfinite(x) for x in (*segment, *segment.end_state()))


@settings(max_examples=300, derandomize=True, deadline=None, database=None)
@given(distance=st.floats(-1e6, 1e6), v_start=st.floats(-2e4, 2e4), vmax=st.floats(1.0, 1e4),
       accel=st.floats(10.0, 1e6), decel=st.floats(10.0, 1e6), percent=st.floats(0.0, 100.0),
       p0=st.floats(-1e6, 1e6))
def test_each_segment_starts_exactly_where_the_one_before_ends(distance, v_start, vmax, accel, decel, percent, p0):
    # What the planner relies on (planner._finite_if_it_ends): each piece starts at the position
    # Segment.end_state gives for the one before, to the bit; the end and the duration reshaped
    # answers are end_state's and end_time's; Rows and Segments hold the same values.
    try:
        plan = trapezoid_rows(distance, v_start, 0.0, vmax, accel, decel)
    except ProfileError:
        assume(False)
    segments, end, total = reshaped(plan, p0, percent)
    rows, row_end, row_total = reshaped(plan, p0, percent, rows=True)
    assert segments == [Segment._make(row) for row in rows]
    assert all(type(segment) is Segment for segment in segments)
    assert (row_end, row_total) == (end, total)
    position = p0
    for segment in segments:
        assert segment.duration > 0.0
        assert segment.p == position
        position = segment.end_state()[0]
    assert end == position
    assert total == (end_time(segments) if segments else 0.0)
