"""The size of a request (issue 14, "Hostile input"; docs/hostile-input.md): a request of more
than params.MAX_REQUEST_VALUES array elements or params.MAX_REQUEST_TEXT characters is refused
before any of it is read, and recorded compacted so that replay refuses it again. Without ROS:
test/ros/test_hostile_input.py sends the same through the suite."""

from __future__ import annotations

import json

import pytest

from mpi_ros import config
from mpi_ros import requests as rq
from mpi_ros.commands import Command, apply
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.params import MAX_REQUEST_TEXT, MAX_REQUEST_VALUES, shown
from mpi_ros.mpi.base.types import MPIState
from mpi_ros.mpi.planning.validate import MAX_PATH_VALUES

PARAM = Message.MPIMessagePARAM_INVALID
TOO_LARGE = "request too large"


@pytest.fixture
def ctl():
    return config.load().build_controller()


def _state(ctl) -> tuple:
    ms = ctl.supervisor(0)
    return (ms.state, tuple(ms.axis_list), tuple(ms.mapped), repr(ms.stored_params), repr(ms.config),
            tuple((a.cmd_p, a.act_p, a.origin) for a in ctl.axes))


@pytest.mark.parametrize(("operation", "request_"), [
    ("motion_start", {"type": "S_CURVE", "position": [1.0] * 1_000_000}),
    ("motion_start", {"type": "BOGUS", "position": [1.0] * (MAX_REQUEST_VALUES + 1)}),  # size first, then the type
    ("motion_modify", {"type": "PT", "position": [0.0] * 40_000, "time": [0.01] * 30_000}),  # the arrays together
    ("motion_start", {"type": "FRAME", "frames": [{"time": 0.001}] * 70_000}),
    ("motion_start", {"type": "S" * 100_000}),
    ("motion_start", {"type": "S_CURVE", "attributes": ["DELAY"] * 100_000}),
    ("motion_start", {"type": "S_CURVE", "event_mask": ["x" * 10_000, "y" * 10_000]}),  # the strings together
    ("params_set", {"params": {"feedforward": [0.0] * 1_000_000}}),
    ("config_set", {"config": {"user_label": "L" * 100_000}}),
    ("position_set", {"actual": [0.0] * 1_000_000, "command": [0.0, 0.0]}),
    ("axis_list_set", {"axis_numbers": [0] * 1_000_000}),
    ("event_notify_set", {"event_types": ["ALL"] * 100_000}),
    ("action", {"action": "STOP" * 25_000}),
])
def test_a_request_too_large_is_refused_before_it_is_read_and_changes_nothing(ctl, operation, request_):
    before = _state(ctl)
    reply = apply(ctl, Command(operation, 0, request=request_))
    assert reply.message is PARAM
    assert reply.detail.startswith(TOO_LARGE), reply.detail
    assert _state(ctl) == before


def test_the_detail_names_the_longest_array_or_string(ctl):
    reply = apply(ctl, Command("motion_start", 0, request={"type": "PT", "position": [0.0] * 1_000_000,
                                                            "time": [0.01] * 500_000}))
    assert reply.detail.startswith("request too large: 1,500,000 array elements (position has 1,000,000); at most "
                                   f"{MAX_REQUEST_VALUES:,} in one request"), reply.detail
    reply = apply(ctl, Command("config_set", 0, request={"config": {"user_label": "L" * 100_000}}))
    assert reply.detail.startswith("request too large: 100,000 characters of text (config.user_label has 100,000)")


def test_up_to_the_limit_a_request_is_read():
    size = rq.request_size({"type": "PT", "position": [0.0] * (MAX_REQUEST_VALUES - 1), "time": [0.01],
                            "attributes": ["x" * (MAX_REQUEST_TEXT - 2)]})
    assert (size.values, size.text, size.ok) == (MAX_REQUEST_VALUES + 1, MAX_REQUEST_TEXT, False)
    size = rq.request_size({"position": [0.0] * (MAX_REQUEST_VALUES - 1), "attributes": ["x" * (MAX_REQUEST_TEXT - 2)],
                            "type": "PT"})
    assert (size.values, size.text, size.ok) == (MAX_REQUEST_VALUES, MAX_REQUEST_TEXT, True)
    assert MAX_PATH_VALUES == MAX_REQUEST_VALUES  # one bound: a path request the size check lets in may be planned


