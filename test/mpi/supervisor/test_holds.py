"""HOLD (mpi_ros/mpi/supervisor/holds.py, motion.py, io.py): a move waits until its trigger, spec
MPI 000, MEIMotionAttrHOLD and MEIMotionAttrHold* (MPI 000, MEIMotionAttrHold)."""

from __future__ import annotations

import pytest

from mpi_ros.mpi import (
    Controller,
    Hold,
    HoldType,
    IoSpace,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIMotionType,
    MPIState,
    Trajectory,
)
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message

A = MotionAttr
T = MPIMotionType
E = MPIEventType
M = Message


def held_start(ms, params, hold, attrs=A.HOLD, target=(500.0, 0.0)):
    message = ms.start(T.TRAPEZOIDAL, attrs, params(target, hold=[hold, hold])).message
    assert message.ok
    return message


def still(ctl, samples=200):
    ctl.step(samples)
    return all(a.cmd_p == 0.0 for a in ctl.axes[:2])


def test_gate_holds_until_opened(ctl, ms, params, run_to):
    # MPI 000, MEIMotionAttrHOLD "the motion will be held until a call to mpiControlGateSet() is made with the
    # closed parameter set to FALSE"; MPI 000, MEIMotionAttrHoldSource, gate gate 0..31
    ctl.gate_set(31, True)
    held_start(ms, params, Hold(type=HoldType.GATE, gate=31))
    assert ms.state is MPIState.MOVING  # MPI 000, MEIMotionAttrHOLD the HOLD frame is executing
    assert still(ctl, 2000)
    k = ctl.sample
    assert ctl.gate_set(31, False).ok
    released = [e for e in ctl.drain_events() if e.type is E.HOLD_RELEASED]
    assert [(e.sample, e.axis, e.detail) for e in released] == [(k, 0, "GATE"), (k, 1, "GATE")]
    ctl.step(1)
    assert ctl.axes[0].cmd_p > 0.0
    run_to(ctl, ms, MPIState.IDLE, 20_000, chunk=100)
    assert ctl.axes[0].command_position == 500.0


STATUS = ("target_position", "command_position", "done", "at_target", "in_fine_position", "in_coarse_position",
          "settled", "trajectory_complete", "state")


def _waiting_status(attrs, **fields):
    """The status of axis 0 while a move to 5000 waits 0.1 s into a HOLD or a DELAY."""
    ctl = Controller()
    _, ms = ctl.create_motion(0)
    assert ms.axis_list_set([0, 1]).ok
    ctl.gate_set(3, True)
    params = MotionParams(trajectory=[Trajectory(1000.0, 10_000.0, 10_000.0)], position=[5000.0, 0.0], **fields)
    assert ms.start(T.TRAPEZOIDAL, attrs, params).ok
    ctl.step(200)
    axis = ms.snapshot().axes[0]
    return {name: getattr(axis, name) for name in STATUS}


def test_a_held_move_reports_its_target_as_a_delayed_one_does():
    # MPI 000, MEIMotionAttrHOLD: the hold "prevents a motion profile from executing until the specified trigger
    # conditions are met": the move is loaded, its target is the target; MPI 002's status table, IN_COARSE_POSITION
    # is the target distance (|target - actual| < coarse): 5000 counts away it is FALSE, as while a DELAY waits
    held = _waiting_status(A.HOLD, hold=[Hold(type=HoldType.GATE, gate=3)] * 2)
    delayed = _waiting_status(A.DELAY, delay=[10.0, 10.0])
    assert held["target_position"] == 5000.0
    assert not held["in_coarse_position"]
    assert held == delayed


def test_open_gate_does_not_hold(ctl, ms, params):
    # MPI 000, MEIMotionAttrHOLD the gate holds only while closed
    held_start(ms, params, Hold(type=HoldType.GATE, gate=2))
    ctl.step(1)
    assert ctl.axes[0].cmd_p > 0.0


def test_gate_get(ctl):
    # MPI 000, MEIMotionAttrHoldTypeGATE "See meiControlGateGet/Set(...)"
    assert ctl.gate_get(5) == (M.MPIMessageOK, False)
    ctl.gate_set(5, True)
    assert ctl.gate_get(5) == (M.MPIMessageOK, True)
    # MPI 000, MEIMotionAttrHoldSource, gate "between 0 and 31"
    assert ctl.gate_set(32, True).message is M.MPIMessagePARAM_INVALID


