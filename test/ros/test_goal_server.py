"""GoalServer on the graph: an action server like any other, with the protocol's cancel
policy and status topic (mpi_ros/ros/goal_server.py, goal_table.py; in-process)."""

from __future__ import annotations

import threading
import uuid

from action_msgs.msg import GoalStatus, GoalStatusArray
from action_msgs.srv import CancelGoal
from rclpy._rclpy_pybind11 import RCLError
from rclpy.action.graph import get_action_server_names_and_types_by_node
from rclpy.qos import qos_profile_action_status_default

from .conftest import WAIT
from .test_supervisor_node import move

CANCEL = "/mpi/ms0/motion_start/_action/cancel_goal"


def cancel(probe, request: CancelGoal.Request) -> CancelGoal.Response:
    """A cancel request from a new client of ms0's MotionStart, answered.

    First a cancel naming no goal the server knows (answered ERROR_UNKNOWN_GOAL_ID; it changes
    nothing), sent again each second until answered: a new client's first request to a server
    in another process (the goal front) can be answered before that process has matched the
    client's response reader, and the answer is then lost (docs/reliability.md, "A client's
    first goal and the middleware's discovery"). Then ``request``, once."""
    client = probe.create_client(CancelGoal, CANCEL)
    try:
        assert client.wait_for_service(timeout_sec=WAIT), f"service {CANCEL} not available"
        unknown = CancelGoal.Request()
        unknown.goal_info.goal_id.uuid = list(uuid.uuid4().bytes)
        assert answer(client, unknown, tries=int(WAIT)).return_code == CancelGoal.Response.ERROR_UNKNOWN_GOAL_ID
        return answer(client, request, tries=1, timeout=WAIT)
    finally:
        probe.destroy_client(client)


def answer(client, request, tries: int, timeout: float = 1.0):
    """``request``'s answer, sent up to ``tries`` times, ``timeout`` s apart, until answered."""
    answers: list = []
    answered = threading.Event()

    def on_answer(future) -> None:
        answers.append(future.result())
        answered.set()

    for _ in range(tries):
        client.call_async(request).add_done_callback(on_answer)
        if answered.wait(timeout):
            return answers[0]
    raise AssertionError(f"no answer from {client.srv_name}")


def action_servers(probe, node: str, count: int) -> list:
    """The action servers the graph says ``/mpi/<node>`` holds, once it says ``count`` (or after WAIT)."""
    found: list = []
    event = threading.Event()
    for _ in range(int(WAIT / 0.05)):
        try:
            found = sorted(get_action_server_names_and_types_by_node(probe, node, "/mpi"))
        except RCLError:  # the node is not discovered yet (a node of another process)
            found = []
        if len(found) == count or event.wait(0.05):  # discovery on this host: wait on it, not for a fixed time
            break
    return found


def test_the_graph_sees_each_supervisors_action_servers(suite, probe):
    found = action_servers(probe, "ms0", 2)
    assert found == [("/mpi/ms0/motion_modify", ["mpi_ros/action/MotionModify"]),
                     ("/mpi/ms0/motion_start", ["mpi_ros/action/MotionStart"])]


def test_cancel_every_goal_cancels_the_running_one(suite, client, applied, drive, probe):
    goal = client.start(move([20000.0, 0.0]))
    applied.wait(1)
    drive(lambda: suite.runner.ctl.axes[0].cmd_v > 1000.0)
    answers: list = []
    asked = threading.Thread(target=lambda: answers.append(
        cancel(probe, CancelGoal.Request())))
    asked.start()
    drive(lambda: goal.done)
    asked.join(WAIT)
    (response,) = answers
    assert response.return_code == CancelGoal.Response.ERROR_NONE
    assert [bytes(info.goal_id.uuid) for info in response.goals_canceling] == [bytes(goal.handle.goal_id.uuid)]
    goal.wait(raise_on_error=False)
    assert goal.handle.status == GoalStatus.STATUS_CANCELED
    assert applied.commands[1][1].request == {"action": "STOP"}


def test_cancel_requests_naming_no_goal_get_the_protocols_codes(suite, client, applied, drive, probe):
    unknown = CancelGoal.Request()
    unknown.goal_info.goal_id.uuid = [7] * 16
    assert cancel(probe, unknown).return_code == (
        CancelGoal.Response.ERROR_UNKNOWN_GOAL_ID)
    goal = client.start(move([10.0, 0.0]))
    applied.wait(1)
    drive(lambda: goal.done)
    goal.wait()
    ended = CancelGoal.Request()
    ended.goal_info.goal_id = goal.handle.goal_id
    assert cancel(probe, ended).return_code == (
        CancelGoal.Response.ERROR_GOAL_TERMINATED)
    # nothing left to cancel: every goal named (none) -> rejected
    assert cancel(probe, CancelGoal.Request()).return_code == (
        CancelGoal.Response.ERROR_REJECTED)


def test_a_late_subscriber_gets_the_status_of_every_goal_kept(suite, client, applied, drive, probe):
    goal = client.start(move([10.0, 0.0]))
    applied.wait(1)
    drive(lambda: goal.done)
    goal.wait()
    arrays: list = []
    got = threading.Event()

    def on_array(msg):
        arrays.append(msg)
        got.set()

    # transient local, as action clients subscribe: the last array published is delivered on joining
    probe.create_subscription(GoalStatusArray, "/mpi/ms0/motion_start/_action/status", on_array,
                              qos_profile_action_status_default)
    assert got.wait(WAIT), "no status array"
    statuses = {bytes(s.goal_info.goal_id.uuid): s.status for s in arrays[-1].status_list}
    assert statuses == {bytes(goal.handle.goal_id.uuid): GoalStatus.STATUS_SUCCEEDED}


def test_a_closed_client_leaves_the_graph(suite, ros_context):
    """MotionClient.close destroys its action clients too: the node's destroy_node leaves them,
    with their feedback subscriptions, on the graph while the client object lives, and the
    lost-client watchdog would count a closed client as present."""
    from mpi_ros.client import MotionClient

    topic = "/mpi/ms1/motion_start/_action/feedback"
    node = suite.supervisor_nodes[1]
    client = MotionClient(1, context=ros_context, timeout=WAIT, node_name="test_closed_client")
    assert client.wait_for_server(WAIT)
    assert "test_closed_client" in [info.node_name for info in node.get_subscriptions_info_by_topic(topic)]
    client.close()
    gone = threading.Event()
    for _ in range(int(WAIT / 0.05)):  # the graph's update: waited on, not for a fixed time
        if "test_closed_client" not in [info.node_name for info in node.get_subscriptions_info_by_topic(topic)]:
            gone.set()
            break
        gone.wait(0.05)
    assert gone.is_set(), "a closed client's feedback subscription is still on the graph"  # (``client`` still held)
