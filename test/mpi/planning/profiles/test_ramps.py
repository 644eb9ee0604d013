"""The trapezoid every TRAPEZOIDAL, S_CURVE and VELOCITY move starts from
(mpi_ros/mpi/planning/profiles/ramps.py)."""

from __future__ import annotations

import itertools
import math

import pytest

from mpi_ros.mpi.planning.profiles.ramps import ProfileError, Ramp, plan_point_to_point, plan_velocity, ramps_between


def distance(plan):
    return sum(r.distance for r in plan)


def duration(plan):
    return sum(r.duration for r in plan)


def contiguous(plan, v_start, v_final):
    joints = all(a.v_end == b.v_start for a, b in itertools.pairwise(plan))
    return joints and plan[0].v_start == v_start and plan[-1].v_end == v_final


def test_long_move_is_accel_cruise_decel():
    # MPI 000, MPIMotionTypeTRAPEZOIDAL TRAPEZOIDAL "specified by acceleration, velocity, deceleration and final
    # position"
    plan = plan_point_to_point(10_000.0, 0.0, 0.0, 1000.0, 10_000.0, 5_000.0)
    assert [(r.v_start, r.v_end) for r in plan] == [(0.0, 1000.0), (1000.0, 1000.0), (1000.0, 0.0)]
    assert [r.duration for r in plan] == pytest.approx([0.1, 10.0 - 0.05 - 0.1, 0.2])
    assert distance(plan) == pytest.approx(10_000.0, abs=1e-9)


def test_short_move_is_a_triangle():
    # a move too short to reach the velocity peaks where the ramps meet (time-optimal)
    plan = plan_point_to_point(100.0, 0.0, 0.0, 1000.0, 10_000.0, 10_000.0)
    peak = max(r.v_end for r in plan)
    assert peak == pytest.approx(math.sqrt(100.0 * 10_000.0))
    assert not any(r.is_cruise for r in plan)
    assert distance(plan) == pytest.approx(100.0)


def test_negative_move():
    plan = plan_point_to_point(-500.0, 0.0, 0.0, 1000.0, 10_000.0, 10_000.0)
    assert min(r.v_end for r in plan) == -1000.0
    assert distance(plan) == pytest.approx(-500.0)


def test_start_above_the_velocity_ramps_down_with_the_deceleration():
    # planner: a modify may lower the velocity below the current one; lowering |v| uses deceleration
    plan = plan_point_to_point(10_000.0, 2000.0, 0.0, 1000.0, 10_000.0, 4000.0)
    assert (plan[0].v_start, plan[0].v_end) == (2000.0, 1000.0)
    assert plan[0].duration == pytest.approx(1000.0 / 4000.0)
    assert distance(plan) == pytest.approx(10_000.0)


def test_moving_away_from_the_target_turns_back():
    # issue 3 modify "including reversal": moving away from the target, decelerate, reverse, arrive
    plan = plan_point_to_point(-100.0, 500.0, 0.0, 1000.0, 10_000.0, 5_000.0)
    assert plan[0].v_start == 500.0
    assert plan[0].v_end == 0.0
    assert plan[0].duration == pytest.approx(0.1)  # decelerating at 5000
    assert plan[1].duration == pytest.approx(abs(plan[1].v_end) / 10_000.0)  # accelerating at 10000
    assert distance(plan) == pytest.approx(-100.0)
    assert contiguous(plan, 500.0, 0.0)


def test_overshoot_when_too_close_to_stop():
    # issue 3 "including reversal": the stopping distance is longer than the distance left
    plan = plan_point_to_point(10.0, 1000.0, 0.0, 1000.0, 10_000.0, 10_000.0)
    assert plan[0].v_start == 1000.0
    assert min(r.v_end for r in plan) < 0.0
    assert contiguous(plan, 1000.0, 0.0)
    assert distance(plan) == pytest.approx(10.0)


def test_final_velocity():
    # MPI 000, MEIMotionAttrFINAL_VEL FINAL_VEL "a non-zero target velocity"
    plan = plan_point_to_point(1000.0, 0.0, 300.0, 1000.0, 10_000.0, 10_000.0)
    assert plan[-1].v_end == 300.0
    assert distance(plan) == pytest.approx(1000.0)
    with pytest.raises(ProfileError):
        plan_point_to_point(1000.0, 0.0, 1500.0, 1000.0, 10_000.0, 10_000.0)


@pytest.mark.parametrize("limits", [(0.0, 1.0, 1.0), (1.0, 0.0, 1.0), (1.0, 1.0, -1.0)])
def test_limits_must_be_positive(limits):
    # MPI 000, MPIMotionMessagePROFILE_ERROR PROFILE_ERROR "if the Motion profile ... cannot be calculated"
    with pytest.raises(ProfileError):
        plan_point_to_point(10.0, 0.0, 0.0, *limits)


def test_zero_distance_from_rest_is_empty():
    assert distance(plan_point_to_point(0.0, 0.0, 0.0, 1.0, 1.0, 1.0)) == 0.0


def test_time_optimal_against_brute_force():
    # the trapezoid is the fastest profile within the limits: no cruise velocity does better
    d, v0, vmax, acc, dec = 700.0, 300.0, 1000.0, 8000.0, 3000.0
    best = duration(plan_point_to_point(d, v0, 0.0, vmax, acc, dec))
    for i in range(1, 200):
        w = vmax * i / 200.0
        up = abs(w - v0) / (acc if w > v0 else dec)
        down = w / dec
        ramps = 0.5 * (v0 + w) * up + 0.5 * w * down
        if ramps <= d:
            assert up + (d - ramps) / w + down >= best - 1e-12


def test_ramps_between_splits_at_zero():
    # ramps.py: "a ramp through zero is split at zero" (slowing uses deceleration, speeding acceleration)
    ramps = ramps_between(200.0, -100.0, 1000.0, 400.0)
    assert [(r.v_start, r.v_end) for r in ramps] == [(200.0, 0.0), (0.0, -100.0)]
    assert [r.duration for r in ramps] == pytest.approx([0.5, 0.1])
    assert ramps_between(5.0, 5.0, 1.0, 1.0) == []


def test_velocity_plan_uses_the_acceleration_only():
    # MPI 000, MPIMotionVelocity VELOCITY: "except deceleration is ignored"
    assert plan_velocity(1000.0, -1000.0, 5000.0) == [Ramp(0.4, 1000.0, -1000.0)]
    assert plan_velocity(3.0, 3.0, 1.0) == []
    with pytest.raises(ProfileError):
        plan_velocity(0.0, 1.0, 0.0)
