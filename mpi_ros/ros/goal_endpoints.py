"""The three services of an action server, as a GoalServer uses them: requests taken as plain
values, responses given as plain values.

A GoalServer (goal_server.py) decides; its endpoints only carry. Two kinds:

- :class:`LocalEndpoints`: the services in this process (rcl services of the server's node,
  waited on by the suite's GoalLoop).
- :class:`RelayedEndpoints`: the services in the goal front, a process of its own
  (goal_front.py) that takes the requests, sends them here as plain values over a pipe and
  sends the responses this side gives it. Taking a request and sending a response cost the
  suite's interpreter about 0.1 ms each (rclpy builds a Python message field by field, and
  back); as plain values over a pipe, a few microseconds.

Plain values, the same for both:

- a goal request: ``(goal id, goal)`` where ``goal`` is the goal message as a dict
  (convert.to_dict), or the exception reading it raised (an internal error: the goal is
  accepted and ends ABORTED with it);
- a cancel request: ``(goal id, stamp ns)`` (an all-zero id and a zero stamp: every goal);
- a result request: ``goal id``;
- a goal response: ``(accepted, stamp ns or None)``;
- a cancel response: ``(return code, [(goal id, stamp ns), ...])``;
- a result response: ``(status, result message)``.
"""

from __future__ import annotations

import logging
import threading
from typing import Any, Protocol

from action_msgs.msg import GoalInfo
from rclpy.type_support import check_for_type_support

from .. import graph_names
from ..qos import profile
from . import convert, rcl

KINDS = ("goal", "cancel", "result")  # the action's services, in the order each round serves them
# The action's services default to a history of 10: an E_STOP that ends more goals than
# that at once would drop results. Deep enough for every goal a frame buffer can queue.
ACTION_SERVICE_QOS = profile(graph_names.ACTION_SERVICE_QOS)

_log = logging.getLogger("mpi_ros.goal_front")


class Endpoints(Protocol):
    def respond(self, kind: str, header: Any, payload: Any) -> None:
        """Answer one request (``header``: what came with it) with a plain payload."""

    def flush(self) -> None:
        """Send what ``respond`` may have held back (relayed responses go in batches)."""

    def destroy(self) -> None:
        """Release the services."""


def plain_request(kind: str, request) -> Any:
    """A request message as the plain value GoalServer reads (see the module's docstring)."""
    if kind == "goal":
        try:
            goal: dict[str, Any] | Exception = convert.to_dict(request.goal)
        except Exception as exc:  # noqa: BLE001 - not swallowed: the goal is accepted and aborted with it
            goal = exc
        return bytes(request.goal_id.uuid), goal
    if kind == "cancel":
        info = request.goal_info
        return bytes(info.goal_id.uuid), info.stamp.sec * 1_000_000_000 + info.stamp.nanosec
    return bytes(request.goal_id.uuid)


def response_message(action_type, kind: str, payload: Any):
    """The response message of a plain payload (see the module's docstring)."""
    impl = action_type.Impl
    if kind == "goal":
        accepted, stamp_ns = payload
        response = impl.SendGoalService.Response(accepted=accepted)
        if stamp_ns is not None:
            response.stamp.sec, response.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
        return response
    if kind == "cancel":
        code, goals = payload
        return impl.CancelGoalService.Response(return_code=code, goals_canceling=[_info(*goal) for goal in goals])
    status, result = payload
    return impl.GetResultService.Response(status=status, result=result)


def _info(key: bytes, stamp_ns: int) -> GoalInfo:
    info = GoalInfo()
    info.goal_id.uuid = list(key)
    info.stamp.sec, info.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
    return info


def create_services(node_handle, action_type, name: str, qos) -> dict[str, Any]:
    """The action's three rcl services on a node (``name``: the action's, resolved as a
    service name of that node)."""
    impl = action_type.Impl
    types = {"goal": impl.SendGoalService, "cancel": impl.CancelGoalService, "result": impl.GetResultService}
    services = {}
    with node_handle:
        for kind in KINDS:
            check_for_type_support(types[kind])  # loads the C type support the service needs
            services[kind] = rcl.service(node_handle, types[kind], graph_names.action_service(name, kind), qos)
    return services


