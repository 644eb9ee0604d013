"""compile_move (mpi_ros/mpi/planning/planner.py): a validated request becomes per-axis frames."""

from __future__ import annotations

import copy
import dataclasses
import math

import numpy as np
import pytest

from mpi_ros.mpi import Hold, HoldType, MotionAttr, MotionParams, MPIMotionType, Output, OutputType, Trajectory
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Refused
from mpi_ros.mpi.planning.frames import AxisPlan, Listed, Scaled
from mpi_ros.mpi.planning.planner import compile_move
from mpi_ros.mpi.planning.profiles.segment import Segment
from mpi_ros.mpi.planning.start import AxisStart

A = MotionAttr
T = MPIMotionType
E = MPIEventType
TRAJ = Trajectory(1000.0, 10_000.0, 5_000.0, 0.0)
RATE = 2000.0


def compile_(attrs=A.NONE, position=(3000.0, 4000.0), kind=T.TRAPEZOIDAL, starts=None, moving=False,
             trajectory=(TRAJ,), rate=RATE, **fields):
    """``moving``: the axes start at 100 counts/s (as a modify in motion does)."""
    params = MotionParams(trajectory=list(trajectory), position=list(position), **fields)
    starts = starts or [AxisStart(i, 0.0, 100.0 if moving else 0.0) for i in range(len(position))]
    return compile_move(0, kind, attrs, params, starts, rate)


def end(plan):
    return plan.segments[-1].end_state()


def test_vector_move_is_one_profile_along_the_line():
    # MPI 000, MPIMotionSCurve "only the first trajectory structure will be applied as the vector trajectory
    # for all the axes"
    move, notes = compile_()
    x, y = move.plans
    assert x.duration == y.duration == pytest.approx(5000.0 / 1000.0 + 0.5 * (0.1 + 0.2))
    for sx, sy in zip(x.segments, y.segments, strict=True):
        assert sx.duration == sy.duration
        assert (sx.v * 4.0, sx.a * 4.0, sx.j * 4.0) == pytest.approx((sy.v * 3.0, sy.a * 3.0, sy.j * 3.0))
    assert max(math.hypot(sx.v, sy.v) for sx, sy in zip(x.segments, y.segments, strict=True)) == pytest.approx(1000.0)
    assert (x.target, y.target) == (3000.0, 4000.0)
    assert end(x)[0] == pytest.approx(3000.0)
    assert notes.events == []


def test_absolute_targets_include_the_origin():
    # axis.py: "Positions seen by users are raw positions minus the origin"
    move, _ = compile_(position=(10.0,), starts=[AxisStart(0, 500.0, 0.0, 500.0)])
    assert move.plans[0].target == 510.0


def test_sync_end_pads_the_start_of_shorter_profiles():
    # MPI 000, MPIMotionAttrSYNC_END "For all but the longest motion profile, wait frames will be added to the
    # beginning of the moves"
    trajectories = (TRAJ, Trajectory(50.0, 1000.0, 1000.0))  # 1.15 s and 2.0 s
    move, _ = compile_(A.SYNC_END, position=(1000.0, 100.0), trajectory=trajectories)
    fast, slow = move.plans
    assert fast.duration == pytest.approx(slow.duration)
    wait = fast.segments[0]
    assert (wait.v, wait.a, wait.j) == (0.0, 0.0, 0.0)
    assert wait.duration > 0.0
    assert slow.segments[0].a > 0.0


def test_sync_start_pads_the_end_of_shorter_profiles():
    # MPI 000, MPIMotionAttrSYNC_START "For those axes that finish first, a delay frame will be added to the end"
    trajectories = (TRAJ, Trajectory(50.0, 1000.0, 1000.0))  # 1.15 s and 2.0 s
    move, _ = compile_(A.SYNC_START, position=(1000.0, 100.0), trajectory=trajectories)
    fast, slow = move.plans
    assert fast.duration == pytest.approx(slow.duration)
    assert fast.segments[0].a > 0.0
    assert fast.segments[-1].v == 0.0
    assert fast.segments[-1].p == 1000.0


def test_delay_prepends_a_wait_frame_per_axis():
    # MPI 000, MPIMotionAttrDELAY delay "assign delay times for each Axis"
    move, _ = compile_(A.DELAY, delay=[0.5, 0.0])
    x, y = move.plans
    assert x.segments[0].duration == 0.5
    assert x.segments[0].v == 0.0
    assert x.duration == pytest.approx(y.duration + 0.5)


def test_illegal_delay_only_while_moving():
    # MPI 000, MPIMotionMessageILLEGAL_DELAY ILLEGAL_DELAY "non-zero delay value ... while in motion"
    with pytest.raises(Refused) as refused:
        compile_(A.DELAY, moving=True, delay=[0.0, 0.1])
    assert refused.value.message is Message.MPIMotionMessageILLEGAL_DELAY
    compile_(A.DELAY, moving=True, delay=[0.0, 0.0])
    compile_(A.DELAY, moving=False, delay=[0.0, 0.1])


