"""Axis and motion calls through ROS (docs/decisions.md, "Supervisors and axes"):
/mpi/axis<k>/amp_enable_set (MPI 000, MPIMessageOBJECT_NOT_ENABLED), /mpi/axis<k>/event_notify_get,
event_notify_set and event_reset (MPI 002, mpiAxisEventNotifyGet/Set, mpiAxisEventReset, with the
motion's srv types), /mpi/ms<n>/params_validate (MPI 000, meiMotionParamsValidate) and
MPIAxisMaster.encoderFaultMotorNumber in /mpi/axis<k>/config_get and config_set."""

from __future__ import annotations

import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

from mpi_ros.mpi.base.types import MPIState
from mpi_ros.msg import AxisStatus, MotionEvent
from mpi_ros.msg import MotionParams as MotionParamsMsg
from mpi_ros.msg import Trajectory as TrajectoryMsg
from mpi_ros.srv import (
    AmpEnableSet,
    AxisConfigGet,
    AxisConfigSet,
    EventNotifyGet,
    EventNotifySet,
    EventReset,
    MotionParamsValidate,
)

from .test_controller_node import Collector


@pytest.fixture
def suite_config():
    """/diagnostics at 50 Hz of controller time, so a few hundred samples show a change there."""
    from mpi_ros import config

    return config.load(overrides={"ros": {"diagnostics_rate": 50.0}})


MOVE = {"type": "TRAPEZOIDAL", "position": [400.0, 200.0],
        "trajectory": [{"velocity": 4000.0, "acceleration": 40_000.0, "deceleration": 40_000.0}]}


def test_a_disabled_axis_refuses_a_start_and_shows_its_amplifier_off(suite, client, probe, service, drive):
    status = Collector(probe, AxisStatus, "/mpi/axis1/status")
    answer = service(probe, AmpEnableSet, "/mpi/axis1/amp_enable_set", AmpEnableSet.Request(enable=False))
    assert (answer.message, answer.enabled) == ("MPIMessageOK", False)
    goal = client.start(MOVE)
    drive(lambda: goal.done)
    assert goal.wait(raise_on_error=False).message == "MPIMessageOBJECT_NOT_ENABLED"
    drive(lambda: bool(status.messages) and not status.messages[-1].amp_enabled, samples=2_000)
    diagnostics = Collector(probe, DiagnosticArray, "/diagnostics")
    drive(lambda: any(_says_disabled(a) for a in diagnostics.messages), samples=2_000)
    assert suite.runner.read(lambda ctl: ctl.axis_snapshot(0).command_position) == 0.0  # nothing moved
    answer = service(probe, AmpEnableSet, "/mpi/axis1/amp_enable_set", AmpEnableSet.Request(enable=True))
    assert (answer.message, answer.enabled) == ("MPIMessageOK", True)
    goal = client.start(MOVE)
    drive(lambda: goal.done)
    assert goal.wait(raise_on_error=False).message == "MPIMessageOK"


def test_disabling_a_moving_axis_aborts_its_motion(suite, client, probe, service, drive):
    goal = client.start({**MOVE, "position": [400_000.0, 0.0]})
    drive(lambda: suite.runner.read(lambda ctl: ctl.supervisor(0).state) is MPIState.MOVING)
    answer = service(probe, AmpEnableSet, "/mpi/axis0/amp_enable_set", AmpEnableSet.Request(enable=False))
    assert answer.message == "MPIMessageOK"
    assert "ABORT" in answer.detail
    drive(lambda: goal.done)
    assert goal.wait(raise_on_error=False).state_name == "ERROR"


