"""Frames and the frame buffer (mpi_ros/mpi/planning/frames.py): per-axis constant-jerk frames, the
128-frame buffer and the refusal of an append that would overflow it (docs/decisions.md, "Motion",
frame buffer overflow)."""

from __future__ import annotations

import numpy as np
import pytest

from mpi_ros.mpi import Controller, ControllerConfig, MotionAttr, MotionParams, MPIAction, MPIMotionType, MPIState
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.planning.frames import AxisPlan, Listed, Move, frames_needed
from mpi_ros.mpi.planning.profiles.segment import Segment

T = MPIMotionType
A = MotionAttr


def fill(ctl, ms, params, jerk_percent=50.0):
    """Append S-curve moves until one is refused; returns the accepted count and the refusal."""
    assert ms.start(T.S_CURVE, params=params((1000.0, 0.0), jerk_percent=jerk_percent)).ok
    count = 1
    while True:
        message = ms.start(T.S_CURVE, A.APPEND, params((1000.0 * (count + 1), 0.0), jerk_percent=jerk_percent)).message
        if not message.ok:
            return count, message
        count += 1


def test_each_axis_has_a_128_frame_buffer(ctl, ms):
    # MPI 000, mpiMotionStart "Each axis has a 128 frame buffer (FIFO)"; MPI 000, MEIMotionFrameBufferStatus, size size
    assert ctl.config.frame_buffer_size == 128
    assert {s.size for s in ms.frame_buffer_status()[1]} == {128}


def test_an_append_that_overflows_is_refused(ctl, ms, params):
    # MPI 000, mpiMotionStart "No provision has been made to check if the new frames will overwrite the
    # currently executing frames"; docs/decisions.md, "Motion": such an append is refused and nothing moves
    # unexpectedly; MPI 000, MPIMotionMessageFRAME_BUFFER_TOO_SMALL FRAME_BUFFER_TOO_SMALL
    count, refusal = fill(ctl, ms, params)
    assert refusal is Message.MPIMotionMessageFRAME_BUFFER_TOO_SMALL
    assert ctl.frame_count(0) <= 128
    assert ctl.frame_count(0) + 8 > 128
    assert len(ms.queue) == count - 1
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 200_000, chunk=500)
    assert ctl.axes[0].command_position == 1000.0 * count  # every accepted move ran, in order


def test_the_refusal_names_the_axis_and_its_frames(ctl, ms, params):
    # MPI 000, MPIMotionMessageFRAME_BUFFER_TOO_SMALL "increase the number of points in the frame buffer":
    # the outcome says which axis needs how many of its frames
    fill(ctl, ms, params)
    outcome, _ = ms.command(T.TRAPEZOIDAL, A.APPEND, params((-5.0, 0.0)), modify=False)
    assert outcome.message is Message.MPIMotionMessageFRAME_BUFFER_TOO_SMALL
    assert outcome.detail.startswith("the move does not fit in the frame buffer: axis 0 needs ")
    assert outcome.detail.endswith(" frames of 128")


def test_the_refusal_changes_nothing(params):
    # docs/decisions.md, "Motion" (frame buffer overflow) and docs/quality.md, "Robust": the refusal changes nothing
    def run(extra):
        ctl = Controller()
        _, ms = ctl.create_motion(0)
        ms.axis_list_set([0, 1])
        _count, _ = fill(ctl, ms, params)
        if extra:
            refused = ms.start(T.TRAPEZOIDAL, A.APPEND, params((-5.0, 0.0))).message
            assert refused is Message.MPIMotionMessageFRAME_BUFFER_TOO_SMALL
        trace = []
        for _ in range(60):
            ctl.step(1000)
            trace.append((ms.state, ctl.axes[0].cmd_p, ctl.frame_count(0)))
        return trace, [(e.sample, e.type) for e in ctl.drain_events()]

    assert run(False) == run(True)


def test_room_frees_up_as_frames_execute(ctl, ms, params):
    # MPI 000, mpiMotionStart the buffer is a FIFO: executed frames leave it
    _count, _ = fill(ctl, ms, params)
    ctl.step(8000)  # some moves done
    assert ms.start(T.S_CURVE, A.APPEND, params((0.0, 0.0), jerk_percent=50.0)).ok


