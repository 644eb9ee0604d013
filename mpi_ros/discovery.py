"""Finding the suite on the ROS graph (discovery), and saying what was found when it is not there.

Shared by the client (:mod:`mpi_ros.client`) and the one-shot actions
(:mod:`mpi_ros.action_call`); it imports nothing heavier than rclpy's node, so a one-shot
verb does not pay for rclpy.action and numpy before its first command.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

from .errors import NoResponse, NoSuchSupervisor, SuiteNotFound
from .graph_names import DEFAULT_NAMESPACE, SUPERVISOR_NODE, supervisor_node

READY_POLL = 0.005  # s between looks at the endpoints (rclpy's wait_for_service looks every 0.25 s)
GRAPH_POLL = 0.05  # s between looks at the graph's nodes (to tell a wrong --supervisor early)
# Every node of a process is announced together (one DDS participant per context), but give
# a late announcement a moment before saying a supervisor is not there.
GRACE = 0.5


def supervisors_on_graph(node: Any, namespace: str) -> list[int]:
    """Numbers of the supervisor nodes (``<namespace>/ms<n>``) ``node`` sees on the graph now."""
    return sorted(int(match.group(1)) for name, ns in node.get_node_names_and_namespaces()
                  if ns == namespace and (match := SUPERVISOR_NODE.fullmatch(name)))


def not_found(node: Any, namespace: str, timeout: float) -> str:
    """Why no suite was found under ``namespace``, with where supervisors were seen instead."""
    where = "" if namespace == DEFAULT_NAMESPACE else f" under {namespace}"
    elsewhere = sorted({ns for name, ns in node.get_node_names_and_namespaces()
                        if SUPERVISOR_NODE.fullmatch(name) and ns != namespace})
    hint = f" (supervisors found under {', '.join(elsewhere)})" if elsewhere else ""
    return (f"no suite found{where} on ROS_DOMAIN_ID {node.context.get_domain_id()} within {timeout:g} s{hint}: "
            f"is `mpi-ros run` running, on the same domain?")


def wait_for_endpoints(node: Any, namespace: str, supervisor: int, ready: Callable[[], bool], timeout: float,
                       what: str) -> None:
    """Wait until ``ready()`` (the endpoints of ``<namespace>/ms<supervisor>`` a command needs are
    matched), looking every READY_POLL s. Raises NoSuchSupervisor once the suite has been seen
    without that supervisor for GRACE s; after ``timeout`` s SuiteNotFound, or NoResponse when
    the supervisor is there but ``what`` (its endpoints, named for the message) is not."""
    start = time.monotonic()
    pause = threading.Event()  # never set: a wait that a debugger can interrupt, unlike sleep
    suite_seen: float | None = None
    next_graph_look = start
    while not ready():
        now = time.monotonic()
        if now >= next_graph_look:
            next_graph_look = now + GRAPH_POLL
            found = supervisors_on_graph(node, namespace)
            suite_seen = suite_seen if suite_seen is not None or not found else now
            if suite_seen is not None and supervisor not in found and now - suite_seen >= GRACE:
                runs = ", ".join(f"ms{n}" for n in found)
                raise NoSuchSupervisor(f"no supervisor {supervisor_node(namespace, supervisor)}: the suite runs {runs}")
        if now - start >= timeout:
            if supervisor in supervisors_on_graph(node, namespace):
                raise NoResponse(f"{supervisor_node(namespace, supervisor)} is on the graph but {what} did not "
                                 f"appear within {timeout:g} s: is the suite shutting down?")
            raise SuiteNotFound(not_found(node, namespace, timeout))
        pause.wait(READY_POLL)
