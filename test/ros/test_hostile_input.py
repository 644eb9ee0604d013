"""Hostile input through ROS (issue 14, "Hostile input"): seeded fuzzed MotionStart/MotionModify
goals and service requests to a running suite, every attribute on every motion type, requests
of 1,000,000 values and strings of 100 kB. Each is answered within a bound with one of the
reference's messages, a refused one changes nothing (states, positions, settings compared
before and after), and the suite keeps serving. The generator and the checks are in
hostile_input.py; bench/fuzz.py runs the same with 10,000 requests and measures the memory of
`mpi-ros run` (bench/RESULTS.md).

Size: a request of more than params.MAX_REQUEST_VALUES array elements or params.MAX_REQUEST_TEXT
characters is refused (MPIMessagePARAM_INVALID, "request too large") before any of it is read,
and the commands topic (reliable, transient local, 1000 deep) carries it compacted: a refused
1,000,000-value goal used to leave its whole request there as JSON, megabytes each.
"""

from __future__ import annotations

import array
import json
import threading

import pytest

from .conftest import WAIT
from .hostile_input import HUGE_MESSAGES, HUGE_NUMBERS, HUGE_TEXT, Fuzzer, Harness, Request, Tally

SEED = 14
FUZZED = 200  # requests in the normal suite (bench/fuzz.py: 10,000)
TOO_LARGE = "request too large"


# A suite per test: rclpy's action servers keep every goal for 900 s (result_timeout) and
# publish the status of all of them at each goal's every change, so a goal's round trip grows
# with the goals before it (about 30 ms after 500 goals, 200 ms after 3,000, on two cores).
@pytest.fixture
def hostile_suite(ros_context):
    from mpi_ros import config
    from mpi_ros.ros.suite import Suite

    suite = Suite(config.load(), time_scale=None, context=ros_context)
    suite.start(spin_in_thread=True)
    try:
        yield suite
    finally:
        suite.shutdown()


@pytest.fixture
def harness(hostile_suite, ros_context):
    harness = Harness(hostile_suite, ros_context, bound=WAIT)
    try:
        yield harness
    finally:
        harness.close()


def _report(tally: Tally) -> str:
    return "\n".join(tally.failures[:25]) + (f"\n... {len(tally.failures)} in all" if len(tally.failures) > 25 else "")


def test_seeded_fuzzed_goals_and_service_requests_through_ros(harness):
    fuzzer = Fuzzer(SEED)
    for _ in range(FUZZED):
        harness.send(fuzzer.request())
    tally = harness.tally
    assert not tally.failures, _report(tally)
    assert tally.goals == tally.results, "a goal ended without a result"
    # the seed exercises both sides, huge fields included
    assert tally.refused > 50, tally
    assert tally.accepted > 20, tally
    assert tally.huge >= 2, tally
    harness.alive()


def _expected(request: Request, firmware_option_21: bool) -> str | None:
    """What MPI 000 mpiMotionStart answers first for the request's type and attribute, from
    IDLE (check_type, then the ATTRIBUTE_INVALID lists); None when both pass."""
    from mpi_ros import requests as rq
    from mpi_ros.mpi.base.types import MotionAttr
    from mpi_ros.mpi.planning import validate
    from mpi_ros.ros import convert

    parsed = rq.motion_request(convert.to_dict(request.message))
    for verdict in (validate.check_type(parsed.type, False, firmware_option_21, MotionAttr.APPEND in parsed.attributes),
                    validate.check_attributes(parsed.type, parsed.attributes, parsed.params, False)):
        if not verdict.ok:
            return verdict.message.name
    return None


def test_every_attribute_on_every_motion_type_through_ros(harness, hostile_suite):
    """Each of the 27 attributes (the path attributes BEHAVIOR .. NO_WAIT included) on each of
    the 16 motion types (PT .. BSPLINE2 and FRAME included), with the data they read."""
    option_21 = hostile_suite.controller.config.firmware_option_21
    requests = Fuzzer(SEED, clean=True).matrix()
    assert len(requests) == 16 * 27
    for request in requests:
        request.expect = _expected(request, option_21)
        harness.send(request)
    tally = harness.tally
    assert not tally.failures, _report(tally)
    assert tally.goals == tally.results == len(requests)
    assert tally.messages["MPIMotionMessageATTRIBUTE_INVALID"] > 100, tally.messages
    assert tally.accepted > 50, tally.messages
    harness.alive()


