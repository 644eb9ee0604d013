"""One mpiMotionAction (STOP, E_STOP, RESET, ...) from a process that has just started.

:class:`ActionCall` is a node with the supervisor's ``action`` service client and nothing
else: what a one-shot ``mpi-ros e-stop`` needs. It waits for that one service, looked at
every few milliseconds, not for the suite's nodes and both actions' round trips as a
:class:`mpi_ros.client.MotionClient` does before a goal, and it imports neither
rclpy.action nor numpy (a third of a second on a busy machine). The answer types live here
so that the client and the one-shot verbs share them.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Any

from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.type_description_service import START_TYPE_DESCRIPTION_SERVICE_PARAM

from mpi_ros.srv import MotionAction

from . import discovery, errors
from .errors import NoResponse, raise_for
from .graph_names import DEFAULT_NAMESPACE, MOTION_ACTION, ns, supervisor_node
from .qos import profile


class State(StrEnum):
    """A supervisor's or axis' state (``state_name``)."""

    INVALID = "INVALID"
    IDLE = "IDLE"
    MOVING = "MOVING"
    STOPPING = "STOPPING"
    STOPPED = "STOPPED"
    STOPPING_ERROR = "STOPPING_ERROR"
    ERROR = "ERROR"


@dataclass(frozen=True)
class ActionReply:
    """The answer of mpiMotionAction (a MotionAction service call)."""

    message: str
    code: int
    state_name: str
    sample: int  # the sample at which the action took effect
    detail: str = ""  # why it was refused (e.g. RESET while a fault persists)

    @property
    def ok(self) -> bool:
        return self.message == errors.OK

    @property
    def state(self) -> State:
        return State(self.state_name)

    @classmethod
    def from_response(cls, response: Any) -> ActionReply:
        return cls(response.message, response.code, response.state_name, response.sample,
                   getattr(response, "detail", ""))


def action_reply(name: str, response: Any, raise_on_error: bool) -> ActionReply:
    """``response`` as an ActionReply; raises the message's exception if asked and not OK."""
    reply = ActionReply.from_response(response)
    if raise_on_error:
        raise_for(reply.message, f"{name} in {reply.state_name}" + (f": {reply.detail}" if reply.detail else ""),
                  reply)
    return reply


class ActionCall:
    """``<namespace>/ms<supervisor>/action`` on a node of its own (spun only while calling)."""

    def __init__(self, supervisor: int, namespace: str = DEFAULT_NAMESPACE, context: Context | None = None,
                 node_name: str | None = None):
        self.supervisor = supervisor
        self.namespace = ns(namespace)
        self.prefix = supervisor_node(namespace, supervisor)
        # No parameter services, /rosout or type description service: each is endpoints for
        # the suite to discover and interfaces to import before the one that matters.
        self.node = Node(node_name or f"mpi_ros_action_ms{supervisor}", context=context,
                         start_parameter_services=False, enable_rosout=False,
                         parameter_overrides=[Parameter(START_TYPE_DESCRIPTION_SERVICE_PARAM, value=False)])
        self._service = self.node.create_client(MotionAction, MOTION_ACTION.name(namespace, supervisor),
                                               qos_profile=profile(MOTION_ACTION.qos))
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)

    def wait_ready(self, timeout: float) -> None:
        """Wait until the service is reachable; raises SuiteNotFound, NoSuchSupervisor or
        NoResponse (the supervisor is there, its service is not) after ``timeout`` s."""
        discovery.wait_for_endpoints(self.node, self.namespace, self.supervisor, self._service.service_is_ready,
                                 timeout, "its action service")

    def call(self, name: str, timeout: float, raise_on_error: bool = True) -> ActionReply:
        """Send action ``name`` and wait up to ``timeout`` s for the answer."""
        future = self._service.call_async(MotionAction.Request(action=name))
        self._executor.spin_until_future_complete(future, timeout_sec=timeout)
        if not future.done():
            raise NoResponse(f"no answer for action {name} from {self.prefix}/action within {timeout:g} s")
        return action_reply(name, future.result(), raise_on_error)

    def close(self) -> None:
        self._executor.shutdown(timeout_sec=1.0)
        self.node.destroy_client(self._service)
        self.node.destroy_node()
