"""Cams on the controller: CAM_LINEAR and CAM_CUBIC slaves following a master position.

MPI 000: MPIMotionCam, MPIMotionType CAM_LINEAR / CAM_CUBIC, the attributes REPEAT, MASTER_START,
NO_BACKTRACK and NO_BACKTRACK_HOLD, MPIMotionMessageFRAME_BUFFER_TOO_SMALL; MPI 002: MPIAxisConfig.master,
MPIAxisMaster, MPIAxisMasterType, masterCorrection. Decisions: docs/cams.md. Everything steps the
controller by samples.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from mpi_ros.commands import Command, apply
from mpi_ros.mpi import (
    AxisMaster,
    AxisMasterType,
    Controller,
    ControllerConfig,
    IoSpace,
    Message,
    MotionAttr,
    MotionParams,
    MPIAction,
    MPIEventType,
    MPIMotionType,
    MPIState,
    SecondaryFeedback,
    Trajectory,
)
from mpi_ros.mpi.planning.profiles.cam import CamTable

A, T, M, S = MotionAttr, MPIMotionType, Message, AxisMasterType
RATE = 1000.0


def controller(**config) -> Controller:
    """1 kHz, 4 axes; supervisor 0 on axis 0 (the master's), supervisor 1 on axes 1 and 2 (the slaves)."""
    ctl = Controller(ControllerConfig(sample_rate=RATE, axis_count=4, supervisor_count=3, **config))
    ctl.create_motion(0, 0)
    _, slaves = ctl.create_motion(1)
    slaves.axis_list_set([1, 2])
    slaves.action(MPIAction.MAP)
    return ctl


def follow(ctl: Controller, master: AxisMaster, axes=(1, 2)) -> None:
    for n in axes:
        assert ctl.axis_master_set(n, master).message is M.MPIMessageOK


def cam(distances, slaves, ratios=(), **fields) -> MotionParams:
    return MotionParams(master_distance=list(distances), slave_position=list(slaves), gear_ratio=list(ratios),
                        **fields)


def set_word(ctl: Controller, value: int) -> None:
    assert ctl.io_set(IoSpace.IO, 3, value).message is M.MPIMessageOK


def command(ctl: Controller, axis: int) -> float:
    return ctl.axes[axis].command_position


def master_velocity(ctl: Controller, velocity: float) -> None:
    """Axis 0 (supervisor 0) at a constant velocity."""
    ms0 = ctl.supervisor(0)
    assert ms0.start(T.VELOCITY, A.NONE, MotionParams(trajectory=[Trajectory(velocity, 1e7, 1e7)])).ok


# ------------------------------------------------------------------ following ----
@pytest.mark.parametrize("kind", [T.CAM_LINEAR, T.CAM_CUBIC])
def test_slave_follows_the_table_at_the_masters_position_every_sample(kind):
    # The slave's command is a function of the master's position, not of time: each sample
    # start + table(master - master at the start), whatever the master does (here it accelerates).
    ctl = controller()
    follow(ctl, AxisMaster(S.AXIS_COMMANDED_POSITION, 0))
    ms0, ms1 = ctl.supervisor(0), ctl.supervisor(1)
    assert ms0.start(T.S_CURVE, A.NONE, MotionParams(trajectory=[Trajectory(4000.0, 30000.0, 30000.0, 50.0)],
                                                     position=[900.0])).ok
    ctl.step(7)
    origin = command(ctl, 0)
    params = cam([300.0, 300.0, 200.0], [100.0, -40.0, 60.0, 50.0, 10.0, -30.0], [0.5, 0.1, 0.2, 0.0, 0.0, 0.0])
    assert ms1.start(kind, A.NONE, params).message is M.MPIMessageOK
    ratios = None if kind is T.CAM_LINEAR else [0.5, 0.2, 0.0]
    table1 = CamTable.build([300.0, 300.0, 200.0], [100.0, 60.0, 10.0], ratios, None)
    ratios2 = None if kind is T.CAM_LINEAR else [0.1, 0.0, 0.0]
    table2 = CamTable.build([300.0, 300.0, 200.0], [-40.0, 50.0, -30.0], ratios2, None)
    seen = []
    while ctl.sample < 500:
        ctl.step(1)
        travel = np.array([command(ctl, 0) - origin])
        assert command(ctl, 1) == table1.position(travel)[0]
        assert command(ctl, 2) == table2.position(travel)[0]
        seen.append(ms1.state)
    # the master stops at 900 - origin > 800: the cam ran through its table and is DONE
    assert ms1.state is MPIState.IDLE
    assert (command(ctl, 1), command(ctl, 2)) == (170.0, -20.0)
    events = [e.type for e in ctl.drain_events() if e.supervisor == 1]
    assert events[0] is MPIEventType.MOTION_START
    assert MPIEventType.MOTION_DONE in events


def test_the_slave_servo_follows_its_command():
    ctl = controller()
    follow(ctl, AxisMaster(S.AXIS_COMMANDED_POSITION, 0))
    master_velocity(ctl, 1000.0)
    assert ctl.supervisor(1).start(T.CAM_LINEAR, A.NONE, cam([10_000.0], [5000.0, 2000.0])).ok
    ctl.step(2000)
    # gear ratio 0.5 at a master speed of 1000 counts/s: the slave moves at 500 counts/s, within a
    # few counts of its command (the simulated loop with its velocity feed-forward)
    slave = ctl.axes[1]
    assert slave.cmd_v == pytest.approx(500.0, abs=1e-6)
    assert abs(slave.position_error) < 5.0
    assert slave.act_v == pytest.approx(500.0, rel=0.02)


# ------------------------------------------------------------------ backtracking ----
REVERSAL = [60, 30, 50, 70, 90]  # the master (an I/O word) goes to 60, back to 30, then forward


@pytest.mark.parametrize(("attrs", "expected"), [
    # without NO_BACKTRACK the slave follows the master back
    (A.NONE, [60.0, 30.0, 50.0, 70.0, 90.0]),
    # NO_BACKTRACK: "if the master changes direction and moves backwards the slave axes will hold that position
    # until the master velocity returns to the original direction": from 30 to 50 the slave moves on by 20
    (A.NO_BACKTRACK, [60.0, 60.0, 80.0, 100.0, 100.0]),
    # NO_BACKTRACK_HOLD: "the slave axes will hold that position until the master returns to the point where the
    # direction changed"
    (A.NO_BACKTRACK_HOLD, [60.0, 60.0, 60.0, 70.0, 90.0]),
])
def test_a_master_that_reverses_under_each_backtrack_mode(attrs, expected):
    ctl = controller()
    follow(ctl, AxisMaster(S.ADDRESS, address=3), axes=(1,))
    ms1 = ctl.supervisor(1)
    ms1.axis_list_set([1])
    assert ms1.start(T.CAM_LINEAR, attrs, cam([100.0], [100.0])).ok  # gear ratio 1
    got = []
    for word in REVERSAL:
        set_word(ctl, word)
        ctl.step(5)
        got.append(command(ctl, 1))
    assert got == expected


def test_no_backtrack_and_no_backtrack_hold_exclude_each_other():
    # MPIMotionAttrMaskNO_BACKTRACK / NO_BACKTRACK_HOLD: "cannot be specified with" the other one
    ctl = controller()
    ms1 = ctl.supervisor(1)
    outcome, _ = ms1.command(T.CAM_LINEAR, A.NO_BACKTRACK | A.NO_BACKTRACK_HOLD,
                                     cam([100.0], [1.0, 1.0]), False)
    message, detail = outcome.message, outcome.detail
    assert message is M.MPIMotionMessageATTRIBUTE_INVALID
    assert "exclude" in detail


# ------------------------------------------------------------------ repeat, master start ----
def test_repeat_runs_many_cycles_without_drift():
    # MPIMotionAttrREPEAT with repeatFrom 1: segment 0 is a run-in, segments 1 and 2 repeat forever. The
    # master is a line-shaft encoder at 1000 counts/s (1 count per sample): cycle c ends at master
    # 100 + 150 c, where the slave is exactly at 10 + 30 c.
    ctl = controller()
    assert ctl.secondary_feedback_set(2, SecondaryFeedback(0.0, 1000.0)).message is M.MPIMessageOK
    follow(ctl, AxisMaster(S.MOTOR_FEEDBACK_SECONDARY, 2), axes=(1,))
    ms1 = ctl.supervisor(1)
    ms1.axis_list_set([1])
    params = cam([100.0, 100.0, 50.0], [10.0, 50.0, -20.0], [0.4, -0.2, 0.4], repeat_from=1)
    assert ms1.start(T.CAM_CUBIC, A.REPEAT, params).ok
    start_sample = ctl.sample
    for cycle in range(40):
        ctl.step(start_sample + 100 + 150 * cycle - ctl.sample)
        assert command(ctl, 1) == 10.0 + 30.0 * cycle
    assert ms1.state is MPIState.MOVING
    assert ms1.progress() == 0.0
    assert ms1.action(MPIAction.STOP).message is M.MPIMessageOK
    ctl.step(1000)
    assert ms1.state is MPIState.STOPPED
    assert ctl.axes[1].cmd_v == 0.0


def test_master_start_holds_the_slave_until_the_master_gets_there():
    # MPIMotionAttributes.masterStart: "the position of the master at the start of the cam motion"
    ctl = controller()
    follow(ctl, AxisMaster(S.ADDRESS, address=3), axes=(1,))
    ms1 = ctl.supervisor(1)
    ms1.axis_list_set([1])
    set_word(ctl, 100)
    assert ms1.start(T.CAM_LINEAR, A.MASTER_START, cam([100.0], [50.0], master_start=500)).ok
    got = []
    for word in (200, 499, 500, 560, 520, 600, 700):
        set_word(ctl, word)
        ctl.step(3)
        got.append(command(ctl, 1))
    assert got == [0.0, 0.0, 0.0, 30.0, 10.0, 50.0, 50.0]
    ctl.step(200)  # (the loop settles after the master's last jump)
    assert ms1.state is MPIState.IDLE  # the end of the table reached at 600: DONE


def test_master_start_behind_the_master_waits_for_it_to_come_back():
    # docs/cams.md: the cam starts when the master reaches masterStart from the side it was on (as a HOLD's
    # position trigger); until then the slave waits at its start, however far the master is past it
    ctl = controller()
    follow(ctl, AxisMaster(S.ADDRESS, address=3), axes=(1,))
    ms1 = ctl.supervisor(1)
    ms1.axis_list_set([1])
    set_word(ctl, 700)
    assert ms1.start(T.CAM_LINEAR, A.MASTER_START | A.NO_BACKTRACK_HOLD, cam([100.0], [50.0], master_start=500)).ok
    got = []
    for word in (800, 600, 450, 520, 480, 560):
        set_word(ctl, word)
        ctl.step(3)
        got.append(command(ctl, 1))
    assert got == [0.0, 0.0, 0.0, 10.0, 10.0, 30.0]


# ------------------------------------------------------------------ master sources ----
@pytest.mark.parametrize("source", list(S))
def test_each_master_source(source):
    # MPI 002, MPIAxisMasterType: the motor's primary or secondary feedback, an axis' command or actual
    # position, or a controller address (an I/O word)
    ctl = controller()
    master_velocity(ctl, 2000.0)
    ctl.axes[0].set_origin(-300.0)  # axis positions are user positions; the primary encoder is raw
    ctl.secondary_feedback_set(0, SecondaryFeedback(1000.0, 1500.0))
    set_word(ctl, 40)
    master = AxisMaster(source, number=0, address=3)
    follow(ctl, master, axes=(1,))
    ms1 = ctl.supervisor(1)
    ms1.axis_list_set([1])
    ctl.step(50)
    read = {
        S.AXIS_COMMANDED_POSITION: lambda: ctl.axes[0].command_position,
        S.AXIS_ACTUAL_POSITION: lambda: ctl.axes[0].actual_position,
        S.MOTOR_FEEDBACK_PRIMARY: lambda: ctl.axes[0].act_p,
        S.MOTOR_FEEDBACK_SECONDARY: lambda: float(np.floor(1000.0 + 1500.0 * (ctl.sample / RATE) + 0.5)),
        S.ADDRESS: lambda: float(ctl.io.words[IoSpace.IO][3]),
    }[source]
    origin = read()
    assert ms1.start(T.CAM_LINEAR, A.NONE, cam([1e6], [2e6])).ok  # gear ratio 2
    for step in (1, 7, 40, 100):
        if source is S.ADDRESS:
            set_word(ctl, 40 + step)
        ctl.step(step)
        assert command(ctl, 1) == pytest.approx(2.0 * (read() - origin), abs=1e-6)
    assert command(ctl, 1) > 0.0


ORIGIN_MASTERS = [
    ("commanded", AxisMaster(S.AXIS_COMMANDED_POSITION, 0), 0),
    ("actual", AxisMaster(S.AXIS_ACTUAL_POSITION, 0), 0),
    ("correction", AxisMaster(S.AXIS_COMMANDED_POSITION, 0, correction=3), 3),
]


@pytest.mark.parametrize(("name", "master", "moved"), ORIGIN_MASTERS, ids=[m[0] for m in ORIGIN_MASTERS])
def test_an_origin_change_does_not_move_a_cam_slave(name, master, moved):
    # MPI 002, mpiAxisOriginSet and MPIAxisMasterType AXIS_COMMANDED/ACTUAL_POSITION: the origin only changes
    # how positions are reported; the master axis (or the masterCorrection axis) does not move, so neither
    # may the slave: it goes on exactly as a twin whose origin stays put
    twins = []
    for change in (True, False):
        ctl = controller()
        follow(ctl, master, axes=(1,))
        master_velocity(ctl, 1000.0)
        ms1 = ctl.supervisor(1)
        ms1.axis_list_set([1])
        ctl.step(20)
        assert ms1.start(T.CAM_LINEAR, A.NONE, cam([10_000.0], [5000.0])).ok  # gear ratio 0.5
        ctl.step(100)
        slave = [command(ctl, 1)]
        if change:
            assert ctl.axis_origin_set(moved, -1000.0).message is M.MPIMessageOK
        for _ in range(300):
            ctl.step(1)
            slave.append(command(ctl, 1))
        twins.append(np.array(slave))
    changed, kept = twins
    assert np.max(np.abs(np.diff(changed))) * RATE < 600.0  # 0.5 x the master's 1000 counts/s, plus the loop
    assert np.array_equal(changed, kept)


def test_a_master_axis_of_another_supervisor_and_a_chain_of_cams():
    # axis 1 (supervisor 1) follows axis 0 (supervisor 0); axis 3 (supervisor 2) follows axis 1's command:
    # the slave of a slave, computed in the same sample after its master
    ctl = controller()
    _, ms2 = ctl.create_motion(2, 3)
    master_velocity(ctl, 1000.0)
    follow(ctl, AxisMaster(S.AXIS_COMMANDED_POSITION, 0), axes=(1,))
    ctl.axis_master_set(3, AxisMaster(S.AXIS_COMMANDED_POSITION, 1))
    ms1 = ctl.supervisor(1)
    ms1.axis_list_set([1])
    ctl.step(20)
    assert ms1.start(T.CAM_LINEAR, A.NONE, cam([1e6], [5e5])).ok
    assert ms2.start(T.CAM_LINEAR, A.NONE, cam([1e6], [-1e6])).ok
    m0, s1 = command(ctl, 0), command(ctl, 1)
    ctl.step(300)
    assert command(ctl, 1) == pytest.approx(0.5 * (command(ctl, 0) - m0), abs=1e-9)
    assert command(ctl, 3) == pytest.approx(-(command(ctl, 1) - s1), abs=1e-9)


def test_master_correction_adds_the_correction_axis_command_position():
    # MPI 002, masterCorrection: "which axis provides the master position correction" (docs/cams.md: its
    # command position is added to the master position; a move on it shifts the cam's phase)
    ctl = controller()
    follow(ctl, AxisMaster(S.ADDRESS, address=3, correction=3), axes=(1,))
    ms1 = ctl.supervisor(1)
    ms1.axis_list_set([1])
    _, ms2 = ctl.create_motion(2, 3)
    assert ms1.start(T.CAM_LINEAR, A.NONE, cam([1000.0], [1000.0])).ok
    set_word(ctl, 100)
    ctl.step(2)
    assert command(ctl, 1) == 100.0
    assert ms2.start(T.TRAPEZOIDAL, A.NONE, MotionParams(trajectory=[Trajectory(1000.0, 1e5, 1e5)],
                                                         position=[25.0])).ok
    ctl.step(200)
    assert command(ctl, 1) == 125.0


def test_a_slave_cannot_follow_itself_directly_or_through_other_cams():
    ctl = controller()
    ms1 = ctl.supervisor(1)
    follow(ctl, AxisMaster(S.AXIS_ACTUAL_POSITION, 2))  # axis 2 is a slave of the same cam
    outcome, _ = ms1.command(T.CAM_LINEAR, A.NONE, cam([100.0], [1.0, 1.0]), False)
    message, detail = outcome.message, outcome.detail
    assert message is M.MPIMessagePARAM_INVALID
    assert "itself" in detail
    # axis 3 follows axis 1; then a cam on axis 1 following axis 3 would be a loop
    _, ms2 = ctl.create_motion(2, 3)
    ctl.axis_master_set(3, AxisMaster(S.MOTOR_FEEDBACK_PRIMARY, 1))
    assert ms2.start(T.CAM_LINEAR, A.NONE, cam([100.0], [1.0])).ok
    follow(ctl, AxisMaster(S.AXIS_COMMANDED_POSITION, 3), axes=(1,))
    ms1.axis_list_set([1])
    assert ms1.command(T.CAM_LINEAR, A.NONE, cam([100.0], [1.0]), False)[0].message is M.MPIMessagePARAM_INVALID
    assert ms1.state is MPIState.IDLE


def test_the_master_is_read_when_the_cam_starts():
    # docs/cams.md: a running cam keeps the master it started with; a new one applies to the next cam
    ctl = controller()
    follow(ctl, AxisMaster(S.ADDRESS, address=3), axes=(1,))
    ms1 = ctl.supervisor(1)
    ms1.axis_list_set([1])
    assert ms1.start(T.CAM_LINEAR, A.NONE, cam([1000.0], [1000.0])).ok
    follow(ctl, AxisMaster(S.ADDRESS, address=4), axes=(1,))
    set_word(ctl, 10)
    ctl.step(2)
    assert command(ctl, 1) == 10.0


@pytest.mark.parametrize(("master", "field"), [
    (AxisMaster(S.AXIS_COMMANDED_POSITION, 4), "number"),
    (AxisMaster(S.AXIS_ACTUAL_POSITION, -1), "number"),
    (AxisMaster(S.MOTOR_FEEDBACK_PRIMARY, 4), "number"),
    (AxisMaster(S.MOTOR_FEEDBACK_SECONDARY, 4), "number"),
    (AxisMaster(S.ADDRESS, address=64), "address"),
    (AxisMaster(S.ADDRESS, correction=4), "correction"),
    (AxisMaster(S.ADDRESS, correction=-2), "correction"),
])
def test_a_master_that_does_not_exist_is_refused_and_changes_nothing(master, field):
    # MPI 002, MPIAxisMaster: number is "the motor or axis number", address "the controller address";
    # masterCorrection: an axis, -1 for none
    ctl = controller()
    verdict = ctl.axis_master_check(1, master)
    assert verdict.message is M.MPIMessagePARAM_INVALID
    assert verdict.detail.startswith(field)
    assert ctl.axis_master_set(1, master).message is M.MPIMessagePARAM_INVALID
    assert ctl.axes[1].master == AxisMaster()


# ------------------------------------------------------------------ stop ----
@pytest.mark.parametrize(("action", "state"), [(MPIAction.STOP, MPIState.STOPPED),
                                               (MPIAction.E_STOP, MPIState.ERROR)])
def test_stop_and_e_stop_bring_the_slaves_to_rest_while_the_master_goes_on(action, state):
    ctl = controller()
    follow(ctl, AxisMaster(S.AXIS_COMMANDED_POSITION, 0))
    master_velocity(ctl, 1000.0)
    ms1 = ctl.supervisor(1)
    assert ms1.start(T.CAM_LINEAR, A.NONE, cam([1e6], [1e6, 5e5])).ok
    ctl.step(500)
    assert ms1.action(action).message is M.MPIMessageOK
    decel = ms1.config.decel_time.stop if action is MPIAction.STOP else ms1.config.decel_time.e_stop
    before = command(ctl, 1)
    ctl.step(int(decel * RATE) + 50)
    assert ms1.state is state
    # the slave decelerated with the feedrate ramp: half the distance it would have gone at speed
    # (the ramp in whole samples: within one sample's travel)
    assert command(ctl, 1) - before == pytest.approx(1000.0 * decel / 2.0, abs=1.0)
    rest = command(ctl, 1)
    ctl.step(200)
    assert command(ctl, 1) == rest
    assert ctl.supervisor(0).state is MPIState.MOVING


def test_resume_continues_the_cam_from_where_the_slave_stopped():
    ctl = controller()
    follow(ctl, AxisMaster(S.AXIS_COMMANDED_POSITION, 0), axes=(1,))
    master_velocity(ctl, 1000.0)
    ms1 = ctl.supervisor(1)
    ms1.axis_list_set([1])
    assert ms1.start(T.CAM_LINEAR, A.NONE, cam([1e6], [1e6])).ok
    ctl.step(300)
    ms1.action(MPIAction.STOP)
    ctl.step(1000)
    assert ms1.action(MPIAction.RESUME).message is M.MPIMessageOK
    ctl.step(1000)
    # back at the master's speed; the phase lost stays lost (docs/cams.md): half a stop time while
    # stopping (250 counts), the 500 samples at rest, half a stop time while resuming
    assert ctl.axes[1].cmd_v == pytest.approx(1000.0, abs=1e-6)
    assert command(ctl, 0) - command(ctl, 1) == pytest.approx(250.0 + 500.0 + 250.0, abs=1e-6)


# ------------------------------------------------------------------ validation ----
def p(**fields):
    return cam([100.0, 100.0], [1.0, 2.0, 3.0, 4.0], [0.0, 0.0, 0.0, 0.0], **fields)


@pytest.mark.parametrize(("kind", "attrs", "params", "message", "words"), [
    # MPIMotionCam masterDistance: "An array containing pointCount number of elements"
    (T.CAM_LINEAR, A.NONE, cam([], []), M.MPIMessagePARAM_INVALID, "at least one segment"),
    # slavePosition: a distance per slave axis and segment (pointCount x axes, interleaved by axis)
    (T.CAM_LINEAR, A.NONE, cam([100.0, 100.0], [1.0, 2.0, 3.0]), M.MPIMessagePARAM_INVALID, "slave_position"),
    # gearRatio (CAM_CUBIC): at each transition, per axis
    (T.CAM_CUBIC, A.NONE, cam([100.0, 100.0], [1.0, 2.0, 3.0, 4.0], [0.0]), M.MPIMessagePARAM_INVALID,
     "gear_ratio"),
    # values must be finite numbers (any move's values: MPIMessagePARAM_INVALID)
    (T.CAM_LINEAR, A.NONE, cam([100.0, float("nan")], [1.0, 2.0, 3.0, 4.0]), M.MPIMessagePARAM_INVALID,
     "master_distance[1]"),
    (T.CAM_CUBIC, A.NONE, cam([100.0, 100.0], [1.0, 2.0, 3.0, float("inf")], [0.0] * 4),
     M.MPIMessagePARAM_INVALID, "slave_position[3]"),
    (T.CAM_CUBIC, A.NONE, cam([100.0, 100.0], [1.0] * 4, [0.0, 0.0, float("nan"), 0.0]),
     M.MPIMessagePARAM_INVALID, "gear_ratio[2]"),
    # a segment the master never moves through (docs/cams.md), or a table run back and forth
    (T.CAM_LINEAR, A.NONE, cam([100.0, 0.0], [1.0] * 4), M.MPIMessagePARAM_INVALID, "non-zero"),
    (T.CAM_LINEAR, A.NONE, cam([100.0, -100.0], [1.0] * 4), M.MPIMessagePARAM_INVALID, "one sign"),
    # MPIMotionAttributes.repeatFrom: "the first frame that is repeated"
    (T.CAM_LINEAR, A.REPEAT, p(repeat_from=2), M.MPIMessagePARAM_INVALID, "repeat_from"),
    (T.CAM_LINEAR, A.REPEAT, p(repeat_from=-1), M.MPIMessagePARAM_INVALID, "repeat_from"),
    # the attributes a cam accepts (docs/cams.md): not RELATIVE, APPEND, DELAY, HOLD, path attributes ...
    (T.CAM_LINEAR, A.RELATIVE, p(), M.MPIMotionMessageATTRIBUTE_INVALID, "RELATIVE"),
    (T.CAM_CUBIC, A.APPEND, p(), M.MPIMotionMessageATTRIBUTE_INVALID, "APPEND"),
    (T.CAM_CUBIC, A.DELAY, p(delay=[0.0, 0.0]), M.MPIMotionMessageATTRIBUTE_INVALID, "DELAY"),
    (T.CAM_LINEAR, A.EMPTY_COUNT, p(), M.MPIMotionMessageATTRIBUTE_INVALID, "EMPTY_COUNT"),
    # ... and the cam attributes only on a cam (MPIMotionAttrMask: "generates a repeating cam motion")
    (T.TRAPEZOIDAL, A.REPEAT, MotionParams(trajectory=[Trajectory(1.0, 1.0, 1.0)], position=[1.0, 1.0]),
     M.MPIMotionMessageATTRIBUTE_INVALID, "cam attributes"),
])
def test_each_validation_rule(kind, attrs, params, message, words):
    ctl = controller()
    ms1 = ctl.supervisor(1)
    outcome, _ = ms1.command(kind, attrs, params, False)
    got, detail = outcome.message, outcome.detail
    assert got is message
    assert words in detail
    ctl.step(10)
    assert ms1.state is MPIState.IDLE
    assert command(ctl, 1) == 0.0


def test_a_linear_cam_ignores_its_gear_ratios():
    # MPIMotionCam gearRatio: "with linear cams this field is completely ignored"
    ctl = controller()
    assert ctl.supervisor(1).start(T.CAM_LINEAR, A.NONE, cam([100.0], [1.0, 1.0], [float("nan")])).ok


def test_cams_cannot_be_modified():
    # MPI 000, mpiMotionModify: "The types of motion whose parameters can be modified while moving are
    # TRAPEZOIDAL, S_CURVE, VELOCITY, PT and PVT"
    ctl = controller()
    ms1 = ctl.supervisor(1)
    assert ms1.start(T.CAM_LINEAR, A.NONE, p()).ok
    assert ms1.modify(T.CAM_LINEAR, A.NONE, p()).message is M.MPIMessageUNSUPPORTED


@pytest.mark.parametrize(("kind", "params"), [
    (T.TRAPEZOIDAL, MotionParams(trajectory=[Trajectory(500.0, 1e4, 1e4)], position=[0.0, 0.0])),
    (T.VELOCITY, MotionParams(trajectory=[Trajectory(500.0, 1e4, 1e4)])),
], ids=["TRAPEZOIDAL", "VELOCITY"])
def test_a_modifiable_type_does_not_replace_a_running_cam(kind, params):
    # MPI 000, mpiMotionModify: the types "whose parameters can be modified while moving" do not name the
    # cams; the running motion's type decides, not the modify's: the slaves go on following the master
    ctl = controller()
    follow(ctl, AxisMaster(S.AXIS_COMMANDED_POSITION, 0))
    master_velocity(ctl, 1000.0)
    ms1 = ctl.supervisor(1)
    assert ms1.start(T.CAM_LINEAR, A.NONE, cam([10_000.0], [5000.0, 2000.0])).ok
    ctl.step(100)
    outcome, _ = ms1.command(kind, A.NONE, params, True)
    assert outcome.message is M.MPIMessageUNSUPPORTED
    assert "CAM_LINEAR" in outcome.detail
    origin = 0.0
    for _ in range(200):
        ctl.step(1)
        travel = command(ctl, 0) - origin
        assert command(ctl, 1) == pytest.approx(0.5 * travel, abs=1e-9)
        assert command(ctl, 2) == pytest.approx(0.2 * travel, abs=1e-9)
    assert ms1.state is MPIState.MOVING
    assert ms1.current.type is T.CAM_LINEAR


def test_a_cam_that_does_not_fit_the_frame_buffer():
    # MPIMotionMessageFRAME_BUFFER_TOO_SMALL: "When trying to start a cam, an insufficient amount of space was
    # found on the controller ... reduce the number of points within the cam ... or increase the number of
    # points in the frame buffer": a segment per frame, and the final frame (docs/cams.md)
    ctl = controller(frame_buffer_size=16)
    ms1 = ctl.supervisor(1)
    ms1.axis_list_set([1])
    answer = ms1.start(T.CAM_LINEAR, A.NONE, cam([10.0] * 16, [1.0] * 16))
    assert answer.message is M.MPIMotionMessageFRAME_BUFFER_TOO_SMALL
    assert ms1.start(T.CAM_LINEAR, A.NONE, cam([10.0] * 15, [1.0] * 15)).ok
    assert ctl.frame_count(1) == 16


# ------------------------------------------------------------------ commands ----
def test_axis_config_set_sets_the_master_with_in_position_all_or_nothing():
    ctl = controller()
    request = {"in_position": {"position_fine": 5.0}, "master": {"type": "address", "address": 7},
               "master_correction": 2}
    assert apply(ctl, Command("axis_config_set", axis=1, request=request)).message is M.MPIMessageOK
    assert ctl.axes[1].master == AxisMaster(S.ADDRESS, 0, 7, 2)
    assert ctl.axes[1].in_position.position_fine == 5.0
    # a bad master: nothing changes, in_position neither
    bad = {"in_position": {"position_fine": 9.0}, "master": {"type": "ADDRESS", "address": 9999}}
    reply = apply(ctl, Command("axis_config_set", axis=1, request=bad))
    assert reply.message is M.MPIMessagePARAM_INVALID
    assert reply.detail.startswith("master.address")
    assert ctl.axes[1].in_position.position_fine == 5.0
    assert ctl.axes[1].master.address == 7
    # a request without a master (as recorded before it existed) or with an empty type keeps it
    for keep in ({"in_position": {"position_fine": 6.0}},
                 {"in_position": {"position_fine": 6.0}, "master": {"type": ""}}):
        assert apply(ctl, Command("axis_config_set", axis=1, request=keep)).message is M.MPIMessageOK
        assert ctl.axes[1].master == AxisMaster(S.ADDRESS, 0, 7, 2)
    reply = apply(ctl, Command("axis_config_set", axis=1, request={"master": {"type": "WARP"}}))
    assert reply.message is M.MPIMessagePARAM_INVALID
    assert "master type" in reply.detail


def test_secondary_feedback_set_command():
    ctl = controller()
    reply = apply(ctl, Command("secondary_feedback_set", request={"motor": 1, "position": 5.0, "velocity": 2000.0}))
    assert reply.message is M.MPIMessageOK
    ctl.step(10)
    assert ctl.secondary.at(1, np.array([ctl.sample]), RATE)[0] == 25.0
    for bad, words in (({"motor": 9}, "no motor"), ({"motor": 0, "velocity": float("inf")}, "velocity")):
        reply = apply(ctl, Command("secondary_feedback_set", request=bad))
        assert reply.message is M.MPIMessagePARAM_INVALID
        assert words in reply.detail


# ------------------------------------------------------------------ batching ----
def _script_run(batches) -> tuple[dict, list]:
    ctl = controller()
    follow(ctl, AxisMaster(S.AXIS_ACTUAL_POSITION, 0), axes=(1,))
    ctl.axis_master_set(2, AxisMaster(S.MOTOR_FEEDBACK_SECONDARY, 2, correction=0))
    ctl.secondary_feedback_set(2, SecondaryFeedback(0.0, 700.0))
    ms0, ms1 = ctl.supervisor(0), ctl.supervisor(1)
    script = {
        3: lambda: ms0.start(T.S_CURVE, A.NONE, MotionParams(trajectory=[Trajectory(6000.0, 8e4, 8e4, 30.0)],
                                                             position=[4000.0])),
        20: lambda: ms1.start(T.CAM_CUBIC, A.REPEAT | A.NO_BACKTRACK_HOLD,
                              cam([300.0, 200.0, 250.0], [50.0, 10.0, -30.0, 40.0, 80.0, -20.0],
                                  [0.3, 0.1, -0.2, 0.2, 0.3, 0.1], repeat_from=1)),
        450: lambda: ms0.start(T.TRAPEZOIDAL, A.NONE, MotionParams(trajectory=[Trajectory(4000.0, 8e4, 8e4)],
                                                                   position=[1000.0])),
        750: lambda: ms1.action(MPIAction.STOP),
        1050: lambda: ms1.action(MPIAction.RESUME),
        1300: lambda: ms1.action(MPIAction.E_STOP),
        1450: lambda: ms1.action(MPIAction.RESET),
        1475: lambda: ms1.start(T.CAM_LINEAR, A.NO_BACKTRACK | A.MASTER_START,
                                cam([400.0], [100.0, 100.0], master_start=1250)),
    }
    seen = {}
    while ctl.sample < 2000:
        if ctl.sample in script:
            script[ctl.sample]()
        upcoming = min([s for s in script if s > ctl.sample] + [2000])
        ctl.step(max(1, min(next(batches), upcoming - ctl.sample)))
        # (repr: the bits of every float, nan included)
        seen[ctl.sample] = repr([(a.cmd_p, a.cmd_v, a.cmd_a, a.act_p, a.act_v, a.rel, a.status) for a in ctl.axes])
    return seen, [(e.sample, e.type, e.axis) for e in ctl.drain_events()]


def test_cams_are_bit_identical_however_the_samples_are_batched():
    one = _script_run(itertools.repeat(1))
    rng = np.random.default_rng(7)
    for batches in (itertools.repeat(4096), iter(rng.integers(1, 300, 10_000).tolist())):
        other = _script_run(batches)
        assert other[1] == one[1]
        for sample, values in other[0].items():
            assert values == one[0][sample], sample


def test_a_move_appended_behind_a_cam_starts_from_the_tables_end():
    # MPIMotionAttrAPPEND: "added to the end of a previous motion profile ... begin execution after the previous
    # profile has completed": a cam completes at its table's end (docs/cams.md)
    ctl = controller()
    follow(ctl, AxisMaster(S.ADDRESS, address=3), axes=(1,))
    ms1 = ctl.supervisor(1)
    ms1.axis_list_set([1])
    assert ms1.start(T.CAM_LINEAR, A.NONE, cam([100.0], [40.0])).ok
    assert ms1.start(T.TRAPEZOIDAL, A.APPEND, MotionParams(trajectory=[Trajectory(1000.0, 1e5, 1e5)],
                                                           position=[-60.0])).ok
    assert ms1.snapshot().moves_pending == 1
    set_word(ctl, 100)
    assert ctl.run_until(lambda c: ms1.state is MPIState.IDLE, 5000)
    assert command(ctl, 1) == -60.0
    done = [e.type for e in ctl.drain_events() if e.supervisor == 1 and e.type is MPIEventType.MOTION_DONE]
    assert len(done) == 2
