"""Ownership of axes: no axis moves without a supervisor that owns its motion and reports it.

Issue 9 regressions: remapping a STOPPED supervisor, and STOP/E_STOP/ABORT/RESUME given by a
second supervisor on a shared axis (MPI 000, mpiMotionAction: an action acts on "the axis (or
axes)" of the motion; E_STOP decelerates over decelTime.eStop), so a vector stays on its path.
"""

from __future__ import annotations

import math

import pytest

from mpi_ros.mpi import Controller, MotionAttr, MPIAction, MPIMotionType, MPIState
from mpi_ros.mpi.base.messages import Message

from .conftest import LONG_MOVE, drive_to, make_params, run_to_state, sharing_axis_1
from .supervisor.test_state_machine import CELLS, command, observe

S = MPIState
T = MPIMotionType
A = MPIAction


def moving_axes(ctl) -> list[int]:
    return [axis.number for axis in ctl.axes if axis.cmd_v != 0.0 or axis.act_v > 1e-6]


def owned_and_reported(ctl) -> bool:
    """Every axis with a command in motion belongs to a supervisor that reports motion."""
    for axis in ctl.axes:
        if axis.cmd_v != 0.0:
            owner = ctl.supervisor(axis.owner)
            if owner is None or owner.state is MPIState.IDLE:
                return False
    return True


def stopped_mid_move(ctl, ms):
    assert ms.start(T.TRAPEZOIDAL, params=make_params(LONG_MOVE)).ok
    ctl.step(600)
    assert ms.action(A.STOP).ok
    run_to_state(ctl, ms, MPIState.STOPPED)


@pytest.mark.parametrize("new_list", [[2], [0], [2, 3]])
@pytest.mark.parametrize("then", ["start", "map_reset"])
def test_remapping_a_stopped_supervisor_leaves_no_axis_moving(ctl, ms, new_list, then):
    # MPI 000, mpiMotionAxisListSet: "Any existing coordinate system is completely replaced".
    # The stopped profile belonged to the old axes: it is dropped, nothing resumes it.
    stopped_mid_move(ctl, ms)
    held = [ctl.axes[n].command_position for n in (0, 1)]
    assert ms.axis_list_set(new_list).ok
    if then == "start":
        assert ms.start(T.TRAPEZOIDAL, params=make_params([10.0] * len(new_list))).ok
    else:
        assert ms.action(A.MAP).ok
        assert ms.action(A.RESET).ok
    for _ in range(40):
        ctl.step(100)
        assert owned_and_reported(ctl)
    for n in (0, 1):
        if n not in new_list:
            assert ctl.axes[n].command_position == held[n]
            assert ctl.axes[n].cmd_v == 0.0


def test_map_of_other_axes_while_stopped_drops_the_pending_profile(ctl, ms):
    # docs/state-machine.md: MAP is OK in STOPPED; RESUME then has nothing to continue.
    stopped_mid_move(ctl, ms)
    assert ms.axis_list_set([2]).ok
    assert ms.action(A.MAP).ok
    assert ms.state is MPIState.IDLE
    assert ms.action(A.RESUME).message is Message.MPIMotionMessageIDLE
    ctl.step(2000)
    assert moving_axes(ctl) == []


def test_map_of_the_same_axes_while_stopped_keeps_the_profile(ctl, ms):
    stopped_mid_move(ctl, ms)
    assert ms.action(A.MAP).ok
    assert ms.state is MPIState.STOPPED
    assert ms.action(A.RESUME).ok
    ctl.step(400)
    assert ctl.axes[0].cmd_v > 0.0


def test_remap_refused_while_a_leaving_axis_still_creeps(ctl, ms):
    # A non-zero pauseFeedrate keeps a STOPPED motion creeping: dropping it would stop the
    # axis dead, so the remap is refused and nothing changes.
    _, config = ms.config_get()
    config.pause_feedrate = 0.5
    assert ms.config_set(config).ok
    stopped_mid_move(ctl, ms)
    assert ctl.axes[0].cmd_v > 0.0
    assert ms.axis_list_set([2]).ok
    assert ms.action(A.MAP).message is Message.MPIMotionMessageSTOPPED
    assert ms.mapped == [0, 1]
    assert ms.state is MPIState.STOPPED


@pytest.mark.parametrize("action", [A.E_STOP, A.STOP, A.ABORT])
def test_an_action_from_a_second_supervisor_stops_the_whole_vector(ctl, action):
    # MPI 000, mpiMotionAction: the action stops the motion of the axes; supervisor 0's vector
    # on [0, 1] decelerates as one (the same feedrate ramp), so it stays on its line.
    a, b = sharing_axis_1(ctl)
    assert a.start(T.TRAPEZOIDAL, params=make_params((50_000.0, 25_000.0))).ok
    ctl.step(1000)
    assert b.action(action).ok
    ratios = []
    for _ in range(4000):
        if ctl.axes[0].cmd_v == 0.0:
            break
        ctl.step(1)
        v0, v1 = ctl.axes[0].cmd_v, ctl.axes[1].cmd_v
        if v0 != 0.0:
            ratios.append(v1 / v0)
        assert owned_and_reported(ctl)
    assert ctl.axes[0].cmd_v == 0.0
    assert ctl.axes[1].cmd_v == 0.0
    assert all(math.isclose(r, 0.5, rel_tol=1e-9) for r in ratios)
    final = {A.STOP: MPIState.STOPPED, A.E_STOP: MPIState.ERROR, A.ABORT: MPIState.ERROR}[action]
    run_to_state(ctl, a, final)
    assert b.state is final


