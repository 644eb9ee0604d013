"""Goals hold no executor thread: with far more goals in flight than executor threads (32),
goal responses, gate_set and E_STOP are still answered at once, and every goal ends
(issue 9, "E_STOP starvation"; docs/quality.md, "Fast": an E_STOP is applied at the sample after
its request arrives, however many goals are in flight)."""

from __future__ import annotations

import statistics
import threading
import time
from collections import deque
from functools import partial

import pytest
from action_msgs.msg import GoalStatus, GoalStatusArray
from rclpy.qos import qos_profile_action_status_default

from .conftest import WAIT

LONG = 60.0  # seconds: the most a storm of several hundred goals may take to be answered
S_CURVE = {"type": "S_CURVE", "trajectory": [{"velocity": 2000.0, "acceleration": 20000.0,
                                               "deceleration": 20000.0, "jerk_percent": 50.0}]}
# A move that runs for hours at 100 counts/s: its goals stay in flight until E_STOP.
CRAWL = {"type": "S_CURVE", "trajectory": [{"velocity": 100.0, "acceleration": 1000.0,
                                             "deceleration": 1000.0, "jerk_percent": 50.0}]}
STEP = {"type": "TRAPEZOIDAL", "attributes": ["APPEND"],
        "trajectory": [{"velocity": 2000.0, "acceleration": 20000.0, "deceleration": 20000.0}]}


class GoalSender:
    """Sends goals from its own spinning thread (rclpy's ActionClient must not send from
    another thread while it spins), in the order ``send`` was called, and collects every
    goal's answer and result."""

    def __init__(self, context, supervisors=(0, 1)):
        from rclpy.action import ActionClient
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node

        from mpi_ros.action import MotionModify, MotionStart
        from mpi_ros.client import ACTION_QOS

        self.types = {"start": MotionStart, "modify": MotionModify}
        self.node = Node("goal_storm_sender", context=context)
        self._clients = {(n, kind): ActionClient(self.node, self.types[kind], f"/mpi/ms{n}/motion_{kind}",
                                                 **ACTION_QOS)
                         for n in supervisors for kind in self.types}
        # The goal statuses each action server publishes (the whole list, latest message).
        # ClientGoalHandle.status is no substitute: rclpy's client takes one goal response
        # and one status message per round, so under a storm a handle registered after the
        # last status message stays UNKNOWN.
        self._statuses: dict[tuple[int, str], dict[bytes, int]] = {}
        for key in self._clients:
            self.node.create_subscription(GoalStatusArray, f"/mpi/ms{key[0]}/motion_{key[1]}/_action/status",
                                          partial(self._on_status, key), qos_profile_action_status_default)
        self.handles: dict[int, object] = {}  # goal index -> ClientGoalHandle
        self.results: dict[int, object] = {}  # goal index -> GetResult response
        self._server_of: dict[int, tuple[int, str]] = {}  # goal index -> (supervisor, kind)
        self._count = 0
        self._batches: deque = deque()  # goals to send, oldest first
        self._cond = threading.Condition()
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)
        self._thread = threading.Thread(target=self._executor.spin, daemon=True)
        self._thread.start()
        assert all(c.wait_for_server(timeout_sec=WAIT) for c in self._clients.values())

    def close(self) -> None:
        self._executor.shutdown(timeout_sec=2.0)
        self._thread.join(timeout=2.0)
        self.node.destroy_node()

    def send(self, supervisor: int, kind: str, goals: list[dict]) -> list[int]:
        """Send ``goals`` back to back; returns their indices."""
        from mpi_ros.ros import convert

        first, self._count = self._count, self._count + len(goals)
        self._server_of.update((index, (supervisor, kind)) for index in range(first, self._count))
        messages = [convert.fill(self.types[kind].Goal(), goal) for goal in goals]
        self._batches.append((self._clients[(supervisor, kind)], first, messages))
        # The executor runs tasks in no particular order (newest first, in rclpy 7.1): each
        # task sends the oldest batch, so batches go out in the order they were given.
        self._executor.create_task(self._send_oldest)
        return list(range(first, self._count))

    def _send_oldest(self) -> None:
        client, first, messages = self._batches.popleft()
        for index, message in enumerate(messages, first):
            client.send_goal_async(message).add_done_callback(partial(self._answered, index))

    def _on_status(self, key, message) -> None:
        with self._cond:
            self._statuses[key] = {bytes(s.goal_info.goal_id.uuid): s.status for s in message.status_list}
            self._cond.notify_all()

    def _answered(self, index: int, future) -> None:
        handle = future.result()
        with self._cond:
            self.handles[index] = handle
            self._cond.notify_all()
        if handle.accepted:
            handle.get_result_async().add_done_callback(partial(self._ended, index))

    def _ended(self, index: int, future) -> None:
        with self._cond:
            self.results[index] = future.result()
            self._cond.notify_all()

    def wait_answers(self, indices, timeout: float = LONG) -> list:
        with self._cond:
            assert self._cond.wait_for(lambda: all(i in self.handles for i in indices), timeout), (
                f"{sum(i in self.handles for i in indices)} of {len(indices)} goals answered")
            return [self.handles[i] for i in indices]

    def wait_results(self, indices, timeout: float = LONG) -> list:
        with self._cond:
            assert self._cond.wait_for(lambda: all(i in self.results for i in indices), timeout), (
                f"{sum(i in self.results for i in indices)} of {len(indices)} goals ended")
            return [self.results[i] for i in indices]

    def wait_status(self, indices, status: int, timeout: float = WAIT) -> None:
        """Until the action servers publish every goal of ``indices`` in ``status``."""
        handles = self.wait_answers(indices)
        ids = [(self._server_of[i], bytes(h.goal_id.uuid)) for i, h in zip(indices, handles, strict=True)]

        def seen() -> list[int]:
            return [self._statuses.get(key, {}).get(uuid, GoalStatus.STATUS_UNKNOWN) for key, uuid in ids]

        with self._cond:
            assert self._cond.wait_for(lambda: all(s == status for s in seen()), timeout), (
                f"statuses {sorted(set(seen()))}, expected all {status}")