def test_a_larger_buffer_takes_more_moves(params):
    # MPI 000, MPIMotionMessageFRAME_BUFFER_TOO_SMALL "increase the number of points in the frame buffer"
    def capacity(size):
        ctl = Controller(ControllerConfig(frame_buffer_size=size))
        _, ms = ctl.create_motion(0)
        ms.axis_list_set([0, 1])
        return fill(ctl, ms, params)[0]

    assert capacity(128) == 16
    assert capacity(256) == 32


def test_frame_count_decreases_as_the_move_runs(ctl, ms, params):
    # MPI 000, MEIMotionFrameBufferStatus, frameCount frameCount "the number of frames in the controller's frame buffer"
    ms.start(T.S_CURVE, params=params((2000.0, 0.0), jerk_percent=50.0))
    counts = []
    while ms.state is MPIState.MOVING:
        counts.append(ctl.frame_count(0))
        ctl.step(25)
    assert counts[0] == 8
    assert counts == sorted(counts, reverse=True)
    assert counts[-1] == 1


def test_trapezoid_frames():
    # MPI 000, Diagram of mpiMotionStart "Number of frames/point vary with type of move (1frame/point for trapezoidal,
    # to 8 frames/point for S-curve)": here a trapezoid is accel, cruise, decel + the final frame
    plan = AxisPlan(0, Listed([Segment(0.1, 0.0, 0.0, 1e4, 0.0), Segment(0.9, 50.0, 1e3, 0.0, 0.0),
                        Segment(0.1, 950.0, 1e3, -1e4, 0.0)]), 0.0, 1000.0)
    assert plan.frame_count == 4
    assert plan.duration == pytest.approx(1.1)
    assert plan.frames_left(0.0) == 4
    assert plan.frames_left(0.5) == 3
    assert plan.frames_left(2.0) == 1


def test_plan_evaluation_ends_exactly_on_target():
    # MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events, AT_TARGET AT_TARGET "TRUE when
    # command = target": the command is the target exactly
    seg = [Segment(0.1, 0.0, 0.0, 1e4, 0.0), Segment(0.1, 50.0, 1e3, -1e4, 0.0)]
    plan = AxisPlan(0, Listed(seg), 0.0, 100.0 + 1e-9)  # rounding in the segments is absorbed at the end
    p, v, a = plan.evaluate(np.array([0.05, plan.duration, plan.duration + 1.0]))
    assert p[1] == plan.target
    assert p[2] == plan.target
    assert v[2] == 0.0
    assert a[2] == 0.0


def test_plan_past_its_end_continues_at_the_final_velocity():
    # MPI 000, MEIMotionAttrFINAL_VEL FINAL_VEL: "a non-zero target velocity for point to point motion types"
    plan = AxisPlan(0, Listed([Segment(1.0, 0.0, 0.0, 100.0, 0.0)]), 0.0, 50.0, final_velocity=100.0)
    p, v, a = plan.evaluate(np.array([1.5]))
    assert p[0] == pytest.approx(100.0)
    assert v[0] == 100.0
    assert a[0] == 0.0


def test_an_empty_plan_holds_its_target():
    # frames.py: "one final frame that holds the end state" (a move of zero length)
    plan = AxisPlan(1, Listed([]), 5.0, 5.0)
    p, v, _ = plan.evaluate(np.array([0.0, 1.0]))
    assert plan.duration == 0.0
    assert list(p) == [5.0, 5.0]
    assert list(v) == [0.0, 0.0]


def test_frames_needed_counts_per_axis():
    # MPI 000, mpiMotionStart the buffer is per axis
    a = AxisPlan(0, Listed([Segment(1.0, 0.0, 1.0, 0.0, 0.0)]), 0.0, 1.0)
    b = AxisPlan(1, Listed([Segment(1.0, 0.0, 1.0, 0.0, 0.0)] * 3), 0.0, 3.0)
    move = Move(0, T.TRAPEZOIDAL, A.NONE, [a, b])
    assert move.frame_counts == {0: 2, 1: 4}
    assert frames_needed([move, move], 1) == 8
    assert frames_needed([move], 2) == 0
    assert move.plan_for(1) is b
    assert move.plan_for(3) is None
    assert move.axes == [0, 1]