def test_e_stop_on_a_shared_axis_uses_the_moving_supervisors_decel_time(ctl):
    # MPI 000, MPIMotionDecelTime: eStop is the time the E_STOP deceleration takes.
    a, b = sharing_axis_1(ctl)
    for ms, e_stop in ((a, 0.2), (b, 0.05)):
        _, config = ms.config_get()
        config.decel_time.e_stop = e_stop
        assert ms.config_set(config).ok
    assert a.start(T.TRAPEZOIDAL, params=make_params(LONG_MOVE)).ok
    ctl.step(1000)
    begin = ctl.sample
    assert b.action(A.E_STOP).ok
    assert ctl.run_until(lambda c: c.axes[0].cmd_v == 0.0, 2000)
    assert ctl.sample - begin == pytest.approx(0.2 * ctl.rate, abs=2)


def test_resume_from_a_second_supervisor_continues_the_shared_motion(ctl):
    a, b = sharing_axis_1(ctl)
    assert a.start(T.TRAPEZOIDAL, params=make_params(LONG_MOVE)).ok
    ctl.step(1000)
    assert b.action(A.STOP).ok
    run_to_state(ctl, a, MPIState.STOPPED)
    assert b.state is MPIState.STOPPED
    assert b.action(A.RESUME).ok
    assert a.state is MPIState.MOVING
    ctl.step(500)
    assert ctl.axes[0].cmd_v > 0.0
    assert owned_and_reported(ctl)


def test_stop_from_a_second_supervisor_with_nothing_moving_is_refused(ctl):
    a, b = sharing_axis_1(ctl)
    assert b.action(A.STOP).message is Message.MPIMotionMessageIDLE
    assert a.state is MPIState.IDLE
    assert b.state is MPIState.IDLE


# ------------------------------------------------------------ the state table on shared axes ----
def shared_in(state: MPIState):
    """A controller where supervisor 0 (axes [0, 1]) is in ``state`` and supervisor 1 (axes
    [1, 2]) has no motion of its own: it shows supervisor 0's state through axis 1."""
    ctl = Controller()
    a, b = sharing_axis_1(ctl)
    drive_to(ctl, a, state)
    ctl.drain_events()
    assert b.own_state is MPIState.IDLE
    assert b.state is state
    return ctl, a, b


# Where a command from the sharing supervisor differs from docs/state-machine.md for the state it
# shows (docs/decisions.md, "Supervisors and axes"): (state, command) -> (message, state after).
SHARED_CELLS = {
    # It has no motion of its own to modify, and may not take axis 1 out of supervisor 0's.
    (S.MOVING, "modify"): (Message.MPIMotionMessageMOVING, S.MOVING),
    # Supervisor 0's stopped motion still owns axis 1 (a RESUME would continue it).
    (S.STOPPED, "start"): (Message.MPIMotionMessageSTOPPED, S.STOPPED),
    # Its own motion was IDLE: it follows the IDLE row (STOPPING_ERROR, then ERROR) and takes over
    # axis 1, which no motion runs in ERROR, so both show STOPPING_ERROR until its ramp ends.
    (S.ERROR, "E_STOP"): (Message.MPIMessageOK, S.STOPPING_ERROR),
    (S.ERROR, "ABORT"): (Message.MPIMessageOK, S.STOPPING_ERROR),
    (S.ERROR, "E_STOP_ABORT"): (Message.MPIMessageOK, S.STOPPING_ERROR),
}
SHARED = [(state, name, *SHARED_CELLS.get((state, name), (message, after))) for state, name, message, after in CELLS]


@pytest.mark.parametrize(("state", "name", "message", "after"), SHARED, ids=[f"{c[0].name}-{c[1]}" for c in SHARED])
def test_cell_from_the_supervisor_sharing_an_axis(state, name, message, after):
    # docs/state-machine.md's state x action table holds for a supervisor in the state its axes show: a command
    # to supervisor 1 answers as the table says for that state, and both supervisors then show the
    # table's state (an action acts on the motion that holds the shared axis; a start or modify
    # may not take an axis out of another supervisor's motion).
    ctl, a, b = shared_in(state)
    assert command(b, name) is message
    assert (a.state, b.state) == (after, after)
    for _ in range(20):
        ctl.step(100)
        assert owned_and_reported(ctl)