class Timer:
    """Service round trips from the probe node, timed from the call to the response."""

    def __init__(self, node):
        self.node = node
        self._clients = {}

    def call(self, srv_type, name: str, request) -> tuple[float, object]:
        client = self._clients.get(name)
        if client is None:
            client = self._clients[name] = self.node.create_client(srv_type, name)
            assert client.wait_for_service(timeout_sec=WAIT), f"service {name} not available"
        done = threading.Event()
        began = time.perf_counter()
        future = client.call_async(request)
        future.add_done_callback(lambda _f: done.set())
        assert done.wait(WAIT), f"no response from {name}"
        return time.perf_counter() - began, future.result()


def _action(timer: Timer, supervisor: int, action: str) -> tuple[float, object]:
    from mpi_ros.srv import MotionAction

    return timer.call(MotionAction, f"/mpi/ms{supervisor}/action", MotionAction.Request(action=action))


@pytest.fixture
def sender(suite, ros_context):
    goals = GoalSender(ros_context)
    yield goals
    goals.close()


@pytest.fixture
def live_suite(ros_context, suite_config):
    """The suite on its real-time clock: moves run, feedback flows, as users see it."""
    from mpi_ros.ros.suite import Suite

    running = Suite(suite_config, time_scale=1.0, context=ros_context)
    running.start(spin_in_thread=True)
    try:
        yield running
    finally:
        running.shutdown()


def _storm(sender: GoalSender, supervisor: int, modifies: int, appends: int) -> tuple[list[int], list[int]]:
    """A crawling move, ``modifies`` goals that retarget it (all follow that move), then
    ``appends`` goals queued behind it. Returns (running goals, queued goals)."""
    base = 1_000_000.0
    # A goal's command is applied before its answer is sent, and one action server applies
    # goals in the order they arrive: the modifies find the move, the appends queue behind it.
    running = sender.send(supervisor, "start", [{**CRAWL, "position": [base, base]}])
    sender.wait_answers(running)
    running += sender.send(supervisor, "modify", [{**CRAWL, "position": [base + i, base - i]}
                                                  for i in range(1, modifies + 1)])
    sender.wait_answers(running)
    queued = sender.send(supervisor, "start", [{**STEP, "position": [base + 10.0 * i, base]}
                                               for i in range(1, appends + 1)])
    return running, queued


