"""The action protocol's server side for goals the controller answers (no execute callback).

rclpy's ActionServer is built for goals that each run a callback on the executor: every goal
request, result request and finished goal is a task and an executor round of its own, every
goal keeps a Future that the executor walks on every round (all goals kept until their
result expires: at 100 goals a second and result_timeout 60 s, 6,000 of them), and every
state change publishes the status of every goal kept. The suite's goals run no callback: the
controller answers them (goal_tracker.py). GoalServer speaks the same protocol on the same
services and topics (``<action>/_action/send_goal``, ``cancel_goal``, ``get_result`` and
``status``, of the action's own types and QoS; the node publishes ``feedback``), so
``ros2 action``, rclpy's and rclcpp's clients see an action server like any other. It keeps
the goals itself (goal_table.py): rcl_action's goal handles cost time in proportion to the
goals kept for every goal accepted and ended. And it does per batch what rclpy does per goal:

- every round takes all the requests waiting (goal, cancel, result), not one of each;
- the goal requests taken together are handed to ``apply`` together: the node applies their
  commands under one lock, at one sample, in the order they came;
- a finished goal's result is stored and sent at once to whoever asked for it; a result
  request for a finished goal is answered at once, for a running one when it finishes;
- the status array is published once per batch of changes, not once per change;
- results expire ``result_timeout`` after their goal ended (the goal loop's rounds look),
  in turn with the requests: a result request taken before the result expired is answered.

The server reads and answers requests as plain values through its endpoints (goal_endpoints.py):
the action's three services in this process, or in the goal front (goal_front.py). The suite's
GoalLoop (goal_loop.py; with the front, its relay) takes what is waiting for every server in one
thread, gives it to the server (``deliver``) and, when no thread is serving this server, hands
``serve`` to a pool. Requests are handled in the order they were taken: takes never overlap, and one
``serve`` at a time handles everything taken so far, until nothing is left. At most one task
per server is ever queued: a task per take piled up by the thousand while the serving task
waited for its commands' sample (12,000 futures, locks and conditions at 400 goals a second,
all walked by every garbage collection). Within one take, goal requests come before cancel
requests (a cancel names goals its client has seen accepted).
"""

from __future__ import annotations

import threading
import traceback
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from action_msgs.msg import GoalStatusArray

from .. import graph_names
from ..qos import profile
from . import goal_table
from .goal_endpoints import Endpoints
from .goal_table import GoalTable

# how a goal ended: its terminal status
SUCCEED, ABORT, CANCELED = goal_table.SUCCEEDED, goal_table.ABORTED, goal_table.CANCELED


@dataclass(frozen=True, slots=True)
class Callbacks:
    """What the node decides (each called with no lock of the server held).

    accepting(): whether new goals are accepted now (else the batch is rejected).
    apply(goals): the accepted goals of a batch, [(goal id, goal as a dict)] in order: apply
        their commands and follow the goals (``finish`` ends each); their clients are
        answered after it returns, so a command has taken effect when its client hears.
    cancel(id): a client asks to cancel this goal: True to accept (the goal goes CANCELING).
    cancelled(): after a batch of cancel requests was answered.
    """

    accepting: Callable[[], bool]
    apply: Callable[[list[tuple[bytes, Any]]], None]
    cancel: Callable[[bytes], bool]
    cancelled: Callable[[], None]