def test_relative_targets_and_truncation():
    # MPI 000, MPIMotionAttrRELATIVE relative distances from the start; MPI 000, mpiMotionStart "the fractional portion
    # is truncated and discarded"
    starts = [AxisStart(0, 1000.0), AxisStart(1, -5.0)]
    move, notes = compile_(A.RELATIVE, position=(2000.0, -3.9), starts=starts)
    assert [p.target for p in move.plans] == [3000.0, -8.0]
    assert [kind for kind, _ in notes.events] == [E.RELATIVE_TRUNCATED]
    assert "-3.9" in notes.events[0][1]
    assert "axis 1" in notes.events[0][1]


@pytest.mark.parametrize(("given", "stored"), [(32767, 32767), (32768, -32768), (-32769, 32767), (1 << 20, 0)])
def test_id_truncated_to_16_bits(given, stored):
    # MPI 000, MPIMotionAttributes, id "The id is limited to 16-bit resolution by the controller firmware"
    move, notes = compile_(A.ID, id=given)
    assert move.id == stored
    assert [kind for kind, _ in notes.events] == ([] if given == stored else [E.ID_TRUNCATED])


def test_id_without_the_attribute_is_zero():
    # MPI 000, MPIMotionAttrID ID "enables an identification tag" (only with the attribute)
    move, _ = compile_(id=77)
    assert move.id == 0


def test_element_id_and_event_mask_only_with_their_attributes():
    # MPI 000, MPIMotionAttrELEMENT_ID ELEMENT_ID; MPI 000, MEIMotionAttrEVENT EVENT
    move, _ = compile_(A.ELEMENT_ID | A.EVENT, element_id=[5, 6], event_mask=E.MOTION_DONE)
    assert (move.element_id, move.event_mask) == (5, E.MOTION_DONE)
    move, _ = compile_(element_id=[5], event_mask=E.MOTION_DONE)
    assert (move.element_id, move.event_mask) == (0, E.NONE)


def test_frame_longer_than_16384000_samples_is_cut():
    # MPI 000, mpiMotionStart "If the commanded motion exceeds the maximum frame time, the axes will stop
    # abruptly after 16,384,000 samples"
    move, notes = compile_(position=(1e6,), trajectory=(Trajectory(1.0, 1e4, 1e4),), rate=100.0)
    plan = move.plans[0]
    assert plan.truncated
    assert plan.final_velocity == 0.0
    assert max(s.duration for s in plan.segments) == 16_384_000 / 100.0
    assert plan.target == pytest.approx(163_840.0, abs=1e-3)
    assert [kind for kind, _ in notes.events] == [E.FRAME_TIME_LIMIT]


def test_long_move_within_the_limit_is_not_cut():
    # MPI 000, mpiMotionStart the limit is 16,384,000 samples (2.27 hours at 2000 Hz)
    move, notes = compile_(position=(8_000_000.0,), trajectory=(Trajectory(1000.0, 1e4, 1e4),))
    assert not move.plans[0].truncated
    assert notes.events == []


def test_velocity_move_cruises_for_the_frame_limit():
    # MPI 000, mpiMotionStart "the maximum velocity time is 2.27 hours" (16,384,000 samples at 2000 Hz)
    move, _ = compile_(kind=T.VELOCITY, position=(), starts=[AxisStart(0, 0.0)],
                       trajectory=(Trajectory(500.0, 5000.0),))
    plan = move.plans[0]
    assert plan.is_velocity
    assert plan.velocity_target == 500.0
    assert plan.ramp_end == pytest.approx(0.1)
    assert plan.segments[-1].duration == pytest.approx(16_384_000 / RATE)
    assert plan.truncated


def test_velocity_move_per_axis_trajectories():
    # docs/decisions.md, "The ROS contract" (array lengths): a VELOCITY move may give one trajectory per axis
    trajectories = (Trajectory(100.0, 1000.0), Trajectory(-50.0, 1000.0))
    move, _ = compile_(kind=T.VELOCITY, position=(), starts=[AxisStart(0, 0.0), AxisStart(1, 0.0)],
                       trajectory=trajectories)
    assert [p.velocity_target for p in move.plans] == [100.0, -50.0]


def test_final_velocity_plans_end_moving():
    # MPI 000, MEIMotionAttributes, finalVelocity finalVelocity "the target velocity for each axis"
    move, _ = compile_(A.FINAL_VEL, position=(1000.0,), final_velocity=[250.0])
    plan = move.plans[0]
    assert plan.final_velocity == 250.0
    p, v, _ = end(plan)
    assert p == pytest.approx(1000.0)
    assert v == pytest.approx(250.0)