def test_a_refused_huge_request_is_recorded_compacted_and_replays_to_the_same_refusal(ctl):
    request_ = {"type": "S_CURVE", "attributes": ["DELAY"], "position": [3.0] * 1_000_000, "delay": [0.0, 0.0],
                "hold": [{"type": "G" * 300}], "trajectory": [{"velocity": 1.0}]}
    command = Command("motion_start", 0, request=request_)
    reply = apply(ctl, command)
    recorded = command.to_json()
    assert len(recorded) < 300, recorded
    data = json.loads(recorded)
    assert data["position"] == {"omitted_values": 1_000_000}
    assert data["hold"] == [{"type": {"omitted_characters": 300}}]
    # the small fields are kept as they were
    assert (data["type"], data["attributes"], data["delay"], data["trajectory"]) == (
        "S_CURVE", ["DELAY"], [0.0, 0.0], [{"velocity": 1.0}])
    replayed = apply(config.load().build_controller(), Command.from_json("motion_start", 0, -1, recorded))
    assert (replayed.message, replayed.detail) == (reply.message, reply.detail)


def test_a_request_within_the_limit_is_recorded_whole():
    request_ = {"type": "PT", "position": [0.5] * 2000, "time": [0.01] * 1000, "attributes": ["x" * 300]}
    assert Command("motion_start", 0, request=request_).to_json() == json.dumps(request_, sort_keys=True,
                                                                                 separators=(",", ":"))


def test_a_marker_in_a_request_counts_as_what_it_stands_for(ctl):
    # a marker within the limits is no list: refused as unreadable, like any other mapping there
    reply = apply(ctl, Command("motion_start", 0, request={"type": "PT", "position": {"omitted_values": 4}}))
    assert reply.message is PARAM, reply.detail
    assert reply.detail.startswith("position: a list expected"), reply.detail
    assert not rq.request_size({"p": {"omitted_values": MAX_REQUEST_VALUES + 1}}).ok
    assert not rq.request_size({"p": {"omitted_characters": MAX_REQUEST_TEXT + 1}}).ok
    # not a marker: other keys, or a count that is not a count
    assert rq.request_size({"p": {"omitted_values": 10**9, "x": 1}}).ok
    assert rq.request_size({"p": {"omitted_values": True}}).ok


def test_any_nesting_is_measured_without_recursion(ctl):
    deep: list = []
    for _ in range(10_000):
        deep = [deep]
    size = rq.request_size({"position": deep})
    assert size.values == 10_000
    assert size.ok
    reply = apply(ctl, Command("motion_start", 0, request={"type": "S_CURVE", "position": deep}))
    assert reply.message is PARAM  # answered, not a RecursionError (an internal error)


def test_refusals_quote_values_cut_short(ctl):
    reply = apply(ctl, Command("motion_start", 0, request={"type": "Q" * 10_000}))
    assert reply.message is Message.MPIMotionMessageTYPE_INVALID, reply.detail
    assert len(reply.detail) < 200, reply.detail
    reply = apply(ctl, Command("config_set", 0, request={"config": {"user_label": "L" * 1000, "decel_time_stop": 0.5,
                                                                      "decel_time_e_stop": 0.05,
                                                                      "normal_feedrate": 1.0}}))
    assert reply.message is PARAM, reply.detail
    assert len(reply.detail) < 200, reply.detail
    assert shown(10**5000) == "<int>"
    assert shown(1e308) == "1e+308"
    assert shown("abc") == "'abc'"


def test_axis_list_set_and_map_is_all_or_nothing(ctl):
    """An empty list with map true: MAP has nothing to map and is refused; the list is kept."""
    ms = ctl.supervisor(0)
    reply = apply(ctl, Command("axis_list_set", 0, request={"axis_numbers": [], "map": True}))
    assert reply.message is Message.MEIMotionMessageNO_AXES_MAPPED
    assert (ms.axis_list, ms.mapped, ms.state) == ([0, 1], [0, 1], MPIState.IDLE)
    assert apply(ctl, Command("axis_list_set", 0, request={"axis_numbers": [], "map": False})).accepted
    assert ms.axis_list == []
