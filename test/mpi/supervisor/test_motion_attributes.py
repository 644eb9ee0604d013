"""Motion attributes through the supervisor (mpi_ros/mpi/supervisor/motion.py, planner.py): APPEND,
AUTO_START, DELAY, ID, RELATIVE, SYNC_START/SYNC_END, FINAL_VEL, NO_REVERSAL, OUTPUT, the jerk
types behind firmware option 21, and the 16,384,000-sample frame limit."""

from __future__ import annotations

import pytest

from mpi_ros.mpi import (
    Controller,
    ControllerConfig,
    IoSpace,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIMotionType,
    MPIState,
    Output,
    OutputType,
    Trajectory,
)
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message

A = MotionAttr
T = MPIMotionType
E = MPIEventType
M = Message
RATE = 2000.0


def events_of(ctl, kind):
    return [e for e in ctl.drain_events() if e.type is kind]


def run_idle(ctl, ms, limit=100_000):
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, limit, chunk=50)


# ------------------------------------------------------------------ APPEND ----
def test_append_begins_after_the_previous_completed_and_settled(ctl, ms, params):
    # MPI 000, MPIMotionAttrAPPEND "The APPENDED profile will begin execution after the previous profile has
    # completed and the settling criteria has been met"
    ms.start(T.TRAPEZOIDAL, params=params((1000.0, 0.0)))
    assert ms.start(T.TRAPEZOIDAL, A.APPEND, params((2000.0, 0.0))).ok
    assert ms.snapshot().moves_pending == 1
    axis = ctl.axes[0]
    while not any(e.type is E.MOTION_DONE for e in ctl.events):
        ctl.step(1)
        assert axis.cmd_p <= 1000.0
    assert axis.status.done
    assert axis.status.settled
    assert axis.cmd_p == 1000.0
    ctl.step(1)
    assert axis.cmd_p > 1000.0  # the next sample runs the appended move
    run_idle(ctl, ms)
    assert axis.command_position == 2000.0


def test_append_on_an_idle_supervisor_is_a_start(ctl, ms, params):
    # MPI 000, MPIMotionAttrAPPEND APPEND adds to "a previous motion profile": with none, the move starts
    assert ms.start(T.TRAPEZOIDAL, A.APPEND, params((300.0, 0.0))).ok
    assert ms.state is MPIState.MOVING
    assert not ms.queue


def _stopped_then_resumed(append_when_stopped: bool):
    """A move to 1000, a STOP at sample 301, RESUME 100 samples after it is STOPPED; the APPEND of
    a move to 2000 is given at sample 300 (MOVING) or once STOPPED. The command, per sample."""
    ctl = Controller()
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0, 1])
    params = (MotionParams(trajectory=[Trajectory(1000.0, 10_000.0, 10_000.0)], position=[x, 0.0])
              for x in (1000.0, 2000.0))
    assert ms.start(T.TRAPEZOIDAL, A.NONE, next(params)).ok
    ctl.step(300)
    if not append_when_stopped:
        assert ms.start(T.TRAPEZOIDAL, A.APPEND, next(params)).ok
    ctl.step(1)
    assert ms.action(MPIAction.STOP).ok
    assert ctl.run_until(lambda c: ms.state is MPIState.STOPPED, 10_000)
    if append_when_stopped:
        assert ms.start(T.TRAPEZOIDAL, A.APPEND, next(params)).ok
        assert ms.state is MPIState.STOPPED
        assert ms.snapshot().moves_pending == 1
    positions = []
    for _ in range(100):
        ctl.step(1)
        positions.append(ctl.axes[0].cmd_p)
    assert ms.action(MPIAction.RESUME).ok
    while ms.state is not MPIState.IDLE:
        ctl.step(1)
        positions.append(ctl.axes[0].cmd_p)
    return positions, len(events_of(ctl, E.MOTION_DONE))


