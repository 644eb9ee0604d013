"""How requests map to ruckig problems (mpi_ros/crosscheck/mapping.py) and how ruckig is run
(solver.py). docs/profiles.md sections cited per test."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from mpi_ros.crosscheck import ProfileRequest, Reason, Verdict, check_request
from mpi_ros.crosscheck.mapping import (
    map_point_to_point,
    map_velocity,
    peak_acceleration,
    ramp_jerk,
    reached_velocity,
    reverses,
)
from mpi_ros.crosscheck.result import RuckigLimits
from mpi_ros.crosscheck.sampling import sample
from mpi_ros.crosscheck.solver import RuckigFailed, solve
from mpi_ros.mpi.base.types import MPIMotionType


def test_peak_acceleration_is_100_133_200_percent():
    # docs/profiles.md, "The trapezoid and the S-curve": the peak is A, 4/3 A, 2 A at f = 0, 0.5, 1
    assert peak_acceleration(3000.0, 0.0) == 3000.0
    assert peak_acceleration(3000.0, 0.5) == pytest.approx(4000.0)
    assert peak_acceleration(3000.0, 1.0) == 6000.0


def test_jerk_is_4A2_over_f_2minusf_v_and_infinite_at_f0():
    # docs/profiles.md, "The cross-check against ruckig": max_jerk = 4*A^2/(f*(2-f)*v) (infinite at f = 0)
    assert ramp_jerk(5000.0, 0.5, 500.0) == pytest.approx(4 * 5000.0**2 / (0.5 * 1.5 * 500.0))
    assert ramp_jerk(5000.0, 0.0, 500.0) == math.inf
    # the jerk phase f*Ta/2 (docs/profiles.md, "The trapezoid and the S-curve") reaches the peak A/(1-f/2) at that jerk
    a, f, v = 5000.0, 0.3, 400.0
    assert peak_acceleration(a, f) / ramp_jerk(a, f, v) == pytest.approx(f * (v / a) / 2)


def test_long_symmetric_scurve_maps_exactly():
    m = map_point_to_point(0.0, 0.0, 0.0, 1000.0, 0.0, 500.0, 5000.0, 5000.0, 50.0)
    assert m.exact
    assert not m.reasons
    # set explicitly: ruckig's default is 0 (docs/profiles.md, "ruckig's pitfalls")
    assert m.limits.max_velocity == 500.0
    assert m.limits.max_acceleration == pytest.approx(5000.0 / 0.75)
    assert m.limits.min_acceleration == -m.limits.max_acceleration
    assert m.limits.max_jerk == pytest.approx(4 * 5000.0**2 / (0.5 * 1.5 * 500.0))


def test_short_move_takes_the_jerk_from_the_velocity_reached():
    # docs/profiles.md, "The cross-check against ruckig": a short move that never reaches v takes the jerk from the
    # velocity it actually reaches
    m = map_point_to_point(0.0, 0.0, 0.0, 10.0, 0.0, 500.0, 5000.0, 5000.0, 50.0)
    w = math.sqrt(5000.0 * 10.0)
    assert reached_velocity(10.0, 500.0, 5000.0, 5000.0) == pytest.approx(w)
    assert m.exact
    assert m.limits.max_jerk == pytest.approx(ramp_jerk(5000.0, 0.5, w))
    assert any("velocity reached" in note for note in m.notes)
    result = check_request(ProfileRequest(MPIMotionType.S_CURVE, 500.0, 5000.0, jerk_percent=50.0, target=10.0))
    assert result.verdict is Verdict.AGREE


def test_trapezoid_with_accel_ne_decel_swaps_signed_limits_with_the_direction():
    forward = map_point_to_point(0.0, 0.0, 0.0, 1000.0, 0.0, 500.0, 5000.0, 2000.0, 0.0)
    backward = map_point_to_point(0.0, 0.0, 0.0, -1000.0, 0.0, 500.0, 5000.0, 2000.0, 0.0)
    assert (forward.limits.max_acceleration, forward.limits.min_acceleration) == (5000.0, -2000.0)
    assert (backward.limits.max_acceleration, backward.limits.min_acceleration) == (2000.0, -5000.0)
    assert forward.exact
    assert backward.exact
    assert forward.limits.max_jerk == math.inf


@pytest.mark.parametrize(("distance", "v0", "vf", "expected"), [
    (100.0, 0.0, 0.0, False),
    (100.0, -300.0, 0.0, True),       # moving away from the target
    (1.0, 300.0, 0.0, True),           # cannot stop in time: overshoot and come back
    (100.0, 300.0, 0.0, False),        # 300^2/(2*2000) = 22.5 <= 100
    (100.0, 0.0, -50.0, True),         # arrive moving backwards
    (0.1, 0.0, 400.0, True),           # 400^2/(2*5000) = 16 > 0.1: needs a run-up
    (20.0, 0.0, 400.0, False),
    (0.0, 0.0, 0.0, False),
])
def test_reverses(distance, v0, vf, expected):
    assert reverses(distance, v0, vf, 5000.0, 2000.0) is expected


def test_reasons_of_each_legitimate_difference():
    def reasons(**kw):
        request = ProfileRequest(**{"type": MPIMotionType.S_CURVE, "velocity": 500.0, "acceleration": 5000.0,
                                    "target": 1000.0, "jerk_percent": 50.0, **kw})
        return set(check_request(request).reasons)

    assert reasons(deceleration=2000.0) == {Reason.DECELERATION_DIFFERS}
    assert reasons(start_velocity=200.0) == {Reason.START_VELOCITY}
    assert reasons(final_velocity=100.0) == {Reason.FINAL_VELOCITY}
    assert reasons(start_velocity=200.0, start_acceleration=1000.0) == {Reason.START_VELOCITY,
                                                                        Reason.ACCELERATION_STEP}
    assert reasons(type=MPIMotionType.TRAPEZOIDAL, deceleration=2000.0, start_velocity=-300.0,
                   target=100.0) == {Reason.REVERSAL_ASYMMETRIC}
    assert reasons(type=MPIMotionType.TRAPEZOIDAL, start_velocity=200.0) == set()


def test_modify_with_acceleration_is_compared_from_zero_acceleration():
    # docs/profiles.md, "Modify: from the current state": a modify of S_CURVE/TRAPEZOIDAL/VELOCITY
    # restarts from the current position and velocity with zero acceleration; ruckig gets that
    # state, and the full-state duration is reported for information.
    result = check_request(ProfileRequest(MPIMotionType.TRAPEZOIDAL, 500.0, 5000.0, target=1000.0,
                                          start_velocity=200.0, start_acceleration=3000.0))
    assert result.verdict is Verdict.DIFFER_EXPLAINED
    assert result.reasons == (Reason.ACCELERATION_STEP,)
    assert result.exact
    assert result.ruckig.current_acceleration == 0.0
    assert result.duration_relative <= 1e-12
    s = check_request(ProfileRequest(MPIMotionType.VELOCITY, 300.0, 5000.0, jerk_percent=50.0,
                                     start_velocity=100.0, start_acceleration=4000.0))
    assert s.ruckig_full_state_duration is not None
    assert s.ruckig_full_state_duration < s.ruckig_duration


def test_velocity_maps_to_the_velocity_interface():
    m = map_velocity(0.0, 100.0, 0.0, -300.0, 5000.0, 40.0)
    assert m.exact
    assert m.limits.control == "velocity"
    assert m.limits.target_velocity == -300.0
    assert m.limits.max_jerk == pytest.approx(ramp_jerk(5000.0, 0.4, 400.0))


def test_solver_segments_match_ruckigs_own_sampling():
    from ruckig import InputParameter, Ruckig, Trajectory

    limits = RuckigLimits("position", 10.0, 50.0, 0.0, 1000.0, 0.0, 500.0, 6000.0, -4000.0, 2e5)
    profile = solve(limits)
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity, inp.target_position = [10.0], [50.0], [1000.0]
    inp.max_velocity, inp.max_acceleration, inp.min_acceleration, inp.max_jerk = [500.0], [6000.0], [-4000.0], [2e5]
    trajectory = Trajectory(1)
    Ruckig(1).calculate(inp, trajectory)
    assert profile.duration == pytest.approx(trajectory.duration, rel=1e-12)
    times = np.linspace(0.0, profile.duration, 57)
    p, v, a, _ = sample(profile.segments, times)
    for t, pi, vi, ai in zip(times, p, v, a, strict=True):
        (rp,), (rv,), (ra,) = trajectory.at_time(float(t))
        assert pi == pytest.approx(rp, abs=1e-7)
        assert vi == pytest.approx(rv, abs=1e-7)
        assert ai == pytest.approx(ra, abs=1e-5)


def test_solver_turns_ruckig_errors_into_ruckig_failed():
    # docs/profiles.md, "ruckig's pitfalls": invalid input raises RuckigError
    bad = RuckigLimits("position", 0.0, 0.0, 0.0, 10.0, 0.0, 100.0, 0.0, -100.0, math.inf)
    with pytest.raises(RuckigFailed):
        solve(bad)


def test_solver_changes_units_where_ruckig_fails_in_others():
    # A problem ruckig 0.19 fails on ("error in step 1") in counts and seconds, solved exactly
    # by a change of units (pantor/ruckig#71).
    from ruckig import InputParameter, Ruckig, RuckigError, Trajectory

    x, v, amax, jerk = 12574.604900305558, 26854.797480913443, 684046.4975325596, 20590042.612750296
    inp = InputParameter(1)
    inp.target_position, inp.max_velocity = [x], [v]
    inp.max_acceleration, inp.min_acceleration, inp.max_jerk = [amax], [-amax], [jerk]
    with pytest.raises(RuckigError):
        Ruckig(1).calculate(inp, Trajectory(1))
    profile = solve(RuckigLimits("position", 0.0, 0.0, 0.0, x, 0.0, v, amax, -amax, jerk))
    assert profile.segments[-1].end_state()[0] == pytest.approx(x, abs=1e-9)


@settings(max_examples=400, derandomize=True, deadline=None, database=None)
@given(distance=st.floats(1e-3, 1e6), velocity=st.floats(1.0, 1e5), acceleration=st.floats(10.0, 1e7),
       jerk_percent=st.one_of(st.floats(0.0, 100.0), st.floats(1e-300, 1e-3)), backwards=st.booleans())
def test_symmetric_scurve_from_rest_always_agrees(distance, velocity, acceleration, jerk_percent, backwards):
    # docs/profiles.md, "The cross-check against ruckig": a symmetric S-curve from rest to rest maps exactly
    assume(distance / velocity < 4000.0)  # longer cruises hit the 16,384,000-sample frame limit
    request = ProfileRequest(MPIMotionType.S_CURVE, velocity, acceleration, jerk_percent=jerk_percent,
                             target=-distance if backwards else distance)
    result = check_request(request)
    assert result.verdict is Verdict.AGREE, result.detail
    assert result.duration_relative <= 1e-12