@pytest.mark.parametrize("final_velocity", [0.0, 5.0])
@pytest.mark.parametrize("velocity_target", [None, 2.0])
def test_a_moves_facts_follow_its_plans(final_velocity, velocity_target):
    # what the stepping asks of a move every stretch, taken once from its plans
    a = AxisPlan(2, Listed([Segment(1.0, 0.0, 1.0, 0.0, 0.0)]), 0.0, 1.0, final_velocity,
                 velocity_target=velocity_target)
    b = AxisPlan(0, Listed([Segment(1.0, 0.0, 1.0, 0.0, 0.0)]), 0.0, 1.0)
    for plans in ([a], [a, b], [b, a], []):
        move = Move(3, T.S_CURVE, A.ID, plans, 7, 9, MPIEventType.MOTION_DONE, 0, None)
        assert move.plan_axes == tuple(plan.axis for plan in plans)
        assert move.is_velocity is (velocity_target is not None and a in plans)
        assert move.ends_moving is (final_velocity != 0.0 and a in plans)


def test_frame_count_after_abort_and_reset(ctl, ms, bring):
    # docs/state-machine.md: RESET drops the pending profile; nothing is left in the buffer but the resting frame
    bring(MPIState.ERROR)
    ms.action(MPIAction.RESET)
    assert ctl.frame_count(0) == 0


# ------------------------------------------------------- per-axis frame buffer sizes ----
def _two_sizes() -> Controller:
    """Axes 0 and 1 with 256-frame buffers, axes 2 and 3 with the default 128."""
    return Controller(ControllerConfig(axis_frame_buffer_sizes={0: 256, 1: 256}))


def test_each_axis_reports_its_own_frame_buffer_size():
    # MPI 000, MEIMotionFrameBufferStatus, size: "the size of the controller's frame buffer", per axis;
    # MPI 000, MPIMotionMessageAXIS_FRAME_COUNT: "The axis frame buffer sizes are configured" per axis
    ctl = _two_sizes()
    _, ms = ctl.create_motion(0)
    _, ms1 = ctl.create_motion(1)
    for sup, axes in ((ms, [0, 1]), (ms1, [2, 3])):
        assert sup.axis_list_set(axes).ok
        assert sup.action(MPIAction.MAP).ok
    assert [(s.axis, s.size) for s in ms.frame_buffer_status()[1]] == [(0, 256), (1, 256)]
    assert [(s.axis, s.size) for s in ms1.frame_buffer_status()[1]] == [(2, 128), (3, 128)]
    assert ms.frame_buffer_size == 256
    assert ms1.frame_buffer_size == 128


@pytest.mark.parametrize("edit", ["append", "insert", "list_set"])
def test_an_axis_of_another_frame_buffer_size_is_refused_and_nothing_changes(edit):
    # MPI 000, MPIMotionMessageAXIS_FRAME_COUNT: "All axes appended to a Motion object must have the same
    # frame buffer size": answered where the axis is appended (docs/paths.md)
    ctl = _two_sizes()
    _, ms = ctl.create_motion(0)
    assert ms.axis_list_set([0, 1]).ok
    assert ms.action(MPIAction.MAP).ok
    answer = {"append": lambda: ms.axis_append(2), "insert": lambda: ms.axis_insert(None, 3),
              "list_set": lambda: ms.axis_list_set([0, 2])}[edit]()
    assert answer.message is Message.MPIMotionMessageAXIS_FRAME_COUNT
    assert answer.detail.startswith("axis_numbers: the axes' frame buffer sizes differ ({0: 256, ")
    assert ms.axis_list_get() == (Message.MPIMessageOK, [0, 1])
    assert ms.mapped == [0, 1]
    assert ms.axis_list_set([2, 3]).ok
    assert ms.axis_append(1).message is Message.MPIMotionMessageAXIS_FRAME_COUNT