def _huge_requests() -> list[Request]:
    from std_srvs.srv import Trigger  # noqa: F401 - the Trigger services carry no request

    from mpi_ros.action import MotionModify, MotionStart
    from mpi_ros.msg import Frame, MotionConfig, MotionParams, Trajectory
    from mpi_ros.srv import (
        AxisListSet,
        AxisPositionSet,
        EventNotifySet,
        IoSet,
        MotionAction,
        MotionConfigSet,
        MotionParamsSet,
        PositionSet,
    )

    numbers = array.array("d", [1.0]) * HUGE_NUMBERS
    text = "S" * HUGE_TEXT
    trajectory = [Trajectory(velocity=1000.0, acceleration=10000.0, deceleration=10000.0)]
    return [
        Request("start", "ms0/motion_start", MotionStart.Goal(type="S_CURVE", position=numbers,
                                                              trajectory=trajectory), "1M positions"),
        Request("start", "ms0/motion_start", MotionStart.Goal(type="PT", position=array.array("d", [0.0]) * 2,
                                                              time=numbers), "PT, 1M times"),
        Request("modify", "ms0/motion_modify", MotionModify.Goal(type="S_CURVE", position=numbers,
                                                                 trajectory=trajectory), "modify, 1M positions",
                state="MOVING"),
        Request("start", "ms0/motion_start", MotionStart.Goal(type="FRAME", frames=[Frame(time=0.001)] * HUGE_MESSAGES),
                "100k frames"),
        Request("start", "ms0/motion_start", MotionStart.Goal(type=text), "a type of 100 kB"),
        Request("start", "ms0/motion_start", MotionStart.Goal(type="S_CURVE", attributes=["DELAY"] * HUGE_MESSAGES),
                "100k attributes"),
        Request("start", "ms0/motion_start", MotionStart.Goal(type="S_CURVE", event_mask=[text]), "an event of 100 kB"),
        Request("service", "ms0/action", MotionAction.Request(action=text), "an action of 100 kB"),
        Request("service", "ms0/position_set", PositionSet.Request(actual=numbers, command=numbers), "1M positions"),
        Request("service", "ms0/axis_list_set", AxisListSet.Request(axis_numbers=array.array("i", [0]) * HUGE_NUMBERS),
                "1M axes"),
        Request("service", "ms0/params_set", MotionParamsSet.Request(params=MotionParams(feedforward=numbers)),
                "params with 1M feedforward values"),
        Request("service", "ms0/config_set", MotionConfigSet.Request(config=MotionConfig(
            decel_time_stop=0.5, decel_time_e_stop=0.05, normal_feedrate=1.0, user_label=text)), "a label of 100 kB"),
        Request("service", "ms0/event_notify_set", EventNotifySet.Request(event_types=["ALL"] * HUGE_MESSAGES),
                "100k event types"),
        Request("service", "axis1/position_set", AxisPositionSet.Request(which=text, value=1.0), "which of 100 kB"),
        Request("service", "io_set", IoSet.Request(space=text, index=0, value=1), "an I/O space of 100 kB"),
    ]


def test_huge_requests_are_refused_at_once_by_the_size_limit(harness):
    for request in _huge_requests():
        request.huge = True
        request.expect = "MPIMessagePARAM_INVALID"
        outcome = harness.send(request)
        assert outcome.refused, request.label
        if request.kind != "service":
            assert outcome.detail.startswith(TOO_LARGE), (request.label, outcome.detail)
    tally = harness.tally
    assert not tally.failures, _report(tally)
    assert tally.slowest < WAIT, tally.slowest_label
    harness.alive()


