"""The goal front (ros.goal_process; mpi_ros/ros/goal_front.py): the action servers' services in
a process of their own. To clients nothing changes but the node that holds the services: the
goal protocol's tests of test_goal_server.py and a choice of the goal tests of
test_supervisor_node.py (one of each way a goal ends: done, refused, E-stopped, cancelled,
modified; two supervisors at once) run here again with the front, and the front's own life is
tested (it starts with the suite, ends with it, and ends when the suite is killed). Each test
starts a front (a fresh interpreter) and its clients wait for a round trip to it: a few
seconds each, so not every goal test runs twice."""

from __future__ import annotations

import contextlib
import signal
import subprocess
import sys
import threading
import uuid
from types import SimpleNamespace

import pytest
from action_msgs.msg import GoalStatus
from rclpy._rclpy_pybind11 import RCLError

from mpi_ros.action import MotionStart
from mpi_ros.ros import goal_endpoints
from mpi_ros.ros.goal_front import GoalRelay

from . import test_goal_server as protocol
from . import test_supervisor_node as goals
from .conftest import WAIT


@pytest.fixture
def suite_config():
    from mpi_ros import config

    return config.load(overrides={"ros": {"goal_process": True}})


# -- plain values (no graph) ----------------------------------------------------------------------
def test_requests_become_plain_values():
    key = uuid.uuid4().bytes
    request = MotionStart.Impl.SendGoalService.Request()
    request.goal_id.uuid = list(key)
    request.goal.type = "S_CURVE"
    request.goal.position = [1.0, 2.0]
    plain_key, goal = goal_endpoints.plain_request("goal", request)
    assert plain_key == key
    assert goal["type"] == "S_CURVE"
    assert goal["position"] == [1.0, 2.0]

    cancel = MotionStart.Impl.CancelGoalService.Request()
    cancel.goal_info.goal_id.uuid = list(key)
    cancel.goal_info.stamp.sec, cancel.goal_info.stamp.nanosec = 3, 4
    assert goal_endpoints.plain_request("cancel", cancel) == (key, 3_000_000_004)

    result = MotionStart.Impl.GetResultService.Request()
    result.goal_id.uuid = list(key)
    assert goal_endpoints.plain_request("result", result) == key


def test_responses_are_built_from_plain_values():
    accepted = goal_endpoints.response_message(MotionStart, "goal", (True, 5_000_000_006))
    assert accepted.accepted
    assert (accepted.stamp.sec, accepted.stamp.nanosec) == (5, 6)
    assert not goal_endpoints.response_message(MotionStart, "goal", (False, None)).accepted

    key = uuid.uuid4().bytes
    cancel = goal_endpoints.response_message(MotionStart, "cancel", (0, [(key, 7_000_000_008)]))
    (info,) = cancel.goals_canceling
    assert cancel.return_code == 0
    assert bytes(info.goal_id.uuid) == key
    assert (info.stamp.sec, info.stamp.nanosec) == (7, 8)

    result = goal_endpoints.response_message(MotionStart, "result",
                                             (GoalStatus.STATUS_SUCCEEDED, MotionStart.Result(message="MPIMessageOK")))
    assert result.status == GoalStatus.STATUS_SUCCEEDED
    assert result.result.message == "MPIMessageOK"


def test_a_goal_that_cannot_be_read_is_carried_as_its_error():
    """An internal error reading a goal goes to the goal's result (aborted), not up the loop."""
    request = SimpleNamespace(goal_id=SimpleNamespace(uuid=[0] * 16), goal=object())  # no message: reading fails
    key, goal = goal_endpoints.plain_request("goal", request)
    assert key == bytes(16)
    assert isinstance(goal, AttributeError)


# -- the front on the graph ------------------------------------------------------------------------
def test_the_graph_still_names_each_supervisor_as_its_action_server(suite, probe):
    """rcl's graph finds an action server by its status and feedback publishers, which stay on
    the supervisor's node: ``ros2 action info`` names ms<n> as before."""
    protocol.test_the_graph_sees_each_supervisors_action_servers(suite, probe)


def test_the_services_are_the_fronts(suite, probe):
    wanted = {f"/mpi/ms{n}/{action}/_action/{service}" for n in (0, 1) for action in ("motion_start", "motion_modify")
              for service in ("send_goal", "cancel_goal", "get_result")}
    held: set[str] = set()
    event = threading.Event()
    for _ in range(int(WAIT / 0.05)):  # discovery of another process's node: wait on it, not for a fixed time
        with contextlib.suppress(RCLError):  # not discovered yet
            held = {name for name, _ in probe.get_service_names_and_types_by_node("goal_front", "/mpi")}
        if wanted <= held or event.wait(0.05):
            break
    assert wanted <= held
    ms0 = [name for name, _ in probe.get_service_names_and_types_by_node("ms0", "/mpi")]
    assert "/mpi/ms0/action" in ms0
    assert not [name for name in ms0 if "/_action/" in name]