def take_all(service, request_type, kind: str) -> list[tuple[Any, Any]]:
    """Every request waiting on one service: [(its header's request id, its plain value)]."""
    requests: list[tuple[Any, Any]] = []
    while True:
        request, header = service.service_take_request(request_type)
        if header is None or request is None:
            return requests
        requests.append((header.request_id, plain_request(kind, request)))


def request_types(action_type) -> dict[str, Any]:
    impl = action_type.Impl
    return {"goal": impl.SendGoalService.Request, "cancel": impl.CancelGoalService.Request,
            "result": impl.GetResultService.Request}


def take_ready(wait_set, guard, each: list[LocalEndpoints], timeout_ns: int) -> list[dict[str, list]] | None:
    """Wait (up to ``timeout_ns``, -1: no limit) on ``guard`` and on every service of ``each``,
    then take what is waiting on each ready service: per endpoints, {kind: [(header, plain
    request)]}. None when ``guard`` was triggered (the caller stops). The goal loop's rounds
    and the goal front's are this."""
    wait_set.clear_entities()
    wait_set.add_guard_condition(guard)
    places = [[wait_set.add_service(endpoints.services[kind]) for kind in KINDS] for endpoints in each]
    wait_set.wait(timeout_ns)
    if wait_set.is_ready("guard_condition", 0):
        return None
    return [{kind: endpoints.take(kind) for kind, place in zip(KINDS, where, strict=True)
             if wait_set.is_ready("service", place)}
            for endpoints, where in zip(each, places, strict=True)]


class LocalEndpoints:
    """The services in this process, on ``node``. The GoalLoop waits on them (``services``)."""

    def __init__(self, node, action_type, name: str, qos):
        self._node = node
        self._type = action_type
        self.services = create_services(node.handle, action_type, name, qos)
        self._request_types = request_types(action_type)
        self._lock = threading.Lock()  # a service is taken from (the goal loop) and answered (others) at once

    def take(self, kind: str) -> list[tuple[Any, Any]]:
        with self._lock:
            return take_all(self.services[kind], self._request_types[kind], kind)

    def respond(self, kind: str, header: Any, payload: Any) -> None:
        response = response_message(self._type, kind, payload)
        try:
            with self._lock:
                self.services[kind].service_send_response(response, header)
        except rcl.RCLError:  # the client went away; its goal (if accepted) runs without it
            self._node.get_logger().warning(f"a {kind} response could not be sent (the client may have gone away)")

    def flush(self) -> None:
        pass

    def destroy(self) -> None:
        for service in self.services.values():
            service.destroy_when_not_in_use()


class RelayedEndpoints:
    """The services in the goal front: responses go to it, in batches, over ``outbox``."""

    def __init__(self, index: int, outbox: Outbox):
        self._index = index
        self._outbox = outbox

    def respond(self, kind: str, header: Any, payload: Any) -> None:
        self._outbox.put((self._index, kind, header, payload))

    def flush(self) -> None:
        self._outbox.flush()

    def destroy(self) -> None:
        pass  # the front's services go with the front


class Outbox:
    """Responses for the goal front, sent in batches over a pipe's connection (thread-safe)."""

    def __init__(self, connection):
        self._connection = connection
        self._lock = threading.Lock()
        self._held: list[tuple] = []

    def put(self, response: tuple) -> None:
        with self._lock:
            self._held.append(response)

    def flush(self) -> None:
        with self._lock:  # held while sending: batches go out in the order they were made
            if not self._held:
                return
            held, self._held = self._held, []
            try:
                self._connection.send(held)
            except (OSError, ValueError) as exc:  # the front is gone: nobody can be answered any more
                _log.warning("%d goal response(s) not sent: the goal front is gone (%s)", len(held), exc)
