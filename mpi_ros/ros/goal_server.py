"""The action protocol's server side for goals the controller answers (no execute callback).

rclpy's ActionServer is built for goals that each run a callback on the executor: every goal
request, result request and finished goal is a task and an executor round of its own, every
goal keeps a Future that the executor walks on every round (all goals kept until their
result expires: at 100 goals a second and result_timeout 60 s, 6,000 of them), and every
state change publishes the status of every goal kept. The suite's goals run no callback: the
controller answers them (goal_tracker.py). GoalServer speaks the same protocol (the same
services and topics, made by rcl_action, so ``ros2 action`` and any client see no
difference) and does per batch what rclpy does per goal:

- every round takes all the requests waiting (goal, cancel, result), not one of each;
- the goal requests taken together are handed to ``apply`` together: the node applies their
  commands under one lock, at one sample, in the order they came;
- a finished goal's result is stored and sent at once to whoever asked for it; a result
  request for a finished goal is answered at once, for a running one when it finishes;
- the status array is published once per batch of changes, not once per change.

The suite's GoalLoop (goal_loop.py) waits on every server's handle in one thread, takes what
is ready (``take_data``) and, when no thread is serving this server, hands ``serve`` to a
pool. Requests are handled in the order they were taken: takes never overlap, and one
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
from dataclasses import dataclass, field
from typing import Any

from action_msgs.msg import GoalInfo, GoalStatus
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.qos import QoSProfile, qos_profile_action_status_default
from rclpy.type_support import check_for_type_support

GoalEvent = _rclpy.GoalEvent
# the events that end a goal, by how it ended
SUCCEED, ABORT, CANCELED = GoalEvent.SUCCEED, GoalEvent.ABORT, GoalEvent.CANCELED
_CANCELABLE = (GoalStatus.STATUS_ACCEPTED, GoalStatus.STATUS_EXECUTING)  # rcl_action's CANCEL_GOAL starts there


@dataclass(eq=False, slots=True)
class _Goal:
    handle: Any  # rclpy's C ActionGoalHandle: the goal's state in rcl_action
    response: Any = None  # the GetResult response, once the goal has ended
    waiting: list = field(default_factory=list)  # headers of result requests to answer when it ends


_NO_GOAL = _Goal(handle=None)


@dataclass(frozen=True, slots=True)
class Callbacks:
    """What the node decides (each called with no lock of the server held).

    accepting(): whether new goals are accepted now (else the batch is rejected).
    apply(goals): the accepted goals of a batch, [(goal id, goal message)] in order: apply
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

    def __init__(self, node, action_type, name: str, callbacks: Callbacks, *,
                 service_qos: QoSProfile, feedback_qos: QoSProfile, result_timeout: float):
        self._node = node
        self._type = action_type
        self._callbacks = callbacks
        check_for_type_support(action_type)  # loads the action's C type support, which the handle needs
        self._lock = threading.RLock()  # the C handle and the goals (a finished goal's result
        # is sent from whichever thread ran the controller's outputs)
        with node.handle, node.get_clock().handle:
            self._handle = _rclpy.ActionServer(
                node.handle, node.get_clock().handle, action_type, name, service_qos.get_c_qos_profile(),
                service_qos.get_c_qos_profile(), service_qos.get_c_qos_profile(), feedback_qos.get_c_qos_profile(),
                qos_profile_action_status_default.get_c_qos_profile(), result_timeout)
        self._goals: dict[bytes, _Goal] = {}
        self._ready = (False, False, False, False)
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
        return sum(len(requests) for batch in list(self._taken) for requests in batch.values())

    def status(self, key: bytes) -> int:
        with self._lock:
            goal = self._goals.get(key)
            return goal.handle.get_status() if goal is not None else GoalStatus.STATUS_UNKNOWN

    # -- what the node changes ------------------------------------------------------------
    def start(self, key: bytes) -> None:
        """The goal's move runs: EXECUTING (an accepted goal only; a cancelled one is CANCELING)."""
        with self._lock:
            goal = self._goals.get(key)
            if goal is not None and goal.handle.get_status() == GoalStatus.STATUS_ACCEPTED:
                goal.handle.update_goal_state(GoalEvent.EXECUTE)
                self._status_changed = True

    def finish(self, key: bytes, event, result) -> None:
        """The goal has ended (``event``: SUCCEED, ABORT or CANCELED): its terminal state, and
        its result to every client that asked. CANCELED needs the goal CANCELING (its cancel
        accepted); otherwise the goal ends ABORTED."""
        with self._lock:
            goal = self._goals.get(key)
            if goal is None or goal.response is not None:
                return
            status = goal.handle.get_status()
            if status == GoalStatus.STATUS_ACCEPTED:
                goal.handle.update_goal_state(GoalEvent.EXECUTE)  # rcl_action ends only what runs
            if event == CANCELED and status != GoalStatus.STATUS_CANCELING:
                event = ABORT
            goal.handle.update_goal_state(event)
            self._handle.notify_goal_done()  # starts the goal's result_timeout
            goal.response = self._type.Impl.GetResultService.Response(status=goal.handle.get_status(), result=result)
            self._status_changed = True
            if goal.waiting:
                self.publish_status()  # a client hears of the terminal state before its result
            for header in goal.waiting:
                self._send_result(header, goal.response)
            goal.waiting.clear()

    def publish_status(self) -> None:
        """The status of every goal kept, if any changed since it was last published."""
        with self._lock:
            if self._status_changed:
                self._status_changed = False
                self._handle.publish_status()

    def destroy(self) -> None:
        with self._lock:
            for goal in self._goals.values():
                goal.handle.destroy_when_not_in_use()
            self._goals.clear()
            self._handle.destroy_when_not_in_use()

    # -- what the goal loop calls (its thread; ``serve`` on its pool) ------------------------
    def __enter__(self):
        return self._handle.__enter__()

    def __exit__(self, t, v, tb):
        self._handle.__exit__(t, v, tb)

    def entity_counts(self) -> tuple[int, ...]:
        """What the handle puts in a wait set: subscriptions, guard conditions, timers,
        clients, services."""
        return tuple(self._handle.get_num_entities())

    def add_to_wait_set(self, wait_set) -> None:
        with self._lock:
            self._handle.add_to_waitset(wait_set)

    def is_ready(self, wait_set) -> bool:
        with self._lock:
            self._ready = tuple(self._handle.is_ready(wait_set))
        return any(self._ready)

    def take_data(self) -> bool:
        """Take everything waiting of each kind the wait set found ready and queue it for
        ``serve``. True when the caller must hand ``serve`` to a thread: none is serving."""
        goal, cancel, result, expired = self._ready
        impl = self._type.Impl
        taken: dict[str, list] = {}
        with self._lock:
            if goal:
                taken["goal"] = self._take_all(self._handle.take_goal_request, impl.SendGoalService.Request)
            if cancel:
                taken["cancel"] = self._take_all(self._handle.take_cancel_request, impl.CancelGoalService.Request)
            if result:
                taken["result"] = self._take_all(self._handle.take_result_request, impl.GetResultService.Request)
            if expired:
                taken["expired"] = list(self._handle.expire_goals(len(self._goals)))
        with self._queue:
            self._taken.append(taken)
            scheduled, self._scheduled = self._scheduled, True
        return not scheduled

    @staticmethod
    def _take_all(take, request_type) -> list:
        requests: list[tuple[Any, Any]] = []
        while True:
            header, request = take(request_type)
            if header is None or request is None:
                return requests
            requests.append((header, request))

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

    def _goal_requests(self, requests: list) -> None:
        fresh = []
        seen: set[bytes] = set()
        with self._lock:
            for header, request in requests:
                key = bytes(request.goal_id.uuid)
                if key in self._goals or key in seen:
                    self._respond_goal(header, False, None)  # a goal id in use: rejected, as rclpy does
                else:
                    seen.add(key)
                    fresh.append((header, request))
        if not fresh:
            return
        if not self._callbacks.accepting():
            with self._lock:
                for header, _ in fresh:
                    self._respond_goal(header, False, None)
            return
        stamp = self._node.get_clock().now().to_msg()
        with self._lock:  # the goals exist before their commands run: what ends them finds them
            for _, request in fresh:
                self._goals[bytes(request.goal_id.uuid)] = _Goal(
                    _rclpy.ActionGoalHandle(self._handle, GoalInfo(goal_id=request.goal_id, stamp=stamp)))
            self._status_changed = True
        try:
            self._callbacks.apply([(bytes(r.goal_id.uuid), r.goal) for _, r in fresh])
        except Exception:
            for _, request in fresh:  # not followed by the node: ended here, the error logged by _serve
                self.finish(bytes(request.goal_id.uuid), ABORT, self._type.Result())
            raise
        finally:  # accepted goals are answered whatever happened to them
            with self._lock:
                for header, _ in fresh:
                    self._respond_goal(header, True, stamp)
                self.publish_status()

    def _respond_goal(self, header, accepted: bool, stamp) -> None:
        response = self._type.Impl.SendGoalService.Response(accepted=accepted)
        if stamp is not None:
            response.stamp = stamp
        try:
            self._handle.send_goal_response(header, response)
        except _rclpy.RCLError:  # the client went away; its goal (if accepted) runs without it
            self._node.get_logger().warning("a goal response could not be sent (the client may have gone away)")

    def _cancel_requests(self, requests: list) -> None:
        for header, request in requests:
            with self._lock:
                response = self._handle.process_cancel_request(request, self._type.Impl.CancelGoalService.Response)
            canceling = []
            for info in response.goals_canceling:
                key = bytes(info.goal_id.uuid)
                if key in self._goals and self._callbacks.cancel(key) and self._to_canceling(key):
                    canceling.append(info)
            response.goals_canceling = canceling
            if not canceling and response.return_code == response.ERROR_NONE:
                response.return_code = response.ERROR_REJECTED
            try:
                with self._lock:
                    self._handle.send_cancel_response(header, response)
            except _rclpy.RCLError:
                self._node.get_logger().warning("a cancel response could not be sent (the client may have gone away)")
        self.publish_status()
        self._callbacks.cancelled()

    def _to_canceling(self, key: bytes) -> bool:
        with self._lock:
            goal = self._goals.get(key)
            if goal is None or goal.handle.get_status() not in _CANCELABLE:
                return False  # ended meanwhile
            goal.handle.update_goal_state(GoalEvent.CANCEL_GOAL)
            self._status_changed = True
            return True

    def _result_requests(self, requests: list) -> None:
        # A client asks for the result once its goal was accepted, so it follows the goal's
        # status from now on: the status again, then the results. A goal that ended at once
        # (a refused command) had its terminal status published before its client had the
        # goal's answer, and rclpy's client ignores the status of goals it does not know yet.
        with self._lock:
            if any(self._goals.get(bytes(r.goal_id.uuid), _NO_GOAL).response is not None for _, r in requests):
                self._status_changed = True
                self.publish_status()
            for header, request in requests:
                goal = self._goals.get(bytes(request.goal_id.uuid))
                if goal is None:  # never accepted, or its result expired
                    unknown = self._type.Impl.GetResultService.Response(status=GoalStatus.STATUS_UNKNOWN)
                    self._send_result(header, unknown)
                elif goal.response is not None:
                    self._send_result(header, goal.response)
                else:
                    goal.waiting.append(header)

    def _send_result(self, header, response) -> None:
        try:
            self._handle.send_result_response(header, response)
        except _rclpy.RCLError:
            self._node.get_logger().warning("a result could not be sent (the client may have gone away)")

    def _expire(self, expired: list) -> None:
        with self._lock:
            for info in expired:
                goal = self._goals.pop(bytes(info.goal_id.uuid), None)
                if goal is not None:
                    goal.handle.destroy_when_not_in_use()