def test_final_velocity_off_the_vector_line():
    # planner.py: "final velocities of a vector move must lie along the move"
    with pytest.raises(Refused) as refused:
        compile_(A.FINAL_VEL, final_velocity=[100.0, 0.0])
    assert refused.value.message is Message.MPIMessagePARAM_INVALID
    move, _ = compile_(A.FINAL_VEL, final_velocity=[60.0, 80.0])
    assert [p.final_velocity for p in move.plans] == [60.0, 80.0]


def test_no_reversal():
    # MPI 000, MPIMotionMessagePROFILE_ERROR PROFILE_ERROR "when the NO_REVERSAL attribute mask is specified, but the
    # specified target position is in the reverse direction"
    moving = [AxisStart(0, 0.0, 1000.0)]
    with pytest.raises(Refused) as refused:
        compile_(A.NO_REVERSAL, position=(-10.0,), starts=moving, moving=True)
    assert refused.value.message is Message.MPIMotionMessagePROFILE_ERROR
    compile_(A.NO_REVERSAL, position=(1000.0,), starts=moving, moving=True)


def test_reversal_profile_from_a_moving_start():
    # issue 3: modify "including reversal": decelerate, turn, arrive
    move, _ = compile_(position=(-100.0,), starts=[AxisStart(0, 0.0, 1000.0)], moving=True)
    plan = move.plans[0]
    velocities = [s.v for s in plan.segments] + [end(plan)[1]]
    assert max(velocities) == 1000.0
    assert min(velocities) == pytest.approx(-1000.0)
    assert end(plan)[0] == pytest.approx(-100.0)


def test_zero_length_move():
    # a target equal to the current position: no motion, the plan holds the position
    move, _ = compile_(position=(0.0, 0.0))
    assert all(p.duration == 0.0 and p.target == 0.0 for p in move.plans)


def test_vector_modify_off_the_line_plans_each_axis():
    # planner.py decision: "each axis is then planned from its own state with the vector's limits
    # scaled by the axis' share of the new displacement (never less than its share of the current
    # velocity)"
    starts = [AxisStart(0, 0.0, 1000.0), AxisStart(1, 0.0, 0.0)]
    move, _ = compile_(position=(0.0, 1000.0), starts=starts, moving=True)
    x, y = move.plans
    assert end(x)[0] == pytest.approx(0.0)
    assert end(y)[0] == pytest.approx(1000.0)
    assert max(abs(s.v) for s in x.segments) == pytest.approx(1000.0)  # share of the velocity: 1
    assert max(abs(s.v) for s in y.segments) <= 1000.0 + 1e-9


def test_hold_and_outputs_go_to_the_plans():
    # MPI 000, MEIMotionAttributes, hold hold "for each axis"; MPI 000, MEIMotionAttrOUTPUT OUTPUT "configures a frame
    # to toggle an output bit as a move begins" (on the first axis' frames)
    holds = [Hold(type=HoldType.GATE, gate=1), Hold(type=HoldType.GATE, gate=2)]
    output = Output(type=OutputType.OUTPUT, on_mask=1)
    move, _ = compile_(A.HOLD | A.OUTPUT, hold=holds, output=[output])
    assert [p.hold.gate for p in move.plans] == [1, 2]
    assert move.plans[0].outputs == [output]
    assert move.plans[1].outputs == []


def _eager(plan: AxisPlan) -> AxisPlan:
    """The same plan with its segments listed as Segments, made now (its duration theirs)."""
    return dataclasses.replace(plan, source=Listed(list(plan.segments), plan.limits))


def _fields(plan: AxisPlan) -> dict:
    """Every field as a reader sees it: the source as the segments and limits it gives."""
    fields = {f.name: getattr(plan, f.name) for f in dataclasses.fields(AxisPlan) if f.compare and f.name != "source"}
    return {**fields, "segments": plan.segments, "limits": plan.limits}


@pytest.mark.parametrize("kind", [T.S_CURVE, T.TRAPEZOIDAL, T.S_CURVE_JERK])
@pytest.mark.parametrize("axes", [1, 2])
@pytest.mark.parametrize("cut", [False, True])
def test_a_plan_given_its_duration_is_the_plan_of_its_segments(kind, axes, cut):
    # the planner gives a source the duration it calculated with the segments: every field as
    # a plan of the same Segments makes it
    trajectory = (Trajectory(1.0 if cut else 1000.0, 1e4, 1e4 if cut else 5e3, 40.0, 1e6, 2e6),)
    position = (6e5, 8e5)[:axes] if cut else (3000.0, -4000.0)[:axes]
    move, _ = compile_(position=position, kind=kind, trajectory=trajectory, rate=100.0 if cut else RATE)
    for plan in move.plans:
        assert plan.truncated == cut
        assert _fields(plan) == _fields(_eager(plan))
    empty = AxisPlan(3, Listed([], None, 0.0, True), 5.0, 5.0)
    assert _fields(empty) == _fields(AxisPlan(3, Listed([]), 5.0, 5.0))


