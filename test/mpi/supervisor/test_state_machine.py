"""The supervisor state machine (mpi_ros/mpi/supervisor/motion.py): every cell of the state x
action table of docs/state-machine.md, with the message the spec gives, and the transitions between the states.

A cell that refuses ("msg X") must change nothing: the refused command is given to one of
two identical controllers and both must then move, report and change state identically.
"""

from __future__ import annotations

import pytest

from mpi_ros.mpi import (
    ActionSource,
    Controller,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIMotionType,
    MPIState,
    Trajectory,
)
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message

S = MPIState
T = MPIMotionType
OK = Message.MPIMessageOK
IDLE, MOVING, STOPPING, STOPPED = (Message.MPIMotionMessageIDLE, Message.MPIMotionMessageMOVING,
                                   Message.MPIMotionMessageSTOPPING, Message.MPIMotionMessageSTOPPED)
STOPPING_ERROR, ERROR = Message.MPIMotionMessageSTOPPING_ERROR, Message.MPIMotionMessageERROR
TARGET = (100_000.0, 0.0)
OTHER = (-300.0, 700.0)


def p2p(position) -> MotionParams:
    return MotionParams(trajectory=[Trajectory(1000.0, 10_000.0, 10_000.0, 0.0)], position=list(position))


def command(ms, name: str) -> Message:
    if name == "start":
        return ms.start(T.TRAPEZOIDAL, params=p2p(OTHER)).message
    if name == "modify":
        return ms.modify(T.TRAPEZOIDAL, params=p2p(OTHER)).message
    return ms.action(MPIAction[name]).message


