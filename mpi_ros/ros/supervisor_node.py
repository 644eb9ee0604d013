"""One node per motion supervisor: /<ns>/ms<n> with its actions, services and status.

Goals are always accepted; the controller's answer comes back in the result (a refused
command ends the goal ABORTED with the spec's message). Services live in their own
reentrant callback group, apart from the goals, so E_STOP is served while goals run.

A goal holds no executor thread while its move runs (with more goals than threads nothing
else would be served, E_STOP included), and runs no callback: GoalServer (goal_server.py)
takes every goal request waiting (the suite's GoalLoop waits for them in a thread of its
own, outside the node's executor: goal_loop.py), the node applies their commands together (so a client's
goal response comes after its command took effect) and files the goals in a GoalBook; the
runner reviews the book after every step batch and command, under its lock. A goal whose
move has become current is marked EXECUTING; a goal whose move has ended is finished with
its result, after the lock. Feedback for every running goal comes from one periodic hook at
the feedback rate. With ``lost_client_timeout`` > 0 a watchdog STOPs the motion of a goal
whose client has left the graph (watchdog.py, docs/cell.md).
"""

from __future__ import annotations

import threading
import traceback
from dataclasses import dataclass
from functools import partial

from action_msgs.msg import GoalStatus
from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.event_handler import PublisherEventCallbacks, UnsupportedEventTypeError
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.serialization import serialize_message
from std_srvs.srv import Trigger
from trajectory_msgs.msg import JointTrajectory

from mpi_ros.action import MotionModify, MotionStart
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import MoveEnd, Outcome, Refused
from mpi_ros.mpi.base.snapshot import MotionFeedback
from mpi_ros.mpi.control import Controller
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
    MotionParamsValidate,
    PositionGet,
    PositionSet,
)

from .. import graph_names as gn
from .. import requests as rq
from ..commands import Command, Operation, Reply
from ..config import RosSettings
from ..joints import AxisJoint
from ..qos import profile
from ..runner import AtSample, ControllerRunner, Output
from ..trajectory_feed import TrajectoryFeed
from . import convert, wire
from .goal_front import GoalRelay
from .goal_loop import GoalLoop
from .goal_server import ABORT, CANCELED, SUCCEED, Callbacks, GoalServer
from .goal_tracker import GoalBook, TrackedGoal
from .stock_goal_server import StockGoalServer
from .watchdog import LostClientWatchdog, WatchdogTicker

# A goal whose cancel was accepted is still in one of these until its GoalServer has moved it
# to CANCELING (right after our cancel callback returns); only then may it end CANCELED.
_NOT_YET_CANCELING = (GoalStatus.STATUS_ACCEPTED, GoalStatus.STATUS_EXECUTING)


@dataclass(eq=False, slots=True)
class _RosGoal:
    """What finishing a goal needs from ROS (the payload of its TrackedGoal)."""

    server: GoalServer | StockGoalServer
    action_type: type