SHARED_REFUSALS = [c for c in SHARED if c[2] is not Message.MPIMessageOK]


@pytest.mark.parametrize(("state", "name", "message", "after"), SHARED_REFUSALS,
                         ids=[f"{c[0].name}-{c[1]}" for c in SHARED_REFUSALS])
def test_refused_cell_from_the_sharing_supervisor_changes_nothing(state, name, message, after):
    # docs/state-machine.md: '"msg X" = refused with MPIMotionMessageX, nothing changes', on shared axes too
    ctl_a, a, _ = shared_in(state)
    ctl_b, _, b = shared_in(state)
    assert command(b, name) is message
    assert observe(ctl_a, a) == observe(ctl_b, ctl_b.supervisor(0))


def test_a_start_may_not_take_an_axis_out_of_a_stopped_vector(ctl):
    # The stopped motion of supervisor 0 still owns axis 1 (RESUME would continue it): supervisor
    # 1 is refused with the state it shows, and says which supervisor holds the axis.
    a, b = sharing_axis_1(ctl)
    stopped_mid_move(ctl, a)
    outcome, _ = b.command(T.TRAPEZOIDAL, MotionAttr.NONE, make_params((10.0, 10.0)), modify=False)
    message, detail = outcome.message, outcome.detail
    assert message is Message.MPIMotionMessageSTOPPED
    assert "supervisor 0" in detail
    assert a.action(A.RESUME).ok
    ctl.step(500)
    assert ctl.axes[0].cmd_v > 0.0
    assert ctl.axes[1].owner == 0


def test_reset_from_the_sharing_supervisor_clears_the_other_s_error(ctl):
    # MPI 000, mpiMotionAction RESET: clears the error of the motion on its axes (both show IDLE)
    a, b = sharing_axis_1(ctl)
    drive_to(ctl, a, MPIState.ERROR)
    assert b.action(A.RESET).ok
    assert a.state is MPIState.IDLE
    assert b.state is MPIState.IDLE
    assert b.start(T.TRAPEZOIDAL, params=make_params((10.0, 10.0))).ok


def test_a_reset_refused_by_a_fault_on_a_shared_axis_names_the_fault(ctl):
    # docs/faults.md: RESET is refused with MPIMotionMessageERROR while a latched fault persists, saying
    # which; given to the supervisor that shares the axis, it is passed on to the motion in ERROR
    # (docs/decisions.md, "Actions on shared axes") and its refusal must name the fault as well
    a, b = sharing_axis_1(ctl)
    assert b.start(T.TRAPEZOIDAL, params=make_params((5000.0, 5000.0))).ok
    ctl.step(100)
    assert ctl.axis_fault_inject(1, "AMP_FAULT", True).message.ok
    run_to_state(ctl, b, MPIState.ERROR)
    outcome = a.action(A.RESET)
    assert outcome.message is Message.MPIMotionMessageERROR
    assert "axis 1 AMP_FAULT persists" in outcome.detail
    assert "supervisor 1" in outcome.detail
    assert b.state is MPIState.ERROR


@pytest.mark.parametrize(("action", "column"), [(A.STOP, "stop"), (A.E_STOP, "stop"), (A.ABORT, "abort")])
def test_status_bits_after_an_action_from_the_sharing_supervisor(ctl, action, column):
    # MPI 002, the status-bit tables with settleOnStop/settleOnEstop FALSE: "After STOP (E-STOP)":
    # IN_FINE_POSITION, IN_COARSE_POSITION and AT_TARGET FALSE, DONE "TRUE when command velocity
    # = 0"; "After ABORT": only DONE TRUE. The same on every axis of the stopped vector, whichever
    # supervisor the action was given to.
    a, b = sharing_axis_1(ctl)
    assert a.start(T.TRAPEZOIDAL, params=make_params((50_000.0, 25_000.0))).ok
    ctl.step(1000)
    assert b.action(action).ok
    assert ctl.run_until(lambda c: a.state in (MPIState.STOPPED, MPIState.ERROR), 20_000)
    ctl.step(2000)
    for n in (0, 1):
        bits = ctl.axes[n].status
        assert not bits.in_fine_position, (column, n)
        assert not bits.in_coarse_position, (column, n)
        assert not bits.at_target, (column, n)
        assert bits.done, (column, n)


def test_status_bits_of_axes_a_remap_released(ctl, ms):
    # MPI 002, the status-bit tables, "After STOP": the axes a remap takes from a STOPPED supervisor
    # rest where they stopped and keep the after-STOP bits (DONE, not AT_TARGET: they never got
    # to the target), while the new list starts clean.
    stopped_mid_move(ctl, ms)
    assert ms.axis_list_set([2]).ok
    assert ms.action(A.MAP).ok
    ctl.step(100)
    for n in (0, 1):
        bits = ctl.axes[n].status
        assert bits.done
        assert not bits.at_target
        assert not bits.in_fine_position
        assert ctl.axes[n].cmd_v == 0.0