def test_the_front_ends_with_the_suite(ros_context, suite_config):
    from mpi_ros.ros.suite import Suite

    running = Suite(suite_config, time_scale=None, context=ros_context)
    running.start(spin_in_thread=True)
    relay = running.goal_loop
    assert isinstance(relay, GoalRelay)
    assert relay.front_alive()
    front = relay.front_pid
    running.shutdown()
    assert not relay.front_alive()
    assert not _running(front)


_KILLED_SUITE = """
import sys
from mpi_ros import config
from mpi_ros.ros.suite import Suite
import rclpy
rclpy.init()
suite = Suite(config.load(overrides={"ros": {"goal_process": True, "namespace": "/killed"}}), time_scale=None)
suite.start(spin_in_thread=True)
print(suite.goal_loop.front_pid, flush=True)
sys.stdin.read()  # until killed
"""


def test_the_front_ends_when_the_suite_is_killed():
    # its own namespace: the killed suite's endpoints stay on the graph until its lease ends
    suite = subprocess.Popen([sys.executable, "-P", "-c", _KILLED_SUITE], stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True)
    try:
        line = suite.stdout.readline()
        assert line.strip().isdigit(), f"the suite did not start its front: {line!r}"
        front = int(line)
        suite.send_signal(signal.SIGKILL)
        suite.wait(WAIT)
        ended = threading.Event()
        for _ in range(int(WAIT / 0.05)):
            if not _running(front) or ended.wait(0.05):
                break
        assert not _running(front), "the goal front outlived its suite"
    finally:
        suite.kill()
        suite.wait(WAIT)


def _running(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] != "Z"  # a zombie has ended
    except FileNotFoundError:
        return False


# -- the goal protocol, through the front ---------------------------------------------------------
def test_cancel_every_goal_cancels_the_running_one(suite, client, applied, drive, probe):
    protocol.test_cancel_every_goal_cancels_the_running_one(suite, client, applied, drive, probe)


def test_cancel_requests_naming_no_goal_get_the_protocols_codes(suite, client, applied, drive, probe):
    protocol.test_cancel_requests_naming_no_goal_get_the_protocols_codes(suite, client, applied, drive, probe)


def test_a_late_subscriber_gets_the_status_of_every_goal_kept(suite, client, applied, drive, probe):
    protocol.test_a_late_subscriber_gets_the_status_of_every_goal_kept(suite, client, applied, drive, probe)


def test_a_result_request_for_an_unknown_goal_is_answered_unknown(suite, probe):
    """Sent again each second until answered: a new client's first request to another process
    can be answered before that process has matched the client's response reader, and the
    answer is then lost (docs/reliability.md, "A client's first goal and the middleware's
    discovery"); MotionClient.wait_for_server does the same."""
    request = MotionStart.Impl.GetResultService.Request()
    request.goal_id.uuid = list(uuid.uuid4().bytes)
    client = probe.create_client(MotionStart.Impl.GetResultService, "/mpi/ms0/motion_start/_action/get_result")
    assert client.wait_for_service(timeout_sec=WAIT)
    assert protocol.answer(client, request, tries=int(WAIT)).status == GoalStatus.STATUS_UNKNOWN
    probe.destroy_client(client)


# -- goals, through the front ----------------------------------------------------------------------
def test_move_reaches_target_and_succeeds_with_ok(suite, client, applied, drive):
    goals.test_move_reaches_target_and_succeeds_with_ok(suite, client, applied, drive)


def test_e_stop_mid_move_ends_goal_with_error_then_reset_returns_idle(suite, client, applied, drive, probe):
    goals.test_e_stop_mid_move_ends_goal_with_error_then_reset_returns_idle(suite, client, applied, drive, probe)


def test_modify_retargets_a_running_move(suite, client, applied, drive):
    goals.test_modify_retargets_a_running_move(suite, client, applied, drive)


def test_cancel_is_a_stop(suite, client, applied, drive):
    goals.test_cancel_is_a_stop(suite, client, applied, drive)


def test_a_bad_goal_gets_the_spec_message_and_changes_nothing(suite, client, applied):
    goals.test_bad_goals_get_the_spec_message_and_change_nothing(
        suite, client, applied, {**goals.S_CURVE, "position": [1.0]}, "MPIMessagePARAM_INVALID")


def test_two_supervisors_move_independently(suite, client, client1, applied, drive):
    goals.test_two_supervisors_move_independently(suite, client, client1, applied, drive)


def test_shutdown_ends_pending_goals_and_answers_them(ros_context, suite_config):
    """A goal running when the suite shuts down gets its result through the front before the
    front ends (the suite answers, then closes the pipe)."""
    from mpi_ros.client import MotionClient
    from mpi_ros.ros.suite import Suite

    running = Suite(suite_config, time_scale=None, context=ros_context)
    running.start(spin_in_thread=True)
    client = MotionClient(0, context=ros_context, timeout=WAIT, node_name="test_client_shutdown")
    try:
        assert client.wait_for_server(WAIT)
        goal = client.start(goals.move([20000.0, 0.0]))
        running.runner.step(200)
        running.shutdown()
        result = goal.wait(raise_on_error=False)
        assert result.message == "MPIMotionMessageSTOPPED"
        assert goal.handle.status == GoalStatus.STATUS_ABORTED
    finally:
        client.close()
