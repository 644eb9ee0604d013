"""Commands as data: every operation, and bad requests answered with the spec's message."""

from __future__ import annotations

import json

import pytest

from mpi_ros import config
from mpi_ros.commands import Command, apply
from mpi_ros.mpi.messages import Message
from mpi_ros.mpi.types import MPIState

GOAL = {"type": "TRAPEZOIDAL", "position": [100.0, 0.0],
        "trajectory": [{"velocity": 1000.0, "acceleration": 10000.0, "deceleration": 10000.0}]}


@pytest.fixture
def ctl():
    return config.load().build_controller()


def test_motion_start_runs_to_done_and_reports_the_move(ctl):
    reply = apply(ctl, Command("motion_start", 0, request=GOAL))
    assert reply.accepted and reply.serial > 0 and reply.state is MPIState.MOVING
    assert ctl.run_until(lambda c: c.supervisor(0).state is MPIState.IDLE, 10_000, chunk=100)
    assert ctl.axes[0].command_position == 100.0


@pytest.mark.parametrize(
    "command, message",
    [
        (Command("motion_start", 0, request={**GOAL, "type": "NOPE"}), "MPIMotionMessageTYPE_INVALID"),
        (Command("motion_start", 0, request={**GOAL, "hold": [{"type": "NOPE"}]}), "MPIMessagePARAM_INVALID"),
        (Command("motion_start", 0, request={**GOAL, "event_mask": ["NOPE"]}), "MPIMessagePARAM_INVALID"),
        (Command("motion_start", 0, request={**GOAL, "position": ["x", 0.0]}), "MPIMessagePARAM_INVALID"),
        (Command("motion_start", 0, request={**GOAL, "trajectory": [{"speed": 1.0}]}), "MPIMessagePARAM_INVALID"),
        (Command("motion_start", 5, request=GOAL), "MPIMotionMessageMOTION_INVALID"),
        (Command("action", 0, request={"action": "LAUNCH"}), "MPIMessagePARAM_INVALID"),
        (Command("axis_list_edit", 0, request={"operation": "SHUFFLE", "axis": 0}), "MPIMessagePARAM_INVALID"),
        (Command("io_set", request={"space": "NOPE", "index": 0, "value": 1}), "MPIMessagePARAM_INVALID"),
        (Command("gate_set", request={"gate": 32, "closed": True}), "MPIMessagePARAM_INVALID"),
        (Command("axis_position_set", axis=0, request={"which": "UP", "value": 1.0}), "MPIMessagePARAM_INVALID"),
        (Command("axis_position_set", axis=9, request={"which": "ORIGIN", "value": 1.0}), "MPIAxisMessageAXIS_INVALID"),
        (Command("teleport", 0), "MPIMessageUNSUPPORTED"),
    ],
)
def test_bad_requests_get_the_spec_message_and_change_nothing(ctl, command, message):
    before = [(a.cmd_p, a.origin) for a in ctl.axes], ctl.supervisor(0).state
    assert apply(ctl, command).message is Message[message]
    assert ([(a.cmd_p, a.origin) for a in ctl.axes], ctl.supervisor(0).state) == before


def test_commands_round_trip_through_json():
    command = Command("motion_start", 0, -1, GOAL)
    again = Command.from_json(command.operation, command.supervisor, command.axis, command.to_json())
    assert again == command and json.loads(command.to_json()) == GOAL


def test_every_operation_applies(ctl):
    replies = [
        apply(ctl, Command("config_set", 0, request={"config": {"decel_time_stop": 0.2, "decel_time_e_stop": 0.02,
                                                               "normal_feedrate": 1.0}})),
        apply(ctl, Command("params_set", 0, request={"params": GOAL})),
        apply(ctl, Command("axis_list_set", 1, request={"axis_numbers": [3, 2]})),
        apply(ctl, Command("axis_list_edit", 1, request={"operation": "REMOVE", "axis": 2})),
        apply(ctl, Command("position_set", 0, request={"actual": [5.0, 6.0], "command": [5.0, 6.0]})),
        apply(ctl, Command("event_notify_set", 0, request={"event_types": ["MOTION"]})),
        apply(ctl, Command("event_reset", 0, request={"event_types": ["ALL"]})),
        apply(ctl, Command("gate_set", request={"gate": 1, "closed": True})),
        apply(ctl, Command("io_set", request={"space": "MOTOR_GENERAL_IO", "index": 1, "value": 5})),
        apply(ctl, Command("axis_config_set", axis=2, request={"in_position": {"settling_time": 0.1}})),
        apply(ctl, Command("axis_position_set", axis=3, request={"which": "ORIGIN", "value": 7.0})),
        apply(ctl, Command("action", 0, request={"action": "MAP"})),
    ]
    assert [r.message for r in replies] == [Message.MPIMessageOK] * len(replies)
    assert ctl.supervisor(0).config.decel_time.stop == 0.2
    assert ctl.supervisor(1).axis_list == [3]
    assert [a.command_position for a in ctl.axes[:2]] == [5.0, 6.0]
    assert ctl.io.gates_closed[1] and ctl.axes[2].in_position.settling_time == 0.1
