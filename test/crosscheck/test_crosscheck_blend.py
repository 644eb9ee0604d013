"""The ruckig and limits checks on blended corners (MEIMotionConfig.blendLimit, MPI 000: "the acceleration
resulting from the blending can exceed the acceleration limit specified in the motion parameters (180 degrees =
acceleration*2.0)"). The plans are the controller's own, taken while the blend runs; the blend shape is
docs/decisions.md, "Blending"; the checks are mpi_ros/crosscheck/limits.py, check_blend."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from mpi_ros.crosscheck import Reason, Verdict, check_plan
from mpi_ros.mpi import Controller, MotionAttr, MotionParams, MPIAction, MPIMotionType, MPIState, Trajectory
from mpi_ros.mpi.planning.frames import AxisPlan, BlendParts, Listed
from mpi_ros.mpi.planning.profiles.segment import Segment

A, T = MotionAttr, MPIMotionType
CORNER = (1000.0, 0.0)


def _blended_plans(kind: MPIMotionType, degrees: float, first: Trajectory, second: Trajectory) -> list[AxisPlan]:
    """The plans of a move appended (blendLimit 1.0) to one that ends at CORNER, turned ``degrees``, as
    the controller runs them once the blend has begun."""
    ctl = Controller()
    _, ms = ctl.create_motion(0)
    assert ms.axis_list_set([0, 1]).ok
    assert ms.action(MPIAction.MAP).ok
    _, config = ms.config_get()
    config.blend_limit = 1.0
    assert ms.config_set(config).ok
    turn = math.radians(degrees)
    target = [CORNER[0] + 1000.0 * math.cos(turn), CORNER[1] + 1000.0 * math.sin(turn)]
    assert ms.start(kind, A.NONE, MotionParams(trajectory=[first], position=list(CORNER))).ok
    outcome, serial = ms.command(kind, A.APPEND, MotionParams(trajectory=[second], position=target), False)
    assert outcome.ok
    assert ctl.run_until(lambda c: c.current_serial(ms.number) == serial, 40_000, chunk=1)
    move = ms.move(serial)
    assert move is not None
    assert ms.state is MPIState.MOVING
    return move.plans


LIMITS = [(T.TRAPEZOIDAL, Trajectory(1000.0, 1e4, 1e4)), (T.S_CURVE, Trajectory(1000.0, 1e4, 1e4, 50.0)),
          (T.S_CURVE, Trajectory(1000.0, 1e4, 1e4, 100.0))]


@pytest.mark.parametrize(("kind", "limits"), LIMITS, ids=["trapezoid", "s-curve-50", "s-curve-100"])
@pytest.mark.parametrize("degrees", [0.0, 90.0, 150.0, 180.0])
def test_blended_corners_pass_the_ruckig_and_limits_checks(kind, limits, degrees):
    # MEIMotionConfig.blendLimit: a blended corner is the appended move's own profile (compared with ruckig
    # as any plan) plus the rest of the move before; the sum keeps the velocity limit, and its acceleration
    # stays within the two peaks added: "180 degrees = acceleration*2.0"
    for plan in _blended_plans(kind, degrees, limits, limits):
        assert plan.blended_from is not None
        result = check_plan(plan, kind)
        assert result.verdict is Verdict.DIFFER_EXPLAINED, result.detail
        assert Reason.BLENDED in result.reasons
        assert Reason.COMPOSITE not in result.reasons
        assert result.ruckig_duration is not None  # the own profile was compared with ruckig


def test_a_blend_of_moves_with_different_limits_passes():
    # each move keeps its own limits (docs/decisions.md, "Blending"): a slow, gentle first move and a fast one
    for plan in _blended_plans(T.S_CURVE, 120.0, Trajectory(400.0, 4e3, 4e3, 50.0),
                               Trajectory(1500.0, 2e4, 2e4, 50.0)):
        result = check_plan(plan, T.S_CURVE)
        assert result.verdict is Verdict.DIFFER_EXPLAINED, result.detail


def _about_face_plan() -> AxisPlan:
    return next(p for p in _blended_plans(T.TRAPEZOIDAL, 180.0, *[Trajectory(1000.0, 1e4, 1e4)] * 2) if p.axis == 0)


def test_a_blend_above_twice_the_acceleration_is_caught():
    # "180 degrees = acceleration*2.0" is the most a blend may reach: the rest of the move before, run at
    # three times its deceleration, breaks it (and the move before's own limit)
    plan = _about_face_plan()
    parts = plan.blended_from
    assert parts is not None
    harsh = tuple(Segment(s.duration / math.sqrt(3.0), s.p, s.v * math.sqrt(3.0), s.a * 3.0, s.j) for s in parts.tail)
    broken = replace(plan, source=Listed(_sum(parts.own, harsh), plan.limits), blended_from=BlendParts(parts.own, harsh,
                                                                                    parts.tail_limits))
    result = check_plan(broken, T.TRAPEZOIDAL)
    assert result.verdict is Verdict.DISAGREE
    assert any("the blend: |a| reaches" in p for p in result.problems), result.problems
    assert any("the move before: |a| reaches" in p for p in result.problems), result.problems


def test_a_blend_that_is_not_the_sum_of_its_profiles_is_caught():
    plan = _about_face_plan()
    shifted = [Segment(s.duration, s.p + 0.5, s.v, s.a, s.j) for s in plan.segments]
    result = check_plan(replace(plan, source=Listed(shifted, plan.limits)), T.TRAPEZOIDAL)
    assert result.verdict is Verdict.DISAGREE
    assert any("not the sum" in p for p in result.problems), result.problems


def _sum(own, tail) -> list[Segment]:
    from mpi_ros.mpi.planning.blend import superpose

    return superpose(list(own), list(tail))