def test_input_hold_matches_mask_and_pattern(ctl, ms, params):
    # MPI 000, MEIMotionAttrHOLD "held until then value of the internal Xmp variable specified by source.input
    # bitwise anded with source.mask matches source.pattern"; MPI 000, MEIMotionAttrHoldSource, input.pattern
    hold = Hold(type=HoldType.INPUT, address=5, mask=0b1100, pattern=0b0100)
    ctl.io_set(IoSpace.IO, 5, 0b1111)
    held_start(ms, params, hold)
    assert still(ctl)
    ctl.io_set(IoSpace.IO, 5, 0b0011)  # masked: 0b0000
    assert still(ctl)
    ctl.io_set(IoSpace.IO, 5, 0b0111)  # masked: 0b0100
    ctl.step(1)
    assert ctl.axes[0].cmd_p > 0.0


@pytest.mark.parametrize(("kind", "space"), [(HoldType.MOTOR_GENERAL_IO, IoSpace.MOTOR_GENERAL_IO),
                                        (HoldType.MOTOR_DEDICATED_IO, IoSpace.MOTOR_DEDICATED_IO)])
def test_motor_io_hold(ctl, ms, params, kind, space):
    # MPI 000, MEIMotionAttrHoldTypeMOTOR_GENERAL_IO "Motion hold input triggers from a General IO bit"; MPI 000,
    # MEIMotionAttrHoldTypeMOTOR_DEDICATED_IO "... from a Dedicated I/O bit"; MPI 000, MEIMotionAttrHoldSource,
    # motor.number motor.number, mask, pattern; MPI 000, MEIMotionAttrHOLD
    held_start(ms, params, Hold(type=kind, number=2, mask=0x10, pattern=0x10))
    ctl.io_set(space, 1, 0x10)  # another motor
    assert still(ctl)
    ctl.io_set(space, 2, 0x10)
    ctl.step(1)
    assert ctl.axes[0].cmd_p > 0.0


def test_user_address_hold(ctl, ms, params):
    # MPI 000, MEIMotionAttrHoldTypeUSER_ADDRESS "Motion hold input trigger from a user specifiable controller memory
    # address"; MPI 000, MEIMotionAttrHoldSource, user.address address, mask, pattern (docs/decisions.md, "The ROS
    # contract": address = an I/O word index)
    held_start(ms, params, Hold(type=HoldType.USER_ADDRESS, address=60, mask=-1, pattern=7))
    assert still(ctl)
    ctl.io_set(IoSpace.IO, 60, 7)
    ctl.step(1)
    assert ctl.axes[0].cmd_p > 0.0


def test_hold_type_none_does_not_hold(ctl, ms, params):
    # MPI 000, MEIMotionAttrHoldTypeNONE "MEIMotionAttrHoldTypeNONE This type disables the hold trigger condition"
    held_start(ms, params, Hold(type=HoldType.NONE))
    ctl.step(1)
    assert ctl.axes[0].cmd_p > 0.0


def leader_and_follower(ctl, params, hold, attrs):
    """Supervisor 0 moves axis 0 from 0 to 1000; supervisor 1's move of axis 2 holds on it."""
    _, lead = ctl.create_motion(0)
    _, follow = ctl.create_motion(1)
    lead.axis_list_set([0])
    follow.axis_list_set([2])
    assert follow.start(T.TRAPEZOIDAL, attrs, params((100.0,), hold=[hold])).ok
    assert lead.start(T.TRAPEZOIDAL, params=params((1000.0,))).ok
    return lead, follow


@pytest.mark.parametrize("kind", [HoldType.AXIS_POSITION_COMMAND, HoldType.AXIS_POSITION_ACTUAL])
def test_axis_position_hold_greater(ctl, params, kind):
    # MPI 000, MEIMotionAttrHOLD_GREATER HOLD_GREATER "greater than or equal hold logic"; MPI 000,
    # MEIMotionAttrHoldTypeAXIS_POSITION_ACTUAL trigger from an axis's actual / command position; MPI 000,
    # MEIMotionAttrHoldSource, axis.number axis.number, axis.position
    hold = Hold(type=kind, number=0, position=400.0)
    _lead, _follow = leader_and_follower(ctl, params, hold, A.HOLD | A.HOLD_GREATER)
    watched = ctl.axes[0]
    while ctl.axes[2].holding:
        position = watched.command_position if kind is HoldType.AXIS_POSITION_COMMAND else watched.actual_position
        assert position < 400.0
        ctl.step(1)
    position = watched.command_position if kind is HoldType.AXIS_POSITION_COMMAND else watched.actual_position
    assert position >= 400.0
    ctl.step(1)
    assert ctl.axes[2].cmd_p > 0.0


