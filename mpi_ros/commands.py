"""Commands: everything that changes the controller, as data.

A :class:`Command` names an operation, its target and its request (a JSON-able dict
with the ROS interfaces' field names). :func:`apply` carries it out on a controller and
answers a :class:`Reply`. The ROS nodes, the Python client and replay all go through
here, so a recording of commands with the samples they took effect at reproduces a run.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Callable

from . import requests as rq
from .mpi.control import Controller
from .mpi.events import MPIEventType
from .mpi.messages import Message
from .mpi.types import ActionSource, IoSpace, MPIAction, MPIState

MOTION_START = "motion_start"
MOTION_MODIFY = "motion_modify"
ACTION = "action"


@dataclass(frozen=True, slots=True)
class Command:
    operation: str
    supervisor: int = -1
    axis: int = -1
    request: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> str:
        return json.dumps(self.request, sort_keys=True, separators=(",", ":"))

    @classmethod
    def from_json(cls, operation: str, supervisor: int, axis: int, text: str) -> "Command":
        return cls(operation, supervisor, axis, json.loads(text) if text else {})


@dataclass(frozen=True, slots=True)
class Reply:
    message: Message
    detail: str = ""
    serial: int = 0  # the move a start/modify made or changed (0 if none)
    state: MPIState = MPIState.INVALID
    value: Any = None  # what an edit returns (e.g. the axis list)

    @property
    def accepted(self) -> bool:
        return self.message in (Message.MPIMessageOK, Message.MPIMotionMessageAUTO_START)


def _supervisor(ctl: Controller, command: Command):
    ms = ctl.supervisor(command.supervisor)
    if ms is None:
        raise rq.RequestError(Message.MPIMotionMessageMOTION_INVALID, f"no supervisor {command.supervisor}")
    return ms


def _motion(ctl: Controller, command: Command, modify: bool) -> Reply:
    ms = _supervisor(ctl, command)
    request = rq.motion_request(command.request)
    message, detail, serial = ms.command(request.type, request.attributes, request.params, modify)
    return Reply(message, detail, serial if message in (Message.MPIMessageOK, Message.MPIMotionMessageAUTO_START) else 0,
                 ms.state)


def _action(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    name = str(command.request.get("action", "")).strip().upper()
    action = MPIAction.__members__.get(name)
    if action is None or action is MPIAction.NONE:
        return Reply(Message.MPIMessagePARAM_INVALID,
                     f"unknown action {name!r} (STOP, E_STOP, ABORT, E_STOP_ABORT, RESET, RESUME, MAP)", state=ms.state)
    source = ActionSource.CONTROLLER if command.request.get("source") == "CONTROLLER" else ActionSource.USER
    message, detail = ms.action_detail(action, source)
    return Reply(message, detail, state=ms.state)


def _config_set(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    return Reply(ms.config_set(rq.motion_config(command.request.get("config", {}))), state=ms.state)


def _params_set(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    return Reply(ms.params_set(rq.motion_params(command.request.get("params", {}))), state=ms.state)


def _axis_list_set(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    message = ms.axis_list_set([int(a) for a in command.request.get("axis_numbers", [])])
    if message.ok and command.request.get("map", True):
        message = ms.action(MPIAction.MAP)
    return Reply(message, state=ms.state, value=list(ms.axis_list))


def _axis_list_edit(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    operation = str(command.request.get("operation", "")).upper()
    axis = int(command.request.get("axis", -1))
    if operation == "APPEND":
        message = ms.axis_append(axis)
    elif operation == "INSERT":
        message = ms.axis_insert(int(command.request.get("after_axis", -1)), axis)
    elif operation == "REMOVE":
        message = ms.axis_remove(axis)
    else:
        return Reply(Message.MPIMessagePARAM_INVALID, f"unknown operation {operation!r} (APPEND, INSERT, REMOVE)",
                     value=list(ms.axis_list))
    return Reply(message, state=ms.state, value=list(ms.axis_list))


def _position_set(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    actual = [float(x) for x in command.request.get("actual", [])]
    commanded = [float(x) for x in command.request.get("command", [])]
    return Reply(ms.position_set(actual, commanded), state=ms.state)


def _event_mask(names) -> MPIEventType:
    mask = MPIEventType.parse(names or [])
    if mask is None:
        raise rq.RequestError(Message.MPIMessagePARAM_INVALID, f"unknown event type in {list(names or [])}")
    return mask


def _event_notify_set(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    return Reply(ms.event_notify_set(_event_mask(command.request.get("event_types"))))


def _event_reset(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    message = ms.event_reset(_event_mask(command.request.get("event_types")))
    return Reply(message, value=ms.latched.names())


def _gate_set(ctl: Controller, command: Command) -> Reply:
    return Reply(ctl.gate_set(int(command.request.get("gate", -1)), bool(command.request.get("closed", False))))


def io_space(name) -> IoSpace:
    try:
        return IoSpace(str(name).strip().upper())
    except ValueError as exc:
        raise rq.RequestError(Message.MPIMessagePARAM_INVALID,
                              f"unknown I/O space {name!r} (IO, MOTOR_GENERAL_IO, MOTOR_DEDICATED_IO)") from exc


def _io_set(ctl: Controller, command: Command) -> Reply:
    r = command.request
    return Reply(ctl.io_set(io_space(r.get("space")), int(r.get("index", -1)), int(r.get("value", 0)),
                            int(r.get("mask", -1))))


def _axis_config_set(ctl: Controller, command: Command) -> Reply:
    return Reply(ctl.axis_in_position_set(command.axis, rq.in_position(command.request.get("in_position", {}))))


def _axis_position_set(ctl: Controller, command: Command) -> Reply:
    which = str(command.request.get("which", "")).upper()
    value = float(command.request.get("value", 0.0))
    setter = {
        "COMMAND": ctl.axis_command_position_set,
        "ACTUAL": ctl.axis_actual_position_set,
        "ORIGIN": ctl.axis_origin_set,
    }.get(which)
    if setter is None:
        return Reply(Message.MPIMessagePARAM_INVALID, f"unknown position {which!r} (COMMAND, ACTUAL, ORIGIN)")
    return Reply(setter(command.axis, value))


OPERATIONS: dict[str, Callable[[Controller, Command], Reply]] = {
    MOTION_START: lambda ctl, c: _motion(ctl, c, modify=False),
    MOTION_MODIFY: lambda ctl, c: _motion(ctl, c, modify=True),
    ACTION: _action,
    "config_set": _config_set,
    "params_set": _params_set,
    "axis_list_set": _axis_list_set,
    "axis_list_edit": _axis_list_edit,
    "position_set": _position_set,
    "event_notify_set": _event_notify_set,
    "event_reset": _event_reset,
    "gate_set": _gate_set,
    "io_set": _io_set,
    "axis_config_set": _axis_config_set,
    "axis_position_set": _axis_position_set,
}


def apply(ctl: Controller, command: Command) -> Reply:
    """Carry out ``command`` at the controller's current sample."""
    handler = OPERATIONS.get(command.operation)
    if handler is None:
        return Reply(Message.MPIMessageUNSUPPORTED, f"unknown operation {command.operation!r}")
    try:
        return handler(ctl, command)
    except rq.RequestError as exc:
        ms = ctl.supervisor(command.supervisor)
        return Reply(exc.message, exc.detail, state=ms.state if ms is not None else MPIState.INVALID)
    except (TypeError, ValueError) as exc:
        return Reply(Message.MPIMessagePARAM_INVALID, str(exc))