def test_e_stop_is_answered_as_fast_as_idle_with_hundreds_of_goals_in_flight(live_suite, ros_context, probe):
    sender = GoalSender(ros_context)
    try:
        timer = Timer(probe)
        idle = []
        for _ in range(10):
            elapsed, response = _action(timer, 0, "E_STOP")
            assert response.message == "MPIMessageOK"
            idle.append(elapsed)
            # RESET leaves ERROR only: wait until the E_STOP has run its course (decelTime.eStop)
            assert live_suite.runner.wait(lambda ctl: ctl.supervisor(0).state.name == "ERROR", WAIT)
            assert _action(timer, 0, "RESET")[1].message == "MPIMessageOK"
        probes_idle = [_action(timer, 1, "RESUME")[0] for _ in range(10)]  # IDLE: answered, nothing moves

        running, queued = [], []
        for supervisor in (0, 1):
            r, q = _storm(sender, supervisor, modifies=140, appends=10)
            running += r
            queued += q
        goals = running + queued
        assert len(goals) == 302
        assert all(h.accepted for h in sender.wait_answers(goals))
        # Honest status: EXECUTING while the move runs, ACCEPTED while an appended move waits.
        sender.wait_status(running, GoalStatus.STATUS_EXECUTING)
        sender.wait_status(queued, GoalStatus.STATUS_ACCEPTED)

        probes_loaded = [_action(timer, 1, "RESUME")[0] for _ in range(10)]  # MOVING: refused, nothing changes
        e_stops = [_action(timer, n, "E_STOP") for n in (0, 1)]
        assert [r.message for _, r in e_stops] == ["MPIMessageOK"] * 2

        results = sender.wait_results(goals)
        idle_e_stop = statistics.median(idle)
        print(f"\nE_STOP round trip: idle median {idle_e_stop * 1e3:.2f} ms (min {min(idle) * 1e3:.2f}); "
              f"with {len(goals)} goals in flight: ms0 {e_stops[0][0] * 1e3:.2f} ms, ms1 {e_stops[1][0] * 1e3:.2f} ms; "
              f"action service median idle {statistics.median(probes_idle) * 1e3:.2f} ms, "
              f"loaded {statistics.median(probes_loaded) * 1e3:.2f} ms")
        # MPI 000, MPIMotionMessageERROR: the motion is in an error state due to an E_STOP action
        assert {(r.status, r.result.message) for r in results} == {
            (GoalStatus.STATUS_ABORTED, "MPIMotionMessageERROR")}
        # What this guards against is starvation (issue 9: the E_STOP waited seconds behind the
        # goals), so the bound is a starved answer's, against the idle figures of this run, not
        # a speed target: the machine is shared and noisy (2 cores), this process also runs the
        # client of every goal, and a loaded answer once took 106 ms against an idle 8 ms here.
        # bench/goal_storm.py measures the figures precisely, in separate processes.
        def bound(idle_figure: float) -> float:
            return idle_figure + max(0.500, 5 * idle_figure)

        assert max(elapsed for elapsed, _ in e_stops) < bound(idle_e_stop)
        assert statistics.median(probes_loaded) < bound(statistics.median(probes_idle))
    finally:
        sender.close()


