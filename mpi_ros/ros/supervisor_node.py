"""One node per motion supervisor: /<ns>/ms<n> with its actions, services and status.

Goals are always accepted; the controller's answer comes back in the result (a refused
command ends the goal ABORTED with the spec's message). Services live in their own
reentrant callback group, apart from the goals, so E_STOP is served while goals run.

A goal holds no executor thread while its move runs (with more goals than threads nothing
else would be served, E_STOP included). Deferred execution: the goal callback applies the
goal's command (so the client's goal response comes after it took effect), the
handle_accepted callback files the goal in a GoalBook, and the runner reviews the book
after every step batch and command, under its lock. A goal whose move has become current
is marked EXECUTING; a goal whose move has ended is handed back to rclpy, whose execute
callback (scheduled then) sets the terminal state and returns the result at once.
Feedback for every running goal comes from one periodic hook at the feedback rate.
Goal and cancel requests are handled in the order they arrived (_GoalServer).
With ``lost_client_timeout`` > 0 a watchdog STOPs the motion of a goal whose client has
left the graph (watchdog.py, docs/cell.md).
"""

from __future__ import annotations

import threading
import traceback
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

from action_msgs.msg import GoalStatus
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.action.server import GoalEvent, RCLError, ServerGoalHandle
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.serialization import serialize_message
from std_srvs.srv import Trigger

from mpi_ros.action import MotionModify, MotionStart
from mpi_ros.msg import FrameBufferStatus as FrameBufferStatusMsg
from mpi_ros.msg import MotionParams as MotionParamsMsg
from mpi_ros.msg import MotionStatus
from mpi_ros.srv import (
    AxisListEdit,
    AxisListGet,
    AxisListSet,
    EventNotifyGet,
    EventNotifySet,
    EventReset,
    FrameBufferStatusGet,
    MotionAction,
    MotionConfigGet,
    MotionConfigSet,
    MotionParamsGet,
    MotionParamsSet,
    PositionGet,
    PositionSet,
)

from .. import requests as rq
from ..commands import ACTION, CLIENT_LOST, MOTION_MODIFY, MOTION_START, Command, Reply
from ..config import RosSettings
from ..mpi.control import Controller
from ..mpi.messages import Message
from ..mpi.outcome import MoveEnd, Outcome
from ..mpi.snapshot import MotionFeedback
from ..runner import ControllerRunner, Output
from . import convert, snapshots, wire
from .goal_tracker import GoalBook, TrackedGoal
from .watchdog import LostClientWatchdog

STATUS_QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
FEEDBACK_QOS = QoSProfile(depth=10)  # rclpy's ActionServer default for its feedback publisher
# The action's services default to a history of 10: an E_STOP that ends more goals than
# that at once would drop results. Deep enough for every goal a frame buffer can queue.
ACTION_SERVICE_QOS = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
ACTION_QOS = dict(goal_service_qos_profile=ACTION_SERVICE_QOS, result_service_qos_profile=ACTION_SERVICE_QOS,
                  cancel_service_qos_profile=ACTION_SERVICE_QOS)
TRIGGER_ACTIONS = {"stop": "STOP", "e_stop": "E_STOP", "abort": "ABORT", "reset": "RESET", "resume": "RESUME"}
# A goal whose cancel was accepted is still in one of these until rclpy has moved it to
# CANCELING (right after our cancel callback returns); only then may it end CANCELED.
_NOT_YET_CANCELING = (GoalStatus.STATUS_ACCEPTED, GoalStatus.STATUS_EXECUTING)


@dataclass(eq=False, slots=True)
class _RosGoal:
    """What finishing a goal needs from ROS (the payload of its TrackedGoal)."""

    handle: ServerGoalHandle
    action_type: type
    server: ActionServer
    executing: bool = False  # we moved it to EXECUTING (changed under the node's _transitions)


