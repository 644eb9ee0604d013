"""The path attributes of MPI 001 (MPIMotionPathAttrMask) and the PTF/PVTF feedforward."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from mpi_ros.mpi import MotionParams, MPIAction, MPIState
from mpi_ros.mpi import MPIMotionType as T
from mpi_ros.mpi.base.events import MPIEventType as E
from mpi_ros.mpi.base.messages import Message as M
from mpi_ros.mpi.base.types import MotionAttr as A

PATH = dict(position=[100.0, 0.0, 300.0, 50.0], time=[0.1, 0.2])  # two points on two axes


def events(ctl) -> list[tuple[int, str]]:
    return [(e.sample, e.type.name) for e in ctl.drain_events()]


@pytest.fixture
def notified(ms):
    ms.event_notify_set(E.MOTION_START | E.MOTION_DONE | E.FRAMES_LOW | E.E_STOP)
    return ms


def test_no_handshake_status_reads_idle_until_execution_begins(ctl, notified):
    # MPI 001, Remarks: "the state is reported as MPIStateIDLE until the controller begins the
    # profile execution and the state transitions to MPIStateMOVING"
    assert notified.start(T.PT, A.NO_HANDSHAKE, MotionParams(**PATH)).ok
    assert notified.snapshot().state is MPIState.IDLE
    ctl.step(1)
    assert notified.snapshot().state is MPIState.MOVING


def test_without_no_handshake_status_reads_moving_at_once(ctl, notified):
    assert notified.start(T.PT, A.NONE, MotionParams(**PATH)).ok
    assert notified.snapshot().state is MPIState.MOVING


def test_no_wait_answers_ok_for_what_the_controller_refuses(ctl, notified):
    # MPI 001, NO_WAIT: "Your application will NOT know if the move profile failed to start ...
    # your application should check for a MOTION_START and MOTION_DONE event"
    assert notified.start(T.PT, A.NONE, MotionParams(**PATH)).ok
    ctl.step(10)
    events(ctl)
    before = [a.cmd_p for a in ctl.axes]
    outcome, serial = notified.command(T.PT, A.NO_WAIT, MotionParams(position=[0.0, 0.0], time=[0.1]), False)
    message, detail = outcome.message, outcome.detail
    assert message is M.MPIMessageOK
    assert detail.startswith("NO_WAIT")
    assert serial == 0
    ctl.step(1)
    assert events(ctl) == []  # refused (MOVING): no MOTION_START
    assert all(abs(a.cmd_p - b) < 10.0 for a, b in zip(ctl.axes, before, strict=True))


def test_no_wait_still_answers_what_the_library_checks(ms):
    # MPI 000, MEIMotionMessageBAD_PATH_DATA: the MPI "will not load the move"
    bad = MotionParams(position=[float("nan"), 0.0], time=[0.1])
    assert ms.start(T.PT, A.NO_WAIT, bad).message is M.MEIMotionMessageBAD_PATH_DATA
    assert ms.start(T.S_CURVE, A.NO_WAIT, MotionParams(**PATH)).message is M.MPIMotionMessageATTRIBUTE_INVALID


def test_no_wait_that_starts_sends_motion_start(ctl, notified):
    outcome, serial = notified.command(T.PVT, A.NO_WAIT | A.NO_HANDSHAKE,
                                          MotionParams(**PATH, point_velocity=[0.0] * 4), False)
    message = outcome.message
    assert message is M.MPIMessageOK
    assert serial == 0
    assert notified.snapshot().state is MPIState.IDLE  # NO_WAIT includes NO_HANDSHAKE
    ctl.step(1)
    assert notified.state is MPIState.MOVING
    assert (0, "MOTION_START") in events(ctl)


def test_expected_axes_must_match_the_axis_count(ms):
    # MPI 001, EXPECTED_AXES: "checked against the number of currently mapped axes, and if they
    # don't match an error will result"
    answer = ms.start(T.PT, A.EXPECTED_AXES, MotionParams(**PATH, expected_axes=3))
    assert answer.message is M.MPIMotionMessageAXIS_COUNT
    assert ms.state is MPIState.IDLE
    assert ms.start(T.PT, A.EXPECTED_AXES, MotionParams(**PATH, expected_axes=2)).ok


def test_behavior_other_than_the_default_is_refused(ms):
    # MPI 001, BEHAVIOR "select a non-default behavior": none is documented
    assert ms.start(T.PT, A.BEHAVIOR, MotionParams(**PATH, behavior=1)).message is M.MPIMessagePARAM_INVALID
    assert ms.start(T.PT, A.BEHAVIOR, MotionParams(**PATH, behavior=0)).ok


def test_retain_is_refused_both_ways(ms):
    assert ms.start(T.PT, A.RETAIN, MotionParams(**PATH)).message is M.MPIMessageUNSUPPORTED
    assert ms.start(T.PT, A.NONE, MotionParams(**PATH, retain=True)).message is M.MPIMessageUNSUPPORTED
    assert ms.state is MPIState.IDLE


def test_relative_move_is_relative(ctl, ms):
    for axis in ms.axes:
        axis.set_command_position(500.0, ctl.time)
    assert ms.start(T.PT, A.RELATIVE_MOVE, MotionParams(position=[10.0, -10.0], time=[0.01])).ok
    ctl.run_until(lambda c: ms.state is MPIState.IDLE, 10_000)
    assert [a.command_position for a in ms.axes] == [510.0, 490.0]


@pytest.mark.parametrize(("low_count", "expected"), [(None, 32), (10, 10), (0, None)])
def test_low_count_sets_when_frames_low_is_sent(ctl, notified, low_count, expected):
    # MPI 001, LOW_COUNT: "the number of points below which to trigger the fetch ... LOW_COUNT
    # default is 32" (a quarter of the 128-frame buffer)
    n = 40
    params = MotionParams(position=list(np.arange(1.0, n + 1.0)), time=[0.01] * n, final=False, empty_count=0)
    attrs = A.NONE
    if low_count is not None:
        attrs, params.low_count = A.LOW_COUNT, low_count
    assert notified.axis_list_set([0]).ok
    assert notified.start(T.PT, attrs, params).ok
    start = ctl.sample
    ctl.step(n * 20 + 10)
    lows = [sample for sample, kind in events(ctl) if kind == "FRAMES_LOW"]
    if expected is None:
        assert lows == []
    else:  # fewer than `expected` points left once point n - expected is reached (20 samples each)
        assert lows == [start + (n - expected + 1) * 20]


def test_low_count_beyond_the_buffer_is_refused(ms):
    assert ms.start(T.PT, A.LOW_COUNT, MotionParams(**PATH, low_count=129)).message is M.MPIMessagePARAM_INVALID


@pytest.mark.parametrize("kind", [T.S_CURVE, T.VELOCITY, T.FRAME])
def test_path_attributes_are_refused_on_other_types(ms, params, kind):
    assert ms.start(kind, A.NO_WAIT, params()).message is M.MPIMotionMessageATTRIBUTE_INVALID


def test_ptf_feedforward_is_interpolated_held_and_kept(ctl, ms):
    # MPI 000, MPIMotionPTF: interpolated linearly over the intervals; "not set to zero at the
    # beginning of the move; they retain the last value"; "not zeroed by non-PTF or PVT moves"
    assert ms.axis_list_set([0]).ok
    assert ms.start(T.PTF, A.NONE, MotionParams(position=[100.0, 300.0], time=[0.1, 0.1],
                                                feedforward=[1000.0, -500.0])).ok
    seen = []
    for _ in range(8):
        ctl.step(50)
        seen.append(ctl.axis_snapshot(0).feedforward)
    assert seen[:4] == [250.0, 500.0, 750.0, 1000.0]
    assert seen[4:] == pytest.approx([625.0, 250.0, -125.0, -500.0], abs=1e-9)
    ctl.run_until(lambda c: ms.state is MPIState.IDLE, 10_000)
    assert ms.start(T.PT, A.NONE, MotionParams(position=[0.0], time=[0.05])).ok
    ctl.run_until(lambda c: ms.state is MPIState.IDLE, 10_000)
    assert ctl.axis_snapshot(0).feedforward == -500.0
    assert ms.start(T.PTF, A.NONE, MotionParams(position=[10.0], time=[0.1], feedforward=[500.0])).ok
    ctl.step(100)  # half way: from the -500 it held toward 500
    assert ctl.axis_snapshot(0).feedforward == pytest.approx(0.0, abs=1e-9)


def test_feedforward_of_appended_points_follows_on(ctl, ms):
    assert ms.axis_list_set([0]).ok
    assert ms.start(T.PVTF, A.NONE, MotionParams(position=[100.0], point_velocity=[0.0], time=[0.1],
                                                 feedforward=[200.0], final=False, empty_count=0)).ok
    ctl.step(100)
    assert ms.modify(T.PTF, A.APPEND, MotionParams(position=[200.0], time=[0.1], feedforward=[400.0])).ok
    ctl.step(100)
    assert ctl.axis_snapshot(0).feedforward == pytest.approx(200.0)  # the first point reached
    ctl.step(100)
    assert ctl.axis_snapshot(0).feedforward == pytest.approx(300.0)  # half way to the second
    assert ms.action(MPIAction.STOP).ok


def _ptf_run(ctl_factory, feedforward, batch):
    ctl = ctl_factory()
    _, ms = ctl.create_motion(0)
    assert ms.axis_list_set([0]).ok
    assert ms.action(MPIAction.MAP).ok
    assert ms.start(T.PTF, A.NONE, MotionParams(position=[200.0, 600.0], time=[0.2, 0.2],
                                                feedforward=feedforward)).ok
    actual = {}
    for _ in range(3000 // batch):
        ctl.step(batch)
        actual[ctl.sample] = (ctl.axes[0].act_p, ctl.axes[0].act_v)
    return ms, ctl, actual


def test_feedforward_drives_the_servo_and_holds_it_off_the_command():
    # MPI 000, MPIMotionPTF: feedforward "values for each PTF motion segment", in DAC counts: the
    # motor is pushed by them (PlantConfig.dac_acceleration counts/s^2 per DAC count), so the
    # actual position leaves the pure loop's, and a feedforward held after the move keeps the motor
    # off the resting command by K d / w^2 (the loop has no integrator).
    from mpi_ros.mpi import Controller

    _, _, plain = _ptf_run(Controller, [0.0, 0.0], 50)
    _ms, ctl, pushed = _ptf_run(Controller, [20_000.0, 20_000.0], 50)
    assert [plain[k] != pushed[k] for k in (100, 400, 700)] == [True] * 3  # along the path
    axis = ctl.axes[0]
    w = 2.0 * np.pi * axis.plant.config.bandwidth_hz
    offset = axis.plant.config.dac_acceleration * 20_000.0 / (w * w)
    assert axis.command_position == 600.0
    assert axis.act_p == pytest.approx(600.0 + offset, abs=0.5)  # the encoder reads whole counts
    assert plain[ctl.sample][0] == 600.0


@pytest.mark.parametrize("batch", [1, 10])
def test_feedforward_is_batching_invariant(batch):
    from mpi_ros.mpi import Controller

    _, _, reference = _ptf_run(Controller, [20_000.0, -5_000.0], 250)
    _, _, actual = _ptf_run(Controller, [20_000.0, -5_000.0], batch)
    assert {k: actual[k] for k in reference} == reference  # every 250th sample, 3 of them along the path


def test_a_held_path_takes_appended_points_and_runs_them_all_once_released(ctl, ms):
    # MPI 001, HOLD "Prevent the move from executing until a specific trigger condition is met";
    # points appended while it waits belong to the same path, which then runs whole.
    from mpi_ros.mpi.base.params import Hold
    from mpi_ros.mpi.base.types import HoldType

    hold = Hold(type=HoldType.GATE, gate=3)
    ctl.gate_set(3, True)
    path = MotionParams(position=[100.0, 0.0, 300.0, 50.0], time=[0.1, 0.2], hold=[hold, hold], final=False,
                        empty_count=0)
    assert ms.start(T.PT, A.HOLD, path).ok
    ctl.step(500)
    assert [a.cmd_p for a in ms.axes] == [0.0, 0.0]
    assert ms.state is MPIState.MOVING
    assert ms.modify(T.PT, A.APPEND, MotionParams(position=[400.0, 0.0], time=[0.1])).ok
    answer = ms.modify(T.PT, A.APPEND | A.HOLD, MotionParams(position=[0.0, 0.0], time=[0.1], hold=[hold, hold]))
    assert answer.message is M.MPIMotionMessageATTRIBUTE_INVALID
    assert ctl.gate_set(3, False).ok
    trace = []
    while ms.state is MPIState.MOVING and len(trace) < 2000:
        ctl.step(1)
        trace.append([a.cmd_p for a in ms.axes])
    assert trace[199] == pytest.approx([100.0, 0.0])
    assert trace[599] == pytest.approx([300.0, 50.0])
    assert trace[799] == pytest.approx([400.0, 0.0])  # the appended point, 0.1 s after the last
    steps = [abs(b[0] - a[0]) for a, b in itertools.pairwise(trace)]
    assert max(steps) <= 0.5 + 1e-9  # no jump anywhere


def test_a_modify_that_replaces_an_open_path_ends_its_appends(ctl, ms):
    # MPI 000, mpiMotionModify: a PVT modify replaces the path in progress, the points appended to
    # it included: their commands end (STOPPED, "replaced by a modify"), none is left waiting.
    open_path = MotionParams(position=[100.0, 0.0], point_velocity=[0.0, 0.0], time=[0.5], final=False,
                             empty_count=0)
    assert ms.start(T.PVT, A.NONE, open_path).ok
    outcome, appended = ms.command(T.PVT, A.APPEND, MotionParams(position=[200.0, 0.0], point_velocity=[0.0, 0.0],
                                                              time=[0.5], final=False, empty_count=0), True)
    ctl.step(100)
    replaced = MotionParams(position=[50.0, 50.0], point_velocity=[0.0, 0.0], time=[0.2])
    outcome, serial = ms.command(T.PVT, A.NONE, replaced, True)
    message = outcome.message
    assert message.ok
    assert serial != appended
    ends = {end.serial: (end.message, end.detail) for end in ctl.move_log.recent(ms.number)}
    assert ends[appended] == (M.MPIMotionMessageSTOPPED, "replaced by a modify")
    ctl.run_until(lambda c: ms.state is MPIState.IDLE, 10_000)
    assert [a.command_position for a in ms.axes] == [50.0, 50.0]
