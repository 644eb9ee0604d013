"""The action protocol as every client sees it, from both servers (ros.action_server: the
batched server on rclpy's private bindings, goal_server.py; rclpy's stock ActionServer,
stock_goal_server.py): rclpy's own ActionClient, used the way Jazzy's `ros2 action
send_goal` uses it (wait for the server, send with a feedback callback, wait for the
answer, ask for the result, wait for it), accepts, rejects, cancels, asks for a result after
it expired, and reads the status array. Each test runs against both servers."""

from __future__ import annotations

import threading
from typing import Any

import pytest
from action_msgs.msg import GoalStatus, GoalStatusArray
from rclpy.action import ActionClient
from rclpy.qos import qos_profile_action_status_default

from mpi_ros.action import MotionStart

from .conftest import WAIT

RESULT_TIMEOUT = 1.0  # s; rclpy's ActionServer takes whole seconds
S_CURVE = {"type": "S_CURVE", "trajectory": [{"velocity": 5000.0, "acceleration": 50_000.0,
                                                "deceleration": 50_000.0, "jerk_percent": 50.0}]}


@pytest.fixture(params=["batched", "rclpy"])
def suite_config(request):
    from mpi_ros import config

    return config.load(overrides={"ros": {"action_server": request.param, "result_timeout": RESULT_TIMEOUT}})


def _done(future, what: str, drive=None) -> Any:
    """The future's result: waited for, or (``drive``) stepped until it is there."""
    if drive is not None:
        drive(future.done)
    event = threading.Event()
    future.add_done_callback(lambda _: event.set())
    assert event.wait(WAIT), f"no {what}"
    return future.result()


class SendGoal:
    """A goal sent as `ros2 action send_goal --feedback` sends it."""

    def __init__(self, probe, goal: dict):
        self.feedback: list = []
        self.client = ActionClient(probe, MotionStart, "/mpi/ms0/motion_start")
        assert self.client.wait_for_server(timeout_sec=WAIT), "no action server"
        message = MotionStart.Goal()
        for key, value in goal.items():
            setattr(message, key, _field(message, key, value))
        self.sent = self.client.send_goal_async(message, feedback_callback=self.feedback.append)

    def accepted(self, drive=None):
        return _done(self.sent, "answer to the goal", drive)

    def result(self, drive):
        handle = self.accepted(drive)
        assert handle.accepted, "the goal was rejected"
        return _done(handle.get_result_async(), "result", drive)


def _field(message, key: str, value):
    if key == "trajectory":
        from mpi_ros.msg import Trajectory

        return [Trajectory(**{k: float(v) for k, v in t.items()}) for t in value]
    if key == "position":
        return [float(v) for v in value]
    return value


def test_a_goal_is_accepted_runs_with_feedback_and_succeeds(suite, probe, drive):
    goal = SendGoal(probe, {**S_CURVE, "position": [2000.0, 0.0]})
    done = goal.result(drive)
    assert done.status == GoalStatus.STATUS_SUCCEEDED
    assert (done.result.message, done.result.state_name) == ("MPIMessageOK", "IDLE")
    assert list(done.result.command_position) == [2000.0, 0.0]
    assert goal.feedback, "no feedback while the goal ran"
    assert goal.feedback[-1].feedback.state_name in {"MOVING", "IDLE"}


def test_a_refused_command_is_accepted_then_aborted_with_the_reason(suite, probe, drive):
    goal = SendGoal(probe, {**S_CURVE, "position": [1.0, 2.0, 3.0]})  # ms0 has two axes
    done = goal.result(drive)
    assert done.status == GoalStatus.STATUS_ABORTED
    assert done.result.message == "MPIMessagePARAM_INVALID"
    assert suite.runner.read(lambda ctl: ctl.supervisor(0).state.name) == "IDLE"


def test_goals_are_rejected_while_the_suite_shuts_down(suite, probe, drive):
    suite.supervisor_nodes[0].shutdown(timeout=0.0)
    goal = SendGoal(probe, {**S_CURVE, "position": [10.0, 0.0]})
    assert not goal.accepted(drive).accepted


def test_a_cancelled_goal_stops_and_ends_cancelled(suite, probe, drive):
    goal = SendGoal(probe, {"type": "VELOCITY", "trajectory": [{"velocity": 500.0, "acceleration": 5000.0,
                                                                 "deceleration": 5000.0}]})
    handle = goal.accepted(drive)
    drive(lambda: suite.runner.read(lambda ctl: ctl.supervisor(0).state.name) == "MOVING")
    answer = _done(handle.cancel_goal_async(), "answer to the cancel")
    assert [bytes(g.goal_id.uuid) for g in answer.goals_canceling] == [bytes(handle.goal_id.uuid)]
    done = _done(handle.get_result_async(), "result", drive)
    assert done.status == GoalStatus.STATUS_CANCELED
    assert done.result.message == "MPIMotionMessageSTOPPED"
    assert suite.runner.read(lambda ctl: ctl.supervisor(0).state.name) == "STOPPED"


def test_a_result_asked_after_it_expired_is_unknown(suite, probe, drive):
    goal = SendGoal(probe, {**S_CURVE, "position": [10.0, 0.0]})
    handle = goal.accepted(drive)
    assert _done(handle.get_result_async(), "result", drive).status == GoalStatus.STATUS_SUCCEEDED
    expired = threading.Event()
    late = None
    for _ in range(int(3 * RESULT_TIMEOUT / 0.1) + int(WAIT / 0.1)):  # bounded: the timeout and then some
        late = _done(handle.get_result_async(), "late result")
        if late.status == GoalStatus.STATUS_UNKNOWN or expired.wait(0.1):
            break
    assert late is not None
    assert late.status == GoalStatus.STATUS_UNKNOWN


def test_the_status_array_shows_each_goal_to_its_end(suite, probe, drive):
    arrays: list = []
    seen = threading.Condition()

    def on_array(msg: GoalStatusArray) -> None:
        with seen:
            arrays.append({bytes(s.goal_info.goal_id.uuid): s.status for s in msg.status_list})
            seen.notify_all()

    probe.create_subscription(GoalStatusArray, "/mpi/ms0/motion_start/_action/status", on_array,
                              qos_profile_action_status_default)
    goal = SendGoal(probe, {**S_CURVE, "position": [10.0, 0.0]})
    handle = goal.accepted(drive)
    key = bytes(handle.goal_id.uuid)
    _done(handle.get_result_async(), "result", drive)
    with seen:
        assert seen.wait_for(lambda: any(a.get(key) == GoalStatus.STATUS_SUCCEEDED for a in arrays), WAIT)
    assert all(a.get(key) != GoalStatus.STATUS_ABORTED for a in arrays)