def test_more_goals_than_executor_threads_still_get_answers(suite, sender, probe, service, drive):
    from mpi_ros.srv import GateSet

    threads = suite.config.ros.executor_threads
    assert service(probe, GateSet, "/mpi/gate_set", GateSet.Request(gate=3, closed=True)).message == "MPIMessageOK"
    held = sender.send(0, "start", [{**S_CURVE, "position": [100.0, 0.0], "attributes": ["HOLD"],
                                     "hold": [{"type": "GATE", "gate": 3}] * 2}])
    sender.wait_answers(held)
    queued = sender.send(0, "start", [{**STEP, "position": [100.0 + 10.0 * i, 0.0]} for i in range(1, threads + 8)])
    goals = held + queued
    assert all(h.accepted for h in sender.wait_answers(goals, timeout=WAIT))
    sender.wait_status(held, GoalStatus.STATUS_EXECUTING)  # its move is current, held at the gate
    sender.wait_status(queued, GoalStatus.STATUS_ACCEPTED)
    # MPI 000, meiControlGateSet: the held motion starts when the gate opens
    assert service(probe, GateSet, "/mpi/gate_set", GateSet.Request(gate=3, closed=False)).message == "MPIMessageOK"
    drive(lambda: sum(i in sender.results for i in goals) >= 10)
    e_stop = _action(Timer(probe), 0, "E_STOP")[1]
    assert e_stop.message == "MPIMessageOK"
    drive(lambda: all(i in sender.results for i in goals))
    results = sender.wait_results(goals)
    outcomes = [(r.status, r.result.message) for r in results]
    done = outcomes.index((GoalStatus.STATUS_ABORTED, "MPIMotionMessageERROR"))
    assert done >= 10
    assert set(outcomes[:done]) == {(GoalStatus.STATUS_SUCCEEDED, "MPIMessageOK")}
    assert set(outcomes[done:]) == {(GoalStatus.STATUS_ABORTED, "MPIMotionMessageERROR")}
    # the appended moves ran in order, each goal ended with its own move
    ends = [r.result.end_sample for r in results[:done]]
    assert ends == sorted(ends)
    assert [r.result.command_position[0] for r in results[1:done]] == [
        100.0 + 10.0 * i for i in range(1, done)]


def test_shutdown_ends_pending_goals_and_rejects_new_ones(suite, sender, drive):
    goals = sender.send(0, "start", [{**CRAWL, "position": [1e6, 0.0]}])
    goals += sender.send(0, "start", [{**STEP, "position": [1e6 + 10.0, 0.0]}])
    assert all(h.accepted for h in sender.wait_answers(goals))
    suite.supervisor_nodes[0].shutdown()
    results = sender.wait_results(goals)
    assert {(r.status, r.result.message, r.result.detail) for r in results} == {
        (GoalStatus.STATUS_ABORTED, "MPIMotionMessageSTOPPED", "the suite is shutting down")}
    late = sender.send(0, "start", [{**STEP, "position": [0.0, 0.0]}])
    assert not sender.wait_answers(late)[0].accepted


def test_cancel_of_a_queued_goal_stops_and_ends_it_canceled(suite, sender, drive):
    goals = sender.send(0, "start", [{**CRAWL, "position": [1e6, 0.0]}])
    goals += sender.send(0, "start", [{**STEP, "position": [1e6 + 10.0, 0.0]}])
    handles = sender.wait_answers(goals)
    sender.wait_status(goals[1:], GoalStatus.STATUS_ACCEPTED)
    drive(lambda: suite.runner.ctl.axes[0].cmd_v > 50.0)
    cancel = threading.Event()
    answer = []
    sender._executor.create_task(lambda: handles[1].cancel_goal_async().add_done_callback(
        lambda future: (answer.append(future.result()), cancel.set())))
    assert cancel.wait(WAIT)
    assert [bytes(g.goal_id.uuid) for g in answer[0].goals_canceling] == [bytes(handles[1].goal_id.uuid)]
    drive(lambda: all(i in sender.results for i in goals))
    results = sender.wait_results(goals)
    # Cancel = STOP (docs/decisions.md, "The ROS goals"): every move of the supervisor decelerates and stops.
    assert [(r.status, r.result.message) for r in results] == [
        (GoalStatus.STATUS_ABORTED, "MPIMotionMessageSTOPPED"), (GoalStatus.STATUS_CANCELED, "MPIMotionMessageSTOPPED")]


def test_goals_whose_moves_end_at_once_all_succeed_in_order(suite, sender, drive):
    # Moves to where the axes already are: each is DONE as soon as it runs (settled at once),
    # one after the other within a few samples; every goal still ends with its own move.
    goals = sender.send(0, "start", [{**S_CURVE, "position": [0.0, 0.0]}])
    goals += sender.send(0, "start", [{**STEP, "position": [0.0, 0.0]} for _ in range(5)])
    assert all(h.accepted for h in sender.wait_answers(goals))
    drive(lambda: all(i in sender.results for i in goals), chunk=1)
    results = sender.wait_results(goals)
    assert {(r.status, r.result.message) for r in results} == {(GoalStatus.STATUS_SUCCEEDED, "MPIMessageOK")}
    assert all(r.result.sample <= r.result.end_sample for r in results)
    ends = [r.result.end_sample for r in results]
    assert ends == sorted(ends)
