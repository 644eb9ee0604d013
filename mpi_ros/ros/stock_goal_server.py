"""The same goals served by rclpy's own ActionServer (``ros.action_server: rclpy``).

The batched server (goal_server.py) speaks the action protocol itself, on rclpy's private
bindings (rcl.py), because rclpy's ActionServer costs a task, an executor round and a Future
per goal. This one is that ActionServer, for an rclpy whose private bindings changed, and as
the reference the batched server is held to: test/ros/test_action_conformance.py runs the
same clients against both. The node's decisions are the same Callbacks; only the protocol's
bookkeeping is rclpy's.

As ros2/examples' action servers do, no goal blocks an executor thread while its move runs:
the execute callback is a coroutine that awaits a Future, completed by :meth:`finish` from
whichever thread saw the move end. Accepted goals are applied one per callback (rclpy hands
them over one at a time), each its own command batch.
"""

from __future__ import annotations

import threading
import traceback
from typing import Any

from action_msgs.msg import GoalStatus
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.action.server import ServerGoalHandle
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.qos import QoSProfile
from rclpy.task import Future

from . import convert, goal_table
from .goal_server import ABORT, CANCELED, SUCCEED, Callbacks

_ACTIVE = (GoalStatus.STATUS_ACCEPTED, GoalStatus.STATUS_EXECUTING)


class StockGoalServer:
    """One action of one node on rclpy's ActionServer, with GoalServer's interface to the node."""

    def __init__(self, node, action_type, name: str, callbacks: Callbacks, qos: QoSProfile, *,
                 result_timeout: float):
        self._node = node
        self._type = action_type
        self._callbacks = callbacks
        self._logger = node.get_logger()
        self._lock = threading.Lock()
        self._handles: dict[bytes, ServerGoalHandle] = {}  # goals whose execute callback has not returned
        self._ends: dict[bytes, Future] = {}  # each goal's (event, result), set by finish
        self._canceling: set[bytes] = set()  # goals whose cancel this server accepted
        self._server = ActionServer(
            node, action_type, name, execute_callback=self._execute, goal_callback=self._on_goal,
            handle_accepted_callback=self._on_accepted, cancel_callback=self._on_cancel,
            callback_group=ReentrantCallbackGroup(), goal_service_qos_profile=qos,
            result_service_qos_profile=qos, cancel_service_qos_profile=qos,
            result_timeout=max(1, round(result_timeout)))  # whole seconds in rclpy

    # -- what the node reads ----------------------------------------------------------
    def kept(self) -> int:
        """Goals not yet ended (rclpy keeps ended ones until result_timeout, out of sight)."""
        with self._lock:
            return len(self._handles)

    def unfiled(self) -> int:
        return 0  # rclpy serves each request as it is taken

    def status(self, key: bytes) -> int:
        """The goal's status; CANCELING from the moment its cancel was accepted (rclpy moves it
        there right after the cancel callback returns, before it answers the client)."""
        with self._lock:
            handle = self._handles.get(key)
            canceling = key in self._canceling
        if handle is None:
            return goal_table.UNKNOWN
        status = handle.status
        return GoalStatus.STATUS_CANCELING if canceling and status in _ACTIVE else status

    # -- what the node changes ----------------------------------------------------------
    def start(self, key: bytes) -> None:
        """The goal's move runs: it is EXECUTING already (accepted goals execute at once)."""

    def finish(self, key: bytes, event: int, result) -> None:
        with self._lock:
            end = self._ends.get(key)
        if end is not None and not end.done():
            end.set_result((event, result))
            # rclpy resumes a waiting coroutine only when its executor wakes: the Future
            # itself wakes nobody (rclpy 7.1's executor re-runs pending tasks on each wake)
            executor = self._node.executor
            if executor is not None:
                executor.wake()

    def publish_status(self) -> None:
        """rclpy publishes the status array at every change."""

    def destroy(self) -> None:
        self._server.destroy()

    # -- rclpy's callbacks --------------------------------------------------------------
    def _on_goal(self, _request) -> GoalResponse:
        return GoalResponse.ACCEPT if self._callbacks.accepting() else GoalResponse.REJECT

    def _on_accepted(self, handle: ServerGoalHandle) -> None:
        key = bytes(handle.goal_id.uuid)
        with self._lock:
            self._handles[key] = handle
            self._ends[key] = Future()
        goal: dict[str, Any] | Exception
        try:
            goal = convert.to_dict(handle.request)
        except Exception as exc:  # noqa: BLE001 - not swallowed: the goal is accepted and aborted with it
            goal = exc
        try:
            self._callbacks.apply([(key, goal)])
        except Exception:  # noqa: BLE001 - logged, and the goal ends ABORTED: the executor goes on
            self._logger.error(f"a goal could not be applied:\n{traceback.format_exc()}")
            self.finish(key, ABORT, self._type.Result())
        handle.execute()

    def _on_cancel(self, handle: ServerGoalHandle) -> CancelResponse:
        key = bytes(handle.goal_id.uuid)
        if not self._callbacks.cancel(key):
            return CancelResponse.REJECT
        with self._lock:
            self._canceling.add(key)
        self._callbacks.cancelled()
        return CancelResponse.ACCEPT

    async def _execute(self, handle: ServerGoalHandle):
        key = bytes(handle.goal_id.uuid)
        with self._lock:
            end = self._ends[key]
        try:
            event, result = await end
        finally:
            with self._lock:
                self._handles.pop(key, None)
                self._ends.pop(key, None)
                canceling = key in self._canceling
                self._canceling.discard(key)
        if event == SUCCEED:
            handle.succeed()
        elif event == CANCELED and canceling:
            self._canceled(handle)
        else:
            handle.abort()
        return result

    def _canceled(self, handle: ServerGoalHandle) -> None:
        """End a goal whose cancel was accepted CANCELED. rclpy moves it to CANCELING just
        after the cancel callback; a move that ended within those microseconds finds it not
        there yet, and the goal ends ABORTED, said in the log."""
        if handle.status == GoalStatus.STATUS_CANCELING:
            handle.canceled()
            return
        self._logger.warning("a cancelled goal ended before rclpy had marked it CANCELING: it ends ABORTED")
        handle.abort()