def test_append_while_stopped_queues_behind_the_pending_move_and_resume_runs_both():
    # MPI 000, MPIMotionAttrAPPEND: "This bit enables the motion profile to be added to the end of a previous
    # motion profile ... The APPENDED profile will begin execution after the previous profile has completed":
    # a STOPPED supervisor's previous profile is still pending (RESUME continues it), so the appended move
    # queues behind it exactly as if it had been appended before the STOP
    stopped, done_stopped = _stopped_then_resumed(append_when_stopped=True)
    moving, done_moving = _stopped_then_resumed(append_when_stopped=False)
    assert stopped == moving
    assert stopped[-1] == 2000.0
    assert done_stopped == done_moving == 2


def test_append_with_modify(ctl, ms, params):
    # MPI 000, MPIMotionAttrAPPEND "The APPEND bit can be used with mpiMotionStart(...) or mpiMotionModify(...)"
    ms.start(T.TRAPEZOIDAL, params=params((500.0, 0.0)))
    ctl.step(10)
    assert ms.modify(T.TRAPEZOIDAL, A.APPEND, params((800.0, 100.0))).ok
    run_idle(ctl, ms)
    assert [a.command_position for a in ms.axes] == [800.0, 100.0]
    assert len(events_of(ctl, E.MOTION_DONE)) == 2


def test_append_velocity_move_after_a_point_to_point(ctl, ms, params):
    # MPI 000, Move Types: PT, PVT, Bessel, Bspline, Bspline2, S-Curve, Trapezoidal, Velocity, Frame APPEND move types
    # include Velocity
    ms.start(T.TRAPEZOIDAL, params=params((200.0, 0.0)))
    assert ms.start(T.VELOCITY, A.APPEND, params((), velocity=-300.0)).ok
    ctl.step(6000)
    assert ms.state is MPIState.MOVING
    assert ctl.axes[0].cmd_v == -300.0


# ------------------------------------------------------------------ AUTO_START ----
def test_auto_start_after_the_move_finished(ctl, ms, params):
    # MPI 000, MPIMotionAttrAUTO_START "calls to mpiMotionModify(...) will automatically start a new motion if the
    # previous motion is done"; MPI 000, MPIMotionMessageAUTO_START answers MPIMotionMessageAUTO_START ("not an error")
    ms.start(T.TRAPEZOIDAL, params=params((200.0, 0.0)))
    run_idle(ctl, ms)
    # MPI 000, MPIMotionAttrAUTO_START
    assert ms.modify(T.TRAPEZOIDAL, params=params((0.0, 0.0))).message is M.MPIMotionMessageIDLE
    assert ms.modify(T.TRAPEZOIDAL, A.AUTO_START, params((0.0, 50.0))).message is M.MPIMotionMessageAUTO_START
    run_idle(ctl, ms)
    assert [a.command_position for a in ms.axes] == [0.0, 50.0]


# ------------------------------------------------------------------ DELAY ----
def test_delay_per_axis_before_the_profile(ctl, ms, params):
    # MPI 000, MPIMotionAttrDELAY DELAY "enables a time delay (seconds) before the motion profile begins";
    # MPI 000, MPIMotionAttrDELAY "an array of doubles that assign delay times for each Axis"
    assert ms.start(T.TRAPEZOIDAL, A.DELAY | A.SYNC_START,
                    params((100.0, 100.0), trajectory=[Trajectory(1000, 1e4, 1e4)] * 2, delay=[0.1, 0.25])).ok
    first_move = [None, None]
    for _ in range(1000):
        ctl.step(1)
        for i in (0, 1):
            if first_move[i] is None and ctl.axes[i].cmd_p > 1e-9:
                first_move[i] = ctl.sample
    assert first_move == [201, 501]


def test_delay_on_auto_start_is_used(ctl, ms, params):
    # MPI 000, MPIMotionMessageILLEGAL_DELAY "If it is currently not in motion and the AUTO_START attribute is set, this
    # message will not be returned and the specified delay will be used at the beginning"
    message = ms.modify(T.TRAPEZOIDAL, A.AUTO_START | A.DELAY, params((100.0, 0.0), delay=[0.05, 0.05])).message
    assert message is M.MPIMotionMessageAUTO_START
    ctl.step(100)
    assert ctl.axes[0].cmd_p < 1e-9
    ctl.step(1)
    assert ctl.axes[0].cmd_p > 1e-9