@pytest.mark.parametrize("kind", [T.S_CURVE, T.TRAPEZOIDAL, T.S_CURVE_JERK])
@pytest.mark.parametrize("moving", [False, True])
def test_a_lone_axis_is_stepped_from_its_rows_until_asked_for_its_segments(kind, moving):
    # the stepping reads the plan's Rows; the Segments are made when asked for
    trajectory = (Trajectory(1000.0, 10_000.0, 5_000.0, 40.0, 1e6, 2e6),)
    move, _ = compile_(position=(3000.0,), kind=kind, trajectory=trajectory, moving=moving)
    (plan,) = move.plans
    assert isinstance(plan.source, Listed)
    assert plan.source.rows
    assert plan.source.made is None
    eager = _eager(plan)  # (made from the plan's fields: its Segments are made now)
    again = compile_(position=(3000.0,), kind=kind, trajectory=trajectory, moving=moving)[0].plans[0]
    times = np.linspace(-0.1, 8.0, 50)
    assert again.frame_count == eager.frame_count
    assert [again.segment_poly(t) for t in times] == [eager.segment_poly(t) for t in times]
    for mine, theirs in zip(again.evaluate(times), eager.evaluate(times), strict=True):
        assert np.array_equal(mine, theirs)
    assert again.segments == eager.segments
    assert all(type(s) is Segment for s in again.segments)
    assert again == plan
    assert _fields(copy.deepcopy(again)) == _fields(eager)


@pytest.mark.parametrize("kind", [T.S_CURVE, T.TRAPEZOIDAL, T.S_CURVE_JERK])
@pytest.mark.parametrize("moving", [False, True])
def test_vector_axes_share_the_line_until_asked_for_their_segments(kind, moving):
    trajectory = (Trajectory(1000.0, 10_000.0, 5_000.0, 40.0, 1e6, 2e6),)
    speed = 100.0 if moving else 0.0  # along the line to the targets
    starts = [AxisStart(0, 30.0, 0.6 * speed), AxisStart(1, -40.0, -0.8 * speed)]
    move, _ = compile_(position=(3000.0, -4000.0), kind=kind, trajectory=trajectory, starts=starts)
    times = np.linspace(-0.1, 8.0, 50)
    for plan in move.plans:
        assert isinstance(plan.source, Scaled)
        assert plan.source.made is None
        frames = plan.frame_count  # counted from the line, before the segments are made
        eager = _eager(plan)
        assert (frames, plan.duration) == (eager.frame_count, eager.duration)
        assert plan.segments == eager.segments
        assert len(plan.segments) == frames - 1
        for mine, theirs in zip(plan.evaluate(times), eager.evaluate(times), strict=True):
            assert np.array_equal(mine, theirs)
    for plan in compile_(position=(3000.0, -4000.0), kind=kind, trajectory=trajectory, starts=starts)[0].plans:
        # made again through AxisPlan's fields (a copy, dataclasses.replace): the same plan
        for again in (copy.deepcopy(plan), dataclasses.replace(plan)):
            assert (again.segments, again.duration, again.frame_count) == (plan.segments, plan.duration,
                                                                            plan.frame_count)
            assert again.limits == plan.limits == trajectory[0].share(abs(plan.source.factor))


def test_vector_axes_with_a_delay_or_a_cut_frame_are_made_and_checked_each():
    move, _ = compile_(A.DELAY, delay=[0.5, 0.0])
    assert [type(plan) for plan in move.plans] == [AxisPlan, AxisPlan]
    move, notes = compile_(position=(6e5, 8e5), trajectory=(Trajectory(1.0, 1e4, 1e4),), rate=100.0)
    assert all(plan.truncated and type(plan) is AxisPlan for plan in move.plans)
    assert [kind for kind, _ in notes.events] == [E.FRAME_TIME_LIMIT] * 2


def test_a_vector_axis_that_overflows_on_its_way_is_refused():
    # The 1-D profile is finite and every axis lands, but axis 0 overshoots its target past the
    # largest float on the way (MPI 000, MPIMotionMessagePROFILE_ERROR: "cannot be calculated")
    params = MotionParams(trajectory=[Trajectory(2e154, 1.0, 1.0, 50.0)], position=[1.79e308, 0.0])
    with pytest.raises(Refused) as refused:
        compile_move(0, T.S_CURVE, A.NONE, params, [AxisStart(0, 1.7e308, 1e154), AxisStart(1, 0.0, 0.0)], RATE)
    assert refused.value.message is Message.MPIMotionMessagePROFILE_ERROR
    assert refused.value.detail == "axis 0: the profile cannot be calculated with these values (overflow)"
