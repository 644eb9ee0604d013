"""The goal front: the action servers' services in a process of their own (``ros.goal_process``).

Why: the suite is one Python interpreter, and under a stream of goals it runs out of it, not
of the machine (bench/RESULTS.md, "What holds the suite at one core"). Of its work per goal,
rclpy's part of the action protocol, taking the goal and result requests (a Python message
built field by field from C) and sending the answers (converted back), was about 0.2 ms of
the 0.5 ms. Here that part runs in the front, on another core; the suite and the front
exchange plain values over a pipe, in batches (goal_endpoints.py says which).

What stays in the suite: every decision. The goal servers (goal_server.py: which goal is
accepted, cancelled, ended, what its result is, the status topic) and the nodes run there as
before; only where their three services live changes. The front has a node of its own
(``<namespace>/goal_front``) that holds the services under their usual names
(``<ns>/ms<n>/motion_start/_action/send_goal``, ...), so clients see the same action servers;
``ros2 action info`` names that node as their server.

Life: :class:`GoalRelay` (the suite's side, in place of the GoalLoop) starts the front once
every server is added and waits until its services exist; ``stop`` closes the pipe and the
front ends. The front also ends on its own when the pipe closes (the suite killed): it never
outlives the suite.

The pipe, suite-bound: ``[(server index, {kind: [(token, plain request)]})]`` per round of
the front; front-bound: ``[(server index, kind, token, plain response)]``. A token stands for
the request's header (rmw's request id, which stays in the front).
"""

from __future__ import annotations

import importlib
import itertools
import logging
import multiprocessing
import signal
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

from . import rcl
from .goal_endpoints import ACTION_SERVICE_QOS, KINDS, LocalEndpoints, Outbox, RelayedEndpoints, take_ready
from .goal_server import GoalServer

ROUND_S = 0.1  # the longest the relay waits before it looks for results due to expire
START_TIMEOUT_S = 60.0  # the front's start: a fresh interpreter importing rclpy and the interfaces

_log = logging.getLogger("mpi_ros.goal_front")


@dataclass(frozen=True, slots=True)
class FrontServer:
    """One action server as the front sees it."""

    action: str  # its type, "<module>:<class>" (mpi_ros.action:MotionStart)
    name: str  # the action's name, resolved (/mpi/ms0/motion_start)


class GoalRelay:
    """The suite's side of the front, in place of a GoalLoop: ``endpoints`` for each server,
    ``add`` every server, then ``start``; ``stop`` before the servers are destroyed."""

    def __init__(self, namespace: str, threads: int):
        self._front_servers: list[FrontServer] = []
        self._servers: list[GoalServer] = []
        context = multiprocessing.get_context("spawn")  # a fresh interpreter: no rclpy state of ours
        self._connection, self._front_end = context.Pipe()
        self._process = context.Process(target=run_front, args=(self._front_end, namespace),
                                        name="mpi-ros-goal-front", daemon=True)
        self._outbox = Outbox(self._connection)
        self._pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="mpi-ros-goals")
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def front_pid(self) -> int | None:
        """The front's process id, once started."""
        return self._process.pid

    def front_alive(self) -> bool:
        return self._process.is_alive()

    def endpoints(self, node, action_type, name: str, qos) -> RelayedEndpoints:
        """The services of a server, in the front (``qos`` must be ACTION_SERVICE_QOS, the
        front's)."""
        if qos is not ACTION_SERVICE_QOS:
            raise ValueError("the goal front's services have ACTION_SERVICE_QOS")
        if self._thread is not None:
            raise RuntimeError("goal servers are added before the goal front starts")
        self._front_servers.append(FrontServer(f"{action_type.__module__}:{action_type.__name__}",
                                               node.resolve_service_name(name)))
        return RelayedEndpoints(len(self._front_servers) - 1, self._outbox)

    def add(self, server: GoalServer) -> None:
        if not isinstance(server.endpoints, RelayedEndpoints):
            raise TypeError("the goal relay serves servers whose services are in the front (GoalRelay.endpoints)")
        self._servers.append(server)

    def start(self) -> None:
        """Start the front and wait until its services exist."""
        if len(self._servers) != len(self._front_servers):
            raise RuntimeError("every server made with GoalRelay.endpoints must be added before start")
        self._process.start()
        self._front_end.close()  # the front holds its end; ours closed, its death is our EOF
        self._connection.send(self._front_servers)
        if not self._connection.poll(START_TIMEOUT_S):
            self._process.kill()
            raise RuntimeError(f"the goal front did not start within {START_TIMEOUT_S:g} s")
        try:
            ready = self._connection.recv()
        except EOFError:  # it ended before it was ready; its traceback is on stderr
            self._process.join(START_TIMEOUT_S)
            raise RuntimeError(f"the goal front ended as it started (exit code {self._process.exitcode})") from None
        if ready != "ready":
            self._process.kill()
            raise RuntimeError(f"the goal front failed to start: {ready}")
        self._thread = threading.Thread(target=self._run, name="mpi-ros-goal-relay", daemon=True)
        self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        """Stop taking requests, finish serving what was taken, and end the front."""
        self._stopping.set()
        if self._thread is not None:
            self._thread.join(timeout)
        self._pool.shutdown(wait=True)
        self._outbox.flush()
        self._connection.close()  # the front's EOF: it ends
        if self._process.pid is not None:
            self._process.join(timeout)
            if self._process.is_alive():
                _log.warning("the goal front did not end within %g s of its pipe closing: killed", timeout)
                self._process.kill()
                self._process.join(timeout)

    def _run(self) -> None:
        try:
            while not self._stopping.is_set():
                batch = self._connection.recv() if self._connection.poll(ROUND_S) else []
                try:
                    self._deliver(dict(batch))
                except Exception:  # noqa: BLE001 - a bug: logged with its traceback; later requests still served
                    _log.exception("the goal relay failed to hand requests to their servers")
        except (EOFError, OSError):
            if not self._stopping.is_set():  # the front died under a running suite: no goal can come
                _log.error("the goal front ended: the suite's action servers are gone")

    def _deliver(self, given: dict[int, dict[str, list]]) -> None:
        """Each server's requests (and a look for results due to expire): what a server was
        given is served on the pool."""
        for index, server in enumerate(self._servers):
            if server.deliver(given.get(index, {}), server.expire_due()):
                self._pool.submit(server.serve)