def test_illegal_delay_on_modify_in_motion(ctl, ms, params, bring):
    # MPI 000, MPIMotionMessageILLEGAL_DELAY ILLEGAL_DELAY "Returned if a motion modify is called with a non-zero delay
    # value and the MPIMotionAttrDELAY attribute is set while in motion"
    bring(MPIState.MOVING)
    answer = ms.modify(T.TRAPEZOIDAL, A.DELAY, params((10.0, 0.0), delay=[0.0, 0.1]))
    assert answer.message is M.MPIMotionMessageILLEGAL_DELAY
    assert ms.modify(T.TRAPEZOIDAL, A.DELAY, params((10.0, 0.0), delay=[0.0, 0.0])).ok  # zero is legal


def test_illegal_delay_while_the_axes_wait_out_a_delay(ctl, ms, params):
    # MPI 000, MPIMotionMessageILLEGAL_DELAY: a modify with a non-zero delay "while in motion".
    # In motion is the supervisor's state (MOVING), not the axes' velocity: during a start's
    # DELAY the axes stand still, yet the motion is under way.
    assert ms.start(T.TRAPEZOIDAL, A.DELAY, params((100.0, 0.0), delay=[0.5, 0.5])).ok
    ctl.step(10)
    assert ms.state is MPIState.MOVING
    assert ctl.axes[0].cmd_v == 0.0
    answer = ms.modify(T.TRAPEZOIDAL, A.DELAY, params((10.0, 0.0), delay=[0.1, 0.1]))
    assert answer.message is M.MPIMotionMessageILLEGAL_DELAY
    ctl.step(1)
    assert ctl.axes[0].cmd_v == 0.0
    assert ms.current.plans[0].target == 100.0


def test_delay_with_velocity_move(ctl, ms, params):
    # MPI 000, Move Types: S-Curve, Trapezoidal, Velocity DELAY move types: S-Curve, Trapezoidal, Velocity
    ms.start(T.VELOCITY, A.DELAY, params((), velocity=100.0, delay=[0.01, 0.0]))
    ctl.step(20)
    assert ctl.axes[0].cmd_v == 0.0
    assert ctl.axes[1].cmd_v > 0.0
    ctl.step(1)
    assert ctl.axes[0].cmd_v > 0.0


# ------------------------------------------------------------------ ID ----
@pytest.mark.parametrize(("given", "stored"), [(1, 1), (32767, 32767), (-32768, -32768), (65535, -1),
                                          (70000, 4464), (-40000, 25536)])
def test_id_is_16_bit(ctl, ms, params, given, stored):
    # MPI 000, MPIMotionAttributes, id id "The id is limited to 16-bit resolution by the controller firmware";
    # docs/decisions.md, "Motion": documented quirks are reproduced and reported as events
    assert ms.start(T.TRAPEZOIDAL, A.ID, params((10.0, 0.0), id=given)).ok
    assert ms.snapshot().move_id == stored
    assert ctl.axes[0].move_id == stored
    truncated = events_of(ctl, E.ID_TRUNCATED)
    assert len(truncated) == (0 if given == stored else 1)
    if truncated:
        assert truncated[0].move_id == stored
        assert str(given) in truncated[0].detail


def test_modify_keeps_the_id_unless_given(ctl, ms, params):
    # MPI 000, MPIMotionAttrID ID "can be used with mpiMotionStart(...) and mpiMotionModify(...)"
    ms.start(T.TRAPEZOIDAL, A.ID, params((5000.0, 0.0), id=11))
    ctl.step(100)
    ms.modify(T.TRAPEZOIDAL, params=params((4000.0, 0.0)))
    assert ms.snapshot().move_id == 11
    ms.modify(T.TRAPEZOIDAL, A.ID, params((3000.0, 0.0), id=12))
    run_idle(ctl, ms)
    assert [e.move_id for e in events_of(ctl, E.MOTION_DONE)] == [12]


