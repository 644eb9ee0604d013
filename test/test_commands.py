"""Commands as data: every operation, and bad requests answered with the spec's message."""

from __future__ import annotations

import copy
import json
import logging
import math

import pytest

from mpi_ros import config
from mpi_ros.commands import INTERNAL_ERROR, OPERATIONS, Command, Operation, apply
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.types import MPIState

GOAL = {"type": "TRAPEZOIDAL", "position": [100.0, 0.0],
        "trajectory": [{"velocity": 1000.0, "acceleration": 10000.0, "deceleration": 10000.0}]}


@pytest.fixture
def ctl():
    return config.load().build_controller()


def test_motion_start_runs_to_done_and_reports_the_move(ctl):
    reply = apply(ctl, Command("motion_start", 0, request=GOAL))
    assert reply.accepted
    assert reply.serial > 0
    assert reply.state is MPIState.MOVING
    assert ctl.run_until(lambda c: c.supervisor(0).state is MPIState.IDLE, 10_000, chunk=100)
    assert ctl.axes[0].command_position == 100.0


@pytest.mark.parametrize(
    ("command", "message"),
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
    assert again == command
    assert json.loads(command.to_json()) == GOAL


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
    assert ctl.io.gates_closed[1]
    assert ctl.axes[2].in_position.settling_time == 0.1


# ------------------------------------------------------------------ values the controller cannot hold ----
# issue 9, "Configuration and errors", reproduced through the command layer the ROS services call.
# Each is refused with MPIMessagePARAM_INVALID (MPI 000, "Returns for mpiMotionStart and
# mpiMotionModify": "if the specified motion parameters are not valid"), the detail names the
# field, nothing changes, and the clock keeps running a move to its end.
def _goal_runs_to_idle(ctl) -> None:
    reply = apply(ctl, Command("motion_start", 0, request=GOAL))
    assert reply.accepted, reply
    assert ctl.run_until(lambda c: c.supervisor(0).state is MPIState.IDLE, 20_000, chunk=100)
    assert ctl.axes[0].command_position == 100.0
    assert all(math.isfinite(x) for a in ctl.axes for x in (a.cmd_p, a.cmd_v, a.act_p, a.act_v))


def test_axis_settling_time_1e308_is_refused_and_the_clock_runs(ctl):
    # issue 9: /mpi/axis0/config_set settling_time 1e308 crashed the clock on every step.
    # MPI 002 MPIAxisInPosition settlingTime: seconds, counted in samples.
    before = ctl.axes[0].in_position.copy()
    reply = apply(ctl, Command("axis_config_set", axis=0, request={"in_position": {"settling_time": 1e308}}))
    assert reply.message is Message.MPIMessagePARAM_INVALID
    assert reply.detail.startswith("settling_time:")
    assert ctl.axes[0].in_position == before
    _goal_runs_to_idle(ctl)


def test_a_fine_tolerance_the_encoder_cannot_resolve_is_refused_with_why(ctl):
    # MPI 002 status tables, NOTE 3: |target - actual| < positionFine; the default encoder reads
    # whole counts, so a reading can be 0.5 count from any target and 0.5 could never be met
    reply = apply(ctl, Command("axis_config_set", axis=1, request={"in_position": {"position_fine": 0.5}}))
    assert reply.message is Message.MPIMessagePARAM_INVALID
    assert reply.detail.startswith("position_fine:")
    assert ctl.axes[1].in_position.position_fine == 10.0


@pytest.mark.parametrize("feedrate", [1e308, 1e-300])
def test_normal_feedrate_out_of_range_is_refused_and_goals_end(ctl, feedrate):
    # issue 9: normal_feedrate 1e308 gave NaN command positions and a goal that never ends,
    # 1e-300 made the execute callback raise. MPI 000 MPIMotionConfig normalFeedrate (1.0 = 100 %).
    config = {"decel_time_stop": 0.5, "decel_time_e_stop": 0.05, "normal_feedrate": feedrate}
    reply = apply(ctl, Command("config_set", 0, request={"config": config}))
    assert reply.message is Message.MPIMessagePARAM_INVALID
    assert reply.detail.startswith("normal_feedrate:")
    assert ctl.supervisor(0).config.normal_feedrate == 1.0
    _goal_runs_to_idle(ctl)


def test_position_set_of_an_actual_1e308_is_refused(ctl):
    # issue 9: accepted, then position_get read -inf while status showed 0. MPI 000
    # mpiMotionPositionSet / 002 mpiAxisActualPositionSet: positions a controller can hold.
    reply = apply(ctl, Command("position_set", 0, request={"actual": [1e308, 0.0], "command": [0.0, 0.0]}))
    assert reply.message is Message.MPIMessagePARAM_INVALID
    assert reply.detail.startswith("actual[0]:")
    ctl.step(10)
    assert ctl.supervisor(0).position_get() == (Message.MPIMessageOK, [0.0, 0.0], [0.0, 0.0])


@pytest.mark.parametrize("which", ["ACTUAL", "COMMAND", "ORIGIN"])
def test_axis_position_set_past_what_a_controller_holds_is_refused(ctl, which):
    # MPI 002 mpiAxisActualPositionSet, mpiAxisCommandPositionSet, mpiAxisOriginSet
    reply = apply(ctl, Command("axis_position_set", axis=0, request={"which": which, "value": 1e308}))
    assert reply.message is Message.MPIMessagePARAM_INVALID
    # the detail names the argument of the MPI call (mpiAxisOriginSet's origin, else position)
    assert reply.detail.startswith("origin:" if which == "ORIGIN" else "position:")
    assert (ctl.axes[0].cmd_p, ctl.axes[0].act_p, ctl.axes[0].origin) == (0.0, 0.0, 0.0)


def test_config_set_refuses_an_unknown_field(ctl):
    # a misspelt field would silently set its real field to 0 (mpiMotionConfigSet writes the
    # whole MPIMotionConfig, MPI 000): the request cannot be read, PARAM_INVALID, nothing changes
    config = {"decel_time_stop": 0.2, "decel_time_e_stop": 0.02, "normal_feedrate": 1.0, "blend_limt": 0.5}
    reply = apply(ctl, Command("config_set", 0, request={"config": config}))
    assert reply.message is Message.MPIMessagePARAM_INVALID
    assert "blend_limt" in reply.detail
    assert ctl.supervisor(0).config.decel_time.stop == 0.5


def test_params_set_checks_every_value_it_stores(ctl):
    # MPI 000 mpiMotionParamsSet stores the parameters for a later start (params None): a value
    # no controller holds is refused now, not at that start
    reply = apply(ctl, Command("params_set", 0, request={"params": {**GOAL, "position": [1e300, 0.0]}}))
    assert reply.message is Message.MPIMessagePARAM_INVALID
    assert reply.detail.startswith("position[0]:")


@pytest.mark.parametrize(("empty_count", "message"), [
    (-1, "MPIMessageOK"),  # MPI 000 MPIMotionPoint: "-1 => disable"
    (0, "MPIMessageOK"),  # MPI 001 EMPTY_COUNT: "To disable ..., set the value to zero"
    (2**40, "MPIMessagePARAM_INVALID"),  # MPI 000 MPIMotionPoint: long emptyCount
])
def test_goal_empty_count(ctl, empty_count, message):
    reply = apply(ctl, Command("motion_start", 0, request={**GOAL, "empty_count": empty_count}))
    assert reply.message is Message[message]


def test_config_set_with_no_axes_answers_axis_count(ctl):
    # MPI 000 MPIMotionMessageAXIS_COUNT: "returned from mpiMotionConfigSet(...) ... if there are
    # no axes associated with the motion object"
    assert apply(ctl, Command("axis_list_set", 1, request={"axis_numbers": [], "map": False})).accepted
    config = {"decel_time_stop": 0.2, "decel_time_e_stop": 0.02, "normal_feedrate": 1.0}
    reply = apply(ctl, Command("config_set", 1, request={"config": config}))
    assert reply.message is Message.MPIMotionMessageAXIS_COUNT
    assert reply.detail
    assert ctl.supervisor(1).config.decel_time.stop == 0.5


# ------------------------------------------------------------------ refusals carry why, from where decided ----
# The controller's calls answer an Outcome (the reference's message and why); the command layer
# passes it on, so a reply (and the ROS response or goal result made from it) names the field
# or object first and says why, without running any validator again.
@pytest.mark.parametrize(("command", "message", "detail"), [
    # MPI 000 mpiMotionAxisListSet: an axis that does not exist is an invalid handle
    (Command("axis_list_set", 0, request={"axis_numbers": [0, 9]}), "MPIMessageHANDLE_INVALID",
     "axis: no axis 9 (4 axes)"),
    # MPI 000 mpiMotionAxisAppend, MPIMessageOBJECT_ON_LIST: "axis is already on the list"
    (Command("axis_list_set", 0, request={"axis_numbers": [1, 1], "map": False}), "MPIMessageOBJECT_ON_LIST",
     "axis_numbers: axis 1 is on the list twice"),
    (Command("axis_list_edit", 0, request={"operation": "APPEND", "axis": 1}), "MPIMessageOBJECT_ON_LIST",
     "axis: axis 1 is already on the list"),
    # MPI 000 mpiMotionAxisInsert / mpiMotionAxisRemove, MPIMotionMessageAXIS_NOT_FOUND
    (Command("axis_list_edit", 0, request={"operation": "INSERT", "after_axis": 3, "axis": 2}),
     "MPIMotionMessageAXIS_NOT_FOUND", "after_axis: axis 3 is not on the list"),
    (Command("axis_list_edit", 0, request={"operation": "REMOVE", "axis": 2}), "MPIMotionMessageAXIS_NOT_FOUND",
     "axis: axis 2 is not on the list"),
    # MPI 000 mpiMotionPositionSet: one value per axis
    (Command("position_set", 0, request={"actual": [1.0], "command": [1.0, 2.0]}), "MPIMessagePARAM_INVALID",
     "actual: 1 values for 2 axes"),
    # meiControlGateSet, and the I/O image's words
    (Command("gate_set", request={"gate": 32, "closed": True}), "MPIMessagePARAM_INVALID", "gate: no gate 32 (0..31)"),
    (Command("io_set", request={"space": "IO", "index": 999, "value": 1}), "MPIMessagePARAM_INVALID",
     "index: no IO word 999"),
    (Command("secondary_feedback_set", request={"motor": 99}), "MPIMessagePARAM_INVALID", "motor: no motor 99"),
    # MPI 002 mpiAxisConfigSet / mpiAxisOriginSet on an axis the controller does not have
    (Command("axis_config_set", axis=9, request={}), "MPIAxisMessageAXIS_INVALID", "axis: no axis 9"),
    (Command("axis_position_set", axis=9, request={"which": "ORIGIN", "value": 1.0}), "MPIAxisMessageAXIS_INVALID",
     "axis: no axis 9"),
])
def test_a_refusal_reaches_the_reply_with_why(ctl, command, message, detail):
    before = [list(ms.axis_list) for ms in ctl.supervisors], ctl.io.version
    reply = apply(ctl, command)
    assert (reply.message, reply.detail[:len(detail)]) == (Message[message], detail)
    assert ([list(ms.axis_list) for ms in ctl.supervisors], ctl.io.version) == before


def test_a_refused_axis_list_set_names_the_state_that_refuses_it(ctl):
    # MPI 000 mpiMotionAxisListSet while the motion runs: the message of its state, and why
    assert apply(ctl, Command("motion_start", 0, request=GOAL)).accepted
    reply = apply(ctl, Command("axis_list_set", 0, request={"axis_numbers": [0]}))
    assert (reply.message, reply.detail) == (Message.MPIMotionMessageMOVING, "state: supervisor 0 is MOVING")
    assert reply.value == [0, 1]


def test_a_command_position_refused_while_moving_names_the_axis_and_state(ctl):
    # MPI 002 mpiAxisCommandPositionSet: MPIAxisMessageCOMMAND_NOT_SET while the axis moves
    assert apply(ctl, Command("motion_start", 0, request=GOAL)).accepted
    reply = apply(ctl, Command("axis_position_set", axis=0, request={"which": "COMMAND", "value": 5.0}))
    assert reply.message is Message.MPIAxisMessageCOMMAND_NOT_SET
    assert reply.detail == "axis: axis 0 cannot take a command position while MOVING"
    reply = apply(ctl, Command("position_set", 0, request={"actual": [0.0, 0.0], "command": [0.0, 0.0]}))
    assert reply.message is Message.MPIAxisMessageCOMMAND_NOT_SET
    assert reply.detail == "command: axis 0 cannot take a command position while MOVING"


# ------------------------------------------------------------------ mpiAxisCommandPositionSet: one rule ----
_ACTIONS = {"STOPPING": "STOP", "STOPPED": "STOP", "STOPPING_ERROR": "E_STOP", "ERROR (E_STOP)": "E_STOP",
            "ERROR (ABORT)": "ABORT"}


def _to_state(ctl, state: str) -> None:
    """Supervisor 0 (axes 0, 1) into ``state`` through commands, as a client would."""
    if state != "IDLE (new)":
        done = state == "IDLE (move done)"
        request = GOAL if done else {**GOAL, "position": [1e5, 0.0]}
        assert apply(ctl, Command("motion_start", 0, request=request)).accepted
        ctl.step(400)  # at speed
        action = _ACTIONS.get(state)
        if action:
            assert apply(ctl, Command("action", 0, request={"action": action})).accepted
        ctl.step(10 if state in ("STOPPING", "STOPPING_ERROR") else 5000 if action or done else 0)
    assert ctl.supervisor(0).state.name == state.split(" ")[0]


@pytest.mark.parametrize(("state", "settable"), [
    ("IDLE (new)", True),
    ("IDLE (move done)", True),  # 002: "set the command position when the motion is in an IDLE state"
    ("MOVING", False),  # 002 error check: "Axis is in a STOPPING, STOPPED, or MOVING state"
    ("STOPPING", False),
    ("STOPPED", False),
    ("STOPPING_ERROR", False),  # stopping too: the controller computes the command every sample
    ("ERROR (E_STOP)", True),  # not on 002's list
    ("ERROR (ABORT)", True),
])
def test_the_axis_service_and_position_set_follow_one_rule(state, settable):
    # MPI 002 "mpiAxisCommandPositionSet(...) Error Check" (MPIAxisMessageCOMMAND_NOT_SET); issue 9:
    # /mpi/axis<k>/position_set and /mpi/ms<n>/position_set disagreed in ERROR
    expected = Message.MPIMessageOK if settable else Message.MPIAxisMessageCOMMAND_NOT_SET
    answers = []
    for operation in ("axis_position_set", "position_set"):
        ctl = config.load().build_controller()
        _to_state(ctl, state)
        a0, a1 = ctl.axes[0], ctl.axes[1]
        target = round(a0.command_position) + 7.0
        if operation == "axis_position_set":
            command = Command(operation, axis=0, request={"which": "COMMAND", "value": target})
        else:
            command = Command(operation, 0, request={"actual": [a0.actual_position, a1.actual_position],
                                                     "command": [target, a1.command_position]})
        before = a0.command_position
        answers.append(apply(ctl, command).message)
        ctl.step(200)
        if settable and state.startswith("IDLE"):
            # the command rests where it was set; a finished move does not pull it back
            assert a0.command_position == target
            assert abs(a0.actual_position - target) < 2.0
        elif not settable:
            assert a0.command_position != target or before == target
    assert answers == [expected, expected]


def test_actual_position_set_while_moving_keeps_the_motion_on_its_path(ctl):
    # MPI 002 mpiAxisActualPositionSet ("Set actual position"): the encoder reads the new value
    # from now on and the servo keeps following the command; the simulated motor does not jump
    assert apply(ctl, Command("motion_start", 0, request={**GOAL, "position": [100_000.0, 0.0]})).accepted
    ctl.step(1000)
    axis = ctl.axes[0]
    error = axis.position_error
    new_actual = axis.actual_position + 100.0
    assert apply(ctl, Command("axis_position_set", axis=0, request={"which": "ACTUAL", "value": new_actual})).accepted
    ctl.step(1)
    assert abs(axis.actual_position - (new_actual + 0.5)) <= 2.0  # 1000 counts/s: 0.5 count a sample
    assert abs(axis.position_error - (error - 100.0)) <= 2.0


# ------------------------------------------------------------------ errors: the user's, or ours ----
WEIRD = [None, "x", [], [1.0], {}, {"a": 1}, True, 2**70, math.nan, math.inf, b"x"]
REQUESTS = [
    Command("motion_start", 0, request=GOAL),
    Command("action", 0, request={"action": "STOP"}),
    Command("config_set", 0, request={"config": {"decel_time_stop": 0.2, "decel_time_e_stop": 0.02,
                                                 "normal_feedrate": 1.0, "user_label": "a"}}),
    Command("params_set", 0, request={"params": GOAL}),
    Command("axis_list_set", 1, request={"axis_numbers": [3, 2], "map": True}),
    Command("axis_list_edit", 1, request={"operation": "INSERT", "axis": 2, "after_axis": 3}),
    Command("position_set", 0, request={"actual": [5.0, 6.0], "command": [5.0, 6.0]}),
    Command("event_notify_set", 0, request={"event_types": ["MOTION"]}),
    Command("gate_set", request={"gate": 1, "closed": True}),
    Command("io_set", request={"space": "IO", "index": 1, "value": 5, "mask": -1}),
    Command("axis_config_set", axis=2, request={"in_position": {"settling_time": 0.1, "position_coarse": 10,
                                                                "settle_on_stop": True}}),
    Command("axis_position_set", axis=3, request={"which": "ORIGIN", "value": 7.0}),
]


def _fields(request, path=()):
    """Every path into a request (its fields, nested ones and list elements)."""
    for key, value in (request.items() if isinstance(request, dict) else enumerate(request)):
        yield (*path, key)
        if isinstance(value, (dict, list)):
            yield from _fields(value, (*path, key))


def _with(request, path, value):
    out = copy.deepcopy(request)
    node = out
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return out


def test_a_request_that_cannot_be_read_is_the_users_error(ctl, caplog):
    # issue 9: only request-parsing errors are PARAM_INVALID. Every field of every operation given a
    # value of the wrong kind: answered with a refusal (PARAM_INVALID or the spec's message for
    # that field), never an internal error, never an exception, and the clock runs on.
    for command in REQUESTS:
        variants = [None] + [_with(command.request, p, w) for p in _fields(command.request) for w in WEIRD]
        for request in variants:
            fresh = config.load().build_controller()
            reply = apply(fresh, Command(command.operation, command.supervisor, command.axis, request))
            assert reply.message is not INTERNAL_ERROR, (command.operation, request, reply.detail)
            fresh.step(50)
    assert not [r for r in caplog.records if r.name == "mpi_ros.commands"]


@pytest.mark.parametrize("exception", [ZeroDivisionError("float division by zero"), TypeError("bad operand"),
                                       ValueError("math domain error"), KeyError("axis")])
def test_a_bug_is_an_internal_error_logged_with_its_traceback(ctl, monkeypatch, caplog, exception):
    # issue 9: commands.apply turned TypeError/ValueError into PARAM_INVALID (the user's fault) and
    # let anything else through (the execute callback raised). A bug is answered with a distinct
    # message (MPIMessageNO_MEMORY, docs/decisions.md), logged with its traceback, and the
    # controller takes the next command.
    ms = ctl.supervisor(0)

    def planner_bug(*args, **kwargs):
        raise exception

    monkeypatch.setattr(ms, "command", planner_bug)
    with caplog.at_level(logging.ERROR, logger="mpi_ros.commands"):
        reply = apply(ctl, Command("motion_start", 0, request=GOAL))
    assert reply.message is INTERNAL_ERROR is Message.MPIMessageNO_MEMORY
    assert reply.message is not Message.MPIMessagePARAM_INVALID
    assert "internal error" in reply.detail
    assert type(exception).__name__ in reply.detail
    assert reply.state is MPIState.IDLE
    assert not reply.accepted
    records = [r for r in caplog.records if r.name == "mpi_ros.commands"]
    assert len(records) == 1
    assert records[0].exc_info
    assert records[0].exc_info[1] is exception
    monkeypatch.undo()
    _goal_runs_to_idle(ctl)


def test_no_refusal_answers_the_internal_error_message():
    # the internal-error message is distinct: nothing in the controller answers NO_MEMORY itself
    # (MPI 000 lists it only for mpiMotionAxisAppend: "Not enough memory was available")
    import pathlib

    controller = pathlib.Path(__file__).resolve().parent.parent / "mpi_ros" / "mpi"
    users = [p.name for p in controller.rglob("*.py") if "NO_MEMORY" in p.read_text(encoding="utf-8")]
    assert users == ["messages.py"]


def test_every_operation_has_one_handler_and_keeps_its_recorded_name():
    assert set(OPERATIONS) == set(Operation)
    # a recording stores the value: a command read back from JSON finds its handler
    assert Command.from_json("motion_start", 0, -1, "{}").operation == Operation.MOTION_START