# -- the front's process ------------------------------------------------------------------------
def run_front(connection, namespace: str) -> None:
    """The front's process: its node, the servers' services, a loop taking requests (this
    thread) and one sending the suite's responses."""
    import rclpy
    from rclpy.node import Node
    from rclpy.signals import SignalHandlerOptions

    # Ctrl-C in a terminal reaches the whole process group: the suite decides when the front
    # ends (it closes the pipe once its goals are answered), so the front ignores it.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # The suite blocks its stop signals (cli/stop_signals.py) and a child inherits the mask:
    # SIGTERM must still end the front.
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
    servers: list[FrontServer] = connection.recv()
    rclpy.init(args=[], signal_handler_options=SignalHandlerOptions.NO)
    try:
        node = Node("goal_front", namespace=namespace, start_parameter_services=False)
        endpoints = [LocalEndpoints(node, _action_type(server.action), server.name, ACTION_SERVICE_QOS)
                     for server in servers]
    except Exception as exc:  # noqa: BLE001 - not swallowed: the suite raises it
        connection.send(f"{type(exc).__name__}: {exc}")
        return
    headers: dict[int, Any] = {}
    stop = rcl.guard_condition(node.context.handle)
    responder = threading.Thread(target=_respond, args=(connection, endpoints, headers, stop), daemon=True)
    responder.start()
    connection.send("ready")
    try:
        _take(connection, node, endpoints, headers, stop)
    finally:
        responder.join(5.0)
        node.destroy_node()
        rclpy.try_shutdown()


def _action_type(path: str):
    module, name = path.split(":")
    return getattr(importlib.import_module(module), name)


def _take(connection, node, endpoints: list[LocalEndpoints], headers: dict[int, Any], stop) -> None:
    """Until the responder says the pipe closed: wait on every service, take what is waiting,
    send it to the suite as one batch."""
    tokens = itertools.count()
    with node.context.handle:
        wait_set = rcl.wait_set(len(KINDS) * len(endpoints), node.context.handle)
        while True:
            taken = take_ready(wait_set, stop, endpoints, -1)
            if taken is None:
                return
            batch = [(index, {kind: [_held(headers, next(tokens), header, plain) for header, plain in requests]
                              for kind, requests in given.items()})
                     for index, given in enumerate(taken) if given]
            if batch:
                try:
                    connection.send(batch)
                except (OSError, ValueError):  # the suite is gone: nothing to take for
                    return


def _held(headers: dict[int, Any], token: int, header: Any, plain: Any) -> tuple[int, Any]:
    """A request as the suite gets it: a token in place of its header, which the front keeps."""
    headers[token] = header
    return token, plain


def _respond(connection, endpoints: list[LocalEndpoints], headers: dict[int, Any], stop) -> None:
    """Send the suite's responses, batch by batch, until the pipe closes; then stop the taking."""
    try:
        while True:
            for index, kind, token, payload in connection.recv():
                header = headers.pop(token, None)
                if header is None:  # a bug in the suite's side, not the client's: said, and the rest still answered
                    _log.error("the suite answered a %s request the front does not hold (token %s)", kind, token)
                    continue
                endpoints[index].respond(kind, header, payload)
    except (EOFError, OSError):
        pass  # the suite closed the pipe (or is gone): the front ends
    finally:
        stop.trigger_guard_condition()