def test_an_empty_list_takes_any_size_and_same_sizes_mix():
    ctl = Controller(ControllerConfig(frame_buffer_size=64, axis_frame_buffer_sizes={3: 64, 0: 512}))
    _, ms = ctl.create_motion(0)
    assert ms.axis_append(1).ok
    assert ms.axis_append(3).ok
    assert ms.axis_append(2).ok
    assert ms.axis_append(0).message is Message.MPIMotionMessageAXIS_FRAME_COUNT
    assert ms.axis_list_set([0]).ok
    assert ms.frame_buffer_size == 512


def test_each_axis_buffer_bounds_its_own_appends(params):
    # MPI 000, MPIMotionMessageFRAME_BUFFER_TOO_SMALL, per axis: 16 S-curves fit 128 frames, 32 fit 256
    ctl = _two_sizes()
    _, ms = ctl.create_motion(0)
    _, ms1 = ctl.create_motion(1)
    assert ms.axis_list_set([0, 1]).ok
    assert ms1.axis_list_set([2, 3]).ok
    assert fill(ctl, ms, params) == (32, Message.MPIMotionMessageFRAME_BUFFER_TOO_SMALL)
    assert fill(ctl, ms1, params) == (16, Message.MPIMotionMessageFRAME_BUFFER_TOO_SMALL)
    assert ctl.frame_count(0) <= 256
    assert ctl.frame_count(2) <= 128
    assert ctl.frame_count(0) > 128


def test_low_count_defaults_to_a_quarter_of_the_axes_buffer_and_is_bounded_by_it():
    # MPI 001, MPIMotionPathAttrMask, LOW_COUNT: a quarter of the buffer by default (256 -> 64); a given
    # lowCount beyond the axes' buffer is PARAM_INVALID (validate.py), on each supervisor's own size
    ctl = _two_sizes()
    _, ms = ctl.create_motion(0)
    _, ms1 = ctl.create_motion(1)
    for sup, axes in ((ms, [0, 1]), (ms1, [2, 3])):
        assert sup.axis_list_set(axes).ok
        assert sup.action(MPIAction.MAP).ok
        assert sup.event_notify_set(MPIEventType.FRAMES_LOW).ok
    ctl.drain_events()
    x = np.arange(1.0, 101.0)
    points = MotionParams(position=list(np.stack([x, x], axis=1).ravel()), time=[0.01] * 100, final=False,
                          empty_count=0)
    assert ms.start(T.PT, A.NONE, points).ok
    assert ms1.start(T.PT, A.NONE, points).ok
    s0 = ctl.sample
    ctl.step(80 * 20)  # 20 samples a point: 80 points reached
    lows = [(e.supervisor, (e.sample - s0) // 20) for e in ctl.drain_events() if e.type is MPIEventType.FRAMES_LOW]
    assert sorted(lows) == [(0, 100 - 63), (1, 100 - 31)]  # fewer than 64 / 32 left
    big = MotionParams(position=[1.0, 1.0], time=[0.01], final=False, low_count=200)
    assert ms.start(T.PT, A.APPEND | A.LOW_COUNT, big).ok
    assert ms1.start(T.PT, A.APPEND | A.LOW_COUNT, big).message is Message.MPIMessagePARAM_INVALID


@pytest.mark.parametrize(("sizes", "field"), [({0: 8}, "axis_frame_buffer_sizes[0]"),
                                              ({0: 70_000}, "axis_frame_buffer_sizes[0]"),
                                              ({4: 128}, "axis_frame_buffer_sizes: axis"),
                                              ({-1: 128}, "axis_frame_buffer_sizes: axis"),
                                              ({0: 128.0}, "axis_frame_buffer_sizes[0]"),
                                              ([128], "axis_frame_buffer_sizes")])
def test_a_bad_axis_frame_buffer_size_is_refused_by_the_one_validator(sizes, field):
    verdict = ControllerConfig(axis_frame_buffer_sizes=sizes).validate()
    assert not verdict.ok
    assert verdict.detail.startswith(field)
    with pytest.raises(ValueError, match=r"config\.axis_frame_buffer_sizes"):
        Controller(ControllerConfig(axis_frame_buffer_sizes=sizes))
