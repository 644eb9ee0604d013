"""check_plan on plans as the controller compiles them (waits, vector shares, truncation) and
on deliberately wrong plans: every broken limit is a DISAGREE with the problem named.
Limits: docs/quality.md, "Correct motion" (|v| <= velocity, |a| <= acceleration/deceleration, jerk
as configured); the S-curve's shape: docs/profiles.md, "The trapezoid and the S-curve"."""

from __future__ import annotations

from dataclasses import replace

import pytest

from mpi_ros.crosscheck import ProfileRequest, Reason, Verdict, check_plan
from mpi_ros.mpi.base.params import MotionParams, Trajectory
from mpi_ros.mpi.base.types import MotionAttr, MPIMotionType
from mpi_ros.mpi.planning.frames import AxisPlan, Listed
from mpi_ros.mpi.planning.planner import compile_move
from mpi_ros.mpi.planning.profiles.point_to_point import point_to_point
from mpi_ros.mpi.planning.profiles.segment import Segment
from mpi_ros.mpi.planning.start import AxisStart

S = MPIMotionType.S_CURVE
LIMITS = Trajectory(500.0, 5000.0, 5000.0, 50.0)


def _plan(segments, limits=LIMITS, target=1000.0, **kw) -> AxisPlan:
    return AxisPlan(axis=0, source=Listed(list(segments), limits), start_position=0.0, target=target, **kw)


def _problems(plan, kind=S) -> str:
    result = check_plan(plan, kind)
    assert result.verdict is Verdict.DISAGREE, result.detail
    return " | ".join(result.problems)


def test_a_correct_plan_agrees():
    plan = _plan(point_to_point(0.0, 0.0, 1000.0, 0.0, 500.0, 5000.0, 5000.0, 50.0))
    assert check_plan(plan, S).verdict is Verdict.AGREE


def test_planned_with_twice_the_acceleration_is_caught():
    plan = _plan(point_to_point(0.0, 0.0, 1000.0, 0.0, 500.0, 10000.0, 10000.0, 50.0))
    problems = _problems(plan)
    assert "average rate" in problems
    assert "|a| reaches" in problems
    assert "duration" in problems


def test_wrong_jerk_share_is_caught():
    plan = _plan(point_to_point(0.0, 0.0, 1000.0, 0.0, 500.0, 5000.0, 5000.0, 20.0))
    assert "of its time with jerk, jerkPercent asks 0.5" in _problems(plan)


def test_too_fast_is_caught():
    plan = _plan(point_to_point(0.0, 0.0, 1000.0, 0.0, 600.0, 5000.0, 5000.0, 50.0))
    assert "above the velocity 500.0" in _problems(plan)


def test_position_jump_and_wrong_end_are_caught():
    segments = point_to_point(0.0, 0.0, 1000.0, 0.0, 500.0, 5000.0, 5000.0, 50.0)
    segments[3:] = [seg._replace(p=seg.p + 1.0) for seg in segments[3:]]
    problems = _problems(_plan(segments))
    assert "jumps" in problems
    assert "ends at" in problems


def test_trapezoid_with_jerk_is_caught():
    segments = point_to_point(0.0, 0.0, 1000.0, 0.0, 500.0, 5000.0, 5000.0, 50.0)
    assert "with jerkPercent 0" in _problems(_plan(segments, Trajectory(500.0, 5000.0, 5000.0, 0.0)),
                                             MPIMotionType.TRAPEZOIDAL)


def test_a_bound_case_breaking_a_limit_is_not_explained_away():
    # accel != decel (DIFFER_EXPLAINED when right) but planned with the deceleration too high
    limits = Trajectory(500.0, 5000.0, 2000.0, 50.0)
    good = _plan(point_to_point(0.0, 0.0, 1000.0, 0.0, 500.0, 5000.0, 2000.0, 50.0), limits)
    assert check_plan(good, S).verdict is Verdict.DIFFER_EXPLAINED
    bad = _plan(point_to_point(0.0, 0.0, 1000.0, 0.0, 500.0, 5000.0, 4000.0, 50.0), limits)
    assert "average rate" in _problems(bad)


def test_velocity_ramp_end_must_match():
    ramp = [Segment(0.1, 0.0, 0.0, 0.0, 1e5), Segment(0.1, 0.0, 500.0, 1e4, -1e5)]
    plan = _plan([*ramp, Segment(10.0, 0.0, 1000.0, 0.0, 0.0)], Trajectory(1000.0, 5000.0, 0.0, 100.0),
                 target=0.0, velocity_target=1000.0, ramp_end=0.3)
    result = check_plan(plan, MPIMotionType.VELOCITY)
    assert any("ramp_end" in p for p in result.problems)


def test_delay_and_sync_waits_are_left_out():
    traj = Trajectory(500.0, 5000.0, 5000.0, 50.0)
    params = MotionParams(trajectory=[traj, replace(traj, velocity=250.0)], position=[1000.0, 400.0],
                          delay=[0.3, 0.0])
    starts = [AxisStart(0, 0.0), AxisStart(1, 0.0)]
    move, _ = compile_move(0, S, MotionAttr.DELAY | MotionAttr.SYNC_START, params, starts, 2000.0)
    assert move.plans[0].segments[0].duration == 0.3  # the DELAY wait frame
    assert move.plans[1].segments[-1].v == 0.0  # SYNC_START pads the shorter profile at its end
    for plan in move.plans:
        assert check_plan(plan, S).verdict is Verdict.AGREE


def test_vector_move_axes_are_checked_with_their_share_of_the_limits():
    # one profile along the line; each axis moves its share (planner.py: the vector's limits
    # scaled by the axis' share), an axis that does not move has no profile at all
    params = MotionParams(trajectory=[Trajectory(500.0, 5000.0, 5000.0, 70.0)], position=[300.0, -400.0, 0.0])
    starts = [AxisStart(0, 0.0), AxisStart(1, 0.0), AxisStart(2, 0.0)]
    move, _ = compile_move(0, S, MotionAttr.NONE, params, starts, 2000.0)
    results = [check_plan(plan, S) for plan in move.plans]
    assert [r.verdict for r in results] == [Verdict.AGREE] * 3
    assert results[0].controller_duration == pytest.approx(results[1].controller_duration)
    assert results[2].controller_duration == 0.0
    assert results[2].ruckig_duration == 0.0


def test_frame_limit_truncation_is_explained_not_compared():
    request = ProfileRequest(MPIMotionType.TRAPEZOIDAL, 1.0, 10.0, target=10_000.0)
    result = check_plan(request.plan(), request.type)
    assert result.verdict is Verdict.DIFFER_EXPLAINED
    assert result.reasons == (Reason.TRUNCATED,)
    assert result.ruckig_duration is None
