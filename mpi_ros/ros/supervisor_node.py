"""One node per motion supervisor: /<ns>/ms<n> with its actions, services and status.

Goals are always accepted; the controller's answer comes back in the result (a refused
command ends the goal ABORTED with the spec's message). Services live in their own
reentrant callback group, apart from the goals, so E_STOP is served while goals run.
"""

from __future__ import annotations

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
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
from ..commands import ACTION, MOTION_MODIFY, MOTION_START, Command, Reply
from ..config import RosSettings
from ..mpi.messages import Message
from ..runner import ControllerRunner
from . import convert
from .goal_tracker import GoalEnd, GoalTracker

STATUS_QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
# The action's services default to a history of 10: an E_STOP that ends more goals than
# that at once would drop results. Deep enough for every goal a frame buffer can queue.
ACTION_SERVICE_QOS = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
ACTION_QOS = dict(goal_service_qos_profile=ACTION_SERVICE_QOS, result_service_qos_profile=ACTION_SERVICE_QOS,
                  cancel_service_qos_profile=ACTION_SERVICE_QOS)
TRIGGER_ACTIONS = {"stop": "STOP", "e_stop": "E_STOP", "abort": "ABORT", "reset": "RESET", "resume": "RESUME"}


class SupervisorNode(Node):
    def __init__(self, runner: ControllerRunner, number: int, settings: RosSettings, **kwargs):
        super().__init__(f"ms{number}", namespace=settings.namespace, **kwargs)
        self.runner = runner
        self.number = number
        self.settings = settings
        self._shutting_down = False
        self._goal_group = ReentrantCallbackGroup()
        self._service_group = ReentrantCallbackGroup()
        self._actions = [
            ActionServer(self, MotionStart, "~/motion_start", lambda h: self._execute(h, MotionStart, MOTION_START),
                         goal_callback=self._on_goal, cancel_callback=self._on_cancel, callback_group=self._goal_group,
                         **ACTION_QOS),
            ActionServer(self, MotionModify, "~/motion_modify", lambda h: self._execute(h, MotionModify, MOTION_MODIFY),
                         goal_callback=self._on_goal, cancel_callback=self._on_cancel, callback_group=self._goal_group,
                         **ACTION_QOS),
        ]
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

    def _service(self, srv_type, name, callback):
        """A service of this supervisor: /<ns>/ms<n>/<name>."""
        self.create_service(srv_type, f"~/{name}", callback, callback_group=self._service_group)

    def shutdown(self) -> None:
        self._shutting_down = True
        for server in self._actions:
            server.destroy()

    # -- status -----------------------------------------------------------------------
    def _collect_status(self, ctl):
        ms = ctl.supervisor(self.number)
        if ms is None:
            return None
        msg = convert.motion_status(ms.snapshot(), ctl.rate)
        return lambda: convert.publish(self, self._pub_status, msg)

    # -- goals ------------------------------------------------------------------------
    def _on_goal(self, _goal) -> GoalResponse:
        return GoalResponse.REJECT if self._shutting_down else GoalResponse.ACCEPT

    def _on_cancel(self, _handle) -> CancelResponse:
        return CancelResponse.ACCEPT

    def _execute(self, handle, action_type, operation: str):
        command = Command(operation, self.number, request=convert.to_dict(handle.request))
        reply, sample = self.runner.submit(command)
        if not reply.accepted:
            handle.abort()
            return self._result(action_type, GoalEnd(reply.message, reply.detail, sample), sample)
        tracker = GoalTracker(self.runner, self.number, reply.serial)
        period = 1.0 / self.settings.feedback_rate
        stop_sent = False
        while True:
            if handle.is_cancel_requested and not stop_sent:
                # Cancel = STOP: decelerate over decelTime.stop, then end the goal.
                self.runner.submit(Command(ACTION, self.number, request={"action": "STOP"}))
                stop_sent = True
            end = tracker.wait(period)
            if end is not None:
                break
            if self._shutting_down or not self.context.ok():
                end = GoalEnd(Message.MPIMotionMessageSTOPPED, "the suite is shutting down", sample)
                break
            handle.publish_feedback(self._feedback(action_type, reply.serial))
        result = self._result(action_type, end, sample)
        if handle.is_cancel_requested:
            handle.canceled()
        elif end.succeeded:
            handle.succeed()
        else:
            handle.abort()
        return result

    def _feedback(self, action_type, serial: int):
        def read(ctl):
            ms = ctl.supervisor(self.number)
            axes = [ctl.axes[n] for n in ms.mapped]
            fb = action_type.Feedback()
            fb.sample = ctl.sample
            fb.state = int(ms.state)
            fb.state_name = ms.state.name
            fb.command_position = [a.command_position for a in axes]
            fb.actual_position = [a.actual_position for a in axes]
            fb.command_velocity = [a.cmd_v for a in axes]
            fb.progress = float(ms.progress()) if ms.current is not None and ms.current.serial == serial else 0.0
            move = ms.current or ms.last_move
            fb.move_id = move.id if move else 0
            fb.element_id = move.element_id if move else 0
            return fb

        return self.runner.read(read)

    def _result(self, action_type, end: GoalEnd, sample: int):
        def read(ctl):
            ms = ctl.supervisor(self.number)
            result = action_type.Result()
            result.message = end.message.name
            result.code = end.message.code
            result.sample = sample
            result.end_sample = end.sample
            result.detail = end.detail
            if ms is not None:
                axes = [ctl.axes[n] for n in ms.mapped]
                result.state = int(ms.state)
                result.state_name = ms.state.name
                result.actual_position = list(end.actual_position or [a.actual_position for a in axes])
                result.command_position = list(end.command_position or [a.command_position for a in axes])
                move = ms.current or ms.last_move
                result.move_id = move.id if move else 0
            return result

        return self.runner.read(read)

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
        return convert.answer(response, Reply(message))

    def _on_config_set(self, request, response):
        return convert.answer(response, self._submit("config_set", {"config": convert.to_dict(request.config)}))

    def _on_params_get(self, _request, response):
        message, params = self._read_ms(lambda ms: ms.params_get())
        response.params = convert.fill(MotionParamsMsg(), rq.params_to_dict(params))
        return convert.answer(response, Reply(message))

    def _on_params_set(self, request, response):
        return convert.answer(response, self._submit("params_set", {"params": convert.to_dict(request.params)}))

    def _on_axis_list_get(self, _request, response):
        message, numbers, mapped = self._read_ms(lambda ms: (*ms.axis_list_get(), list(ms.mapped)))
        response.axis_numbers = numbers
        response.mapped_axis_numbers = mapped
        return convert.answer(response, Reply(message))

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
        return convert.answer(response, Reply(message))

    def _on_position_set(self, request, response):
        reply = self._submit("position_set", {"actual": list(request.actual), "command": list(request.command)})
        return convert.answer(response, reply)

    def _on_frame_buffer_status(self, _request, response):
        message, statuses = self._read_ms(lambda ms: ms.frame_buffer_status())
        response.axes = [FrameBufferStatusMsg(axis=s.axis, size=s.size, frame_count=s.frame_count) for s in statuses]
        return convert.answer(response, Reply(message))

    def _on_event_notify_get(self, _request, response):
        message, mask = self._read_ms(lambda ms: ms.event_notify_get())
        response.event_types = mask.names()
        return convert.answer(response, Reply(message))

    def _on_event_notify_set(self, request, response):
        return convert.answer(response, self._submit("event_notify_set", {"event_types": list(request.event_types)}))

    def _on_event_reset(self, request, response):
        reply = self._submit("event_reset", {"event_types": list(request.event_types)})
        response.latched_event_types = list(reply.value or [])
        return convert.answer(response, reply)

