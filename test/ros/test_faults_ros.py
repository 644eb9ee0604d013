"""Faults through ROS (docs/faults.md): the per-axis services /mpi/axis<k>/fault_inject,
fault_config_get and fault_config_set; each fault shows as its event on /mpi/events naming
the fault and the axis, in /mpi/axis<k>/status (faults, amp_enabled, state) and on
/diagnostics; RESET while it persists is refused with the reason in the answer, RESET once
it is cleared recovers. The status bytes with faults are still exactly convert.py's CDR."""

from __future__ import annotations

import dataclasses

import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from std_srvs.srv import Trigger

from mpi_ros.bag import cdr
from mpi_ros.mpi.base.types import MPIState
from mpi_ros.msg import AxisStatus, MotionEvent
from mpi_ros.ros import convert, wire
from mpi_ros.srv import AxisFaultConfigGet, AxisFaultConfigSet, AxisFaultInject, MotionAction

from .test_controller_node import Collector
from .test_wire import EPOCH, _controller

AGGRESSIVE = {"type": "S_CURVE", "position": [20_000.0, 0.0],
              "trajectory": [{"velocity": 100_000.0, "acceleration": 5e6, "deceleration": 5e6}]}


@pytest.fixture
def suite_config():
    """The default configuration with /diagnostics at 50 Hz of controller time (not 1 Hz), so
    the tests step a few hundred samples, not thousands, to see a fault there."""
    from mpi_ros import config

    return config.load(overrides={"ros": {"diagnostics_rate": 50.0}})


def test_axis_status_with_faults_is_packed_as_the_canonical_cdr():
    ctl = _controller()
    for names in ((), ("AMP_FAULT",), ("LIMIT_ERROR", "LIMIT_SW_POSITIVE", "FRAME_UNDERFLOW")):
        axes = tuple(dataclasses.replace(ctl.axis_snapshot(n), faults=names[: n + 1]) for n in range(3))
        for snap in axes:
            assert wire.axis_status(snap, ctl.rate, EPOCH) == cdr.serialize(convert.axis_status(snap, ctl.rate, EPOCH))
        # every alignment an AxisStatus starts at inside a MotionStatus
        motion = dataclasses.replace(ctl.supervisors[2].snapshot(), axes=axes, axis_numbers=(0, 1, 2))
        assert wire.motion_status(motion, ctl.rate, EPOCH) == cdr.serialize(
            convert.motion_status(motion, ctl.rate, EPOCH))


def _diagnostic(array: DiagnosticArray, name: str) -> DiagnosticStatus | None:
    return next((s for s in array.status if s.name == name), None)


def _level(status: DiagnosticStatus) -> int:
    return status.level[0] if isinstance(status.level, bytes) else status.level


def test_an_injected_amplifier_fault_shows_everywhere_and_recovers_with_reset(suite, client, probe, service, drive):
    events = Collector(probe, MotionEvent, "/mpi/events")
    status = Collector(probe, AxisStatus, "/mpi/axis1/status")
    diagnostics = Collector(probe, DiagnosticArray, "/diagnostics")
    answer = service(probe, AxisFaultInject, "/mpi/axis1/fault_inject", AxisFaultInject.Request(fault="AMP_FAULT"))
    assert (answer.message, list(answer.faults)) == ("MPIMessageOK", ["AMP_FAULT"])
    seen = events.wait_for(lambda ms: any(m.type == "ABORT" for m in ms))
    fault = next(m for m in seen if m.type == "AMP_FAULT")
    assert fault.axis == 1
    assert fault.supervisor == 0
    assert "AMP_FAULT" in fault.detail
    assert "axis 1" in fault.detail
    # diagnostics come at 1 Hz of controller time: step until one shows the fault
    drive(lambda: any(_faulted(a, "mpi/axis1") for a in diagnostics.messages), samples=20_000, chunk=100)
    entry = _diagnostic(next(a for a in diagnostics.messages if _faulted(a, "mpi/axis1")), "mpi/axis1")
    assert "AMP_FAULT" in entry.message
    assert {v.key: v.value for v in entry.values}["amp_enabled"] == "False"
    last = status.wait_for(lambda ms: ms and ms[-1].state_name == "ERROR")[-1]
    assert list(last.faults) == ["AMP_FAULT"]
    assert not last.amp_enabled

    refused = service(probe, MotionAction, "/mpi/ms0/action", MotionAction.Request(action="RESET"))
    assert refused.message == "MPIMotionMessageERROR"
    assert refused.state_name == "ERROR"
    assert "axis 1 AMP_FAULT persists" in refused.detail
    trigger = service(probe, Trigger, "/mpi/ms0/reset", Trigger.Request())
    assert not trigger.success
    assert "AMP_FAULT persists" in trigger.message
    reply = client.action("RESET", raise_on_error=False)  # the Python client carries the reason too
    assert reply.message == "MPIMotionMessageERROR"
    assert "axis 1 AMP_FAULT persists" in reply.detail

    cleared = service(probe, AxisFaultInject, "/mpi/axis1/fault_inject",
                      AxisFaultInject.Request(fault="AMP_FAULT", active=False))
    assert (cleared.message, list(cleared.faults)) == ("MPIMessageOK", ["AMP_FAULT"])  # latched until RESET
    reset = service(probe, MotionAction, "/mpi/ms0/action", MotionAction.Request(action="RESET"))
    assert (reset.message, reset.state_name, reset.detail) == ("MPIMessageOK", "IDLE", "")
    drive(lambda: status.messages and not status.messages[-1].faults and status.messages[-1].amp_enabled)
    drive(lambda: any(_healthy(a, "mpi/axis1") for a in diagnostics.messages[-1:]), samples=20_000, chunk=100)