# (state, command, message, state right after the call). One row per cell of docs/state-machine.md.
CELLS = [
    # IDLE
    (S.IDLE, "start", OK, S.MOVING),  # MPI 000, mpiMotionStart start changes IDLE to MOVING
    (S.IDLE, "modify", IDLE, S.IDLE),  # MPI 000, MPIMotionMessageIDLE IDLE "returned from mpiMotionModify when IDLE"
    (S.IDLE, "STOP", IDLE, S.IDLE),  # MPI 000, MPIMotionMessageIDLE "also returned ... when a STOP ... in the IDLE
                                     # state"
    (S.IDLE, "RESUME", IDLE, S.IDLE),  # MPI 000, MPIMotionMessageIDLE "... or RESUME is commanded when ... IDLE"
    (S.IDLE, "RESET", OK, S.IDLE),  # docs/state-machine.md: RESET in IDLE "OK, no change"
    (S.IDLE, "E_STOP", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction E_STOP -> STOPPING_ERROR -> ERROR
    (S.IDLE, "ABORT", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction; docs/state-machine.md: never refused
    (S.IDLE, "E_STOP_ABORT", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction
    (S.IDLE, "MAP", OK, S.IDLE),  # MPI 000, MEIActionMAP MAP writes the axis mapping
    # MOVING
    (S.MOVING, "start", MOVING, S.MOVING),  # MPI 000, MPIMotionMessageMOVING MOVING "returned from mpiMotionStart when
                                            # MOVING"
    (S.MOVING, "modify", OK, S.MOVING),  # MPI 000, mpiMotionModify modify "if motion is in progress (MPIStateMOVING)"
    (S.MOVING, "STOP", OK, S.STOPPING),  # MPI 000, MPIActionSTOP STOP: MOVING -> STOPPING
    (S.MOVING, "RESUME", MOVING, S.MOVING),  # MPI 000, MPIMotionMessageMOVING "when a RESUME ... is commanded ...
                                             # MOVING"
    (S.MOVING, "RESET", MOVING, S.MOVING),  # MPI 000, MPIMotionMessageMOVING "... or RESET is commanded ... MOVING"
    (S.MOVING, "E_STOP", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction
    (S.MOVING, "ABORT", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction
    (S.MOVING, "E_STOP_ABORT", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction, 921
    (S.MOVING, "MAP", MOVING, S.MOVING),  # MPI 000, Motion Objects, introduction maps "should NOT be changed when the
                                          # axes are moving"
    # STOPPING
    (S.STOPPING, "start", STOPPING, S.STOPPING),  # MPI 000, MPIMotionMessageSTOPPING STOPPING from start "in the
                                                  # STOPPING state"
    (S.STOPPING, "modify", STOPPING, S.STOPPING),  # MPI 000, MPIMotionMessageSTOPPING "... or mpiMotionModify"
    (S.STOPPING, "STOP", STOPPING, S.STOPPING),  # docs/state-machine.md: STOP in STOPPING "msg STOPPING"
    (S.STOPPING, "RESUME", STOPPING, S.STOPPING),  # MPI 000, MPIMotionMessageSTOPPING "RESUME or RESET ... STOPPING
                                                   # state"
    (S.STOPPING, "RESET", STOPPING, S.STOPPING),  # MPI 000, MPIMotionMessageSTOPPING
    (S.STOPPING, "E_STOP", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction; docs/state-machine.md: never refused
    (S.STOPPING, "ABORT", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction
    (S.STOPPING, "E_STOP_ABORT", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction
    (S.STOPPING, "MAP", STOPPING, S.STOPPING),  # MPI 000, Motion Objects, introduction (axes still moving)
    # STOPPED
    (S.STOPPED, "start", OK, S.MOVING),  # docs/state-machine.md: a start from STOPPED drops the pending profile
    (S.STOPPED, "modify", STOPPED, S.STOPPED),  # docs/state-machine.md: modify in STOPPED "msg STOPPED"
    (S.STOPPED, "STOP", STOPPED, S.STOPPED),  # MPI 000, MPIMotionMessageSTOPPED STOPPED "when a STOP ... already
                                              # STOPPED"
    (S.STOPPED, "RESUME", OK, S.MOVING),  # MPI 000, MPIActionRESUME RESUME continues a motion stopped by STOP
    (S.STOPPED, "RESET", OK, S.IDLE),  # docs/state-machine.md: RESET in STOPPED "OK, to IDLE, pending dropped"
    (S.STOPPED, "E_STOP", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction
    (S.STOPPED, "ABORT", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction
    (S.STOPPED, "E_STOP_ABORT", OK, S.STOPPING_ERROR),  # MPI 000, mpiMotionAction
    (S.STOPPED, "MAP", OK, S.STOPPED),  # docs/state-machine.md: MAP in STOPPED "OK"
    # STOPPING_ERROR
    (S.STOPPING_ERROR, "start", STOPPING_ERROR, S.STOPPING_ERROR),  # MPI 000, MPIMotionMessageSTOPPING_ERROR from
                                                                    # mpiMotionStart
    (S.STOPPING_ERROR, "modify", STOPPING_ERROR, S.STOPPING_ERROR),  # MPI 000, MPIMotionMessageSTOPPING_ERROR "... or
                                                                     # mpiMotionModify"
    (S.STOPPING_ERROR, "STOP", STOPPING_ERROR, S.STOPPING_ERROR),  # docs/state-machine.md
    (S.STOPPING_ERROR, "RESUME", STOPPING_ERROR, S.STOPPING_ERROR),  # MPI 000, MPIMotionMessageSTOPPING_ERROR "RESUME
                                                                     # or RESET"
    (S.STOPPING_ERROR, "RESET", STOPPING_ERROR, S.STOPPING_ERROR),  # MPI 000, MPIMotionMessageSTOPPING_ERROR
    (S.STOPPING_ERROR, "E_STOP", OK, S.STOPPING_ERROR),  # docs/state-machine.md: safety actions "OK"
    (S.STOPPING_ERROR, "ABORT", OK, S.STOPPING_ERROR),  # docs/state-machine.md
    (S.STOPPING_ERROR, "E_STOP_ABORT", OK, S.STOPPING_ERROR),  # docs/state-machine.md
    (S.STOPPING_ERROR, "MAP", STOPPING_ERROR, S.STOPPING_ERROR),  # docs/state-machine.md: "msg STOPPING_ERROR"
    # ERROR
    (S.ERROR, "start", ERROR, S.ERROR),  # MPI 000, MPIMotionMessageERROR ERROR from start "in an error state"; MPI 000,
                                         # MPIMotionMessageERROR
    (S.ERROR, "modify", ERROR, S.ERROR),  # MPI 000, MPIMotionMessageERROR "... or mpiMotionModify"
    (S.ERROR, "STOP", ERROR, S.ERROR),  # MPI 000, MPIMotionMessageERROR "when a STOP or RESUME is commanded ... ERROR"
    (S.ERROR, "RESUME", ERROR, S.ERROR),  # MPI 000, MPIMotionMessageERROR
    (S.ERROR, "RESET", OK, S.IDLE),  # MPI 000, MPIActionRESET RESET clears the error, to IDLE
    (S.ERROR, "E_STOP", OK, S.ERROR),  # docs/state-machine.md: "OK, stays ERROR"
    (S.ERROR, "ABORT", OK, S.ERROR),  # docs/state-machine.md
    (S.ERROR, "E_STOP_ABORT", OK, S.ERROR),  # docs/state-machine.md
    (S.ERROR, "MAP", OK, S.ERROR),  # docs/state-machine.md: MAP in ERROR "OK"
]


def test_the_table_has_every_cell():
    # docs/state-machine.md: the whole table of 6 states x (start, modify, 7 actions)
    cells = {(state, name) for state, name, _, _ in CELLS}
    names = ["start", "modify", "STOP", "RESUME", "RESET", "E_STOP", "ABORT", "E_STOP_ABORT", "MAP"]
    assert cells == {(state, name) for state in S if state is not S.INVALID for name in names}


@pytest.mark.parametrize(("state", "name", "message", "after"), CELLS, ids=[f"{c[0].name}-{c[1]}" for c in CELLS])
def test_cell(state, name, message, after, prepared):
    _ctl, ms = prepared(state)
    assert command(ms, name) is message
    assert ms.state is after


def observe(ctl, ms, samples=4000):
    trace = []
    for _ in range(samples // 50):
        ctl.step(50)
        trace.append((ms.state, ms.last_action, tuple((a.cmd_p, a.act_p, a.amp_enabled) for a in ctl.axes)))
    events = [(e.sample, e.type, e.supervisor, e.axis, e.move_id) for e in ctl.drain_events()]
    return trace, events, len(ms.queue)


REFUSALS = [c for c in CELLS if c[2] is not OK]


@pytest.mark.parametrize(("state", "name", "message", "after"), REFUSALS, ids=[f"{c[0].name}-{c[1]}" for c in REFUSALS])
def test_refused_cell_changes_nothing(state, name, message, after, prepared):
    # docs/state-machine.md: '"msg X" = refused with MPIMotionMessageX, nothing changes'
    ctl_a, ms_a = prepared(state)
    ctl_b, ms_b = prepared(state)
    assert command(ms_b, name) is message
    assert observe(ctl_a, ms_a) == observe(ctl_b, ms_b)


@pytest.mark.parametrize("state", [S.IDLE, S.MOVING, S.STOPPING, S.STOPPED, S.STOPPING_ERROR])
@pytest.mark.parametrize("action", ["E_STOP", "ABORT", "E_STOP_ABORT"])
def test_safety_actions_end_in_error(state, action, prepared):
    # MPI 000, mpiMotionAction "the Motion will perform an emergency stop and/or abort on all axes, and then
    # change to the error state (MPIStateSTOPPING_ERROR to MPIStateERROR)"
    ctl, ms = prepared(state)
    assert ms.action(MPIAction[action]).ok
    assert ctl.run_until(lambda c: ms.state is S.ERROR, 1000)
    ctl.step(2000)
    assert ms.state is S.ERROR  # MPI 000, mpiMotionAction "you must first make a call to ... RESET"


def test_modify_auto_start_in_idle_starts_and_answers_auto_start(prepared):
    # MPI 000, MPIMotionMessageAUTO_START AUTO_START "returned from mpiMotionModify when the AUTO_START attribute mask
    # was specified and the motion was commanded while the motion supervisor is in the IDLE state";
    # MPI 000, MPIMotionAttrAUTO_START "converts a mpiMotionModify(...) call to a mpiMotionStart(...)"
    ctl, ms = prepared(S.IDLE)
    assert ms.modify(T.TRAPEZOIDAL, MotionAttr.AUTO_START, p2p(OTHER)).message is Message.MPIMotionMessageAUTO_START
    assert ms.state is S.MOVING
    assert ctl.run_until(lambda c: ms.state is S.IDLE, 20_000, chunk=100)
    assert [a.command_position for a in ms.axes] == list(OTHER)


@pytest.mark.parametrize(("state", "message"), [(S.STOPPING, STOPPING), (S.STOPPED, STOPPED),
                                           (S.STOPPING_ERROR, STOPPING_ERROR), (S.ERROR, ERROR)])
def test_auto_start_does_not_start_outside_idle(state, message, prepared):
    # MPI 000, MPIMotionMessageAUTO_START AUTO_START converts a modify to a start only in the IDLE state
    _ctl, ms = prepared(state)
    assert ms.modify(T.TRAPEZOIDAL, MotionAttr.AUTO_START, p2p(OTHER)).message is message


def test_modify_auto_start_while_moving_is_a_plain_modify(prepared):
    # MPI 000, MPIMotionAttrAUTO_START AUTO_START acts "if the modify occurs after the previous motion profile has
    # completed"; while moving the modify answers OK
    _ctl, ms = prepared(S.MOVING)
    assert ms.modify(T.TRAPEZOIDAL, MotionAttr.AUTO_START, p2p(OTHER)).message is OK


def test_start_from_stopped_drops_the_pending_profile(prepared):
    # docs/state-machine.md: a new start from STOPPED throws the pending profile away
    ctl, ms = prepared(S.STOPPED)
    serial = ms.current.serial
    assert ms.start(T.TRAPEZOIDAL, params=p2p(OTHER)).ok
    assert ctl.run_until(lambda c: ms.state is S.IDLE, 20_000, chunk=100)
    assert [a.command_position for a in ms.axes] == list(OTHER)
    ended = {end.serial: end.message for end in ctl.move_log.recent(ms.number)}
    assert ended[serial] is STOPPED  # the dropped move ended with the state it was dropped in
    assert ms.action(MPIAction.RESUME).message is IDLE  # nothing pending any more


def test_reset_from_stopped_drops_the_pending_profile(prepared):
    # docs/state-machine.md: RESET in STOPPED "OK, to IDLE, pending dropped"
    ctl, ms = prepared(S.STOPPED)
    where = [a.command_position for a in ms.axes]
    assert ms.action(MPIAction.RESET).ok
    assert ms.state is S.IDLE
    ctl.step(2000)
    assert ms.state is S.IDLE
    assert [a.command_position for a in ms.axes] == where
    assert ms.action(MPIAction.RESUME).message is IDLE  # MPI 000, MPIMotionMessageIDLE "no motion profile pending"


def test_resume_from_stopped_finishes_the_move():
    # MPI 000, MPIActionRESUME RESUME: "the Motion will resume if it was stopped by a prior call to ...STOP"
    ctl = Controller()
    _, ms = ctl.create_motion(0)
    ms.axis_list_set([0, 1])
    assert ms.start(T.TRAPEZOIDAL, params=p2p((2000.0, 1000.0))).ok
    ctl.step(400)
    assert ms.action(MPIAction.STOP).ok
    assert ctl.run_until(lambda c: ms.state is S.STOPPED, 5000)
    assert ms.action(MPIAction.RESUME).ok
    assert ms.state is S.MOVING
    assert ctl.run_until(lambda c: ms.state is S.IDLE, 20_000, chunk=10)
    assert [a.command_position for a in ms.axes] == [2000.0, 1000.0]


def test_stop_completes_to_stopped_after_the_stop_time(prepared):
    # MPI 000, MPIActionSTOP STOP "decelerates the axis (or axes) to a stop in the time specified by the
    # stop time"; docs/state-machine.md: MOVING -> STOPPING (decelerate over decelTime.stop) -> STOPPED
    ctl, ms = prepared(S.MOVING)
    k = ctl.sample
    assert ms.action(MPIAction.STOP).ok
    ctl.step(999)
    assert ms.state is S.STOPPING
    ctl.step(1)
    assert ms.state is S.STOPPED
    assert ctl.sample == k + 1000


def test_e_stop_completes_to_error_after_the_e_stop_time(prepared):
    # MPI 000, MPIActionE_STOP E_STOP "will decelerate the axis (or axes) to a stop in the time specified by
    # the eStop time. After the Motion stops, the Motion will be set to the ERROR state."
    ctl, ms = prepared(S.MOVING)
    k = ctl.sample
    assert ms.action(MPIAction.E_STOP).ok
    ctl.step(99)
    assert ms.state is S.STOPPING_ERROR
    ctl.step(1)
    assert ms.state is S.ERROR
    assert ctl.sample == k + 100


def test_abort_reaches_error_at_the_next_sample(prepared):
    # MPI 000, MPIActionABORT ABORT "After the abort completes, the Motion will be set to the ERROR state";
    # docs/decisions.md, "Stopping": ABORT turns the amplifier off at once
    ctl, ms = prepared(S.MOVING)
    assert ms.action(MPIAction.ABORT).ok
    assert ms.state is S.STOPPING_ERROR
    ctl.step(1)
    assert ms.state is S.ERROR


def test_e_stop_while_stopping_error_keeps_the_first_ramp(prepared):
    # docs/state-machine.md: E_STOP in STOPPING_ERROR is "OK" and does not restart the ramp
    ctl, ms = prepared(S.MOVING)
    k = ctl.sample
    assert ms.action(MPIAction.E_STOP).ok
    ctl.step(50)
    assert ms.action(MPIAction.E_STOP).ok
    ctl.step(50)
    assert ms.state is S.ERROR
    assert ctl.sample == k + 100


def test_e_stop_abort_while_e_stopping_disables_at_the_end(prepared):
    # MPI 000, MPIActionE_STOP_ABORT E_STOP_ABORT "first performs an E_STOP, and then performs an ABORT"
    ctl, ms = prepared(S.MOVING)
    assert ms.action(MPIAction.E_STOP).ok
    ctl.step(20)
    assert ms.action(MPIAction.E_STOP_ABORT).ok
    assert all(a.amp_enabled for a in ms.axes)
    assert ctl.run_until(lambda c: ms.state is S.ERROR, 200)
    assert not any(a.amp_enabled for a in ms.axes)


def test_reset_in_error_returns_to_idle_and_allows_a_start(prepared):
    # MPI 000, MPIActionRESET RESET "change to the idle state (MPIStateIDLE), so that motion supervisor can
    # be restarted"
    ctl, ms = prepared(S.ERROR)
    assert ms.action(MPIAction.RESET).ok
    assert ms.state is S.IDLE
    assert ms.start(T.TRAPEZOIDAL, params=p2p(OTHER)).ok
    assert ctl.run_until(lambda c: ms.state is S.IDLE, 20_000, chunk=10)
    assert [a.command_position for a in ms.axes] == list(OTHER)


@pytest.mark.parametrize("action", ["STOP", "E_STOP", "ABORT", "E_STOP_ABORT", "RESET", "RESUME", "MAP"])
def test_actions_without_axes_answer_no_axes_mapped(action):
    # MPI 000, MEIMotionMessageNO_AXES_MAPPED NO_AXES_MAPPED "returned by mpiMotionStart, mpiMotionModify or
    # mpiMotionAction if there are no axes mapped to the motion object"
    ctl = Controller()
    _, ms = ctl.create_motion(0)
    assert ms.action(MPIAction[action]).message is Message.MEIMotionMessageNO_AXES_MAPPED
    assert ms.state is S.IDLE


def test_the_action_source_is_recorded(prepared):
    # issue 3: "Whether the user or the controller caused a state (action source) is recorded"
    ctl, ms = prepared(S.MOVING)
    assert ms.action(MPIAction.E_STOP, ActionSource.CONTROLLER).ok
    assert ctl.run_until(lambda c: ms.state is S.ERROR, 200)
    snap = ms.snapshot()
    assert (snap.last_action, snap.action_source) == ("E_STOP", "CONTROLLER")
    assert ms.action(MPIAction.RESET).ok
    snap = ms.snapshot()
    assert (snap.last_action, snap.action_source) == ("RESET", "USER")


def test_stop_records_stop_until_stopped(prepared):
    # issue 3: the action behind a state is recorded (STOPPING and STOPPED after a user STOP)
    ctl, ms = prepared(S.MOVING)
    ms.action(MPIAction.STOP)
    assert (ms.snapshot().last_action, ms.snapshot().action_source) == ("STOP", "USER")
    assert ctl.run_until(lambda c: ms.state is S.STOPPED, 2000)
    assert ms.snapshot().last_action == "STOP"


@pytest.mark.parametrize(("action", "event"), [("STOP", MPIEventType.STOP), ("E_STOP", MPIEventType.E_STOP),
                                          ("ABORT", MPIEventType.ABORT)])
def test_actions_emit_their_event_at_the_command_sample(action, event, prepared):
    # MPI 000, mpiMotionAction "How STOP Events Work"; docs/decisions.md, "Samples, commands and replay"
    ctl, ms = prepared(S.MOVING)
    k = ctl.sample
    ms.action(MPIAction[action])
    events = [e for e in ctl.drain_events() if e.type is event]
    assert [(e.sample, e.supervisor) for e in events] == [(k, 0)]
