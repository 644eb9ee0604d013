"""What the actions do to the motion (mpi_ros/mpi/supervisor/motion.py, clock.py): STOP ramps the feedrate
to pauseFeedrate over decelTime.stop and RESUME continues on the same path; E_STOP ramps to zero
over decelTime.eStop; ABORT disables the amplifiers; RESET after ABORT sets command = actual."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from mpi_ros.mpi import Controller, ControllerConfig, Hold, HoldType, MotionAttr, MPIAction, MPIMotionType, MPIState
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message

T = MPIMotionType
RATE = 2000.0


def run_smoothly_to_idle(ctl, ms, accel_limit=10_000.0):
    """Step until IDLE, checking no command velocity step exceeds the acceleration limit."""
    previous = ctl.axes[0].cmd_v
    while ms.state is MPIState.MOVING:
        ctl.step(1)
        assert abs(ctl.axes[0].cmd_v - previous) <= accel_limit / RATE * (1 + 1e-9)
        previous = ctl.axes[0].cmd_v


def two_axes():
    ctl = Controller(ControllerConfig(axis_count=2, supervisor_count=1))
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0, 1])
    return ctl, ms


def record(ctl, ms, samples):
    rows = []
    for _ in range(samples):
        ctl.step(1)
        rows.append([ctl.sample, ms.state] + [x for a in ms.axes for x in (a.cmd_p, a.cmd_v, a.cmd_a)])
    return rows


def test_stop_decelerates_to_zero_over_the_stop_time(params):
    # MPI 000, MPIActionSTOP STOP "decelerates the axis (or axes) to a stop in the time specified by the stop
    # time"; MPI 000, MPIMotionDecelTime, stop stop = 0.5 s; docs/decisions.md, "Stopping": STOP ramps the feedrate to
    # pauseFeedrate
    ctl, ms = two_axes()
    ms.start(T.S_CURVE, params=params((30_000.0, 40_000.0), jerk_percent=50.0))
    ctl.step(1000)
    assert ms.action(MPIAction.STOP).ok
    rows = record(ctl, ms, 1000)
    speeds = [np.hypot(r[3], r[6]) for r in rows]
    assert speeds[-1] == 0.0
    assert speeds[-2] > 0.0
    assert all(b <= a for a, b in itertools.pairwise(speeds))  # never speeds up while stopping
    assert ms.state is MPIState.STOPPED
    assert ms.snapshot().feedrate == 0.0


def test_stop_stays_on_the_path_and_resume_continues_it(params):
    # docs/decisions.md, "Stopping": STOP ramps the feedrate to pauseFeedrate over the stop time, so
    # RESUME continues on the same path; MPI 000, MPIActionRESUME RESUME "the Motion will resume if it
    # was stopped by a prior call"
    ctl, ms = two_axes()
    ms.log_open(1_000_000)
    ms.start(T.S_CURVE, params=params((3000.0, 4000.0), jerk_percent=60.0))
    ctl.step(700)
    ms.action(MPIAction.STOP)
    ctl.step(1000)
    stopped_at = (ms.axes[0].cmd_p, ms.axes[1].cmd_p)
    ctl.step(500)
    assert (ms.axes[0].cmd_p, ms.axes[1].cmd_p) == stopped_at  # STOPPED holds still
    assert ms.action(MPIAction.RESUME).ok
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 50_000, chunk=500)
    log = np.concatenate(ms.log.columns)  # per sample: command, actual, velocity of each axis
    xs, ys = log[:, 0], log[:, 3]
    assert np.max(np.abs(xs * 4000.0 - ys * 3000.0)) < 1e-6  # on the straight line throughout
    assert np.all(np.diff(xs) >= 0.0)  # and never backwards
    assert [a.command_position for a in ms.axes] == [3000.0, 4000.0]


def test_resume_ramps_the_feedrate_back_over_the_stop_time(params):
    # docs/decisions.md, "Stopping": RESUME ramps the feedrate back; MPI 000, MPIMotionConfig,
    # normalFeedrate normalFeedrate
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(1000)
    ms.action(MPIAction.STOP)
    ctl.step(1000)
    ms.action(MPIAction.RESUME)
    ctl.step(500)
    assert ms.snapshot().feedrate == pytest.approx(0.5)
    assert ctl.axes[0].cmd_v == pytest.approx(500.0)
    ctl.step(500)
    assert ms.snapshot().feedrate == 1.0
    assert ctl.axes[0].cmd_v == 1000.0


def test_resume_then_stop_again(params):
    # MPI 000, MPIActionRESUME: STOP and RESUME can alternate; the move still ends on its target
    ctl, ms = two_axes()
    ms.start(T.S_CURVE, params=params((2000.0, -1000.0), jerk_percent=30.0))
    for wait in (300, 150, 999):
        ctl.step(wait)
        if ms.state is MPIState.MOVING:
            ms.action(MPIAction.STOP)
            assert ctl.run_until(lambda c: ms.state is MPIState.STOPPED, 2000)
            ms.action(MPIAction.RESUME)
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 20_000, chunk=10)
    assert [a.command_position for a in ms.axes] == [2000.0, -1000.0]


def test_e_stop_ramps_to_zero_over_the_e_stop_time(params):
    # MPI 000, MPIActionE_STOP E_STOP "will decelerate the axis (or axes) to a stop in the time specified by the
    # eStop time"; MPI 000, MPIMotionDecelTime, eStop eStop = 0.05 s
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(1000)
    ms.action(MPIAction.E_STOP)
    rows = record(ctl, ms, 100)
    assert rows[-1][3] == 0.0
    assert rows[-2][3] > 0.0
    assert rows[0][4] == pytest.approx(-1000.0 / 0.05)  # linear ramp of the feedrate
    assert ms.state is MPIState.ERROR


def test_e_stop_stays_on_the_path(params):
    # docs/decisions.md, "Stopping": E_STOP ramps the feedrate to zero over decelTime.eStop (the path is kept)
    ctl, ms = two_axes()
    ms.start(T.S_CURVE, params=params((3000.0, 4000.0), jerk_percent=50.0))
    ctl.step(500)
    ms.action(MPIAction.E_STOP)
    rows = record(ctl, ms, 200)
    xs, ys = np.array([r[2] for r in rows]), np.array([r[5] for r in rows])
    assert np.max(np.abs(xs * 4000.0 - ys * 3000.0)) < 1e-6


def test_abort_disables_the_amplifiers_and_freezes_the_command(params):
    # MPI 000, MPIActionABORT ABORT "will disable the PID control ..., and disable the amp enable outputs"
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(1000)
    command = ctl.axes[0].cmd_p
    assert ms.action(MPIAction.ABORT).ok
    assert not any(a.amp_enabled for a in ms.axes)
    assert not ctl.axis_snapshot(0).amp_enabled
    ctl.step(4000)
    axis = ctl.axes[0]
    assert axis.cmd_p == command
    assert axis.act_p > command + 10.0
    assert abs(axis.act_v) < 1.0  # and came to rest on its own


def test_reset_after_abort_sets_command_to_actual(params):
    # MPI 000, MPIActionRESET "If the error state was caused by an Abort action, then the command position of
    # associated axes will be set equal to the actual position during the Reset"
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(1000)
    ms.action(MPIAction.ABORT)
    ctl.step(2000)
    assert ms.action(MPIAction.RESET).ok
    axis = ctl.axes[0]
    assert axis.amp_enabled
    assert axis.cmd_p == axis.act_p
    ctl.step(1000)
    assert axis.cmd_p == axis.act_p
    assert ms.state is MPIState.IDLE


def test_reset_after_e_stop_keeps_the_command(params):
    # MPI 000, MPIActionRESET: only after an Abort is the command set to the actual position
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(1000)
    ms.action(MPIAction.E_STOP)
    assert ctl.run_until(lambda c: ms.state is MPIState.ERROR, 200)
    command = ctl.axes[0].cmd_p
    assert command != ctl.axes[0].act_p
    ms.action(MPIAction.RESET)
    assert ctl.axes[0].cmd_p == command


def test_e_stop_abort_decelerates_then_disables(params):
    # MPI 000, MPIActionE_STOP_ABORT E_STOP_ABORT "will decelerate the axis (or axes) to a stop in the time specified
    # by the eStop time. Next, MotionAction will generate an MPIActionABORT"
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(1000)
    ms.action(MPIAction.E_STOP_ABORT)
    rows = record(ctl, ms, 99)
    assert all(a.amp_enabled for a in ms.axes)
    assert rows[-1][3] > 0.0
    ctl.step(1)
    assert ctl.axes[0].cmd_v == 0.0
    assert not any(a.amp_enabled for a in ms.axes)
    assert ms.state is MPIState.ERROR
    ms.action(MPIAction.RESET)
    assert ctl.axes[0].cmd_p == ctl.axes[0].act_p  # it was aborted: command = actual


def _safety_events(ctl):
    kinds = (MPIEventType.E_STOP, MPIEventType.ABORT)
    return [(e.type, e.sample) for e in ctl.drain_events() if e.type in kinds and e.supervisor == 0]


def test_e_stop_abort_emits_the_abort_it_generates(params):
    # MPI 000, MPIActionE_STOP_ABORT: "The E_STOP_ABORT first performs an E_STOP, and then performs an ABORT"
    # ("Next, MotionAction will generate an MPIActionABORT"): the E_STOP event at the action, the ABORT event
    # at the sample the amplifiers go off, as a plain ABORT emits it
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(1000)
    ctl.drain_events()
    ms.action(MPIAction.E_STOP_ABORT)
    began = ctl.sample
    assert ctl.run_until(lambda c: not ms.axes[0].amp_enabled, 1000)
    ctl.step(10)
    assert _safety_events(ctl) == [(MPIEventType.E_STOP, began), (MPIEventType.ABORT, ctl.sample - 10)]


def test_e_stop_abort_in_error_after_an_e_stop_emits_abort(params):
    # docs/state-machine.md: E_STOP_ABORT in ERROR "OK, stays ERROR" and still disables the amplifiers: the
    # ABORT it performs (MPI 000, MPIActionE_STOP_ABORT) is an ABORT event
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(500)
    ms.action(MPIAction.E_STOP)
    assert ctl.run_until(lambda c: ms.state is MPIState.ERROR, 200)
    ctl.drain_events()
    assert ms.action(MPIAction.E_STOP_ABORT).ok
    assert _safety_events(ctl) == [(MPIEventType.ABORT, ctl.sample)]
    assert not ms.axes[0].amp_enabled


def test_abort_in_error_after_e_stop_disables(params):
    # docs/state-machine.md: ABORT in ERROR "OK, stays ERROR" (and does abort)
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(500)
    ms.action(MPIAction.E_STOP)
    assert ctl.run_until(lambda c: ms.state is MPIState.ERROR, 200)
    assert ms.axes[0].amp_enabled
    ms.action(MPIAction.ABORT)
    assert not ms.axes[0].amp_enabled
    assert ms.state is MPIState.ERROR


def test_stop_before_the_move_would_end(params):
    # MPI 000, MPIActionSTOP: a STOP near the end of a move; the pending rest runs on RESUME
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, params=params((1000.0, 0.0)))
    ctl.step(1500)  # 0.35 s of the profile left; the stop ramp runs 0.25 s of it
    ms.action(MPIAction.STOP)
    assert ctl.run_until(lambda c: ms.state is MPIState.STOPPED, 2000)
    assert ctl.axes[0].command_position < 1000.0
    ms.action(MPIAction.RESUME)
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 20_000, chunk=10)
    assert ctl.axes[0].command_position == 1000.0


def test_velocity_move_stops_and_resumes(params):
    # MPI 000, MPIActionSTOP STOP on a VELOCITY move; RESUME returns to the commanded velocity
    ctl, ms = two_axes()
    ms.start(T.VELOCITY, params=params((), velocity=-800.0))
    ctl.step(1000)
    ms.action(MPIAction.STOP)
    ctl.step(1000)
    assert ctl.axes[0].cmd_v == 0.0
    assert ms.state is MPIState.STOPPED
    ms.action(MPIAction.RESUME)
    ctl.step(1000)
    assert ctl.axes[0].cmd_v == -800.0
    assert ms.state is MPIState.MOVING


def test_start_from_a_slowly_moving_stop_keeps_the_velocity(params):
    # MPI 000, MPIMotionConfig, pauseFeedrate pauseFeedrate "the feed speed rate for the Stop action": with 0.5 the axes
    # still move when STOPPED; docs/state-machine.md: a new start from STOPPED drops the pending profile; the new
    # move must start from the velocity the axes have (limits never exceeded)
    ctl, ms = two_axes()
    config = ms.config_get()[1]
    config.pause_feedrate = 0.5
    ms.config_set(config)
    ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0)))
    ctl.step(1000)
    ms.action(MPIAction.STOP)
    assert ctl.run_until(lambda c: ms.state is MPIState.STOPPED, 2000)
    assert ctl.axes[0].cmd_v == pytest.approx(500.0)
    assert ms.start(T.TRAPEZOIDAL, params=params((0.0, 0.0))).ok
    run_smoothly_to_idle(ctl, ms)
    assert ctl.axes[0].command_position == 0.0


def _creeping(params):
    """Supervisor 0 STOPPED at pauseFeedrate 0.5: its axis 0 still moves at 500 counts/s."""
    ctl, ms = two_axes()
    config = ms.config_get()[1]
    config.pause_feedrate = 0.5
    assert ms.config_set(config).ok
    assert ms.start(T.TRAPEZOIDAL, params=params((100_000.0, 0.0))).ok
    ctl.step(1000)
    assert ms.action(MPIAction.STOP).ok
    assert ctl.run_until(lambda c: ms.state is MPIState.STOPPED, 2000)
    assert ctl.axes[0].cmd_v == pytest.approx(500.0)
    return ctl, ms


def test_reset_and_remap_follow_one_rule_while_stopped_axes_creep(params):
    # MPI 000, MPIMotionConfig, pauseFeedrate: "the feed speed rate for the Stop action": above 0 the STOPPED
    # axes still move. A RESET (to IDLE, pending profile dropped: docs/state-machine.md) or a remap that drops
    # the profile would stop them dead in one sample: both are refused with MPIMotionMessageSTOPPED, say why,
    # and change nothing; an E_STOP decelerates them (decelTime.eStop), and RESET is then OK
    ctl, ms = _creeping(params)
    twin, twin_ms = _creeping(params)
    reset = ms.action(MPIAction.RESET)
    assert reset.message is Message.MPIMotionMessageSTOPPED
    assert "pauseFeedrate" in reset.detail
    assert ms.axis_list_set([1]).ok
    remap = ms.action(MPIAction.MAP)
    assert (remap.message, remap.detail) == (reset.message, reset.detail)
    assert twin_ms.axis_list_set([1]).ok
    for _ in range(20):
        ctl.step(10)
        twin.step(10)
        assert ms.state is twin_ms.state is MPIState.STOPPED
        assert (ctl.axes[0].cmd_p, ctl.axes[0].cmd_v) == (twin.axes[0].cmd_p, twin.axes[0].cmd_v)
    assert ms.action(MPIAction.E_STOP).ok
    assert ctl.run_until(lambda c: ms.state is MPIState.ERROR, 2000)
    assert ms.action(MPIAction.RESET).ok
    assert ms.state is MPIState.IDLE


def test_a_final_velocity_move_goes_on_moving_and_a_modify_continues_from_it(params):
    # MPI 000, MEIMotionAttrFINAL_VEL FINAL_VEL "a non-zero target velocity": the axis leaves the move at that
    # velocity, so the supervisor stays MOVING (docs/decisions.md: never DONE, never IDLE while
    # the axis moves) and the next command is a modify that continues from the velocity
    # (limits never exceeded, docs/quality.md, "Correct motion").
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, MotionAttr.FINAL_VEL, params((1000.0, 0.0), final_velocity=[400.0, 0.0]))
    assert ctl.run_until(lambda c: c.axes[0].command_position > 1000.0, 10_000, chunk=10)
    ctl.step(2000)
    assert ms.state is MPIState.MOVING
    assert ctl.axes[0].cmd_v == 400.0
    bits = ctl.axes[0].status  # the last frame runs on: not complete, not at the target, not done
    assert not (bits.trajectory_complete)
    assert not (bits.at_target)
    assert not (bits.done)
    assert not (bits.in_fine_position)
    assert ms.start(T.TRAPEZOIDAL, params=params((0.0, 0.0))).message is Message.MPIMotionMessageMOVING
    assert ms.modify(T.TRAPEZOIDAL, params=params((0.0, 0.0))).ok
    run_smoothly_to_idle(ctl, ms)
    assert ctl.axes[0].command_position == 0.0


def test_stop_while_holding_then_resume(params):
    # MPI 000, MEIMotionAttrHOLD the HOLD frame is part of the motion: STOP and RESUME apply to it
    ctl, ms = two_axes()
    ctl.gate_set(0, True)
    hold = Hold(type=HoldType.GATE, gate=0)
    ms.start(T.TRAPEZOIDAL, MotionAttr.HOLD, params((300.0, 0.0), hold=[hold, hold]))
    ms.action(MPIAction.STOP)
    assert ctl.run_until(lambda c: ms.state is MPIState.STOPPED, 2000)
    ctl.gate_set(0, False)
    ctl.step(500)
    assert ctl.axes[0].cmd_p == 0.0  # released, but stopped
    assert ms.action(MPIAction.RESUME).message is Message.MPIMessageOK
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 20_000, chunk=10)
    assert ctl.axes[0].command_position == 300.0


def test_append_in_stopped_queues_behind_the_pending_profile(params):
    # docs/state-machine.md: modify in STOPPED answers MPIMotionMessageSTOPPED, with APPEND too; a start
    # with APPEND is "added to the end of a previous motion profile" (MPI 000, MPIMotionAttrAPPEND): it
    # queues behind the stopped profile, nothing moves until RESUME, which runs both in turn
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, params=params((5000.0, 0.0)))
    ctl.step(400)
    ms.action(MPIAction.STOP)
    assert ctl.run_until(lambda c: ms.state is MPIState.STOPPED, 5000)
    assert ms.modify(T.TRAPEZOIDAL, MotionAttr.APPEND, params((0.0, 0.0))).message is Message.MPIMotionMessageSTOPPED
    assert ms.start(T.TRAPEZOIDAL, MotionAttr.APPEND, params((100.0, 0.0))).ok
    stopped_at = ctl.axes[0].cmd_p
    ctl.step(200)
    assert len(ms.queue) == 1
    assert ms.state is MPIState.STOPPED
    assert ctl.axes[0].cmd_p == stopped_at
    assert ms.action(MPIAction.RESUME).ok
    assert ctl.run_until(lambda c: c.axes[0].cmd_p == 5000.0, 20_000)
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 40_000, chunk=50)
    assert ctl.axes[0].command_position == 100.0


def test_command_position_can_be_set_in_error_after_abort():
    # MPI 002, MPIAxisMessageCOMMAND_NOT_SET COMMAND_NOT_SET while STOPPING, STOPPED or MOVING; ERROR is not among them
    ctl, ms = two_axes()
    ms.action(MPIAction.ABORT)
    ctl.step(5)
    assert ms.state is MPIState.ERROR
    assert ctl.axis_command_position_set(0, 42.0).ok
    assert ctl.axes[0].command_position == 42.0


def test_append_behind_a_cruising_final_velocity_move_continues_without_a_jump(params):
    # docs/decisions.md: behind a move already going on at its final velocity, an appended
    # move starts from where the axes are
    ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, MotionAttr.FINAL_VEL, params((1000.0, 0.0), final_velocity=[400.0, 0.0]))
    assert ctl.run_until(lambda c: c.axes[0].command_position > 1200.0, 10_000, chunk=10)
    before = ctl.axes[0].command_position
    assert ms.start(T.TRAPEZOIDAL, MotionAttr.APPEND, params((0.0, 0.0))).ok
    ctl.step(1)
    assert abs(ctl.axes[0].command_position - before) < 1.0  # no jump back to the old target
    assert ctl.run_until(lambda c: ms.state is MPIState.IDLE, 20_000, chunk=10)
    assert ctl.axes[0].command_position == 0.0


def test_a_move_that_starts_in_motion_cannot_wait(params):
    # MPI 000, MPIMotionMessageILLEGAL_DELAY ILLEGAL_DELAY "non-zero delay value ... while in motion" and MPI 000,
    # mpiMotionModify "It is impossible to use the HOLD attributes with mpiMotionModify": a move appended behind one
    # that ends moving (FINAL_VEL) starts in motion too, and a wait would stop the axes dead.
    _ctl, ms = two_axes()
    ms.start(T.TRAPEZOIDAL, MotionAttr.FINAL_VEL, params((1000.0, 0.0), final_velocity=[400.0, 0.0]))
    delayed = params((2000.0, 0.0), delay=[0.1, 0.1])
    message = ms.start(T.TRAPEZOIDAL, MotionAttr.APPEND | MotionAttr.DELAY, delayed).message
    assert message is Message.MPIMotionMessageILLEGAL_DELAY
    hold = Hold(type=HoldType.GATE, gate=1)
    held = params((2000.0, 0.0), hold=[hold, hold])
    message = ms.start(T.TRAPEZOIDAL, MotionAttr.APPEND | MotionAttr.HOLD, held).message
    assert message is Message.MPIMotionMessageATTRIBUTE_INVALID
    assert not ms.queue  # nothing changed
    assert ms.start(T.TRAPEZOIDAL, MotionAttr.APPEND, params((2000.0, 0.0))).ok
