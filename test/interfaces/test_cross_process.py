"""A goal (with feedback), a service call and a topic message cross between two processes over
DDS (rmw_fastrtps_cpp) with mpi_ros's own types, under the contract's endpoint names.

The peer (dds_peer.py) runs in a child process with the same environment (same ROS_DOMAIN_ID,
from conftest). This side spins a single-threaded executor from the test thread, waiting on
futures with timeouts: no sleeps, no second spinning thread (ActionClient registers a goal's
future only after sending, so a reply can race a concurrently spinning thread).
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

PEER = Path(__file__).with_name("dds_peer.py")
TIMEOUT = 30.0  # seconds, for each wait; discovery normally takes well under one


class Peer:
    def __init__(self):
        self.proc = subprocess.Popen(
            [sys.executable, "-P", str(PEER)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            env=dict(os.environ), text=True)
        self.ready = threading.Event()
        self.lines: list[str] = []
        self.stderr = ""
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        self._err_reader = threading.Thread(target=self._read_err, daemon=True)
        self._err_reader.start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))
            if line.strip() == "READY":
                self.ready.set()
        self.ready.set()  # EOF: the peer died; the test reports it

    def _read_err(self):
        self.stderr = self.proc.stderr.read()

    def close(self, timeout: float = TIMEOUT) -> int:
        if self.proc.stdin and not self.proc.stdin.closed:
            self.proc.stdin.close()
        try:
            return self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait(timeout=timeout)
            raise

    def describe(self) -> str:
        self._err_reader.join(timeout=1.0)
        return f"peer stdout={self.lines!r}\npeer stderr=\n{self.stderr}"


@pytest.fixture
def peer():
    p = Peer()
    try:
        yield p
    finally:
        if p.proc.poll() is None:
            p.proc.kill()
            p.proc.wait(timeout=TIMEOUT)


def spin_until(executor, future, what: str, timeout: float = TIMEOUT):
    executor.spin_until_future_complete(future, timeout_sec=timeout)
    assert future.done(), f"timed out after {timeout} s waiting for {what}"
    return future.result()


def test_goal_service_and_topic_cross_processes(ros_context, peer):
    import rclpy
    from rclpy.action import ActionClient
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.task import Future

    from mpi_ros.action import MotionStart
    from mpi_ros.msg import AxisStatus, Trajectory
    from mpi_ros.srv import MotionAction

    assert peer.ready.wait(TIMEOUT), "peer did not start\n" + peer.describe()
    assert peer.proc.poll() is None, "peer exited early\n" + peer.describe()

    node = rclpy.create_node("cross_process_test", context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    try:
        # Topic: the first AxisStatus from the other process.
        status_future = Future()

        def on_status(msg):
            if not status_future.done():
                status_future.set_result(msg)

        node.create_subscription(AxisStatus, "/mpi/axis0/status", on_status, 10)
        status = spin_until(executor, status_future, "/mpi/axis0/status")
        assert status.number == 0
        assert status.state_name == "IDLE"
        assert status.command_position == 12.5
        assert status.sample >= 1

        # Action: send a goal written as the README's send_goal example, with feedback.
        client = ActionClient(node, MotionStart, "/mpi/ms0/motion_start")
        service = node.create_client(MotionAction, "/mpi/ms0/action")
        server_ready = Future()

        def poll_servers():
            if client.server_is_ready() and service.service_is_ready() and not server_ready.done():
                server_ready.set_result(True)

        poll = node.create_timer(0.02, poll_servers)
        spin_until(executor, server_ready, "the action server and the service")
        poll.cancel()

        goal = MotionStart.Goal()
        goal.type = "S_CURVE"
        goal.position = [1000.0, 0.0]
        goal.trajectory = [Trajectory(velocity=500.0, acceleration=5000.0,
                                      deceleration=5000.0, jerk_percent=50.0)]
        feedback_future = Future()

        def on_feedback(msg):
            if not feedback_future.done():
                feedback_future.set_result(msg.feedback)

        goal_handle = spin_until(
            executor, client.send_goal_async(goal, feedback_callback=on_feedback), "goal response")
        assert goal_handle.accepted
        result_future = goal_handle.get_result_async()

        feedback = spin_until(executor, feedback_future, "feedback")
        assert feedback.state_name == "MOVING"
        assert list(feedback.command_position) == [1000.0, 0.0]

        # Service: MotionAction; the peer ends the goal when it answers.
        response = spin_until(
            executor, service.call_async(MotionAction.Request(action="STOP")), "service response")
        assert response.message == "MPIMessageOK"
        assert response.code == 0
        assert response.state_name == "after STOP"
        assert response.sample == 42

        wrapped = spin_until(executor, result_future, "goal result")
        from action_msgs.msg import GoalStatus
        assert wrapped.status == GoalStatus.STATUS_SUCCEEDED
        result = wrapped.result
        assert result.message == "MPIMessageOK"
        assert result.state_name == "IDLE"
        assert list(result.actual_position) == [1000.0, 0.0]
        assert result.detail == "S_CURVE with 1 trajectory element(s)"

        client.destroy()
        node.destroy_client(service)
    finally:
        executor.shutdown(timeout_sec=5.0)
        node.destroy_node()

    assert peer.close() == 0, "peer did not shut down cleanly\n" + peer.describe()
    assert peer.lines[-1] == "BYE", peer.describe()
