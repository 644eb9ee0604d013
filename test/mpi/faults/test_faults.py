"""Faults of an axis (mpi_ros/mpi/faults/monitor.py, docs/faults.md): each trips at the sample its
condition becomes true, emits its event naming the fault and the axis, latches in the axis'
status, takes its action (MPI 000, mpiMotionAction: E_STOP / ABORT / E_STOP_ABORT to
MPIStateERROR), refuses RESET while its condition holds and is cleared by RESET once it
does not. The servo model makes the following error real: a move too aggressive for the
loop's bandwidth trips it, a gentle one does not. Everything steps by samples."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mpi_ros.commands import Command, apply
from mpi_ros.mpi import Controller, MotionParams, MPIAction, MPIMotionType, MPIState, Trajectory
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import Outcome
from mpi_ros.mpi.base.params import AxisFaultConfig
from mpi_ros.mpi.faults.monitor import Fault, error_samples

GENTLE = Trajectory(4000.0, 20000.0, 20000.0, 0.0)  # about 4 counts of following error at 30 Hz
AGGRESSIVE = Trajectory(100_000.0, 5e6, 5e6, 0.0)  # about 190 counts
LIMIT = 100.0


def fault_events(ctl: Controller) -> list:
    kinds = {fault.event for fault in Fault}
    return [e for e in ctl.drain_events() if e.type in kinds]


def start(ms, position, trajectory=GENTLE, **fields) -> None:
    assert ms.start(MPIMotionType.S_CURVE, params=MotionParams(trajectory=[trajectory], position=list(position),
                                                               **fields)).ok


def configure(ctl: Controller, axis: int, **fields) -> None:
    _, config = ctl.axis_fault_config_get(axis)
    for key, value in fields.items():
        setattr(config, key, value)
    verdict = ctl.axis_fault_config_set(axis, config)
    assert verdict.ok, verdict.detail


def _split(outcome: Outcome) -> tuple[Message, str]:
    return outcome.message, outcome.detail


def reset(ms) -> Outcome:
    return ms.action(MPIAction.RESET)


# -- following error ------------------------------------------------------------------------
def test_a_gentle_move_does_not_trip_the_following_error(ctl, ms, run_to):
    configure(ctl, 0, following_error_limit=LIMIT)
    start(ms, (20_000.0, 0.0))
    run_to(ctl, ms, MPIState.IDLE, chunk=50)
    assert fault_events(ctl) == []
    assert ctl.faults.names(0) == ()


def test_a_move_too_aggressive_for_the_bandwidth_trips_at_the_exact_sample(ctl, ms, run_to):
    """The sample it trips at is the first at which |command - actual| has been above the
    limit for the configured time, computed from a run of the same move without the limit."""
    free = Controller()
    _, free_ms = free.create_motion(0)
    free_ms.axis_list_set([0, 1])
    free_ms.action(MPIAction.MAP)
    start(free_ms, (20_000.0, 0.0), AGGRESSIVE)
    errors = []
    for _ in range(400):
        free.step(1)
        errors.append(abs(free.axes[0].position_error))
    configure(ctl, 0, following_error_limit=LIMIT, following_error_time=0.002)
    need = error_samples(ctl.faults.axes[0].config, ctl.rate)
    assert need == 5
    above = np.array(errors) > LIMIT
    expected = next(i for i in range(len(above)) if above[max(0, i - need + 1): i + 1].sum() == need) + 1

    start(ms, (20_000.0, 0.0), AGGRESSIVE)
    run_to(ctl, ms, MPIState.ERROR, chunk=50)
    events = ctl.drain_events()
    trip = next(e for e in events if e.type is MPIEventType.LIMIT_ERROR)
    assert trip.sample == expected
    assert trip.axis == 0
    assert trip.supervisor == 0
    assert "LIMIT_ERROR" in trip.detail
    assert "axis 0" in trip.detail
    assert "ABORT" in trip.detail
    # the default action ABORT follows at the same sample: amplifiers off, ERROR next sample
    abort = next(e for e in events if e.type is MPIEventType.ABORT)
    assert abort.sample == trip.sample
    assert events.index(abort) > events.index(trip)
    snap = ctl.axis_snapshot(0)
    assert snap.faults == ("LIMIT_ERROR",)
    assert not snap.amp_enabled
    assert ms.last_action == "ABORT"
    assert ms.action_source.value == "CONTROLLER"
    # with the amplifier off RESET sets the command to the actual: nothing persists
    assert reset(ms) == Outcome(Message.MPIMessageOK)
    assert ms.state is MPIState.IDLE
    assert ctl.axis_snapshot(0).faults == ()
    assert ctl.axes[0].amp_enabled


def test_a_following_error_that_persists_refuses_reset_until_the_loop_removes_it(ctl, ms, run_to):
    configure(ctl, 0, following_error_limit=LIMIT, following_error_action="E_STOP")
    start(ms, (20_000.0, 0.0), AGGRESSIVE)
    run_to(ctl, ms, MPIState.ERROR, chunk=50)
    assert ctl.faults.names(0) == ("LIMIT_ERROR",)
    assert ctl.axes[0].amp_enabled
    # a disturbance pushes the motor 5000 counts off its command (the loop works on it)
    assert ctl.axis_actual_position_set(0, ctl.axes[0].actual_position + 5000.0).ok
    message, detail = _split(reset(ms))
    assert message is Message.MPIMotionMessageERROR
    assert ms.state is MPIState.ERROR
    assert "RESET refused" in detail
    assert "axis 0 LIMIT_ERROR persists" in detail
    assert "following error" in detail
    assert ctl.run_until(lambda c: abs(c.axes[0].position_error) < LIMIT, 20_000, chunk=20)
    assert reset(ms).message is Message.MPIMessageOK
    assert ctl.faults.names(0) == ()


def test_following_error_action_none_reports_and_keeps_moving(ctl, ms):
    configure(ctl, 0, following_error_limit=LIMIT, following_error_action="NONE")
    start(ms, (20_000.0, 0.0), AGGRESSIVE)
    ctl.step(200)
    [trip] = fault_events(ctl)
    assert trip.type is MPIEventType.LIMIT_ERROR
    assert ms.state is MPIState.MOVING
    assert ctl.axis_snapshot(0).faults == ("LIMIT_ERROR",)


# -- software limits ------------------------------------------------------------------------
@pytest.mark.parametrize(("fault", "target", "limit"), [
    (Fault.LIMIT_SW_POSITIVE, 10_000.0, 5000.0), (Fault.LIMIT_SW_NEGATIVE, -10_000.0, -5000.0)])
def test_a_software_limit_trips_where_the_actual_position_crosses_it(ctl, ms, run_to, fault, target, limit):
    side = "positive" if fault is Fault.LIMIT_SW_POSITIVE else "negative"
    configure(ctl, 0, **{f"software_limit_{side}_enabled": True, f"software_limit_{side}": limit})
    start(ms, (target, 0.0))
    assert ctl.run_until(lambda c: c.faults.names(0), 20_000, chunk=50)
    [trip] = fault_events(ctl)
    # the same move without the limit: inside it one sample before, beyond it at the trip
    free = Controller()
    _, free_ms = free.create_motion(0)
    free_ms.axis_list_set([0, 1])
    free_ms.action(MPIAction.MAP)
    start(free_ms, (target, 0.0))
    free.step(trip.sample - 1)
    before = free.axes[0].actual_position
    free.step(1)
    beyond = (lambda p: p > limit) if limit > 0 else (lambda p: p < limit)
    assert beyond(free.axes[0].actual_position)
    assert not beyond(before)
    assert trip.type is fault.event
    assert trip.axis == 0
    assert fault.value in trip.detail
    assert "E_STOP" in trip.detail
    assert ms.state is MPIState.STOPPING_ERROR
    assert ms.last_action == "E_STOP"
    run_to(ctl, ms, MPIState.ERROR, chunk=50)
    # beyond the limit after the E_STOP's deceleration: RESET is refused, saying why
    message, detail = _split(reset(ms))
    assert message is Message.MPIMotionMessageERROR
    assert f"axis 0 {fault.value} persists" in detail
    assert ms.state is MPIState.ERROR
    assert ctl.faults.names(0) == (fault.value,)
    # the limit moved out of the way (as an operator overrides it to drive back): cleared
    configure(ctl, 0, **{f"software_limit_{side}": 2 * target})
    assert reset(ms).message is Message.MPIMessageOK
    assert ctl.faults.names(0) == ()
    assert ms.state is MPIState.IDLE


def test_a_software_limit_is_recovered_by_driving_back_inside(ctl, ms, run_to):
    """Another way out: after an E_STOP the servo holds; the command set back inside the
    limit (mpiAxisCommandPositionSet, allowed in ERROR) and the loop brings the motor there."""
    configure(ctl, 0, software_limit_positive_enabled=True, software_limit_positive=5000.0)
    start(ms, (10_000.0, 0.0))
    run_to(ctl, ms, MPIState.ERROR, chunk=50)
    assert reset(ms).message is Message.MPIMotionMessageERROR
    assert ctl.axis_command_position_set(0, 4000.0).ok
    assert ctl.run_until(lambda c: c.axes[0].actual_position <= 5000.0, 20_000, chunk=20)
    assert reset(ms).message is Message.MPIMessageOK
    assert ms.state is MPIState.IDLE


# -- amplifier fault ------------------------------------------------------------------------
def test_an_amplifier_fault_disables_the_amplifier_and_aborts(ctl, ms, run_to):
    start(ms, (0.0, 20_000.0))
    ctl.step(400)
    assert ctl.axis_fault_inject(1, "AMP_FAULT", True) == Outcome(Message.MPIMessageOK)
    [trip] = fault_events(ctl)
    assert trip.type is MPIEventType.AMP_FAULT
    assert trip.axis == 1
    assert "AMP_FAULT" in trip.detail
    assert not ctl.axes[1].amp_enabled
    assert ctl.axis_snapshot(1).faults == ("AMP_FAULT",)
    run_to(ctl, ms, MPIState.ERROR, chunk=50)
    # the motor coasts to rest
    velocity = abs(ctl.axes[1].act_v)
    ctl.step(400)
    assert abs(ctl.axes[1].act_v) < velocity / 2
    message, detail = _split(reset(ms))
    assert message is Message.MPIMotionMessageERROR
    assert "axis 1 AMP_FAULT persists" in detail
    assert ctl.axis_fault_inject(1, "AMP_FAULT", False).message.ok
    assert ctl.axis_snapshot(1).faults == ("AMP_FAULT",)  # latched until the RESET
    assert reset(ms).message is Message.MPIMessageOK
    assert ctl.axes[1].amp_enabled
    assert ctl.axes[1].command_position == ctl.axes[1].actual_position
    assert ctl.axis_snapshot(1).faults == ()
    assert ms.state is MPIState.IDLE


def test_an_amplifier_fault_with_action_none_lets_the_motor_coast_behind_its_command(ctl, ms):
    configure(ctl, 1, amp_fault_action="NONE")
    start(ms, (0.0, 20_000.0))
    ctl.step(400)
    assert ctl.axis_fault_inject(1, "AMP_FAULT", True).message.ok
    ctl.step(400)
    axis = ctl.axes[1]
    assert ms.state is MPIState.MOVING
    assert not axis.amp_enabled
    assert axis.cmd_v > 1000.0
    assert abs(axis.act_v) < axis.cmd_v / 2
    # RESET is refused in MOVING (the state table), and stays refused with the fault active
    assert reset(ms).message is Message.MPIMotionMessageMOVING


def test_reset_in_idle_clears_a_latched_amplifier_fault(ctl, ms):
    configure(ctl, 0, amp_fault_action="NONE")
    assert ctl.axis_fault_inject(0, "AMP_FAULT", True).message.ok
    assert ms.state is MPIState.IDLE
    assert not ctl.axes[0].amp_enabled
    assert reset(ms).message is Message.MPIMotionMessageERROR  # refused: it persists
    assert ctl.axis_fault_inject(0, "AMP_FAULT", False).message.ok
    assert reset(ms).message is Message.MPIMessageOK
    assert ctl.axes[0].amp_enabled
    assert ctl.faults.names(0) == ()


# -- encoder fault --------------------------------------------------------------------------
def test_an_encoder_fault_aborts_every_axis_that_watches_that_motor(ctl, ms, ms1, run_to):
    """MPI 002, MPIAxisMaster, encoderFaultMotorNumber: "If this motor detects an encoder
    fault this axis will abort. A value of -1 disables this encoder fault function." Axis 2
    watches motor 0; axis 1 has it disabled."""
    configure(ctl, 2, encoder_fault_motor_number=0)
    configure(ctl, 1, encoder_fault_motor_number=-1)
    assert ctl.axis_fault_inject(0, "ENCODER_FAULT", True).message.ok
    trips = fault_events(ctl)
    assert [(e.type, e.axis, e.supervisor) for e in trips] == [
        (MPIEventType.ENCODER_FAULT, 0, 0), (MPIEventType.ENCODER_FAULT, 2, 1)]
    assert all("ABORT" in e.detail and "motor 0" in e.detail for e in trips)
    run_to(ctl, ms, MPIState.ERROR, chunk=50)
    run_to(ctl, ms1, MPIState.ERROR, chunk=50)
    assert ms.last_action == ms1.last_action == "ABORT"
    assert ctl.axis_fault_inject(1, "ENCODER_FAULT", True).message.ok
    assert fault_events(ctl) == []  # motor 1's encoder: axis 1 has the function disabled
    assert "axis 2 ENCODER_FAULT persists" in reset(ms1).detail
    assert ctl.axis_fault_inject(0, "ENCODER_FAULT", False).message.ok
    assert reset(ms1).message.ok
    assert reset(ms).message.ok
    assert ms.state is ms1.state is MPIState.IDLE


# -- frame buffer underflow -----------------------------------------------------------------
def _open_path(ms, empty_count: int) -> None:
    positions = [float(x) for i in range(1, 9) for x in (i * 100.0, 0.0)]
    assert ms.start(MPIMotionType.PT, params=MotionParams(position=positions, time=[0.01] * 8, final=False,
                                                           empty_count=empty_count)).ok


def test_a_stream_that_runs_dry_trips_frame_underflow_and_its_action(ctl, ms, run_to):
    for axis in (0, 1):
        configure(ctl, axis, frame_underflow_action="E_STOP")
    _open_path(ms, empty_count=0)  # the emptyCount E_STOP disabled: the buffer can run dry
    run_to(ctl, ms, MPIState.ERROR, chunk=50)
    trips = fault_events(ctl)
    assert [(e.type, e.axis) for e in trips] == [(MPIEventType.FRAME_UNDERFLOW, 0), (MPIEventType.FRAME_UNDERFLOW, 1)]
    assert ms.last_action == "E_STOP"
    assert ctl.faults.names(0) == ("FRAME_UNDERFLOW",)
    assert reset(ms).message is Message.MPIMessageOK
    assert ctl.faults.names(0) == ctl.faults.names(1) == ()


def test_the_default_underflow_action_none_rests_on_the_last_point_and_reports_it(ctl, ms):
    _open_path(ms, empty_count=0)
    ctl.step(400)
    kinds = [(e.type, e.axis) for e in fault_events(ctl)]
    assert kinds == [(MPIEventType.FRAME_UNDERFLOW, 0), (MPIEventType.FRAME_UNDERFLOW, 1)]
    assert ms.state is MPIState.MOVING
    assert ctl.axes[0].command_position == 800.0


def test_the_empty_count_e_stop_comes_before_an_underflow(ctl, ms, run_to):
    """With emptyCount on (MPI 000, MPIMotionPoint), the E_STOP happens while points are left:
    the buffer never runs dry while MOVING, so no underflow trips."""
    configure(ctl, 0, frame_underflow_action="ABORT")
    _open_path(ms, empty_count=5)
    run_to(ctl, ms, MPIState.ERROR, chunk=50)
    assert fault_events(ctl) == []
    assert ms.last_action == "E_STOP"


# -- injection and configuration --------------------------------------------------------------
@pytest.mark.parametrize("fault", [Fault.LIMIT_ERROR, Fault.LIMIT_SW_POSITIVE, Fault.LIMIT_SW_NEGATIVE,
                                   Fault.FRAME_UNDERFLOW])
def test_a_detected_fault_can_be_injected_as_a_one_off_trip(ctl, ms, run_to, fault):
    configure(ctl, 1, **{"following_error_action" if fault is Fault.LIMIT_ERROR else
                         f"software_limit_{fault.value[9:].lower()}_action" if "SW" in fault.value else
                         "frame_underflow_action": "E_STOP_ABORT"})
    assert ctl.axis_fault_inject(1, fault.value.lower(), True).ok
    [trip] = fault_events(ctl)
    assert trip.type is fault.event
    assert trip.axis == 1
    assert "injected" in trip.detail
    run_to(ctl, ms, MPIState.ERROR, chunk=50)
    assert ms.last_action == "E_STOP_ABORT"
    assert not ctl.axes[1].amp_enabled
    assert reset(ms).message.ok
    assert ctl.faults.names(1) == ()


def test_bad_injections_are_refused_and_change_nothing(ctl, ms):
    message, detail = _split(ctl.axis_fault_inject(0, "OVERHEAT", True))
    assert message is Message.MPIMessagePARAM_INVALID
    assert "unknown fault 'OVERHEAT'" in detail
    message, detail = _split(ctl.axis_fault_inject(0, "LIMIT_ERROR", False))
    assert message is Message.MPIMessagePARAM_INVALID
    assert "trips once" in detail
    assert ctl.axis_fault_inject(9, "AMP_FAULT", True).message is Message.MPIAxisMessageAXIS_INVALID
    assert ctl.drain_events() == []
    assert ms.state is MPIState.IDLE
    assert ctl.faults.names(0) == ()


@pytest.mark.parametrize(("fields", "named"), [
    ({"following_error_limit": -1.0}, "following_error_limit"),
    ({"following_error_limit": math.nan}, "following_error_limit"),
    ({"following_error_action": "STOP"}, "following_error_action"),
    ({"software_limit_positive_enabled": True, "software_limit_positive": 0.0,
      "software_limit_negative_enabled": True, "software_limit_negative": 10.0}, "software_limit_negative"),
    ({"software_limit_positive_enabled": True, "software_limit_positive": 2.0**31,
      "software_limit_negative_enabled": True, "software_limit_negative": -(2.0**31)}, "4,294,967,296"),
    ({"encoder_fault_motor_number": 4}, "motor 4 does not exist"),
    ({"encoder_fault_motor_number": -2}, "encoder_fault_motor_number"),
])
def test_a_bad_fault_configuration_is_refused_naming_the_field(ctl, fields, named):
    before = ctl.axis_fault_config_get(0)[1]
    config = AxisFaultConfig(**{**{k: getattr(before, k) for k in before.__slots__}, **fields})
    verdict = ctl.axis_fault_config_set(0, config)
    assert verdict.message is Message.MPIMessagePARAM_INVALID
    assert named in verdict.detail
    assert ctl.axis_fault_config_get(0)[1] == before


def test_the_defaults_watch_only_the_own_encoder():
    ctl = Controller()
    configs = [ctl.axis_fault_config_get(n)[1] for n in range(4)]
    assert [c.encoder_fault_motor_number for c in configs] == [0, 1, 2, 3]
    assert all(c.following_error_limit == 0.0 and not c.software_limit_positive_enabled for c in configs)
    assert [c.amp_fault_action for c in configs] == ["ABORT"] * 4


def test_commands_inject_and_configure_with_partial_requests(ctl, ms):
    """The recorded commands (what /mpi/commands carries and replay applies): a partial
    configuration keeps the other fields; action names in any case."""
    reply = apply(ctl, Command("axis_fault_config_set", axis=0,
                               request={"config": {"following_error_limit": 50.0, "following_error_action": "e_stop"}}))
    assert reply.message.ok
    config = ctl.axis_fault_config_get(0)[1]
    assert (config.following_error_limit, config.following_error_action, config.encoder_fault_motor_number) == (
        50.0, "E_STOP", 0)
    reply = apply(ctl, Command("axis_fault_config_set", axis=0, request={"config": {"amp_fault_action": "HALT"}}))
    assert reply.message is Message.MPIMessagePARAM_INVALID
    assert "amp_fault_action" in reply.detail
    reply = apply(ctl, Command("axis_fault_inject", axis=0, request={"fault": "AMP_FAULT"}))
    assert reply.message.ok
    assert reply.value == ["AMP_FAULT"]
    reply = apply(ctl, Command("axis_fault_inject", axis=0, request={"fault": 3}))
    assert reply.message is Message.MPIMessagePARAM_INVALID


# -- batching ---------------------------------------------------------------------------------
def _faulty_run(batch: int) -> tuple[list, np.ndarray]:
    """Every fault that trips while stepping, stepped in batches of ``batch`` samples."""
    ctl = Controller()
    ms = []
    for number, axes in ((0, [0, 1]), (1, [2, 3])):
        _, supervisor = ctl.create_motion(number)
        supervisor.axis_list_set(axes)
        supervisor.action(MPIAction.MAP)
        ms.append(supervisor)
    configure(ctl, 0, following_error_limit=LIMIT, following_error_time=0.003, following_error_action="E_STOP")
    configure(ctl, 2, software_limit_positive_enabled=True, software_limit_positive=3000.0)
    configure(ctl, 3, frame_underflow_action="NONE")
    script = {
        0: lambda: start(ms[0], (20_000.0, 0.0), AGGRESSIVE),
        3: lambda: start(ms[1], (6000.0, 0.0)),
        1500: lambda: (reset(ms[0]), reset(ms[1])),
        1600: lambda: start(ms[0], (0.0, 3000.0)),
        1700: lambda: ctl.axis_fault_inject(1, "AMP_FAULT", True),
        2600: lambda: (ctl.axis_fault_inject(1, "AMP_FAULT", False), reset(ms[0])),
    }
    positions = []
    end = 4000
    while ctl.sample < end:
        action = script.get(ctl.sample)
        if action is not None:
            action()
        upcoming = [k for k in script if k > ctl.sample] + [end, (ctl.sample // 500 + 1) * 500]
        ctl.step(min(batch, min(upcoming) - ctl.sample))
        if ctl.sample % 500 == 0:
            positions.append([ctl.sample, *(a.act_p for a in ctl.axes), *(a.cmd_p for a in ctl.axes)])
    events = [(e.sample, e.type, e.supervisor, e.axis, e.detail) for e in ctl.drain_events()]
    return events, np.array(positions)


def test_faults_trip_at_the_same_samples_however_the_samples_are_batched():
    one, one_positions = _faulty_run(7)
    many, many_positions = _faulty_run(10_000)
    tripped = {kind for _, kind, *_ in one}
    assert {MPIEventType.LIMIT_ERROR, MPIEventType.LIMIT_SW_POSITIVE, MPIEventType.AMP_FAULT} <= tripped
    assert one == many
    assert np.array_equal(one_positions, many_positions)
