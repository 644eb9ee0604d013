"""How long the action servers keep an ended goal (ros.result_timeout): its result is answered
to a client that asks late, until the timeout; then the goal and its result are gone (rclpy
answers STATUS_UNKNOWN), so goals sent for hours do not pile up in the suite (issue 14's soak:
rclpy's own default keeps every goal 900 s and publishes the status of all it keeps at every
goal's change)."""

from __future__ import annotations

import threading
import time

import pytest
from action_msgs.msg import GoalStatus

from .conftest import WAIT

RESULT_TIMEOUT = 0.5  # s


@pytest.fixture
def suite_config():
    from mpi_ros import config

    return config.load(overrides={"ros": {"result_timeout": RESULT_TIMEOUT}})


def _late_result(client, goal) -> int:
    """Ask the server again for the goal's result, as a client that asks late does: its status."""
    future = client._on_executor(goal.handle.get_result_async)
    return client._wait_future(future, WAIT, "a late result request").status


def test_an_ended_goal_is_kept_for_result_timeout_then_released(suite, client, drive):
    server = suite.supervisor_nodes[0]._servers
    goal = client.start({"type": "VELOCITY", "trajectory": [{"velocity": 500.0, "acceleration": 50_000.0}]})
    drive(lambda: goal.done)
    assert goal.wait().detail == "at velocity"
    ended = time.monotonic()
    assert _late_result(client, goal) == GoalStatus.STATUS_SUCCEEDED  # kept: a late client gets it

    # the goal loop expires goals when the server's timer says; wait (bounded) until the goal is gone
    gone = threading.Event()
    deadline = ended + RESULT_TIMEOUT + WAIT
    while not gone.is_set() and time.monotonic() < deadline:
        if all(s.kept() == 0 for s in server.values()):
            gone.set()
        else:
            gone.wait(0.05)
    assert gone.is_set(), "the ended goal was still kept after result_timeout"
    assert time.monotonic() - ended >= RESULT_TIMEOUT * 0.9
    assert _late_result(client, goal) == GoalStatus.STATUS_UNKNOWN