class _GoalServer(ActionServer):
    """An ActionServer that handles goal and cancel requests in the order it took them.

    rclpy takes one request per executor round and handles each in a task of its own, so
    with a reentrant group two goals sent back to back could be applied out of order (an
    APPEND before the start it follows, an older modify last) and a cancel could be handled
    before its goal is filed. Here the requests join a queue as they are taken (takes of
    one waitable never overlap), and whichever task holds the queue's lock handles all of
    them, oldest first; the others return at once, so no executor thread waits here. The
    callbacks are synchronous: nothing awaits while the lock is held.
    """

    def __init__(self, *args: Any, after_cancel: Callable[[], None], **kwargs: Any) -> None:
        self._taken: deque[dict] = deque()
        self._in_order = threading.Lock()
        self._after_cancel = after_cancel
        self.goal_id: bytes | None = None  # the goal request being handled (for the goal callback)
        # goal id -> its command's (reply, sample), or the error
        self.applied: dict[bytes, tuple[Reply, int] | Exception] = {}
        super().__init__(*args, **kwargs)

    def kept(self) -> int:
        """Goals rclpy keeps: the unfinished ones and the ended ones until result_timeout."""
        return len(self._goal_handles)

    def unfiled(self) -> int:
        """Goal and cancel requests taken and not yet handled, and goals applied and not yet filed."""
        return len(self._taken) + len(self.applied)

    def take_data(self):
        data = super().take_data()
        requests = {key: data.pop(key) for key in ("goal", "cancel") if key in data}
        if requests:
            self._taken.append(requests)
        return data

    async def execute(self, taken_data):
        # Try again after releasing: a request taken while another task held the lock
        # (and so returned at once) is handled by the holder.
        while self._taken and self._in_order.acquire(blocking=False):
            try:
                while self._taken:
                    await self._serve(self._taken.popleft())
            finally:
                self._in_order.release()
        if taken_data:
            await super().execute(taken_data)  # result requests, expired goals

    async def _serve(self, requests: dict) -> None:
        goal = requests.get("goal")
        self.goal_id = bytes(goal[1].goal_id.uuid) if goal is not None else None
        try:
            await super().execute(requests)
            if "cancel" in requests:
                self._after_cancel()  # the goals whose cancel was accepted are CANCELING now
        except Exception:  # noqa: BLE001 - one bad request must neither strand the queue nor stop the executor
            self._node.get_logger().error(f"a goal or cancel request failed:\n{traceback.format_exc()}")
        finally:
            if self.goal_id is not None and self.applied.pop(self.goal_id, None) is not None:
                # rclpy did not hand the accepted goal over (its response could not be sent)
                self._node.get_logger().warning("a goal's command was applied, but the goal did not reach "
                                                "its client (gone?): its move runs without a goal")
            self.goal_id = None


def _never_executed(_handle) -> None:
    """The action servers' registered execute callback. Goals are finished with a callback
    of their own (``SupervisorNode._close``), so rclpy never calls this one; if it ever did,
    the goal would fail loudly (rclpy logs the error and aborts it) instead of hanging."""
    raise RuntimeError("a goal was executed without going through the goal book")


def _reraise(exc: BaseException, _handle) -> None:
    raise exc