def test_axis_position_hold_less(ctl, params):
    # MPI 000, MEIMotionAttrHOLD_LESS HOLD_LESS "less than or equal hold logic"
    ctl.axis_command_position_set(0, 1000.0)
    ctl.step(5000)
    hold = Hold(type=HoldType.AXIS_POSITION_COMMAND, number=0, position=600.0)
    _, lead = ctl.create_motion(0)
    _, follow = ctl.create_motion(1)
    lead.axis_list_set([0])
    follow.axis_list_set([2])
    follow.start(T.TRAPEZOIDAL, A.HOLD | A.HOLD_LESS, params((100.0,), hold=[hold]))
    lead.start(T.TRAPEZOIDAL, params=params((0.0,)))
    while ctl.axes[2].holding:
        assert ctl.axes[0].command_position > 600.0
        ctl.step(1)
    assert ctl.axes[0].command_position <= 600.0  # released at the first sample at or below


def test_axis_position_hold_without_less_or_greater_waits_for_the_crossing(ctl, params):
    # holds.py: neither HOLD_LESS nor HOLD_GREATER: "the position is reached from the side it
    # starts on" (MPI 000, MEIMotionAttrHoldSource, axis.position axis.position "A position comparison value")
    hold = Hold(type=HoldType.AXIS_POSITION_COMMAND, number=0, position=250.0)
    leader_and_follower(ctl, params, hold, A.HOLD)
    assert ctl.run_until(lambda c: not c.axes[2].holding, 10_000)
    assert 250.0 <= ctl.axes[0].command_position < 250.0 + 1.0


def test_hold_less_already_true_releases_at_once(ctl, params):
    # MPI 000, MEIMotionAttrHOLD_LESS "less than or equal": true at the start, the move is not held
    hold = Hold(type=HoldType.AXIS_POSITION_COMMAND, number=0, position=400.0)
    leader_and_follower(ctl, params, hold, A.HOLD | A.HOLD_LESS)
    assert not ctl.axes[2].holding


def test_timeout_starts_the_move_anyway(ctl, ms, params):
    # MPI 000, MEIMotionAttrHOLD "The timeout field of MEIMotionAttrHold{} will cause the motion to start after the
    # specified timeout period (in seconds), even if the other hold criteria have not been
    # satisfied"; docs/decisions.md, "Motion", HOLD: the timeout is in seconds
    ctl.gate_set(1, True)
    k = ctl.sample
    held_start(ms, params, Hold(type=HoldType.GATE, gate=1, timeout=0.1))
    ctl.step(199)
    assert ctl.axes[0].holding
    assert ctl.axes[0].cmd_p == 0.0
    ctl.step(1)
    assert not ctl.axes[0].holding
    assert ctl.sample == k + 200
    timeouts = [e for e in ctl.drain_events() if e.type is E.HOLD_TIMEOUT]
    assert [(e.sample, e.axis) for e in timeouts] == [(k + 200, 0), (k + 200, 1)]
    ctl.step(1)
    assert ctl.axes[0].cmd_p > 0.0


def test_zero_timeout_waits_forever(ctl, ms, params):
    # MPI 000, MEIMotionAttrHOLD "A value of zero for timeout causes the timeout feature to be disabled and
    # forces the motion to wait for the hold criteria"
    ctl.gate_set(1, True)
    held_start(ms, params, Hold(type=HoldType.GATE, gate=1, timeout=0.0))
    assert still(ctl, 100_000)
    assert ms.state is MPIState.MOVING


def test_same_hold_starts_in_the_same_sample_across_supervisors(ctl, ms, ms1, params):
    # MPI 000, MEIMotionAttrHOLD "All axes holding with the same hold attributes (same gate, same input, mask,
    # and pattern) will start motion in the same sample even if the moves are specified using
    # different motion supervisors"
    ctl.gate_set(4, True)
    hold = Hold(type=HoldType.GATE, gate=4)
    held_start(ms, params, hold)
    ctl.step(123)
    ms1.start(T.S_CURVE, A.HOLD, params((900.0, 50.0), jerk_percent=50.0, hold=[hold, hold]))
    ctl.step(77)
    ctl.gate_set(4, False)
    ctl.step(1)
    assert all(ctl.axes[n].cmd_p != 0.0 for n in (0, 2, 3))
    released = [e for e in ctl.drain_events() if e.type is E.HOLD_RELEASED]
    assert len(released) == 4
    assert len({e.sample for e in released}) == 1