def test_axis_list_set_and_map_is_all_or_nothing(harness):
    """Found by the fuzzer (seed 1): axis_list_set with an empty list and map true set the list,
    then answered MAP's refusal (MEIMotionMessageNO_AXES_MAPPED, "the axis list is empty"):
    refused, yet the supervisor had changed. Now the refusal changes nothing."""
    from mpi_ros.srv import AxisListSet

    for numbers in ([], [0, 1, 2]):
        request = Request("service", "ms0/axis_list_set", AxisListSet.Request(axis_numbers=numbers, map=True),
                          f"axis_list_set {numbers}, map", state="ERROR" if numbers else "IDLE")
        if not numbers:
            request.expect = "MEIMotionMessageNO_AXES_MAPPED"
        harness.send(request)
    assert not harness.tally.failures, _report(harness.tally)


def _collect_commands(node):
    """Subscribe to /mpi/commands as a recorder joining late would (transient local, 1000
    deep): the messages received, and a condition notified on each."""
    from mpi_ros import graph_names
    from mpi_ros.msg import Command as CommandMsg
    from mpi_ros.qos import profile

    received: list = []
    arrived = threading.Condition()

    def on_command(msg) -> None:
        with arrived:
            received.append(msg)
            arrived.notify_all()

    subscription = node.create_subscription(CommandMsg, graph_names.COMMANDS.name(), on_command,
                                            profile(graph_names.COMMANDS_QOS))
    return subscription, received, arrived


def test_a_refused_huge_request_leaves_only_its_size_on_the_commands_topic(harness, hostile_suite):
    """What the commands topic (and a recording) keeps of a request refused for its size: its
    small fields and the sizes of its large ones, which replayed are refused again."""
    from mpi_ros import config
    from mpi_ros.commands import Command, apply

    node = harness.node
    subscription, received, arrived = _collect_commands(node)
    try:
        requests = _huge_requests()
        for request in requests:
            harness.send(request)
        with arrived:
            assert arrived.wait_for(lambda: sum('"omitted_' in m.request for m in received) >= len(requests), WAIT), (
                "the refused requests did not all reach the commands topic compacted")
        compacted = [m for m in received if '"omitted_' in m.request]
        ctl = config.load().build_controller()
        for msg in compacted:
            assert len(msg.request) < 1000, msg.request[:200]
            assert msg.message == "MPIMessagePARAM_INVALID"
            # replayed from the record, the same refusal
            reply = apply(ctl, Command.from_json(msg.operation, msg.supervisor, msg.axis, msg.request))
            assert (reply.message.name, reply.detail.split(":")[0]) == (msg.message, TOO_LARGE), reply.detail
        position = next(json.loads(m.request) for m in compacted if m.operation == "motion_start"
                        and json.loads(m.request).get("type") == "S_CURVE" and "position" in json.loads(m.request))
        assert position["position"] == {"omitted_values": HUGE_NUMBERS}
    finally:
        node.destroy_subscription(subscription)

    # A recorder joining now gets the topic's whole history: small, however huge the refused input.
    subscription, history, arrived = _collect_commands(node)
    try:
        with arrived:
            arrived.wait_for(lambda: len(history) >= min(harness.commands, 1000), WAIT)
        assert len(history) >= min(harness.commands, 1000)
        sizes = sorted(len(m.request) for m in history)
        assert sizes[-1] < 100_000, (sizes[-5:], sum(sizes))
        assert sum(sizes) < 4_000_000, (sizes[-5:], sum(sizes))
    finally:
        node.destroy_subscription(subscription)


def test_refused_huge_goals_leave_no_memory_behind(harness):
    """tracemalloc over refused 1,000,000-value goals: nothing of them stays (each is 8 MB)."""
    import gc
    import tracemalloc

    from mpi_ros.action import MotionStart

    def refused_goal() -> Request:
        goal = MotionStart.Goal(type="S_CURVE", position=array.array("d", [2.0]) * HUGE_NUMBERS)
        return Request("start", "ms0/motion_start", goal, "1M positions", expect="MPIMessagePARAM_INVALID")

    harness.send(refused_goal())  # first-time allocations (caches, pools) before measuring
    gc.collect()
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        for _ in range(4):
            harness.send(refused_goal())
        gc.collect()
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert not harness.tally.failures, _report(harness.tally)
    assert grown < 4_000_000, f"{grown / 1e6:.1f} MB kept after 4 refused goals of 8 MB"