class SupervisorNode(Node):
    def __init__(self, runner: ControllerRunner, number: int, settings: RosSettings,
                 lost_client_timeout: float = 0.0, **kwargs):
        super().__init__(f"ms{number}", namespace=settings.namespace, **kwargs)
        self.runner = runner
        self.number = number
        self.settings = settings
        self._shutting_down = False
        self._goal_group = ReentrantCallbackGroup()
        self._service_group = ReentrantCallbackGroup()
        self._book = GoalBook(number)
        self._snapshots = snapshots.shared(runner)
        # Orders our own goal-state changes against an accepted cancel (see _mark_executing).
        self._transitions = threading.Lock()
        self._closing = threading.Condition()
        self._unfinished = 0  # goals handed to rclpy whose execute callback has not run yet
        actions = ((MotionStart, "motion_start", MOTION_START), (MotionModify, "motion_modify", MOTION_MODIFY))
        # each action's feedback topic: its clients subscribe there (the watchdog looks for them)
        self._feedback_topics = {action_type: f"{self.get_fully_qualified_name()}/{name}/_action/feedback"
                                 for action_type, name, _ in actions}
        self._servers = {action_type: self._action_server(action_type, name, operation)
                         for action_type, name, operation in actions}
        # Feedback goes out pre-serialized on the actions' own feedback topics (see _collect_feedback).
        self._feedback_pubs = {action_type: self.create_publisher(action_type.Impl.FeedbackMessage,
                                                                  f"~/{name}/_action/feedback", FEEDBACK_QOS)
                               for action_type, name, _ in actions}
        self._service(MotionAction, "action", self._on_action)
        for name, action in TRIGGER_ACTIONS.items():
            self._service(Trigger, name, lambda req, resp, a=action: self._on_trigger(a, resp))
        self._service(MotionConfigGet, "config_get", self._on_config_get)
        self._service(MotionConfigSet, "config_set", self._on_config_set)
        self._service(MotionParamsGet, "params_get", self._on_params_get)
        self._service(MotionParamsSet, "params_set", self._on_params_set)
        self._service(AxisListGet, "axis_list_get", self._on_axis_list_get)
        self._service(AxisListSet, "axis_list_set", self._on_axis_list_set)
        self._service(AxisListEdit, "axis_list_edit", self._on_axis_list_edit)
        self._service(PositionGet, "position_get", self._on_position_get)
        self._service(PositionSet, "position_set", self._on_position_set)
        self._service(FrameBufferStatusGet, "frame_buffer_status", self._on_frame_buffer_status)
        self._service(EventNotifyGet, "event_notify_get", self._on_event_notify_get)
        self._service(EventNotifySet, "event_notify_set", self._on_event_notify_set)
        self._service(EventReset, "event_reset", self._on_event_reset)
        self._pub_status = self.create_publisher(MotionStatus, "~/status", STATUS_QOS)
        runner.add_periodic(settings.status_rate, self._collect_status)
        runner.add_periodic(settings.feedback_rate, self._collect_feedback)
        runner.on_change(self._review)
        self.watchdog = (LostClientWatchdog(self, lost_client_timeout, self._running, self._client_lost,
                                            self._service_group) if lost_client_timeout > 0 else None)

    def held(self) -> dict[str, int]:
        """What this node holds of its goals (for /diagnostics: none of it may grow without
        bound): goals tracked until they end, goals rclpy keeps until their result expires,
        requests not yet filed. Runner lock held."""
        return {"goals_tracked": len(self._book), "goals_kept": sum(s.kept() for s in self._servers.values()),
                "requests_unfiled": sum(s.unfiled() for s in self._servers.values())}

    def _action_server(self, action_type, name: str, operation: str) -> _GoalServer:
        return _GoalServer(self, action_type, f"~/{name}", _never_executed,
                           goal_callback=lambda goal: self._on_goal(goal, action_type, operation),
                           handle_accepted_callback=lambda handle: self._accept(handle, action_type),
                           cancel_callback=self._on_cancel,
                           after_cancel=lambda: self.runner.update(self._review),
                           callback_group=self._goal_group, result_timeout=self.settings.result_timeout,
                           **ACTION_QOS)

    def _service(self, srv_type, name, callback):
        """A service of this supervisor: /<ns>/ms<n>/<name>."""
        self.create_service(srv_type, f"~/{name}", callback, callback_group=self._service_group)

    def shutdown(self, timeout: float = 2.0) -> None:
        """Reject new goals and end the pending ones with MPIMotionMessageSTOPPED ("the suite
        is shutting down"); waits (up to ``timeout`` s, while ROS runs) until rclpy has them."""
        self._shutting_down = True
        self.runner.update(self._end_all)
        if self.context.ok():
            with self._closing:
                self._closing.wait_for(lambda: self._unfinished == 0, timeout)

    def destroy_node(self):
        """The action servers go first (after the executor has stopped: see Suite.shutdown)."""
        for server in self._servers.values():
            server.destroy()
        return super().destroy_node()

    # -- status -----------------------------------------------------------------------
    def _collect_status(self, ctl):
        snap = self._snapshots.motion(ctl, self.number)  # read once a sample for every node (snapshots.py)
        if snap is None:
            return None
        # packed straight into CDR and published raw where the interfaces allow (wire.py)
        encode = wire.motion_status if wire.AVAILABLE else convert.motion_status
        msg = encode(snap, ctl.rate, convert.epoch_of(ctl))
        return lambda: convert.publish(self, self._pub_status, msg)

    # -- goals: acceptance and cancel (executor threads) -------------------------------
    def _on_goal(self, goal_msg, action_type, operation: str) -> GoalResponse:
        """goal_callback: apply the goal's command now, before rclpy answers the client, so
        that a client that sends a modify on receiving its start's answer finds the move.
        Every goal is accepted (but while shutting down); a refused command ends it ABORTED."""
        if self._shutting_down:
            return GoalResponse.REJECT
        server = self._servers[action_type]
        goal_id = server.goal_id
        assert goal_id is not None  # set while the server handles the goal request that calls this
        try:
            command = Command(operation, self.number, request=convert.to_dict(goal_msg))
            convert.release(goal_msg)  # read once; rclpy would keep it until the result expires
            server.applied[goal_id] = self.runner.submit(command)
        except Exception as exc:  # noqa: BLE001 - not swallowed: the goal is aborted with it (_accept)
            server.applied[goal_id] = exc
        return GoalResponse.ACCEPT

    def _accept(self, handle: ServerGoalHandle, action_type) -> None:
        """handle_accepted_callback: file the goal (its command has been applied) and review
        the book at once. Returns at once. Goal and cancel requests are handled in order
        (_GoalServer), so a cancel of this goal comes after this."""
        server = self._servers[action_type]
        key = bytes(handle.goal_id.uuid)
        applied = server.applied.pop(key, None)
        if not isinstance(applied, tuple):  # the command raised: rclpy logs it and aborts the goal
            handle.execute(partial(_reraise, applied or RuntimeError("the goal's command was not applied")))
            return
        reply, sample = applied
        goal = TrackedGoal(key, _RosGoal(handle, action_type, server), sample=sample)
        if reply.accepted and reply.serial:
            goal.serial = reply.serial
        else:  # refused, or answered without a move to follow (NO_WAIT): the reply is the result
            goal.end = MoveEnd(0, reply.outcome, sample)
        self.runner.update(partial(self._file, goal))
        if self.watchdog is not None:
            self.watchdog.watch(key, self._feedback_topics[action_type])

    def _file(self, goal: TrackedGoal, ctl: Controller) -> Output | None:
        """Runner lock held: file the goal and review the book. What its move did since its
        command is in the controller's move log, so the review decides it as if it had been
        filed with the command; a refused command ends it here."""
        if self._shutting_down and goal.end is None:
            goal.end = self._shutdown_end(ctl)  # accepted just before shutdown began
        self._book.add(goal)
        return self._review(ctl)

    def _on_cancel(self, handle: ServerGoalHandle) -> CancelResponse:
        """Cancel = STOP: the axes decelerate over decelTime.stop and the goal ends CANCELED
        once stopped. A goal whose end is already known cannot be cancelled any more."""
        with self.runner.lock:
            goal = self._book.get(bytes(handle.goal_id.uuid))
            if goal is None or goal.end is not None or goal.cancel:
                return CancelResponse.REJECT
            with self._transitions:
                goal.cancel = True
        self._stop()
        return CancelResponse.ACCEPT

    def _stop(self) -> None:
        self.runner.submit(Command(ACTION, self.number, request={"action": "STOP"}))

    # -- the lost-client watchdog (watchdog.py; its timer, service group) ---------------
    def _running(self, keys: list[bytes]) -> set[bytes]:
        """Which of these goals have not ended."""
        def read(_ctl) -> set[bytes]:
            return {key for key in keys if (goal := self._book.get(key)) is not None and goal.end is None}
        return self.runner.read(read)

    def _client_lost(self, detail: str) -> None:
        reply, sample = self.runner.submit(Command(CLIENT_LOST, self.number, request={"detail": detail}))
        self.get_logger().warning(f"lost-client watchdog at sample {sample}: {detail} "
                                  f"(STOP answered {reply.message.name})")

    # -- goals: the runner's hooks (runner lock held) ---------------------------------
    def _review(self, ctl: Controller) -> Output | None:
        """After every step batch and command: which goals started, which ended."""
        if not self._book:
            return None
        review = self._book.review(ctl, self._may_end)
        if not review.started and not review.ended:
            return None
        close = self._ended(review.ended, ctl) if review.ended else None

        def output() -> None:
            for goal in review.started:
                self._mark_executing(goal)
            if close is not None:
                close()

        return output

    @staticmethod
    def _may_end(goal: TrackedGoal) -> bool:
        # A cancelled goal ends CANCELED, which rclpy allows only from CANCELING.
        return not goal.cancel or goal.payload.handle.status not in _NOT_YET_CANCELING

    def _end_all(self, ctl: Controller) -> Output | None:
        goals = self._book.end_all(self._shutdown_end(ctl))
        return self._ended(goals, ctl) if goals else None

    @staticmethod
    def _shutdown_end(ctl: Controller) -> MoveEnd:
        return MoveEnd(0, Outcome(Message.MPIMotionMessageSTOPPED, "the suite is shutting down"), ctl.sample)

    def _ended(self, goals: list[TrackedGoal], ctl: Controller) -> Output:
        """Reads what the results need now; the goals are closed after the lock."""
        facts = ctl.motion_feedback(self.number)
        with self._closing:
            self._unfinished += len(goals)

        def close() -> None:
            for goal in goals:
                self._close(goal, facts)

        return close

    def _collect_feedback(self, ctl: Controller) -> Output | None:
        """At the feedback rate: first the review (a goal that has ended gets no more
        feedback), then one reading of the supervisor gives the feedback of every running
        goal; all of it published after the lock.

        Hundreds of goals may be in flight, and the feedback of one goal differs from its
        neighbour's only in the goal id: each message is serialized once (per action type
        and "is the goal's move current") and published raw, with each goal's id in place,
        on the action's feedback topic (``<action>/_action/feedback``, where rcl_action
        publishes it; the goal id is the FeedbackMessage's first field, 16 bytes after the
        4-byte CDR header). ServerGoalHandle.publish_feedback would build and convert a
        message per goal: four times the work, all of it holding the GIL that an E_STOP
        service needs."""
        review = self._review(ctl)
        running = list(self._book.running())
        now = ctl.motion_feedback(self.number)
        if not running or now is None:
            return review
        templates = {}
        sends = []
        for goal in running:
            kind = (goal.payload.action_type, goal.serial == now.serial)
            if kind not in templates:
                templates[kind] = _feedback_template(now, *kind)
            head, tail = templates[kind]
            sends.append((self._feedback_pubs[kind[0]], head + goal.key + tail))
        return partial(_publish_feedback, review, sends)

    # -- goals: state changes (after the lock) ----------------------------------------
    def _mark_executing(self, goal: TrackedGoal) -> None:
        """The goal's move is now the supervisor's current one: status EXECUTING.

        rclpy has no public call for a deferred goal that starts executing (rclcpp has
        ServerGoalHandle::set_executing): ServerGoalHandle.execute() also schedules the
        execute callback, which would end the goal at once. ServerGoalHandle._update_state
        is what execute() itself uses, unchanged since rclpy's first ActionServer; it keeps
        the status honest for clients (ACCEPTED while an appended move waits its turn,
        EXECUTING while it runs).
        """
        with self._transitions:
            if goal.cancel or goal.payload.executing:
                return  # cancelled while waiting: rclpy moves it from ACCEPTED to CANCELING
            goal.payload.handle._update_state(GoalEvent.EXECUTE)
            goal.payload.executing = True

    def _close(self, goal: TrackedGoal, facts: MotionFeedback | None) -> None:
        """Hand an ended goal back to rclpy: its execute callback, scheduled now on the
        executor, sets the terminal state and returns the result without waiting."""
        ros = goal.payload
        assert goal.end is not None  # an ended goal
        finish = partial(self._finish, goal, _result(ros.action_type, goal.end, goal.sample, facts))
        with self._transitions:
            if ros.executing:
                ros.server.notify_execute(ros.handle, finish)
                return
            try:
                ros.handle.execute(finish)  # ACCEPTED -> EXECUTING (not if CANCELING), then `finish`
            except RCLError:
                # A cancel moved it to CANCELING between rclpy's check and its EXECUTE (only
                # at shutdown, which does not wait for the cancel): just schedule `finish`.
                if not ros.handle.is_cancel_requested:
                    raise
                ros.server.notify_execute(ros.handle, finish)

    def _finish(self, goal: TrackedGoal, result, handle: ServerGoalHandle):
        """The goal's execute callback (executor thread): terminal state and result."""
        try:
            assert goal.end is not None  # an ended goal
            if goal.end.succeeded:
                handle.succeed()  # done (or at velocity) before a cancel's STOP took effect
            elif goal.serial is not None and handle.is_cancel_requested:
                handle.canceled()
            else:
                handle.abort()  # refused, stopped, E_STOP/ABORT, dropped, shut down
        finally:
            with self._closing:
                self._unfinished -= 1
                self._closing.notify_all()
        return result

    # -- services ---------------------------------------------------------------------
    def _submit(self, operation: str, request: dict) -> Reply:
        reply, _ = self.runner.submit(Command(operation, self.number, request=request))
        return reply

    def _on_action(self, request, response):
        reply, sample = self.runner.submit(Command(ACTION, self.number, request={"action": request.action}))
        convert.answer(response, reply)
        response.state = int(reply.state)
        response.state_name = reply.state.name
        response.sample = sample
        response.detail = reply.detail
        return response

    def _on_trigger(self, action: str, response):
        reply, sample = self.runner.submit(Command(ACTION, self.number, request={"action": action}))
        response.success = reply.message is Message.MPIMessageOK
        response.message = reply.message.name + (f": {reply.detail}" if reply.detail else "")
        return response

    def _read_ms(self, reader):
        return self.runner.read(lambda ctl: reader(ctl.supervisor(self.number)))

    def _on_config_get(self, _request, response):
        message, config = self._read_ms(lambda ms: ms.config_get())
        convert.fill(response.config, rq.motion_config_to_dict(config))
        return convert.answer(response, Reply.of(message))

    def _on_config_set(self, request, response):
        return convert.answer(response, self._submit("config_set", {"config": convert.to_dict(request.config)}))

    def _on_params_get(self, _request, response):
        message, params = self._read_ms(lambda ms: ms.params_get())
        response.params = convert.fill(MotionParamsMsg(), rq.params_to_dict(params))
        return convert.answer(response, Reply.of(message))

    def _on_params_set(self, request, response):
        return convert.answer(response, self._submit("params_set", {"params": convert.to_dict(request.params)}))

    def _on_axis_list_get(self, _request, response):
        message, numbers, mapped = self._read_ms(lambda ms: (*ms.axis_list_get(), list(ms.mapped)))
        response.axis_numbers = numbers
        response.mapped_axis_numbers = mapped
        return convert.answer(response, Reply.of(message))

    def _on_axis_list_set(self, request, response):
        reply = self._submit("axis_list_set", {"axis_numbers": list(request.axis_numbers), "map": request.map})
        return convert.answer(response, reply)

    def _on_axis_list_edit(self, request, response):
        reply = self._submit("axis_list_edit", convert.to_dict(request))
        response.axis_numbers = list(reply.value or [])
        return convert.answer(response, reply)

    def _on_position_get(self, _request, response):
        message, actual, command = self._read_ms(lambda ms: ms.position_get())
        response.actual = [float(x) for x in actual]
        response.command = [float(x) for x in command]
        return convert.answer(response, Reply.of(message))

    def _on_position_set(self, request, response):
        reply = self._submit("position_set", {"actual": list(request.actual), "command": list(request.command)})
        return convert.answer(response, reply)

    def _on_frame_buffer_status(self, _request, response):
        message, statuses = self._read_ms(lambda ms: ms.frame_buffer_status())
        response.axes = [FrameBufferStatusMsg(axis=s.axis, size=s.size, frame_count=s.frame_count) for s in statuses]
        return convert.answer(response, Reply.of(message))

    def _on_event_notify_get(self, _request, response):
        message, mask = self._read_ms(lambda ms: ms.event_notify_get())
        response.event_types = mask.names()
        return convert.answer(response, Reply.of(message))

    def _on_event_notify_set(self, request, response):
        return convert.answer(response, self._submit("event_notify_set", {"event_types": list(request.event_types)}))

    def _on_event_reset(self, request, response):
        reply = self._submit("event_reset", {"event_types": list(request.event_types)})
        response.latched_event_types = list(reply.value or [])
        return convert.answer(response, reply)


