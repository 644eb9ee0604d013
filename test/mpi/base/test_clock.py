"""The feedrate clock (mpi_ros/mpi/base/clock.py): profile time runs at feedrate x real time; a
STOP ramps the feedrate linearly (docs/decisions.md, "Stopping"), so tau(t) is piecewise quadratic."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mpi_ros.mpi.base.clock import ProfileClock


def test_a_steady_clock_is_real_time_times_the_feedrate():
    # MPI 000, MPIMotionConfig, normalFeedrate normalFeedrate 1.0 = 100 %
    clock = ProfileClock(0.0, 0.0, 1.0, 1.0, 0.0)
    assert clock.tau_at(2.5) == 2.5
    assert clock.feedrate(2.5) == 1.0
    half = ProfileClock(1.0, 3.0, 0.5, 0.5, 1.0)
    assert half.tau_at(3.0) == 4.0


def test_ramp_to_zero_over_the_stop_time():
    # docs/decisions.md, "Stopping": STOP ramps the feedrate to pauseFeedrate over decelTime.stop
    clock = ProfileClock().ramp_to(1.0, 0.0, 0.5)
    assert clock.feedrate(1.0) == 1.0
    assert clock.feedrate(1.25) == 0.5
    assert clock.feedrate(1.5) == 0.0
    assert clock.tau_at(1.5) == pytest.approx(1.0 + 0.25)  # the area under the ramp
    assert clock.tau_at(9.0) == clock.tau_at(1.5)  # stopped: profile time stands still


def test_ramp_is_continuous_in_tau_and_feedrate():
    # clock.py: "A clock that continues this one"
    clock = ProfileClock().ramp_to(0.7, 0.2, 0.3)
    again = clock.ramp_to(0.85, 1.0, 0.5)
    assert again.tau_at(0.85) == clock.tau_at(0.85)
    assert again.feedrate(0.85) == clock.feedrate(0.85)


def test_vector_queries_match_the_scalar_ones():
    # clock.py: tau(t) and feedrates(t) evaluate many samples at once
    clock = ProfileClock().ramp_to(0.2, 0.25, 0.4)
    t = np.linspace(0.0, 1.0, 101)
    f, df = clock.feedrates(t)
    assert np.allclose(clock.tau(t), [clock.tau_at(x) for x in t], rtol=0, atol=1e-15)
    assert np.allclose(f, [clock.feedrate(x) for x in t])
    assert np.allclose(df, [clock.feedrate_slope(x) for x in t])


def test_time_of_tau_inverts_tau():
    # clock.py time_of_tau: "Earliest time >= t_from at which profile time reaches tau"
    clock = ProfileClock().ramp_to(0.5, 0.0, 0.5)
    for t in (0.1, 0.5, 0.6, 0.9):
        assert clock.time_of_tau(clock.tau_at(t), 0.0) == pytest.approx(t)
    assert clock.time_of_tau(clock.tau_end + 1.0, 0.0) == math.inf  # a stopped clock never gets there


def test_immediate_change():
    # clock.py ramp_to with duration 0: the feedrate changes at once (a start)
    clock = ProfileClock(0.0, 0.0, 0.0, 0.0, 0.0).ramp_to(1.0, 1.0, 0.0)
    assert clock.feedrate(1.0) == 1.0
    assert clock.tau_at(2.0) == 1.0


def test_local_quadratic():
    # clock.py: "tau(t + s) = q0 + q1 s + q2 s^2 within the current clock piece"
    clock = ProfileClock().ramp_to(0.0, 0.0, 1.0)
    q0, q1, q2 = clock.local_quadratic(0.25)
    s = 0.3
    assert q0 + q1 * s + q2 * s * s == pytest.approx(clock.tau_at(0.55))