def test_an_axis_event_mask_notifies_on_the_events_topic(suite, client, probe, service, drive):
    assert service(probe, EventNotifySet, "/mpi/ms0/event_notify_set",
                   EventNotifySet.Request(event_types=["MOTION_DONE"])).message == "MPIMessageOK"
    answer = service(probe, EventNotifySet, "/mpi/axis1/event_notify_set", EventNotifySet.Request(event_types=["DONE"]))
    assert answer.message == "MPIMessageOK"
    got = service(probe, EventNotifyGet, "/mpi/axis1/event_notify_get", EventNotifyGet.Request())
    assert (got.message, list(got.event_types)) == ("MPIMessageOK", ["DONE"])
    events = Collector(probe, MotionEvent, "/mpi/events")
    goal = client.start(MOVE)
    drive(lambda: goal.done)
    seen = events.wait_for(lambda ms: any(m.type == "DONE" for m in ms) and any(m.type == "MOTION_DONE" for m in ms))
    assert sorted({(m.type, m.axis) for m in seen}) == [("DONE", 1), ("MOTION_DONE", -1)]
    reset = service(probe, EventReset, "/mpi/axis1/event_reset", EventReset.Request(event_types=["DONE"]))
    assert reset.message == "MPIMessageOK"
    assert "DONE" not in reset.latched_event_types
    assert "SETTLED" in reset.latched_event_types or "AT_TARGET" in reset.latched_event_types


def test_params_validate_answers_as_a_start_without_moving(suite, probe, service):
    params = MotionParamsMsg(position=[100.0], trajectory=[TrajectoryMsg(velocity=10.0, acceleration=100.0,
                                                                         deceleration=100.0)])
    bad = service(probe, MotionParamsValidate, "/mpi/ms0/params_validate",
                  MotionParamsValidate.Request(type="TRAPEZOIDAL", params=params))
    assert bad.message == "MPIMessagePARAM_INVALID"
    assert bad.detail
    params.position = [100.0, 0.0]
    good = service(probe, MotionParamsValidate, "/mpi/ms0/params_validate",
                   MotionParamsValidate.Request(type="TRAPEZOIDAL", params=params))
    assert (good.message, good.points) == ("MPIMessageOK", 0)
    path = MotionParamsMsg(position=[1.0, 0.0, 2.0, 0.0], time=[0.1, 0.1])
    answer = service(probe, MotionParamsValidate, "/mpi/ms0/params_validate",
                     MotionParamsValidate.Request(type="PT", params=path))
    assert (answer.message, answer.points) == ("MPIMessageOK", 2)
    unknown = service(probe, MotionParamsValidate, "/mpi/ms0/params_validate",
                      MotionParamsValidate.Request(type="WIGGLE", params=path))
    assert unknown.message == "MPIMotionMessageTYPE_INVALID"
    assert suite.runner.read(lambda ctl: (ctl.supervisor(0).state, ctl.axis_snapshot(0).command_position)) == (
        MPIState.IDLE, 0.0)


def test_the_axis_master_carries_the_encoder_fault_motor(suite, probe, service):
    got = service(probe, AxisConfigGet, "/mpi/axis2/config_get", AxisConfigGet.Request())
    assert got.master.encoder_fault_motor_number == 2
    request = AxisConfigSet.Request(in_position=got.in_position, master=got.master,
                                    master_correction=got.master_correction)
    request.master.encoder_fault_motor_number = 0
    assert service(probe, AxisConfigSet, "/mpi/axis2/config_set", request).message == "MPIMessageOK"
    assert suite.runner.read(lambda ctl: ctl.axis_fault_config_get(2)[1].encoder_fault_motor_number) == 0
    request.master.encoder_fault_motor_number = 9
    assert service(probe, AxisConfigSet, "/mpi/axis2/config_set", request).message == "MPIMessagePARAM_INVALID"
    assert service(probe, AxisConfigGet, "/mpi/axis2/config_get",
                   AxisConfigGet.Request()).master.encoder_fault_motor_number == 0


def _says_disabled(array: DiagnosticArray) -> bool:
    """/diagnostics shows axis 1 disabled by the host: a warning that names the service, not an ABORT."""
    entry = next((s for s in array.status if s.name == "mpi/axis1"), None)
    return entry is not None and entry.level == DiagnosticStatus.WARN and "amp_enable_set" in entry.message