@pytest.mark.parametrize(("fault", "state"), [
    ("LIMIT_ERROR", "ERROR"), ("LIMIT_SW_POSITIVE", "ERROR"), ("LIMIT_SW_NEGATIVE", "ERROR"),
    ("AMP_FAULT", "ERROR"), ("ENCODER_FAULT", "ERROR"), ("FRAME_UNDERFLOW", "IDLE")])
def test_each_fault_reaches_its_state_shows_in_status_and_diagnostics_and_recovers(
        suite, probe, service, drive, fault, state):
    """Injected on axis 3 (supervisor 1) with its default action: ABORT, E_STOP, E_STOP,
    ABORT, ABORT (MPI 002: "this axis will abort"), NONE."""
    events = Collector(probe, MotionEvent, "/mpi/events")
    status = Collector(probe, AxisStatus, "/mpi/axis3/status")
    diagnostics = Collector(probe, DiagnosticArray, "/diagnostics")
    answer = service(probe, AxisFaultInject, "/mpi/axis3/fault_inject", AxisFaultInject.Request(fault=fault))
    assert (answer.message, list(answer.faults)) == ("MPIMessageOK", [fault])
    trip = next(m for m in events.wait_for(lambda ms: any(m.type == fault for m in ms)) if m.type == fault)
    assert (trip.axis, trip.supervisor) == (3, 1)
    assert f"{fault} " in trip.detail
    assert "axis 3" in trip.detail
    def shown() -> bool:
        last = status.messages[-1] if status.messages else None
        return (last is not None and last.state_name == state and list(last.faults) == [fault]
                and any(_faulted(a, "mpi/axis3") for a in diagnostics.messages))

    drive(shown, samples=20_000, chunk=100)
    entry = _diagnostic(next(a for a in diagnostics.messages if _faulted(a, "mpi/axis3")), "mpi/axis3")
    assert fault in entry.message
    assert {v.key: v.value for v in entry.values}["faults"] == fault
    if fault in ("AMP_FAULT", "ENCODER_FAULT"):  # conditions that hold until cleared
        service(probe, AxisFaultInject, "/mpi/axis3/fault_inject", AxisFaultInject.Request(fault=fault, active=False))
    reset = service(probe, MotionAction, "/mpi/ms1/action", MotionAction.Request(action="RESET"))
    assert (reset.message, reset.state_name) == ("MPIMessageOK", "IDLE")
    drive(lambda: status.messages and not status.messages[-1].faults and status.messages[-1].state_name == "IDLE")


def _faulted(array: DiagnosticArray, name: str) -> bool:
    entry = _diagnostic(array, name)
    return entry is not None and _level(entry) == DiagnosticStatus.ERROR[0] and "fault" in entry.message


def _healthy(array: DiagnosticArray, name: str) -> bool:
    entry = _diagnostic(array, name)
    return entry is not None and _level(entry) == DiagnosticStatus.OK[0]


def _get_config(probe, service, axis: int):
    answer = service(probe, AxisFaultConfigGet, f"/mpi/axis{axis}/fault_config_get", AxisFaultConfigGet.Request())
    assert answer.message == "MPIMessageOK"
    return answer.config


def _set_config(probe, service, axis: int, config, **fields):
    for key, value in fields.items():
        setattr(config, key, value)
    request = AxisFaultConfigSet.Request(config=config)
    return service(probe, AxisFaultConfigSet, f"/mpi/axis{axis}/fault_config_set", request)


def test_a_following_error_configured_by_service_ends_the_goal_in_error(suite, client, probe, service, drive):
    current = _get_config(probe, service, 0)
    assert current.encoder_fault_motor_number == 0  # its own motor by default
    answer = _set_config(probe, service, 0, current, following_error_limit=100.0, following_error_action="E_STOP")
    assert answer.message == "MPIMessageOK"
    got = _get_config(probe, service, 0)
    assert (got.following_error_limit, got.following_error_action) == (100.0, "E_STOP")

    events = Collector(probe, MotionEvent, "/mpi/events")
    goal = client.start(AGGRESSIVE)
    drive(lambda: goal.done)
    result = goal.wait(raise_on_error=False)
    assert result.message == "MPIMotionMessageERROR"
    assert result.state_name == "ERROR"
    trip = next(m for m in events.wait_for(lambda ms: any(m.type == "LIMIT_ERROR" for m in ms))
                if m.type == "LIMIT_ERROR")
    assert trip.axis == 0
    assert "following error" in trip.detail
    assert "E_STOP" in trip.detail
    assert suite.runner.read(lambda ctl: ctl.supervisor(0).state) is MPIState.ERROR
    reset = service(probe, MotionAction, "/mpi/ms0/action", MotionAction.Request(action="RESET"))
    assert reset.message == "MPIMessageOK"


def test_bad_fault_requests_are_refused_with_a_clear_message(suite, probe, service):
    answer = service(probe, AxisFaultInject, "/mpi/axis0/fault_inject", AxisFaultInject.Request(fault="MELTDOWN"))
    assert answer.message == "MPIMessagePARAM_INVALID"
    assert "unknown fault" in answer.detail
    answer = _set_config(probe, service, 2, _get_config(probe, service, 2), amp_fault_action="SHRUG")
    assert answer.message == "MPIMessagePARAM_INVALID"
    assert "amp_fault_action" in answer.detail
    assert _get_config(probe, service, 2).amp_fault_action == "ABORT"  # unchanged
    assert suite.runner.read(lambda ctl: (ctl.supervisor(0).state, ctl.supervisor(1).state)) == (
        MPIState.IDLE, MPIState.IDLE)
