"""Commands: everything that changes the controller, as data.

A :class:`Command` names an operation, its target and its request (a JSON-able dict
with the ROS interfaces' field names). :func:`apply` carries it out on a controller and
answers a :class:`Reply`. The ROS nodes, the Python client and replay all go through
here, so a recording of commands with the samples they took effect at reproduces a run.

Size: a request larger than params.MAX_REQUEST_VALUES array elements or
params.MAX_REQUEST_TEXT characters is refused (MPIMessagePARAM_INVALID, "request too
large: ...") before any of it is read, and recorded compacted (:meth:`Command.to_json`),
so input refused for its size costs a bounded time and leaves nothing large behind.

Errors: a request that cannot be read (:class:`mpi_ros.mpi.base.outcome.Refused`) is the
user's and answers its message (MPIMessagePARAM_INVALID unless named). Any other
exception is a bug of this package, not of the request: it is logged with its traceback
and answered with :data:`INTERNAL_ERROR`, so it never passes for the user's fault, and
the node that asked stays up (docs/decisions.md, "Validation and ranges").
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from enum import StrEnum
from typing import Any

from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import CarriesOutcome, Outcome, Refused
from mpi_ros.mpi.base.params import shown
from mpi_ros.mpi.base.types import ActionSource, IoSpace, MPIAction, MPIState
from mpi_ros.mpi.control import Controller

from . import requests as rq
from . import trajectory


class Operation(StrEnum):
    """What a command does: one per handler in OPERATIONS. The values are what a recording
    stores (Command.operation), so they never change."""

    MOTION_START = "motion_start"
    MOTION_MODIFY = "motion_modify"
    ACTION = "action"
    CLIENT_LOST = "client_lost"
    JOINT_TRAJECTORY = "joint_trajectory"
    CONFIG_SET = "config_set"
    PARAMS_SET = "params_set"
    AXIS_LIST_SET = "axis_list_set"
    AXIS_LIST_EDIT = "axis_list_edit"
    POSITION_SET = "position_set"
    EVENT_NOTIFY_SET = "event_notify_set"
    EVENT_RESET = "event_reset"
    GATE_SET = "gate_set"
    IO_SET = "io_set"
    AXIS_CONFIG_SET = "axis_config_set"
    SECONDARY_FEEDBACK_SET = "secondary_feedback_set"
    AXIS_POSITION_SET = "axis_position_set"
    AXIS_FAULT_CONFIG_SET = "axis_fault_config_set"
    AXIS_FAULT_INJECT = "axis_fault_inject"
    AXIS_CREATE = "axis_create"
    AXIS_DELETE = "axis_delete"
    AXIS_AMP_ENABLE_SET = "axis_amp_enable_set"
    AXIS_EVENT_NOTIFY_SET = "axis_event_notify_set"
    AXIS_EVENT_RESET = "axis_event_reset"


# The reference has no "internal error" message; of its generic messages, NO_MEMORY ("not
# enough memory was available") is the one that says the library failed, not the call.
# Nothing else in the controller answers it, so it tells a bug apart from every refusal.
INTERNAL_ERROR = Message.MPIMessageNO_MEMORY
INTERNAL_DETAIL = "internal error in mpi_ros (logged with its traceback; please report it)"

_log = logging.getLogger("mpi_ros.commands")


@dataclass(frozen=True, slots=True)
class Command:
    operation: str
    supervisor: int = -1
    axis: int = -1
    request: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> str:
        """The request as JSON: what the commands topic and recordings carry, and replay reads.

        A request too large to be read (requests.check_size: apply refuses it before reading
        any of it) is recorded compacted (requests.compact): its long arrays and strings are
        replaced by their sizes, which replayed are refused again with the same message.
        Recorded whole, a refused goal of 1,000,000 values would keep megabytes in the
        commands topic's history (1000 messages deep, kept for late joiners)."""
        request = self.request
        if isinstance(request, Mapping) and not rq.request_size(request).ok:
            request = rq.compact(request)
        return json.dumps(request, sort_keys=True, separators=(",", ":"))

    @classmethod
    def from_json(cls, operation: str, supervisor: int, axis: int, text: str) -> Command:
        return cls(operation, supervisor, axis, json.loads(text) if text else {})


