"""The client's typed surface, without a suite: its names agree with the controller's
(messages and codes, event types, states), goals are filled from YAML-like data with the
types checked at the edge, messages become plain data, and goal outcomes are classified.
The client and mpi_ros.errors must import nothing of the simulated controller."""

from __future__ import annotations

import subprocess
import sys
from types import SimpleNamespace

import pytest

from mpi_ros import errors
from mpi_ros.client import (
    Action,
    EventType,
    MotionResult,
    MotionType,
    Outcome,
    State,
    fill,
    message_class,
    message_to_dict,
)
from mpi_ros.mpi.events import MPIEventType
from mpi_ros.mpi.messages import Message
from mpi_ros.mpi.types import MPIState


def test_one_exception_class_per_message_with_the_same_name_and_code():
    expected = {m.name: m.code for m in Message if m is not Message.MPIMessageOK}
    assert {name: cls.code for name, cls in errors.ERRORS.items()} == expected
    assert errors.CODES == {m.name: m.code for m in Message}
    for name in expected:
        cls = getattr(errors, name)
        assert cls.message_name == name and issubclass(cls, errors.MpiError)
        assert errors.error_for(name) is cls


def test_state_refusals_are_state_errors():
    states = {name for name in errors.ERRORS if issubclass(errors.ERRORS[name], errors.StateError)}
    assert states == {f"MPIMotionMessage{s}" for s in ("IDLE", "MOVING", "STOPPING", "STOPPED", "STOPPING_ERROR",
                                                       "ERROR")}


def test_raise_for_raises_the_messages_class_with_detail_and_result():
    errors.raise_for("MPIMessageOK", "fine")  # nothing
    with pytest.raises(errors.MPIMotionMessageMOVING) as caught:
        errors.raise_for("MPIMotionMessageMOVING", "supervisor is MOVING", result="the reply")
    assert (caught.value.message, caught.value.code, caught.value.detail, caught.value.result) == (
        "MPIMotionMessageMOVING", Message.MPIMotionMessageMOVING.code, "supervisor is MOVING", "the reply")
    assert str(caught.value) == "MPIMotionMessageMOVING: supervisor is MOVING"


def test_a_message_this_client_does_not_know_still_raises_by_name():
    first = errors.error_for("MPIMotionMessageFROM_THE_FUTURE")
    assert first is errors.error_for("MPIMotionMessageFROM_THE_FUTURE")  # made once: `except` on it works
    with pytest.raises(first) as caught:
        errors.raise_for("MPIMotionMessageFROM_THE_FUTURE")
    assert isinstance(caught.value, errors.MpiError) and caught.value.message == "MPIMotionMessageFROM_THE_FUTURE"


def test_connection_errors_are_not_controller_errors():
    assert issubclass(errors.SuiteNotFound, errors.NoResponse) and issubclass(errors.NoResponse, TimeoutError)
    assert not issubclass(errors.NoSuchSupervisor, errors.MpiError)


def test_enums_name_what_the_controller_names():
    assert set(EventType) == {e.name for e in MPIEventType if e.name and e is not MPIEventType.NONE}
    assert set(State) == {s.name for s in MPIState}
    assert {"STOP", "E_STOP", "ABORT", "E_STOP_ABORT", "RESET", "RESUME", "MAP"} == set(Action)
    assert MotionType.S_CURVE == "S_CURVE" and f"{MotionType.VELOCITY}" == "VELOCITY"


def test_fill_sets_nested_fields_and_makes_numbers_float64():
    from mpi_ros.action import MotionStart

    goal = fill(MotionStart.Goal(), {"type": MotionType.S_CURVE, "position": [1000, 0],
                                     "trajectory": [{"velocity": 500, "acceleration": 5000}],
                                     "attributes": ["RELATIVE"], "id": 7.0})
    assert goal.type == "S_CURVE" and type(goal.type) is str
    assert list(goal.position) == [1000.0, 0.0]
    assert goal.trajectory[0].velocity == 500.0 and goal.id == 7


@pytest.mark.parametrize("data, text", [
    ({"positions": [1.0]}, "positions: no such field in MotionStart_Goal (fields: "),
    ({"position": 5.0}, "position: expected a list, got 5.0"),
    ({"position": ["a"]}, "position[0]: expected a number, got 'a'"),
    ({"id": 1.5}, "id: expected an integer, got 1.5"),
    ({"id": True}, "id: expected an integer, got True"),
    ({"type": 3}, "type: expected a string, got 3"),
    ({"trajectory": [{"velocity": "fast"}]}, "trajectory[0].velocity: expected a number, got 'fast'"),
    ({"trajectory": [5]}, "trajectory[0]: expected a mapping of fields, got 5"),
    ({"final": "yes"}, "final: expected true or false, got 'yes'"),
])
def test_fill_names_the_field_that_is_wrong(data, text):
    from mpi_ros.action import MotionStart

    with pytest.raises(ValueError) as caught:
        fill(MotionStart.Goal(), data)
    assert str(caught.value).startswith(text)


def test_message_to_dict_and_message_class():
    from mpi_ros.msg import AxisStatus, MotionStatus

    status = MotionStatus(number=1, state_name="IDLE", axis_numbers=[2, 3], axes=[AxisStatus(number=2)])
    plain = message_to_dict(status)
    assert plain["number"] == 1 and plain["axis_numbers"] == [2, 3]
    assert plain["axes"][0]["number"] == 2 and plain["stamp"] == {"sec": 0, "nanosec": 0}
    assert list(plain)[:3] == ["stamp", "sample", "number"]  # in field order
    assert message_class("mpi_ros/msg/MotionStatus") is MotionStatus
    assert message_class("mpi_ros/MotionStatus") is MotionStatus
    with pytest.raises(ValueError):
        message_class("MotionStatus")


@pytest.mark.parametrize("message, sample, end, status, outcome", [
    ("MPIMessageOK", 10, 500, 4, Outcome.DONE),
    ("MPIMessagePARAM_INVALID", 10, 10, 6, Outcome.REFUSED),
    ("MPIMotionMessageERROR", 10, 900, 6, Outcome.ENDED),
    ("MPIMotionMessageSTOPPED", 10, 900, 5, Outcome.CANCELED),
])
def test_motion_result_outcome(message, sample, end, status, outcome):
    raw = SimpleNamespace(message=message, code=0, state_name="IDLE", actual_position=[1.0], command_position=[1.0],
                          move_id=0, sample=sample, end_sample=end, detail="")
    result = MotionResult.from_ros(raw, status)
    assert result.outcome is outcome and result.ok == (message == "MPIMessageOK")
    assert result.state is State.IDLE and result.actual_position == (1.0,)


def test_client_and_errors_import_nothing_of_the_simulated_controller():
    code = ("import sys, mpi_ros.client, mpi_ros.errors;"
            "print(sorted(m for m in sys.modules if m.startswith(('mpi_ros.mpi', 'mpi_ros.ros', 'mpi_ros.runner'))))")
    proc = subprocess.run([sys.executable, "-P", "-c", code], check=False, capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"