# ------------------------------------------------------------------ RELATIVE ----
def test_relative_move(ctl, ms, params):
    # MPI 000, MPIMotionAttrRELATIVE "a move beginning at position 1000 with a position parameter value of 2000 will
    # move to position 2000. If the RELATIVE attribute is turned on, the final move position will
    # be 3000"
    ms.start(T.TRAPEZOIDAL, params=params((1000.0, 1000.0)))
    run_idle(ctl, ms)
    ms.start(T.TRAPEZOIDAL, A.RELATIVE, params((2000.0, -500.0)))
    run_idle(ctl, ms)
    assert [a.command_position for a in ms.axes] == [3000.0, 500.0]


def test_relative_fraction_is_truncated(ctl, ms, params):
    # MPI 000, mpiMotionStart "When successive non-integer length relative motions are commanded, the
    # fractional portion is truncated and discarded"; docs/decisions.md, "Motion": reported as an event
    for _ in range(4):
        ms.start(T.TRAPEZOIDAL, A.RELATIVE, params((10.75, -2.5)))
        run_idle(ctl, ms)
    assert [a.command_position for a in ms.axes] == [40.0, -8.0]
    events = events_of(ctl, E.RELATIVE_TRUNCATED)
    assert len(events) == 8
    assert "10.75" in events[0].detail


def test_relative_with_append_adds_to_the_previous_target(ctl, ms, params):
    # MPI 000, MPIMotionAttrRELATIVE RELATIVE "Currently only supports APPEND and ID attributes"
    ms.start(T.TRAPEZOIDAL, params=params((100.0, 0.0)))
    ms.start(T.TRAPEZOIDAL, A.APPEND | A.RELATIVE, params((50.0, 20.0)))
    run_idle(ctl, ms)
    assert [a.command_position for a in ms.axes] == [150.0, 20.0]


def test_relative_is_not_shifted_by_the_origin(ctl, ms, params):
    # MPI 000, MPIMotionAttrRELATIVE relative = "a relative distance ... from the starting value"
    ctl.axis_origin_set(0, 1000.0)
    ms.start(T.TRAPEZOIDAL, A.RELATIVE, params((10.0, 0.0)))
    run_idle(ctl, ms)
    assert ctl.axes[0].command_position == -990.0


# ------------------------------------------------------------------ SYNC ----
SYNC_TRAJ = [Trajectory(1000.0, 1e4, 1e4), Trajectory(200.0, 1e3, 1e3)]


def first_and_last_motion(ctl, ms, samples):
    first, last = [None, None], [None, None]
    previous = [a.cmd_p for a in ms.axes]
    for _ in range(samples):
        ctl.step(1)
        for i, axis in enumerate(ms.axes):
            if axis.cmd_p != previous[i]:
                first[i] = first[i] or ctl.sample
                last[i] = ctl.sample
            previous[i] = axis.cmd_p
    return first, last


def test_sync_end_ends_together(ctl, ms, params):
    # MPI 000, MPIMotionAttrSYNC_END SYNC_END "synchronizes the motion profiles for multiple axes so they will all end
    # at the same time. Delays are inserted before the shorter profiles. When enabled, each axis
    # will use its own MPITrajectory values"; MPI 000, MPIMotionAttrSYNC_END
    ms.start(T.TRAPEZOIDAL, A.SYNC_END, params((1000.0, 100.0), trajectory=SYNC_TRAJ))
    first, last = first_and_last_motion(ctl, ms, 3000)
    assert last[0] == last[1]
    assert first[0] == 1
    assert first[1] > 1
    assert [a.command_position for a in ms.axes] == [1000.0, 100.0]


