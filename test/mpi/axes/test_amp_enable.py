"""The amplifier enable of an axis (Controller.axis_amp_enable_set, Axis.enabled): MPI 000,
MPIMessageOBJECT_NOT_ENABLED ("axis is not an enabled axis"); MPIActionABORT ("disable the amp
enable outputs"); docs/decisions.md, "Amplifier enable"."""

from __future__ import annotations

from mpi_ros.mpi import MotionAttr, MPIAction, MPIMotionType, MPIState
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message

from ..conftest import LONG_MOVE

T = MPIMotionType
NOT_ENABLED = Message.MPIMessageOBJECT_NOT_ENABLED


def test_a_start_on_a_disabled_axis_is_refused_and_changes_nothing(ctl, ms, params):
    # MPI 000, MPIMessageOBJECT_NOT_ENABLED
    assert ctl.axis_amp_enable_set(1, False).ok
    before = (ms.state, ctl.axis_snapshot(0).command_position, ctl.axis_snapshot(1).command_position)
    assert ms.start(T.TRAPEZOIDAL, params=params((1000.0, 0.0))).message is NOT_ENABLED
    ctl.step(100)
    assert (ms.state, ctl.axis_snapshot(0).command_position, ctl.axis_snapshot(1).command_position) == before
    assert ms.current is None
    assert not ctl.axis_snapshot(1).amp_enabled
    assert ctl.axis_snapshot(0).amp_enabled


def test_a_modify_with_auto_start_on_a_disabled_axis_is_refused(ctl, ms, params):
    # MPI 000, mpiMotionModify with MPIMotionAttrMaskAUTO_START starts a motion: the same check
    assert ctl.axis_amp_enable_set(0, False).ok
    assert ms.modify(T.TRAPEZOIDAL, MotionAttr.AUTO_START, params((1000.0, 0.0))).message is NOT_ENABLED
    assert ms.state is MPIState.IDLE
    assert ms.current is None


def test_enabled_again_the_axis_moves_from_where_the_motor_coasted_to(ctl, ms, params, run_to):
    assert ctl.axis_amp_enable_set(0, False).ok
    ctl.axis_actual_position_set(0, 37.0)  # the motor was pushed while its amplifier was off
    ctl.step(10)
    assert ctl.axis_amp_enable_set(0, True).ok
    snap = ctl.axis_snapshot(0)
    assert snap.amp_enabled
    assert snap.command_position == snap.actual_position == 37.0
    assert ms.start(T.TRAPEZOIDAL, params=params((500.0, 0.0))).ok
    run_to(ctl, ms, MPIState.IDLE, 20_000, chunk=50)
    assert ctl.axis_snapshot(0).command_position == 500.0


def test_disabling_a_moving_axis_aborts_its_motion(ctl, ms, params, run_to):
    # docs/decisions.md, "Amplifier enable": MPI 000, MPIActionABORT disables the amp enable outputs
    assert ms.start(T.VELOCITY, params=params(LONG_MOVE)).ok
    ctl.step(400)
    ctl.drain_events()
    outcome = ctl.axis_amp_enable_set(1, False)
    assert outcome.ok
    assert "ABORT" in outcome.detail
    run_to(ctl, ms, MPIState.ERROR, 10)
    assert [e.type for e in ctl.drain_events() if e.type is MPIEventType.ABORT] == [MPIEventType.ABORT]
    assert not ctl.axis_snapshot(0).amp_enabled
    assert not ctl.axis_snapshot(1).amp_enabled


def test_reset_leaves_a_disabled_axis_off_and_its_starts_refused(ctl, ms, params, run_to):
    assert ms.start(T.VELOCITY, params=params(LONG_MOVE)).ok
    ctl.step(400)
    assert ctl.axis_amp_enable_set(1, False).ok
    run_to(ctl, ms, MPIState.ERROR, 10)
    assert ms.action(MPIAction.RESET).ok
    assert ms.state is MPIState.IDLE
    assert ctl.axis_snapshot(0).amp_enabled
    assert not ctl.axis_snapshot(1).amp_enabled
    assert ms.start(T.TRAPEZOIDAL, params=params((100.0, 0.0))).message is NOT_ENABLED


def test_enabling_in_error_waits_for_reset(ctl, ms, params, run_to):
    assert ms.start(T.VELOCITY, params=params(LONG_MOVE)).ok
    ctl.step(400)
    assert ctl.axis_amp_enable_set(1, False).ok
    run_to(ctl, ms, MPIState.ERROR, 10)
    outcome = ctl.axis_amp_enable_set(1, True)
    assert outcome.ok
    assert "RESET" in outcome.detail
    assert not ctl.axis_snapshot(1).amp_enabled  # the ABORT still holds it off


def test_an_unknown_axis_is_refused(ctl):
    assert ctl.axis_amp_enable_set(9, False).message is Message.MPIAxisMessageAXIS_INVALID


def test_a_disabled_axis_cannot_be_appended(ctl, ms):
    # MPI 000, mpiMotionAxisAppend: MPIMessageOBJECT_NOT_ENABLED "axis is not an enabled axis"
    assert ctl.axis_amp_enable_set(3, False).ok
    assert ms.axis_append(3).message is NOT_ENABLED
    assert ms.axis_list == [0, 1]