@dataclass(frozen=True, slots=True)
class Reply(CarriesOutcome):
    """The controller's answer to a command: its outcome, with what the command made."""

    outcome: Outcome
    serial: int = 0  # the move a start/modify made or changed (0 if none)
    state: MPIState = MPIState.INVALID
    value: Any = None  # what an edit returns (e.g. the axis list)

    @classmethod
    def of(cls, message: Message, detail: str = "", serial: int = 0, state: MPIState = MPIState.INVALID,
           value: Any = None) -> Reply:
        return cls(Outcome(message, detail), serial, state, value)

    @property
    def accepted(self) -> bool:
        return self.message in (Message.MPIMessageOK, Message.MPIMotionMessageAUTO_START)


def _supervisor(ctl: Controller, command: Command):
    ms = ctl.supervisor(command.supervisor)
    if ms is None:
        raise Refused(Message.MPIMotionMessageMOTION_INVALID, f"no supervisor {command.supervisor}")
    return ms


def _motion(ctl: Controller, command: Command, modify: bool) -> Reply:
    ms = _supervisor(ctl, command)
    request = rq.motion_request(command.request)
    outcome, serial = ms.command(request.type, request.attributes, request.params, modify)
    reply = Reply(outcome, serial, ms.state)
    return reply if reply.accepted else replace(reply, serial=0)


def _joint_trajectory(ctl: Controller, command: Command) -> Reply:
    """A chunk of a JointTrajectory (trajectory.py, docs/trajectories.md): checked against the
    supervisor now (its axes, and the speed from where the path starts), then the MPI path.
    The first chunk replaces a PT or PVT path in progress from now (mpiMotionModify, MPI 000:
    PT and PVT may be modified) or starts one (mpiMotionStart: refused while another motion
    runs, or in ERROR, with the controller's message); later chunks APPEND to it. No points:
    STOP."""
    ms = _supervisor(ctl, command)
    if not command.request.get("time_from_start"):
        return Reply(ms.action(MPIAction.STOP), state=ms.state)
    chunk = trajectory.Chunk.from_request(command.request)
    axes = [j.axis for j in chunk.joints]
    if axes != list(ms.axis_list):
        return Reply.of(Message.MPIMessagePARAM_INVALID, f"the trajectory's axes {axes} are not supervisor "
                        f"{ms.number}'s axes {list(ms.axis_list)}", state=ms.state)
    start = None
    if not chunk.append:
        snaps = [ctl.axis_snapshot(n) for n in axes]
        start = [(s.command_position, s.command_velocity) for s in snaps]
    verdict = chunk.check(start)
    if not verdict.ok:
        return Reply(verdict, state=ms.state)
    running = ms.current
    modify = chunk.append or (ms.state is MPIState.MOVING and running is not None
                              and running.type.name in ("PT", "PVT"))
    request = rq.motion_request(chunk.motion_request())
    outcome, serial = ms.command(request.type, request.attributes, request.params, modify)
    reply = Reply(outcome, serial, ms.state)
    return reply if reply.accepted else replace(reply, serial=0)


