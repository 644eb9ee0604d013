"""A small Python API over the suite's ROS interface, hiding the action plumbing.

    from mpi_ros.client import MotionClient
    with MotionClient(supervisor=0) as ms0:
        ms0.move([1000.0, 0.0], velocity=500.0, acceleration=5000.0)   # waits until DONE
        goal = ms0.start({"type": "VELOCITY", "trajectory": [{"velocity": 200.0, "acceleration": 1000.0}]})
        ms0.stop()
        ms0.reset()
        print(ms0.status().state_name)

Refusals raise the exception of the spec's message (``mpi_ros.errors.MPIMotionMessageMOVING``
...); a missing answer raises ``mpi_ros.errors.NoResponse``. The client spins its own node
in a background thread; action goals are sent from that thread (rclpy's ActionClient is
not safe to send from another thread while spinning).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Any, Callable, Iterable

import rclpy
from rclpy.action import ActionClient
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from mpi_ros.action import MotionModify, MotionStart
from mpi_ros.msg import MotionStatus
from mpi_ros.srv import MotionAction

from .errors import NoResponse, raise_for
from .ros import convert
from .ros.supervisor_node import ACTION_QOS

@dataclass(frozen=True)
class ActionReply:
    message: str
    code: int
    state_name: str
    sample: int


class Goal:
    """A running MotionStart/MotionModify goal."""

    def __init__(self, client: "MotionClient", handle, result_future):
        self._client = client
        self.handle = handle
        self._result_future = result_future
        self.feedback = None  # the latest feedback message

    @property
    def done(self) -> bool:
        return self._result_future.done()

    def wait(self, timeout: float | None = None, raise_on_error: bool = True):
        """Wait for the result (the action's Result message)."""
        response = self._client._wait_future(self._result_future, timeout, "the goal's result")
        result = response.result
        if raise_on_error:
            raise_for(result.message, result.detail, result)
        return result

    def cancel(self, timeout: float | None = 5.0) -> None:
        """Cancel = STOP: the axes decelerate over decelTime.stop and the goal ends."""
        future = self._client._on_executor(self.handle.cancel_goal_async)
        self._client._wait_future(future, timeout, "the cancel answer")


class MotionClient:
    def __init__(self, supervisor: int = 0, namespace: str = "/mpi", context: Context | None = None,
                 timeout: float = 10.0, node_name: str | None = None):
        self.supervisor = supervisor
        self.namespace = namespace.rstrip("/")
        self.timeout = timeout
        self._own_context = context is None and not rclpy.ok()
        if self._own_context:
            rclpy.init()
        self._context = context
        prefix = f"{self.namespace}/ms{supervisor}"
        self.node = Node(node_name or f"mpi_ros_client_ms{supervisor}", context=context)
        self._start = ActionClient(self.node, MotionStart, f"{prefix}/motion_start", **ACTION_QOS)
        self._modify = ActionClient(self.node, MotionModify, f"{prefix}/motion_modify", **ACTION_QOS)
        self._action = self.node.create_client(MotionAction, f"{prefix}/action")
        self._status: MotionStatus | None = None
        self._status_event = threading.Condition()
        qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self.node.create_subscription(MotionStatus, f"{prefix}/status", self._on_status, qos)
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, name="mpi-ros-client", daemon=True)
        self._thread.start()

    # -- lifecycle -------------------------------------------------------------------------
    def _spin(self) -> None:
        try:
            self._executor.spin()
        except Exception:  # noqa: BLE001 - the context shut down under us: stop spinning
            pass

    def close(self) -> None:
        self._executor.shutdown(timeout_sec=2.0)
        self._thread.join(timeout=2.0)
        self.node.destroy_node()
        if self._own_context:
            rclpy.try_shutdown()

    def __enter__(self) -> "MotionClient":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def wait_for_server(self, timeout: float | None = None) -> bool:
        timeout = self.timeout if timeout is None else timeout
        return self._start.wait_for_server(timeout_sec=timeout) and self._action.wait_for_service(timeout_sec=timeout)

    # -- plumbing ------------------------------------------------------------------------
    def _on_executor(self, call: Callable[[], Any]):
        """Run ``call`` on the spinning thread; returns the future it returns."""
        box: dict[str, Any] = {}
        ready = threading.Event()

        def run():
            try:
                box["future"] = call()
            finally:
                ready.set()

        self._executor.create_task(run)
        if not ready.wait(self.timeout):
            raise NoResponse("the client's executor did not run the request")
        return box["future"]

    def _wait_future(self, future, timeout: float | None, what: str):
        done = threading.Event()
        future.add_done_callback(lambda _f: done.set())
        if not done.wait(self.timeout if timeout is None else timeout):
            raise NoResponse(f"no answer for {what} within the timeout")
        return future.result()

    # -- goals ---------------------------------------------------------------------------
    def start(self, goal: dict[str, Any], feedback: Callable[[Any], None] | None = None) -> Goal:
        """Send a MotionStart goal given as a dict of its fields; returns the running Goal."""
        return self._send(self._start, MotionStart.Goal(), goal, feedback)

    def modify(self, goal: dict[str, Any], feedback: Callable[[Any], None] | None = None) -> Goal:
        """Send a MotionModify goal given as a dict of its fields."""
        return self._send(self._modify, MotionModify.Goal(), goal, feedback)

    def _send(self, action_client, msg, goal: dict[str, Any], feedback) -> Goal:
        convert.fill(msg, goal)
        holder: dict[str, Goal] = {}

        def on_feedback(message):
            if "goal" in holder:
                holder["goal"].feedback = message.feedback
            if feedback is not None:
                feedback(message.feedback)

        if not action_client.wait_for_server(timeout_sec=self.timeout):
            raise NoResponse(f"action server {action_client._action_name} not available")
        send = self._on_executor(lambda: action_client.send_goal_async(msg, feedback_callback=on_feedback))
        handle = self._wait_future(send, None, "the goal request")
        result = self._on_executor(handle.get_result_async)
        holder["goal"] = Goal(self, handle, result)
        return holder["goal"]

    def move(self, position: Iterable[float], velocity: float, acceleration: float, deceleration: float | None = None,
             jerk_percent: float = 0.0, motion_type: str = "S_CURVE", attributes: Iterable[str] = (),
             wait: bool = True, timeout: float | None = None, **fields):
        """A point-to-point move; waits for DONE and returns the result (or the Goal)."""
        goal = {
            "type": motion_type,
            "attributes": list(attributes),
            "position": [float(p) for p in position],
            "trajectory": [{"velocity": velocity, "acceleration": acceleration,
                            "deceleration": acceleration if deceleration is None else deceleration,
                            "jerk_percent": jerk_percent}],
            **fields,
        }
        running = self.start(goal)
        return running.wait(timeout) if wait else running

    def wait_done(self, goal: Goal, timeout: float | None = None, raise_on_error: bool = True):
        return goal.wait(timeout, raise_on_error)

    # -- actions ----------------------------------------------------------------------------
    def action(self, name: str, raise_on_error: bool = True) -> ActionReply:
        """mpiMotionAction: STOP, E_STOP, ABORT, E_STOP_ABORT, RESET, RESUME or MAP."""
        if not self._action.wait_for_service(timeout_sec=self.timeout):
            raise NoResponse("the supervisor's action service is not available")
        response = self._wait_future(self._action.call_async(MotionAction.Request(action=name)), None,
                                     f"action {name}")
        reply = ActionReply(response.message, response.code, response.state_name, response.sample)
        if raise_on_error:
            raise_for(reply.message, f"{name} in {reply.state_name}", reply)
        return reply

    def stop(self) -> ActionReply:
        return self.action("STOP")

    def e_stop(self) -> ActionReply:
        return self.action("E_STOP")

    def abort(self) -> ActionReply:
        return self.action("ABORT")

    def reset(self) -> ActionReply:
        return self.action("RESET")

    def resume(self) -> ActionReply:
        return self.action("RESUME")

    # -- status ---------------------------------------------------------------------------------
    def _on_status(self, msg: MotionStatus) -> None:
        with self._status_event:
            self._status = msg
            self._status_event.notify_all()

    def status(self, timeout: float | None = None, newer_than: int = -1) -> MotionStatus:
        """The latest MotionStatus (waits for one newer than sample ``newer_than``)."""
        with self._status_event:
            ok = self._status_event.wait_for(
                lambda: self._status is not None and self._status.sample > newer_than,
                self.timeout if timeout is None else timeout)
            if not ok:
                raise NoResponse("no MotionStatus received")
            return self._status

    def wait_for_state(self, state_name: str, timeout: float | None = None) -> MotionStatus:
        """Wait until the supervisor's status shows ``state_name``."""
        with self._status_event:
            ok = self._status_event.wait_for(
                lambda: self._status is not None and self._status.state_name == state_name,
                self.timeout if timeout is None else timeout)
            if not ok:
                raise NoResponse(f"the supervisor did not reach {state_name}")
            return self._status