def test_sync_start_starts_together(ctl, ms, params):
    # MPI 000, MPIMotionAttrSYNC_START SYNC_START "they will all start at the same time. Delays are inserted after the
    # shorter profiles"; MPI 000, MPIMotionAttrSYNC_START
    ms.start(T.TRAPEZOIDAL, A.SYNC_START, params((1000.0, 100.0), trajectory=SYNC_TRAJ))
    first, last = first_and_last_motion(ctl, ms, 3000)
    assert first == [1, 1]
    assert last[1] < last[0]


def test_without_sync_one_vector_trajectory(ctl, ms, params):
    # MPI 000, MPIMotionSCurve "If more than one axis is associated with the motion and neither SYNC_START nor
    # SYNC_END are specified, then only the first trajectory structure will be applied as the
    # vector trajectory for all the axes"
    ms.start(T.TRAPEZOIDAL, params=params((300.0, 400.0), velocity=1000.0))
    ctl.step(300)
    vx, vy = (a.cmd_v for a in ms.axes)
    assert (vx, vy) == (pytest.approx(600.0), pytest.approx(800.0))
    _first, last = first_and_last_motion(ctl, ms, 1000)
    assert last[0] == last[1] == 1200


# ------------------------------------------------------------------ FINAL_VEL ----
def test_final_velocity_then_appended_move_keeps_the_speed(ctl, ms, params):
    # MPI 000, MEIMotionAttrFINAL_VEL FINAL_VEL "a non-zero target velocity for point to point motion types"; the
    # appended move starts from it (motion.py: "An appended move follows one that ends moving")
    ms.start(T.TRAPEZOIDAL, A.FINAL_VEL, params((1000.0, 0.0), final_velocity=[500.0, 0.0]))
    ms.start(T.TRAPEZOIDAL, A.APPEND, params((2000.0, 0.0)))
    axis = ctl.axes[0]
    previous_v, jumps, passed_target_at = 0.0, [], None
    while ms.state is MPIState.MOVING:
        ctl.step(1)
        jumps.append(abs(axis.cmd_v - previous_v))
        previous_v = axis.cmd_v
        if passed_target_at is None and axis.cmd_p >= 1000.0:
            passed_target_at = axis.cmd_v
    assert passed_target_at == pytest.approx(500.0, abs=5.0)
    assert max(jumps) <= 10_000.0 / RATE * (1 + 1e-9)  # never more than the acceleration allows
    assert axis.command_position == 2000.0


def test_final_velocity_above_the_velocity_is_a_profile_error(ms, params):
    # MPI 000, MPIMotionMessagePROFILE_ERROR PROFILE_ERROR "The motion profile is not possible with the specified
    # constraints"
    message = ms.start(T.TRAPEZOIDAL, A.FINAL_VEL, params((1000.0, 0.0), final_velocity=[1500.0, 0.0])).message
    assert message is M.MPIMotionMessagePROFILE_ERROR


def test_vector_final_velocity_off_the_line_is_param_invalid(ms, params):
    # planner.py: "final velocities of a vector move must lie along the move"
    message = ms.start(T.TRAPEZOIDAL, A.FINAL_VEL, params((1000.0, 0.0), final_velocity=[100.0, 100.0])).message
    assert message is M.MPIMessagePARAM_INVALID


# ------------------------------------------------------------------ NO_REVERSAL ----
def test_no_reversal_refuses_a_modify_behind_the_motion(ctl, ms, params, bring):
    # MPI 000, MPIMotionMessagePROFILE_ERROR PROFILE_ERROR "returned by mpiMotionModify when the NO_REVERSAL attribute
    # mask is specified, but the specified target position is in the reverse direction"; MPI 000,
    # MEIMotionAttrNO_REVERSAL
    bring(MPIState.MOVING)
    where = ctl.axes[0].command_position
    answer = ms.modify(T.TRAPEZOIDAL, A.NO_REVERSAL, params((where - 100.0, 0.0)))
    assert answer.message is M.MPIMotionMessagePROFILE_ERROR
    assert ms.modify(T.TRAPEZOIDAL, A.NO_REVERSAL, params((where + 5000.0, 0.0))).ok
    run_idle(ctl, ms)
    assert ctl.axes[0].command_position == where + 5000.0