def _action(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    name = rq.text(command.request.get("action", ""), "action").strip().upper()
    action = MPIAction.__members__.get(name)
    if action is None or action is MPIAction.NONE:
        return Reply.of(Message.MPIMessagePARAM_INVALID,
                        f"unknown action {shown(name)} (STOP, E_STOP, ABORT, E_STOP_ABORT, RESET, RESUME, MAP)",
                        state=ms.state)
    source = ActionSource.CONTROLLER if command.request.get("source") == "CONTROLLER" else ActionSource.USER
    return Reply(ms.action(action, source), state=ms.state)


def _client_lost(ctl: Controller, command: Command) -> Reply:
    """The lost-client watchdog's STOP (mpi_ros/ros/watchdog.py, docs/cell.md): a CLIENT_LOST
    event with the watchdog's ``detail`` (which goals, whose client, how long), then STOP as
    the controller's own action, answered as STOP answers. A command like any other, so a
    bag holds it and replay reproduces both the event and the STOP."""
    ms = _supervisor(ctl, command)
    detail = rq.text(command.request.get("detail", ""), "detail")
    move = ms.current or ms.last_move
    ctl.emit(MPIEventType.CLIENT_LOST, supervisor=ms.number, move_id=move.id if move else 0, detail=detail)
    return Reply(ms.action(MPIAction.STOP, ActionSource.CONTROLLER), state=ms.state)


def _config_set(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    config = rq.motion_config(command.request.get("config", {}))
    return Reply(ms.config_set(config), state=ms.state)


def _params_set(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    params = rq.motion_params(command.request.get("params", {}))
    return Reply(ms.params_set(params), state=ms.state)


def _axis_list_set(ctl: Controller, command: Command) -> Reply:
    """mpiMotionAxisListSet, then (``map``, the default) MEIActionMAP: all or nothing, so a
    refused MAP leaves the axis list as it was (a refusal changes nothing)."""
    ms = _supervisor(ctl, command)
    numbers = rq.integers(command.request.get("axis_numbers", []), "axis_numbers")
    mapping = rq.boolean(command.request.get("map", True), "map")
    if mapping and not numbers:
        return Reply.of(Message.MEIMotionMessageNO_AXES_MAPPED, "map true with an empty axis list: nothing to map "
                        "(map false empties the list)", state=ms.state, value=list(ms.axis_list))
    previous = list(ms.axis_list)
    outcome = ms.axis_list_set(numbers)
    if outcome.ok and mapping:
        outcome = ms.action(MPIAction.MAP)
        if not outcome.ok:
            ms.axis_list_set(previous)  # valid a moment ago, in the same state
    return Reply(outcome, state=ms.state, value=list(ms.axis_list))


def _axis_list_edit(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    operation = rq.text(command.request.get("operation", ""), "operation").upper()
    axis = rq.integer(command.request.get("axis", -1), "axis")
    if operation == "APPEND":
        outcome = ms.axis_append(axis)
    elif operation == "INSERT":
        outcome = ms.axis_insert(rq.integer(command.request.get("after_axis", -1), "after_axis"), axis)
    elif operation == "REMOVE":
        outcome = ms.axis_remove(axis)
    else:
        return Reply.of(Message.MPIMessagePARAM_INVALID,
                        f"unknown operation {shown(operation)} (APPEND, INSERT, REMOVE)", value=list(ms.axis_list))
    return Reply(outcome, state=ms.state, value=list(ms.axis_list))


def _position_set(ctl: Controller, command: Command) -> Reply:
    ms = _supervisor(ctl, command)
    actual = rq.numbers(command.request.get("actual", []), "actual")
    commanded = rq.numbers(command.request.get("command", []), "command")
    return Reply(ms.position_set(actual, commanded), state=ms.state)


def _event_notify_set(ctl: Controller, command: Command) -> Reply:
    """mpiMotionEventNotifySet, or mpiAxisEventNotifySet for an axis' command."""
    mask = rq.event_mask(command.request.get("event_types"), "event_types")
    if command.operation == Operation.AXIS_EVENT_NOTIFY_SET:
        return Reply(ctl.axis_event_notify_set(command.axis, mask))
    return Reply(_supervisor(ctl, command).event_notify_set(mask))


def _event_reset(ctl: Controller, command: Command) -> Reply:
    """mpiMotionEventReset, or mpiAxisEventReset for an axis' command; the events still latched."""
    mask = rq.event_mask(command.request.get("event_types"), "event_types")
    if command.operation == Operation.AXIS_EVENT_RESET:
        outcome = ctl.axis_event_reset(command.axis, mask)
        return Reply(outcome, value=ctl.axes[command.axis].events.latched.names() if outcome.ok else [])
    ms = _supervisor(ctl, command)
    return Reply(ms.event_reset(mask), value=ms.latched.names())


def _axis_amp_enable_set(ctl: Controller, command: Command) -> Reply:
    """The amplifier enable of an axis (docs/decisions.md, "Amplifier enable")."""
    outcome = ctl.axis_amp_enable_set(command.axis, rq.boolean(command.request.get("enable", True), "enable"))
    return Reply(outcome, value=ctl.axes[command.axis].enabled if outcome.ok else None)


def _gate_set(ctl: Controller, command: Command) -> Reply:
    r = command.request
    return Reply(ctl.gate_set(rq.integer(r.get("gate", -1), "gate"), rq.boolean(r.get("closed", False), "closed")))


def io_space(name) -> IoSpace:
    try:
        return IoSpace(str(name).strip().upper())
    except ValueError as exc:
        raise Refused(Message.MPIMessagePARAM_INVALID,
                              f"unknown I/O space {shown(name)} (IO, MOTOR_GENERAL_IO, MOTOR_DEDICATED_IO)") from exc


def _io_set(ctl: Controller, command: Command) -> Reply:
    r = command.request
    return Reply(ctl.io_set(io_space(r.get("space")), rq.integer(r.get("index", -1), "index"),
                         rq.integer(r.get("value", 0), "value"), rq.integer(r.get("mask", -1), "mask")))


def _axis_config_set(ctl: Controller, command: Command) -> Reply:
    """mpiAxisConfigSet: inPosition, master and masterCorrection, all or nothing."""
    request = command.request
    in_position = rq.in_position(request.get("in_position", {}))
    if not 0 <= command.axis < len(ctl.axes):
        return Reply(ctl.axis_in_position_set(command.axis, in_position))
    master = rq.axis_master(request.get("master"), request.get("master_correction"), ctl.axes[command.axis].master)
    verdict = ctl.axis_master_check(command.axis, master)  # checked first: all or nothing
    if not verdict.ok:
        return Reply(verdict.prefixed("master."))
    outcome = ctl.axis_in_position_set(command.axis, in_position)
    if outcome.ok:
        outcome = ctl.axis_master_set(command.axis, master).prefixed("master.")
    return Reply(outcome)


def _secondary_feedback_set(ctl: Controller, command: Command) -> Reply:
    motor, feedback = rq.secondary_feedback(command.request)
    return Reply(ctl.secondary_feedback_set(motor, feedback))


def _axis_position_set(ctl: Controller, command: Command) -> Reply:
    which = rq.text(command.request.get("which", ""), "which").upper()
    value = rq.number(command.request.get("value", 0.0), "value")
    setter = {
        "COMMAND": ctl.axis_command_position_set,
        "ACTUAL": ctl.axis_actual_position_set,
        "ORIGIN": ctl.axis_origin_set,
    }.get(which)
    if setter is None:
        return Reply.of(Message.MPIMessagePARAM_INVALID, f"unknown position {shown(which)} (COMMAND, ACTUAL, ORIGIN)")
    return Reply(setter(command.axis, value))


def _axis_fault_config_set(ctl: Controller, command: Command) -> Reply:
    """The fault limits and actions of an axis (docs/faults.md); fields left out keep their values."""
    _, current = ctl.axis_fault_config_get(command.axis)
    verdict = ctl.axis_fault_config_set(command.axis, rq.fault_config(command.request.get("config", {}), current))
    return Reply.of(verdict.message, verdict.detail)


def _axis_fault_inject(ctl: Controller, command: Command) -> Reply:
    """A fault injected on an axis (docs/faults.md): recorded, so a replay injects it at the same sample."""
    r = command.request
    outcome = ctl.axis_fault_inject(command.axis, rq.text(r.get("fault", ""), "fault"),
                                    rq.boolean(r.get("active", True), "active"))
    faults = list(ctl.faults.names(command.axis)) if 0 <= command.axis < len(ctl.axes) else []
    return Reply(outcome, value=faults)


def _axis_create(ctl: Controller, command: Command) -> Reply:
    """mpiAxisCreate (MPI 002): recorded, so a replay has the same axes at the same sample."""
    outcome, _ = ctl.axis_create(command.axis)
    return Reply(outcome)


def _axis_delete(ctl: Controller, command: Command) -> Reply:
    """mpiAxisDelete (MPI 002)."""
    return Reply(ctl.axis_delete(command.axis))


OPERATIONS: dict[str, Callable[[Controller, Command], Reply]] = {  # by Operation
    Operation.MOTION_START: lambda ctl, c: _motion(ctl, c, modify=False),
    Operation.MOTION_MODIFY: lambda ctl, c: _motion(ctl, c, modify=True),
    Operation.ACTION: _action,
    Operation.CLIENT_LOST: _client_lost,
    Operation.JOINT_TRAJECTORY: _joint_trajectory,
    Operation.CONFIG_SET: _config_set,
    Operation.PARAMS_SET: _params_set,
    Operation.AXIS_LIST_SET: _axis_list_set,
    Operation.AXIS_LIST_EDIT: _axis_list_edit,
    Operation.POSITION_SET: _position_set,
    Operation.EVENT_NOTIFY_SET: _event_notify_set,
    Operation.EVENT_RESET: _event_reset,
    Operation.GATE_SET: _gate_set,
    Operation.IO_SET: _io_set,
    Operation.AXIS_CONFIG_SET: _axis_config_set,
    Operation.SECONDARY_FEEDBACK_SET: _secondary_feedback_set,
    Operation.AXIS_POSITION_SET: _axis_position_set,
    Operation.AXIS_FAULT_CONFIG_SET: _axis_fault_config_set,
    Operation.AXIS_FAULT_INJECT: _axis_fault_inject,
    Operation.AXIS_CREATE: _axis_create,
    Operation.AXIS_DELETE: _axis_delete,
    Operation.AXIS_AMP_ENABLE_SET: _axis_amp_enable_set,
    Operation.AXIS_EVENT_NOTIFY_SET: _event_notify_set,
    Operation.AXIS_EVENT_RESET: _event_reset,
}


def apply(ctl: Controller, command: Command) -> Reply:
    """Carry out ``command`` at the controller's current sample."""
    handler = OPERATIONS.get(command.operation)
    if handler is None:
        return Reply.of(Message.MPIMessageUNSUPPORTED, f"unknown operation {shown(command.operation)}")
    try:
        if command.request is None:  # no request: every field takes its default
            command = replace(command, request={})
        rq.mapping(command.request, "request")
        rq.check_size(command.request)  # before reading any of it
        return handler(ctl, command)
    except Refused as exc:
        return Reply.of(exc.message, exc.detail, state=_state(ctl, command))
    except Exception as exc:  # noqa: BLE001 - a bug, not the request: logged in full, answered, the node stays up
        _log.exception("internal error applying %s (supervisor %s, axis %s, request %s)",
                       command.operation, command.supervisor, command.axis, _logged(command.request))
        return Reply.of(INTERNAL_ERROR, f"{INTERNAL_DETAIL}: {type(exc).__name__}: {exc}", state=_state(ctl, command))


def _logged(request: Any) -> str:
    """A request for the log: compacted (long arrays and strings as their sizes)."""
    try:
        return repr(rq.compact(request))
    except Exception:  # noqa: BLE001 - the log line must not fail in turn
        return shown(request)


def _state(ctl: Controller, command: Command) -> MPIState:
    ms = ctl.supervisor(command.supervisor)
    return ms.state if ms is not None else MPIState.INVALID
