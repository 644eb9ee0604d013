"""Frames and the frame buffer (mpi_ros/mpi/frames.py): per-axis constant-jerk frames, the
128-frame buffer and the refusal of an append that would overflow it (docs/decisions.md, "Motion",
frame buffer overflow)."""

from __future__ import annotations

import numpy as np
import pytest

from mpi_ros.mpi import Controller, ControllerConfig, MotionAttr, MPIAction, MPIMotionType, MPIState
from mpi_ros.mpi.frames import AxisPlan, Move, frames_needed
from mpi_ros.mpi.messages import Message
from mpi_ros.mpi.profiles.segment import Segment

T = MPIMotionType
A = MotionAttr


def fill(ctl, ms, params, jerk_percent=50.0):
    """Append S-curve moves until one is refused; returns the accepted count and the refusal."""
    assert ms.start(T.S_CURVE, params=params((1000.0, 0.0), jerk_percent=jerk_percent)).ok
    count = 1
    while True:
        message = ms.start(T.S_CURVE, A.APPEND, params((1000.0 * (count + 1), 0.0), jerk_percent=jerk_percent))
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
    assert ctl.frame_count(0) <= 128 and ctl.frame_count(0) + 8 > 128  # an S-curve move is 7 + 1 frames
    assert len(ms.queue) == count - 1
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 200_000, chunk=500)
    assert ctl.axes[0].command_position == 1000.0 * count  # every accepted move ran, in order


def test_the_refusal_changes_nothing(params):
    # docs/decisions.md, "Motion" (frame buffer overflow) and docs/quality.md, "Robust": the refusal changes nothing
    def run(extra):
        ctl = Controller()
        _, ms = ctl.create_motion(0)
        ms.axis_list_set([0, 1])
        count, _ = fill(ctl, ms, params)
        if extra:
            refused = ms.start(T.TRAPEZOIDAL, A.APPEND, params((-5.0, 0.0)))
            assert refused is Message.MPIMotionMessageFRAME_BUFFER_TOO_SMALL
        trace = []
        for _ in range(60):
            ctl.step(1000)
            trace.append((ms.state, ctl.axes[0].cmd_p, ctl.frame_count(0)))
        return trace, [(e.sample, e.type) for e in ctl.drain_events()]

    assert run(False) == run(True)


def test_room_frees_up_as_frames_execute(ctl, ms, params):
    # MPI 000, mpiMotionStart the buffer is a FIFO: executed frames leave it
    count, _ = fill(ctl, ms, params)
    ctl.step(8000)  # some moves done
    assert ms.start(T.S_CURVE, A.APPEND, params((0.0, 0.0), jerk_percent=50.0)).ok


def test_a_larger_buffer_takes_more_moves(params):
    # MPI 000, MPIMotionMessageFRAME_BUFFER_TOO_SMALL "increase the number of points in the frame buffer"
    def capacity(size):
        ctl = Controller(ControllerConfig(frame_buffer_size=size))
        _, ms = ctl.create_motion(0)
        ms.axis_list_set([0, 1])
        return fill(ctl, ms, params)[0]

    assert capacity(128) == 16 and capacity(256) == 32


def test_frame_count_decreases_as_the_move_runs(ctl, ms, params):
    # MPI 000, MEIMotionFrameBufferStatus, frameCount frameCount "the number of frames in the controller's frame buffer"
    ms.start(T.S_CURVE, params=params((2000.0, 0.0), jerk_percent=50.0))
    counts = []
    while ms.state is MPIState.MOVING:
        counts.append(ctl.frame_count(0))
        ctl.step(25)
    assert counts[0] == 8 and counts == sorted(counts, reverse=True) and counts[-1] == 1


def test_trapezoid_frames():
    # MPI 000, Diagram of mpiMotionStart "Number of frames/point vary with type of move (1frame/point for trapezoidal,
    # to 8 frames/point for S-curve)": here a trapezoid is accel, cruise, decel + the final frame
    plan = AxisPlan(0, [Segment(0.1, 0.0, 0.0, 1e4, 0.0), Segment(0.9, 50.0, 1e3, 0.0, 0.0),
                        Segment(0.1, 950.0, 1e3, -1e4, 0.0)], 0.0, 1000.0)
    assert plan.frame_count == 4 and plan.duration == pytest.approx(1.1)
    assert plan.frames_left(0.0) == 4 and plan.frames_left(0.5) == 3 and plan.frames_left(2.0) == 1


def test_plan_evaluation_ends_exactly_on_target():
    # MPI 002, Configuration of IN_POSITION and DONE Events after STOP or E-STOP Events, AT_TARGET AT_TARGET "TRUE when
    # command = target": the command is the target exactly
    seg = [Segment(0.1, 0.0, 0.0, 1e4, 0.0), Segment(0.1, 50.0, 1e3, -1e4, 0.0)]
    plan = AxisPlan(0, seg, 0.0, 100.0 + 1e-9)  # rounding in the segments is absorbed at the end
    p, v, a = plan.evaluate(np.array([0.05, plan.duration, plan.duration + 1.0]))
    assert p[1] == plan.target and p[2] == plan.target and v[2] == 0.0 and a[2] == 0.0


def test_plan_past_its_end_continues_at_the_final_velocity():
    # MPI 000, MEIMotionAttrFINAL_VEL FINAL_VEL: "a non-zero target velocity for point to point motion types"
    plan = AxisPlan(0, [Segment(1.0, 0.0, 0.0, 100.0, 0.0)], 0.0, 50.0, final_velocity=100.0)
    p, v, a = plan.evaluate(np.array([1.5]))
    assert p[0] == pytest.approx(100.0) and v[0] == 100.0 and a[0] == 0.0


def test_an_empty_plan_holds_its_target():
    # frames.py: "one final frame that holds the end state" (a move of zero length)
    plan = AxisPlan(1, [], 5.0, 5.0)
    p, v, _ = plan.evaluate(np.array([0.0, 1.0]))
    assert plan.duration == 0.0 and list(p) == [5.0, 5.0] and list(v) == [0.0, 0.0]


def test_frames_needed_counts_per_axis():
    # MPI 000, mpiMotionStart the buffer is per axis
    a = AxisPlan(0, [Segment(1.0, 0.0, 1.0, 0.0, 0.0)], 0.0, 1.0)
    b = AxisPlan(1, [Segment(1.0, 0.0, 1.0, 0.0, 0.0)] * 3, 0.0, 3.0)
    move = Move(0, T.TRAPEZOIDAL, A.NONE, [a, b])
    assert move.frame_counts == {0: 2, 1: 4}
    assert frames_needed([move, move], 1) == 8 and frames_needed([move], 2) == 0
    assert move.plan_for(1) is b and move.plan_for(3) is None and move.axes == [0, 1]


def test_frame_count_after_abort_and_reset(ctl, ms, bring):
    # docs/state-machine.md: RESET drops the pending profile; nothing is left in the buffer but the resting frame
    bring(MPIState.ERROR)
    ms.action(MPIAction.RESET)
    assert ctl.frame_count(0) == 0