def test_no_reversal_refuses_a_target_too_close_to_stop(ctl, ms, params, bring):
    # MPI 000, MEIMotionAttrNO_REVERSAL NO_REVERSAL "prevents a motion profile from changing direction": a target the
    # axis cannot stop before would need a reversal
    bring(MPIState.MOVING)
    where = ctl.axes[0].command_position
    answer = ms.modify(T.TRAPEZOIDAL, A.NO_REVERSAL, params((where + 1.0, 0.0)))
    assert answer.message is M.MPIMotionMessagePROFILE_ERROR
    assert ms.modify(T.TRAPEZOIDAL, params=params((where + 1.0, 0.0))).ok  # without it: reverses


# ------------------------------------------------------------------ OUTPUT ----
def test_output_bits_as_the_move_begins(ctl, ms, params):
    # MPI 000, MEIMotionAttrOUTPUT OUTPUT "configures a frame to toggle an output bit as a move begins"; MPI 000,
    # MEIMotionAttrOutput, offMask offMask "bits to be turned OFF", onMask "bits to be turned ON"; MPI 000,
    # MEIMotionAttrOutputTypeOUTPUT type OUTPUT
    ctl.io_set(IoSpace.IO, 3, 0b1010)
    out = Output(type=OutputType.OUTPUT, address=3, on_mask=0b0101, off_mask=0b1000)
    assert ms.start(T.TRAPEZOIDAL, A.OUTPUT, params((100.0, 0.0), output=[out])).ok
    assert ctl.io_get(IoSpace.IO, 3)[1] == 0b0111


def test_motor_output(ctl, ms, params):
    # MPI 000, MEIMotionAttrOutputTypeMOTOR type MOTOR "configures a motor's output bit(s)"; MPI 000,
    # MEIMotionAttrOutput, motor motor number
    out = Output(type=OutputType.MOTOR, motor=2, on_mask=0x100)
    ms.start(T.TRAPEZOIDAL, A.OUTPUT, params((100.0, 0.0), output=[out]))
    assert ctl.io_get(IoSpace.MOTOR_GENERAL_IO, 2)[1] == 0x100


def test_output_type_none_sets_nothing(ctl, ms, params):
    # MPI 000, MEIMotionAttrOutputTypeNONE NONE "disables the setting/clearing of output bit(s)"
    ms.start(T.TRAPEZOIDAL, A.OUTPUT, params((100.0, 0.0), output=[Output(type=OutputType.NONE, on_mask=-1)]))
    assert all(ctl.io_get(IoSpace.IO, i)[1] == 0 for i in range(64))


def test_output_of_an_appended_move_fires_when_it_begins(ctl, ms, params):
    # MPI 000, MEIMotionAttrOUTPUT "as a move begins": an appended move begins after the previous one
    ms.start(T.TRAPEZOIDAL, params=params((300.0, 0.0)))
    out = Output(type=OutputType.OUTPUT, address=0, on_mask=1)
    ms.start(T.TRAPEZOIDAL, A.APPEND | A.OUTPUT, params((0.0, 0.0), output=[out]))
    while ms.current is not None and ms.queue:
        assert ctl.io_get(IoSpace.IO, 0)[1] == 0
        ctl.step(10)
    assert ctl.io_get(IoSpace.IO, 0)[1] == 1


# ------------------------------------------------------------------ jerk types ----
JERK = Trajectory(1000.0, 10_000.0, 5_000.0, 0.0, 1e6, 5e5)


@pytest.mark.parametrize("kind", [T.S_CURVE_JERK, T.VELOCITY_JERK])
def test_jerk_types_need_firmware_option_21(ctl, ms, params, kind):
    # MPI 000, MPIMotionType "In the standard firmware, the MPIMotionTypeS_CURVE_JERK and
    # MPIMotionTypeVELOCITY_JERK motion types are not supported and if specified, the MPI will return
    # a profile not supported error"; MPI 000, MPIMotionMessagePROFILE_NOT_SUPPORTED
    answer = ms.start(kind, params=params((100.0, 0.0), trajectory=[JERK]))
    assert answer.message is M.MPIMotionMessagePROFILE_NOT_SUPPORTED
    assert ms.state is MPIState.IDLE