class SupervisorNode(Node):
    def __init__(self, runner: ControllerRunner, number: int, settings: RosSettings, goal_loop: GoalLoop | GoalRelay,
                 lost_client_timeout: float = 0.0, joints: list[AxisJoint] | None = None,
                 packer: wire.Packer | None = None, watchdogs: WatchdogTicker | None = None, **kwargs):
        super().__init__(f"ms{number}", namespace=settings.namespace, **kwargs)
        self.runner = runner
        # the suite's Packer (Suite): an axis' body packed for its own topic is reused here
        self._packer = packer or wire.Packer(runner.ctl.rate, convert.epoch_of(runner.ctl), settings.namespace)
        self.number = number
        self.settings = settings
        self._shutting_down = False
        self._service_group = ReentrantCallbackGroup()
        self._book = GoalBook(number)
        self._closing = threading.Condition()
        self._goal_loop = goal_loop
        self._unfinished = 0  # goals ended whose result has not been handed to their server yet
        ns = settings.namespace
        actions = ((MotionStart, gn.MOTION_START.name(ns, number), Operation.MOTION_START),
                   (MotionModify, gn.MOTION_MODIFY.name(ns, number), Operation.MOTION_MODIFY))
        # each action's feedback topic: its clients subscribe there (the watchdog looks for them)
        self._feedback_topics = {action_type: gn.action_feedback(name) for action_type, name, _ in actions}
        self._servers = {action_type: self._action_server(action_type, name, operation)
                         for action_type, name, operation in actions}
        for server in self._servers.values():
            if isinstance(server, GoalServer):
                goal_loop.add(server)
        # its checks on the suite's one watchdog timer (``watchdogs``, Suite) where there is one
        self.watchdog = (LostClientWatchdog(self, lost_client_timeout, self._running, self._client_lost,
                                            self._service_group, ticker=watchdogs)
                         if lost_client_timeout > 0 else None)
        # Feedback goes out pre-serialized on the actions' own feedback topics (see _collect_feedback).
        self._feedback_pubs = {action_type: self._feedback_publisher(action_type, self._feedback_topics[action_type])
                               for action_type in self._feedback_topics}
        self._service(MotionAction, gn.MOTION_ACTION, self._on_action)
        for endpoint, action in gn.TRIGGERS.values():
            self._service(Trigger, endpoint, lambda req, resp, a=action: self._on_trigger(a, resp))
        self._service(MotionConfigGet, gn.MOTION_CONFIG_GET, self._on_config_get)
        self._service(MotionConfigSet, gn.MOTION_CONFIG_SET, self._on_config_set)
        self._service(MotionParamsGet, gn.PARAMS_GET, self._on_params_get)
        self._service(MotionParamsSet, gn.PARAMS_SET, self._on_params_set)
        self._service(AxisListGet, gn.AXIS_LIST_GET, self._on_axis_list_get)
        self._service(AxisListSet, gn.AXIS_LIST_SET, self._on_axis_list_set)
        self._service(AxisListEdit, gn.AXIS_LIST_EDIT, self._on_axis_list_edit)
        self._service(PositionGet, gn.POSITION_GET, self._on_position_get)
        self._service(PositionSet, gn.POSITION_SET, self._on_position_set)
        self._service(FrameBufferStatusGet, gn.FRAME_BUFFER_STATUS, self._on_frame_buffer_status)
        self._service(EventNotifyGet, gn.EVENT_NOTIFY_GET, self._on_event_notify_get)
        self._service(EventNotifySet, gn.EVENT_NOTIFY_SET, self._on_event_notify_set)
        self._service(EventReset, gn.EVENT_RESET, self._on_event_reset)
        self._service(MotionParamsValidate, gn.PARAMS_VALIDATE, self._on_params_validate)
        self._pub_status = self.create_publisher(MotionStatus, gn.MOTION_STATUS.name(ns, number),
                                                 profile(gn.MOTION_STATUS.qos))
        runner.add_status(settings.status_rate, self._collect_status)
        # without a goal tracked, a feedback stop would find nothing to do
        runner.add_periodic(settings.feedback_rate, self._collect_feedback, wanted=lambda: len(self._book) > 0)
        runner.on_change(self._review)
        # JointTrajectory commands in SI units (trajectory_feed.py, docs/trajectories.md)
        self.trajectories = TrajectoryFeed(runner, number, joints or [], convert.epoch_of(runner.ctl) or 0,
                                           self.get_logger().warning)
        self.create_subscription(JointTrajectory, gn.JOINT_TRAJECTORY.name(ns, number), self._on_trajectory,
                                 profile(gn.JOINT_TRAJECTORY.qos),
                                 callback_group=self._service_group)

    def held(self) -> dict[str, int]:
        """What this node holds of its goals (for /diagnostics: none of it may grow without
        bound): goals tracked until they end, goals kept until their result expires,
        requests taken and not yet handled. Runner lock held."""
        return {"goals_tracked": len(self._book), "goals_kept": sum(s.kept() for s in self._servers.values()),
                "requests_unfiled": sum(s.unfiled() for s in self._servers.values())}

    def _action_server(self, action_type, name: str, operation: str) -> GoalServer | StockGoalServer:
        callbacks = Callbacks(accepting=lambda: not self._shutting_down,
                              apply=partial(self._on_goals, action_type, operation), cancel=self._on_cancel,
                              cancelled=lambda: self.runner.update(self._review))
        if self.settings.action_server == "rclpy":
            return StockGoalServer(self, action_type, name, callbacks, profile(gn.ACTION_SERVICE_QOS),
                                   result_timeout=self.settings.result_timeout)
        endpoints = self._goal_loop.endpoints(self, action_type, name, profile(gn.ACTION_SERVICE_QOS))
        return GoalServer(self, action_type, name, callbacks, endpoints,
                          result_timeout=self.settings.result_timeout)

    def _service(self, srv_type, endpoint: gn.Endpoint, callback):
        """A service of this supervisor: /<ns>/ms<n>/<leaf>."""
        self.create_service(srv_type, endpoint.name(self.settings.namespace, self.number), callback,
                            qos_profile=profile(endpoint.qos), callback_group=self._service_group)

    def shutdown(self, timeout: float = 2.0) -> None:
        """Reject new goals and end the pending ones with MPIMotionMessageSTOPPED ("the suite
        is shutting down"); waits (up to ``timeout`` s, while ROS runs) until their results are out."""
        self._shutting_down = True
        self.runner.update(self._end_all)
        if self.context.ok():
            with self._closing:
                self._closing.wait_for(lambda: self._unfinished == 0, timeout)

    def destroy_node(self):
        """The action servers go first (after the executor and the goal loop have stopped: see
        Suite.shutdown)."""
        for server in self._servers.values():
            server.destroy()
        return super().destroy_node()

    # -- status -----------------------------------------------------------------------
    def _collect_status(self, ctl, at: AtSample):
        """The runner calls it with the snapshots of its sample (runner.add_status), the same
        ones the axis topics publish; the controller may be past that sample."""
        snap = at.taken()[0].get(self.number)
        if snap is None:
            return None
        # packed straight into CDR and published raw where the interfaces allow (wire.py)
        msg = (self._packer.motion_status(snap) if wire.AVAILABLE
               else convert.motion_status(snap, ctl.rate, convert.epoch_of(ctl), self.settings.namespace))
        return lambda: convert.publish(self, self._pub_status, msg)

    # -- JointTrajectory commands -----------------------------------------------------
    def _on_trajectory(self, msg: JointTrajectory) -> None:
        points = [(list(p.positions), list(p.velocities), p.time_from_start.sec + p.time_from_start.nanosec * 1e-9)
                  for p in msg.points]
        stamp_ns = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        self.trajectories.receive(list(msg.joint_names), points, stamp_ns)

    def trajectory_diagnostic(self, _ctl=None) -> list[DiagnosticStatus]:
        """/diagnostics "<ns>/ms<n>/joint_trajectory": trajectories received, accepted, refused
        (per MPI message) and interrupted, and the last refusal with its reason."""
        counts = self.trajectories.snapshot()
        status = DiagnosticStatus()
        status.name = gn.JOINT_TRAJECTORY.name(self.settings.namespace, self.number).lstrip("/")
        status.hardware_id = "mpi_ros simulated controller"
        level = DiagnosticStatus.WARN if counts.refused_total or counts.interrupted else DiagnosticStatus.OK
        status.level = bytes([level]) if isinstance(level, int) else level
        status.message = (f"{counts.accepted} accepted, {counts.refused_total} refused, {counts.interrupted} "
                          "interrupted" + (f"; last: {counts.last_refusal}" if counts.last_refusal else ""))
        values = [("received", counts.received), ("accepted", counts.accepted), ("refused", counts.refused_total),
                  ("interrupted", counts.interrupted), ("last_refusal", counts.last_refusal)]
        values += [(f"refused_{name}", n) for name, n in sorted(counts.refused.items())]
        status.values = [KeyValue(key=k, value=str(v)) for k, v in values]
        return [status]

    # -- goals: acceptance and cancel (executor threads) -------------------------------
    def _on_goals(self, action_type, operation: str, goals: list[tuple[bytes, dict | Exception]]) -> None:
        """A batch of accepted goals (each as a dict, or the exception reading it raised):
        their commands applied now, together, in order, and the goals filed in the book under
        the same hold of the lock (GoalServer answers their clients after this: a client that
        sends a modify on receiving its start's answer finds the move). A refused command ends
        its goal ABORTED; a command that raised, or a goal that could not be read (internal
        errors), ends it ABORTED with the error in its detail, and the error is logged."""
        commands: dict[bytes, Command | Exception] = {
            key: goal if isinstance(goal, Exception) else Command(operation, self.number, request=goal)
            for key, goal in goals}
        valid = [(key, command) for key, command in commands.items() if isinstance(command, Command)]
        payload = _RosGoal(self._servers[action_type], action_type)

        def file(ctl: Controller, answers: list) -> None:
            answered = dict(zip((key for key, _ in valid), answers, strict=True))
            for key, command in commands.items():
                goal = self._tracked(key, payload, answered.get(key, command), ctl)
                if self._shutting_down and goal.end is None:
                    goal.end = self._shutdown_end(ctl)  # accepted just before shutdown began
                self._book.add(goal)

        self.runner.submit_all([command for _, command in valid], then=file)
        if self.watchdog is not None:
            for key, _ in goals:
                self.watchdog.watch(key, self._feedback_topics[action_type])

    def _tracked(self, key: bytes, payload: _RosGoal, answer, ctl: Controller) -> TrackedGoal:
        """The goal to follow, from its command's answer: its move, or its end."""
        if isinstance(answer, Exception):
            self.get_logger().error("a goal's command failed (an internal error, not the request's):\n"
                                    + "".join(traceback.format_exception(answer)))
            outcome = Outcome(Message.MPIMotionMessageERROR, f"internal error: {type(answer).__name__}: {answer}")
            return TrackedGoal(key, payload, end=MoveEnd(0, outcome, ctl.sample))
        reply, sample = answer
        goal = TrackedGoal(key, payload, sample=sample)
        if reply.accepted and reply.serial:
            goal.serial = reply.serial
        else:  # refused, or answered without a move to follow (NO_WAIT): the reply is the result
            goal.end = MoveEnd(0, reply.outcome, sample)
        return goal

    def _on_cancel(self, key: bytes) -> bool:
        """Cancel = STOP: the axes decelerate over decelTime.stop and the goal ends CANCELED
        once stopped. A goal whose end is already known cannot be cancelled any more."""
        with self.runner.lock:
            goal = self._book.get(key)
            if goal is None or goal.end is not None or goal.cancel:
                return False
            goal.cancel = True
        self._stop()
        return True

    def _stop(self) -> None:
        self.runner.submit(Command(Operation.ACTION, self.number, request={"action": "STOP"}))

    # -- the lost-client watchdog (watchdog.py; its timer, service group) ---------------
    def _feedback_publisher(self, action_type, topic: str) -> Publisher:
        """The feedback topic's publisher; with a watchdog, its matched event (a client's
        subscription came or left) tells the watchdog when to look at the topic on the graph."""
        qos = profile(gn.FEEDBACK_QOS)
        watchdog = self.watchdog
        if watchdog is None:
            return self.create_publisher(action_type.Impl.FeedbackMessage, topic, qos)
        events = PublisherEventCallbacks(matched=lambda _status: watchdog.changed(topic))
        try:
            publisher = self.create_publisher(action_type.Impl.FeedbackMessage, topic, qos, event_callbacks=events)
        except UnsupportedEventTypeError:  # a middleware without the event: the watchdog looks at every tick
            return self.create_publisher(action_type.Impl.FeedbackMessage, topic, qos)
        watchdog.signalled(topic)
        return publisher

    def _running(self, keys: list[bytes]) -> set[bytes]:
        """Which of these goals have not ended."""
        def read(_ctl) -> set[bytes]:
            return {key for key in keys if (goal := self._book.get(key)) is not None and goal.end is None}
        return self.runner.read(read)

    def _client_lost(self, detail: str) -> None:
        reply, sample = self.runner.submit(Command(Operation.CLIENT_LOST, self.number, request={"detail": detail}))
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
            self._publish_statuses()

        return output

    def _publish_statuses(self) -> None:
        """Each action's goal statuses, once for all the changes of a review."""
        for server in self._servers.values():
            server.publish_status()

    @staticmethod
    def _may_end(goal: TrackedGoal) -> bool:
        # A cancelled goal ends CANCELED, which the protocol allows only from CANCELING: its
        # server moves it there right after the cancel callback accepted.
        return not goal.cancel or goal.payload.server.status(goal.key) not in _NOT_YET_CANCELING

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
            self._publish_statuses()

        return close

    def _collect_feedback(self, ctl: Controller) -> Output | None:
        """At the feedback rate: first the review (a goal that has ended gets no more
        feedback), then one reading of the supervisor gives the feedback of every running
        goal; all of it published after the lock.

        Hundreds of goals may be in flight, and the feedback of one goal differs from its
        neighbour's only in the goal id: each message is serialized once (per action type
        and "is the goal's move current") and published raw, with each goal's id in place,
        on the action's feedback topic (``<action>/_action/feedback``, where action clients
        subscribe; the goal id is the FeedbackMessage's first field, 16 bytes after the
        4-byte CDR header). ServerGoalHandle.publish_feedback would build and convert a
        message per goal: four times the work, all of it holding the GIL that an E_STOP
        service needs."""
        review = self._review(ctl)
        running = list(self._book.running())
        if not running:
            return review
        now = ctl.motion_feedback(self.number)
        if now is None:
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
    @staticmethod
    def _mark_executing(goal: TrackedGoal) -> None:
        """The goal's move is now the supervisor's current one: EXECUTING (the status stays
        honest for clients: ACCEPTED while an appended move waits its turn). A goal whose
        cancel was accepted meanwhile stays CANCELING."""
        goal.payload.server.start(goal.key)

    def _close(self, goal: TrackedGoal, facts: MotionFeedback | None) -> None:
        """An ended goal: its terminal state and its result, to the clients that asked."""
        end = goal.end
        assert end is not None  # an ended goal
        if end.succeeded:
            event = SUCCEED  # done (or at velocity) before a cancel's STOP took effect
        elif goal.serial is not None and goal.cancel:
            event = CANCELED
        else:
            event = ABORT  # refused, stopped, E_STOP/ABORT, dropped, shut down
        try:
            goal.payload.server.finish(goal.key, event, _result(goal.payload.action_type, end, goal.sample, facts))
        finally:
            with self._closing:
                self._unfinished -= 1
                self._closing.notify_all()

    # -- services ---------------------------------------------------------------------
    def _submit(self, operation: str, request: dict) -> Reply:
        reply, _ = self.runner.submit(Command(operation, self.number, request=request))
        return reply

    def _on_action(self, request, response):
        reply, sample = self.runner.submit(Command(Operation.ACTION, self.number, request={"action": request.action}))
        convert.answer(response, reply)
        response.state = int(reply.state)
        response.state_name = reply.state.name
        response.sample = sample
        return response

    def _on_trigger(self, action: str, response):
        reply, _sample = self.runner.submit(Command(Operation.ACTION, self.number, request={"action": action}))
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
        return convert.event_mask_answer(response, *self._read_ms(lambda ms: ms.event_notify_get()))

    def _on_event_notify_set(self, request, response):
        return convert.answer(response, self._submit("event_notify_set", {"event_types": list(request.event_types)}))

    def _on_params_validate(self, request, response):
        """meiMotionParamsValidate: read-only (nothing to record), answered under the lock."""
        try:
            motion = rq.motion_request({"type": request.type, "attributes": list(request.attributes),
                                        **convert.to_dict(request.params)})
        except Refused as exc:
            return convert.answer(response, Reply(exc.outcome))
        outcome, points = self._read_ms(
            lambda ms: ms.params_validate(motion.type, motion.attributes, motion.params, request.modify))
        response.points = points
        return convert.answer(response, Reply(outcome))

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