def _result(action_type, end: MoveEnd, sample: int, facts: MotionFeedback | None):
    """The result: the end's message and positions, the supervisor's state when it ended."""
    result = action_type.Result()
    result.message = end.message.name
    result.code = end.message.code
    result.sample = sample
    result.end_sample = end.sample
    result.detail = end.detail
    if facts is not None:
        result.state = int(facts.state)
        result.state_name = facts.state.name
        result.actual_position = list(end.actual_position or facts.actual_position)
        result.command_position = list(end.command_position or facts.command_position)
        result.move_id = facts.move_id
    return result


def _feedback(now: MotionFeedback, action_type, current: bool):
    """A goal's feedback; ``current``: the goal's move is the supervisor's current one."""
    fb = action_type.Feedback()
    fb.sample = now.sample
    fb.state = int(now.state)
    fb.state_name = now.state.name
    fb.command_position = list(now.command_position)
    fb.actual_position = list(now.actual_position)
    fb.command_velocity = list(now.command_velocity)
    fb.progress = now.progress if current else 0.0
    fb.move_id = now.move_id
    fb.element_id = now.element_id
    return fb


def _feedback_template(now: MotionFeedback, action_type, current: bool) -> tuple[bytes, bytes]:
    """A FeedbackMessage serialized, split around its goal id: (CDR header, the rest)."""
    message = action_type.Impl.FeedbackMessage()
    message.feedback = _feedback(now, action_type, current)
    data = serialize_message(message)
    return data[:4], data[4 + _GOAL_ID_SIZE:]


_GOAL_ID_SIZE = 16  # unique_identifier_msgs/UUID: uint8[16], no length, alignment 1


def _publish_feedback(review: Output | None, sends: list) -> None:
    if review is not None:
        review()
    for publisher, data in sends:
        publisher.publish(data)