def option_21():
    ctl = Controller(ControllerConfig(firmware_option_21=True))
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0, 1])
    return ctl, ms


def test_s_curve_jerk_with_the_option(params):
    # MPI 000, MPIMotionTypeS_CURVE_JERK S_CURVE_JERK "specified by acceleration, velocity, deceleration,
    # accelerationJerk, decelerationJerk, and final position"
    ctl, ms = option_21()
    assert ms.start(T.S_CURVE_JERK, params=params((3000.0, 4000.0), trajectory=[JERK])).ok
    run_idle(ctl, ms)
    assert [a.command_position for a in ms.axes] == [3000.0, 4000.0]


def test_velocity_jerk_with_the_option(params):
    # MPI 000, MPIMotionTypeVELOCITY_JERK VELOCITY_JERK "S-Curve acceleration to a constant velocity"
    ctl, ms = option_21()
    assert ms.start(T.VELOCITY_JERK, params=params((), trajectory=[JERK])).ok
    ctl.step(4000)
    assert [a.cmd_v for a in ms.axes] == [1000.0, 1000.0]
    assert ms.snapshot().motion_type == "VELOCITY_JERK"


# ------------------------------------------------------------------ frame time limit ----
def test_velocity_frame_stops_after_16384000_samples():
    # MPI 000, mpiMotionStart "The XMP firmware velocity frame execution time ... cannot exceed 16,384,000
    # samples ... the axes will stop abruptly after 16,384,000 samples. The motors will still
    # maintain servo control and no errors are reported"; docs/decisions.md, "Motion": reproduced and
    # reported as an event. At 100 Hz the ramp takes 10 samples, then the velocity frame runs its limit.
    ctl = Controller(ControllerConfig(sample_rate=100.0, axis_count=1, supervisor_count=1))
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0])
    assert ms.start(T.VELOCITY, params=MotionParams(trajectory=[Trajectory(1000.0, 10_000.0)])).ok
    ctl.step(10 + 16_384_000 - 1)
    axis = ctl.axes[0]
    assert axis.cmd_v == 1000.0
    assert not events_of(ctl, E.FRAME_TIME_LIMIT)
    ctl.step(1)  # the velocity frame has run 16,384,000 samples
    assert axis.cmd_v == 0.0
    assert axis.amp_enabled
    limit = events_of(ctl, E.FRAME_TIME_LIMIT)
    assert [(e.sample, e.axis) for e in limit] == [(10 + 16_384_000, 0)]
    end = axis.cmd_p
    ctl.step(1)
    assert axis.cmd_p == end
    assert axis.cmd_v == 0.0
    assert ms.state is not MPIState.ERROR


def test_point_to_point_frame_over_the_limit_is_cut_and_reported():
    # MPI 000, mpiMotionStart "The XMP firmware velocity frame execution time for point-to-point moves cannot
    # exceed 16,384,000 samples"; MPI 000, mpiMotionModify (modify alike)
    ctl = Controller(ControllerConfig(sample_rate=100.0, axis_count=1, supervisor_count=1))
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0])
    params = MotionParams(trajectory=[Trajectory(1.0, 10_000.0, 10_000.0)], position=[200_000.0])
    assert ms.start(T.TRAPEZOIDAL, params=params).ok
    warned = events_of(ctl, E.FRAME_TIME_LIMIT)
    assert len(warned) == 1
    assert warned[0].sample == 0
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 16_500_000, chunk=1 << 20)
    assert ctl.axes[0].command_position == pytest.approx(163_840.0, abs=1e-3)  # not 200000
    assert len(events_of(ctl, E.FRAME_TIME_LIMIT)) == 1  # and again when it bites