class GoalServer:
    """One action (``<node>/<name>``) of one node. The goals' outcome comes from the node:
    ``start(id)`` when its move runs, ``finish(id, event, result)`` when it has ended."""

    def __init__(self, node, action_type, name: str, callbacks: Callbacks, endpoints: Endpoints, *,
                 result_timeout: float):
        self._node = node
        self._type = action_type
        self._callbacks = callbacks
        self.endpoints = endpoints  # the action's services: here (LocalEndpoints) or in the goal front
        self._lock = threading.RLock()  # the goals and the responses (a finished goal's result
        # is sent from whichever thread ran the controller's outputs)
        self._status_publisher = node.create_publisher(GoalStatusArray, graph_names.action_status(name),
                                                       profile(graph_names.ACTION_STATUS_QOS))
        self._goals = GoalTable(result_timeout)
        self._expiring = False  # an expiry is queued with the requests taken (one at a time)
        self._taken: deque[dict[str, list]] = deque()
        self._queue = threading.Lock()  # _taken and _scheduled, together
        self._scheduled = False  # a serve task is queued or running
        self._status_changed = False

    # -- what the node reads ----------------------------------------------------------
    def kept(self) -> int:
        """Goals kept: the unfinished ones and the finished ones until result_timeout."""
        return len(self._goals)

    def unfiled(self) -> int:
        """Requests taken and not yet handled."""
        return sum(len(requests) for batch in list(self._taken) for kind, requests in batch.items()
                   if kind != "expired")

    def status(self, key: bytes) -> int:
        with self._lock:
            return self._goals.status(key)

    # -- what the node changes ------------------------------------------------------------
    def start(self, key: bytes) -> None:
        """The goal's move runs: EXECUTING (an accepted goal only; a cancelled one is CANCELING)."""
        with self._lock:
            if self._goals.execute(key):
                self._status_changed = True

    def finish(self, key: bytes, event: int, result) -> None:
        """The goal has ended (``event``: SUCCEED, ABORT or CANCELED): its terminal state, and
        its result to every client that asked. CANCELED needs the goal CANCELING (its cancel
        accepted); otherwise the goal ends ABORTED."""
        with self._lock:
            goal = self._goals.end(key, event)  # its result expires result_timeout from now
            if goal is None:
                return
            goal.response = (goal.status, result)
            self._status_changed = True
            if goal.waiting:
                self.publish_status()  # a client hears of the terminal state before its result
                for header in goal.waiting:
                    self.endpoints.respond("result", header, goal.response)
                goal.waiting.clear()
                self.endpoints.flush()

    def publish_status(self) -> None:
        """The status of every goal kept, if any changed since it was last published."""
        with self._lock:
            if self._status_changed:
                self._status_changed = False
                self._status_publisher.publish(self._goals.status_array())  # CDR, published raw

    def destroy(self) -> None:
        with self._lock:
            self._goals.clear()
            self.endpoints.destroy()
            self._node.destroy_publisher(self._status_publisher)

    # -- what the goal loop (or the goal front's relay) calls ---------------------------------
    def expire_due(self) -> bool:
        """Whether a kept result is due to be forgotten."""
        with self._lock:
            return self._goals.expire_due()

    def deliver(self, taken: dict[str, list], expire: bool) -> bool:
        """Requests taken (kind: [(header, plain request)]), and whether results are due to
        expire, queued for ``serve``. True when the caller must hand ``serve`` to a thread:
        none is serving."""
        taken = {kind: requests for kind, requests in taken.items() if requests}
        with self._lock:
            if expire and not self._expiring:
                # forgotten in turn: result requests taken before are still answered
                taken["expired"] = [self._goals.now()]
                self._expiring = True
        if not taken:
            return False
        with self._queue:
            self._taken.append(taken)
            scheduled, self._scheduled = self._scheduled, True
        return not scheduled

    def serve(self) -> None:
        """Handle everything taken so far, batch after batch, until nothing is left."""
        while True:
            with self._queue:  # checked and cleared together: a take after this schedules anew
                if not self._taken:
                    self._scheduled = False
                    return
                batch = self._merged()
            try:
                self._serve(batch)  # logs its own errors; only a BaseException comes through
            except BaseException:
                with self._queue:  # the next take schedules a task again
                    self._scheduled = False
                raise

    def _merged(self) -> dict[str, list]:
        """Everything taken so far, as one batch: requests taken while a batch was being
        served are served together (their commands applied at one sample), kind by kind in
        the order taken."""
        merged: dict[str, list] = {}
        while self._taken:
            for kind, requests in self._taken.popleft().items():
                merged.setdefault(kind, []).extend(requests)
        return merged

    # -- handling a batch ------------------------------------------------------------------
    def _serve(self, taken: dict[str, list]) -> None:
        steps = (("goal", self._goal_requests), ("cancel", self._cancel_requests),
                 ("result", self._result_requests), ("expired", self._expire))
        for kind, handle in steps:
            if taken.get(kind):
                try:
                    handle(taken[kind])
                except Exception:  # noqa: BLE001 - logged; one bad batch must not stop the others or the executor
                    self._node.get_logger().error(f"{len(taken[kind])} {kind} request(s) failed:\n"
                                                  f"{traceback.format_exc()}")
        self.publish_status()
        self.endpoints.flush()

    def _goal_requests(self, requests: list) -> None:
        fresh = []
        seen: set[bytes] = set()
        with self._lock:
            for header, (key, goal) in requests:
                if key in self._goals or key in seen:
                    self.endpoints.respond("goal", header, (False, None))  # a goal id in use: rejected, as rclpy does
                else:
                    seen.add(key)
                    fresh.append((header, key, goal))
        if not fresh:
            return
        if not self._callbacks.accepting():
            with self._lock:
                for header, _, _ in fresh:
                    self.endpoints.respond("goal", header, (False, None))
            return
        now = self._node.get_clock().now().nanoseconds
        with self._lock:  # the goals exist before their commands run: what ends them finds them
            for _, key, _ in fresh:
                self._goals.accept(key, now)
            self._status_changed = True
        try:
            self._callbacks.apply([(key, goal) for _, key, goal in fresh])
        except Exception:
            for _, key, _ in fresh:  # not followed by the node: ended here, the error logged by _serve
                self.finish(key, ABORT, self._type.Result())
            raise
        finally:  # accepted goals are answered whatever happened to them
            with self._lock:
                for header, _, _ in fresh:
                    self.endpoints.respond("goal", header, (True, now))
                self.publish_status()

    def _cancel_requests(self, requests: list) -> None:
        none, rejected = self._cancel_codes
        for header, (key, stamp_ns) in requests:
            with self._lock:
                code, named = self._goals.to_cancel(key, stamp_ns)
            canceling = [goal for goal in named if self._callbacks.cancel(goal.key) and self._to_canceling(goal.key)]
            if not canceling and code == none:
                code = rejected
            with self._lock:
                self.endpoints.respond("cancel", header, (code, [(goal.key, goal.stamp_ns) for goal in canceling]))
        self.publish_status()
        self._callbacks.cancelled()

    @property
    def _cancel_codes(self) -> tuple[int, int]:
        response = self._type.Impl.CancelGoalService.Response
        return response.ERROR_NONE, response.ERROR_REJECTED

    def _to_canceling(self, key: bytes) -> bool:
        with self._lock:
            if not self._goals.cancel(key):
                return False  # ended meanwhile
            self._status_changed = True
            return True

    def _result_requests(self, requests: list) -> None:
        # A client asks for the result once its goal was accepted, so it follows the goal's
        # status from now on: the status again, then the results. A goal that ended at once
        # (a refused command) had its terminal status published before its client had the
        # goal's answer, and rclpy's client ignores the status of goals it does not know yet.
        with self._lock:
            # a goal's result is set when it ends, under this lock: ended means answered
            if any(self._goals.status(key) in goal_table.TERMINAL for _, key in requests):
                self._status_changed = True
                self.publish_status()
            for header, key in requests:
                goal = self._goals.get(key)
                if goal is None:  # never accepted, or its result expired
                    self.endpoints.respond("result", header, (goal_table.UNKNOWN, self._type.Result()))
                elif goal.response is not None:
                    self.endpoints.respond("result", header, goal.response)
                else:
                    goal.waiting.append(header)

    def _expire(self, taken_at: list[float]) -> None:
        with self._lock:
            self._goals.expire(until=taken_at[-1])
            self._expiring = False