def test_hold_is_refused_on_modify(ctl, ms, params, bring):
    # MPI 000, MEIMotionAttrHOLD "MPIMotionMessageATTRIBUTE_INVALID will be returned if MEIMotionAttrHOLD is used
    # with a mpiMotionModify(...) method"
    bring(MPIState.MOVING)
    hold = Hold(type=HoldType.GATE, gate=1)
    assert ms.modify(T.TRAPEZOIDAL, A.HOLD, params(hold=[hold, hold])).message is M.MPIMotionMessageATTRIBUTE_INVALID


@pytest.mark.parametrize("attr", [A.HOLD, A.HOLD_LESS, A.HOLD_GREATER])
def test_hold_is_refused_on_modify_even_with_auto_start(ctl, ms, params, attr):
    # MPI 000, mpiMotionModify "It is impossible to use the HOLD attributes with mpiMotionModify, even when
    # using the AUTO_START attribute"; MPI 000, MPIMotionMessageATTRIBUTE_INVALID
    hold = Hold(type=HoldType.GATE, gate=1)
    message = ms.modify(T.TRAPEZOIDAL, A.AUTO_START | attr, params(hold=[hold, hold])).message
    assert message is M.MPIMotionMessageATTRIBUTE_INVALID
    assert ms.state is MPIState.IDLE


def test_hold_with_append(ctl, ms, params, run_to):
    # MPI 000, MPIMotionAttrAPPEND "The MEIMotionAttrHOLD attribute is supported with MPIMotionAttrMaskAPPEND"
    ctl.gate_set(3, True)
    ms.start(T.TRAPEZOIDAL, params=params((200.0, 0.0)))
    hold = Hold(type=HoldType.GATE, gate=3)
    assert ms.start(T.TRAPEZOIDAL, A.APPEND | A.HOLD, params((400.0, 0.0), hold=[hold, hold])).ok
    ctl.step(5000)
    assert ctl.axes[0].command_position == 200.0
    assert ctl.axes[0].holding
    assert ms.state is MPIState.MOVING
    ctl.gate_set(3, False)
    run_to(ctl, ms, MPIState.IDLE, 20_000, chunk=100)
    assert ctl.axes[0].command_position == 400.0


def test_the_hold_frame_is_in_the_buffer(ctl, ms, params):
    # MPI 000, MEIMotionAttrHOLD "The HOLD attribute is applied at the beginning of the motion (one HOLD frame)"
    ctl.gate_set(3, True)
    ms.start(T.TRAPEZOIDAL, params=params((200.0, 0.0)))
    plain = ctl.frame_count(0)
    ms.action(MPIAction.ABORT)
    ctl.step(1)
    ms.action(MPIAction.RESET)
    hold = Hold(type=HoldType.GATE, gate=3)
    ms.start(T.TRAPEZOIDAL, A.HOLD, params((400.0, 0.0), hold=[hold, hold]))
    assert ctl.frame_count(0) == plain + 1


def test_e_stop_while_holding_drops_the_move(ctl, ms, params, run_to):
    # MPI 000, mpiMotionAction E_STOP then ERROR; docs/state-machine.md: only RESET leaves ERROR (nothing pending)
    ctl.gate_set(3, True)
    held_start(ms, params, Hold(type=HoldType.GATE, gate=3))
    ms.action(MPIAction.E_STOP)
    run_to(ctl, ms, MPIState.ERROR, 500)
    ctl.gate_set(3, False)
    ms.action(MPIAction.RESET)
    assert still(ctl, 2000)
    assert ms.state is MPIState.IDLE


def test_io_words_are_32_bit(ctl):
    # io.py: "Words are 32-bit" (an input word compared under a mask, MPI 000, MEIMotionAttrHoldSource, input.pattern)
    assert ctl.io_set(IoSpace.IO, 0, 0xFFFFFFFF).ok
    assert ctl.io_get(IoSpace.IO, 0) == (M.MPIMessageOK, -1)
    assert ctl.io_set(IoSpace.IO, 0, 0x0, mask=0x0000FFFF).ok
    assert ctl.io_get(IoSpace.IO, 0)[1] == -65536
    assert ctl.io_set(IoSpace.IO, 64, 1).message is M.MPIMessagePARAM_INVALID
    assert ctl.io_get(IoSpace.MOTOR_GENERAL_IO, 4)[0] is M.MPIMessagePARAM_INVALID
