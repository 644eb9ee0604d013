"""S_CURVE_JERK / VELOCITY_JERK (mpi_ros/mpi/planning/profiles/jerk.py): jerk-limited profiles from the
full current state (firmware option 21)."""

from __future__ import annotations

import pytest

from mpi_ros.mpi.planning.profiles.jerk import point_to_point_jerk, velocity_change, velocity_jerk
from mpi_ros.mpi.planning.profiles.ramps import ProfileError
from mpi_ros.mpi.planning.profiles.segment import chain


def integrate(v, a, pieces):
    segments = chain(0.0, v, a, pieces)
    return segments[-1].end_state() if segments else (0.0, v, a)


@pytest.mark.parametrize(("v", "a", "v1"), [(0.0, 0.0, 1000.0), (0.0, 0.0, -1000.0), (500.0, 3000.0, 0.0),
                                    (500.0, -3000.0, 1000.0), (0.0, 0.0, 10.0)])
def test_velocity_change_reaches_the_velocity_with_zero_acceleration(v, a, v1):
    # jerk.py: "A velocity change from (v, a) to (v1, 0) is: jerk toward a peak acceleration p (at
    # most the limit), hold p, jerk back to zero"
    pieces = velocity_change(v, a, v1, 10_000.0, 1e5)
    _, v_end, a_end = integrate(v, a, pieces)
    assert v_end == pytest.approx(v1, abs=1e-6)
    assert a_end == pytest.approx(0.0, abs=1e-6)
    assert all(abs(j) == 1e5 or j == 0.0 for _, j in pieces)


def test_velocity_change_respects_the_acceleration_limit():
    # MPI 000, MPIMotionSCurveJerk accelerationJerk/decelerationJerk with acceleration/deceleration limits
    pieces = velocity_change(0.0, 0.0, 5000.0, 10_000.0, 1e5)
    accels = [s.a for s in chain(0.0, 0.0, 0.0, pieces)] + [integrate(0.0, 0.0, pieces)[2]]
    assert max(abs(x) for x in accels) == pytest.approx(10_000.0)


def test_velocity_change_limits_must_be_positive():
    with pytest.raises(ProfileError):
        velocity_change(0.0, 0.0, 1.0, 0.0, 1.0)


@pytest.mark.parametrize(("v0", "a0", "target"), [(0.0, 0.0, 5000.0), (0.0, 0.0, 50.0), (800.0, 4000.0, 3000.0),
                                          (800.0, 4000.0, -500.0), (-300.0, 0.0, 1000.0)])
def test_point_to_point_jerk_ends_on_target_at_rest(v0, a0, target):
    # MPI 000, MPIMotionTypeS_CURVE_JERK S_CURVE_JERK point to point "and final position"
    accel, decel = (10_000.0, 2e5), (8_000.0, 1e5)
    segments = point_to_point_jerk(0.0, v0, a0, target, 0.0, 1000.0, accel, decel)
    p, v, a = segments[-1].end_state()
    assert p == pytest.approx(target, abs=1e-6)
    assert v == pytest.approx(0.0, abs=1e-6)
    assert a == pytest.approx(0.0, abs=1e-6)
    assert segments[0].a == a0  # from the full state (docs/profiles.md, "Modify")
    assert all(abs(s.j) in (0.0, 2e5, 1e5) for s in segments)
    peak_v = max(abs(s.v) for s in segments)
    assert peak_v <= max(1000.0, abs(v0)) * (1 + 1e-9)


def test_point_to_point_jerk_needs_a_velocity():
    with pytest.raises(ProfileError):
        point_to_point_jerk(0.0, 0.0, 0.0, 10.0, 0.0, 0.0, (1.0, 1.0), (1.0, 1.0))


def test_velocity_jerk_ramps_then_cruises():
    # MPI 000, MPIMotionTypeVELOCITY_JERK VELOCITY_JERK "S-Curve acceleration to a constant velocity"
    segments, ramp_time = velocity_jerk(0.0, 0.0, 0.0, 1000.0, 10_000.0, 1e5, 5e4, cruise=2.0)
    assert segments[-1].v == pytest.approx(1000.0)
    assert segments[-1].duration == 2.0
    assert segments[-1].a == 0.0
    assert ramp_time == pytest.approx(sum(s.duration for s in segments[:-1]))
    down, _ = velocity_jerk(0.0, 1000.0, 0.0, 0.0, 10_000.0, 1e5, 5e4, cruise=0.0)
    assert max(abs(s.j) for s in down) == 5e4  # slowing uses the deceleration jerk
