"""One thread that waits for the requests of every goal server of the suite.

Why not the nodes' executors: rclpy's executor rebuilds its wait set in Python from every
entity of its node on every round (about 0.6 ms for a supervisor node's 36 entities), and a
goal costs at least two rounds (its request, its result request) plus the task that serves
it. Under a stream of modifies those rounds took more of the suite's CPU than applying the
commands did (docs/reliability.md, "The goal path"). This loop's wait set
holds only the goal servers' services (three each) and a guard condition: made once,
refilled each round with a few C calls; each round also lets the servers forget expired
results. What a round takes is served on a pool of threads (a goal's command waits there for
its sample, never in this thread), each server's batches in the order they were taken, by
one task at a time (GoalServer.serve).

The loop must be stopped (``stop``) before the nodes holding its servers are destroyed.
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from contextlib import ExitStack

from rclpy.context import Context

from . import rcl
from .goal_endpoints import KINDS, LocalEndpoints, take_ready
from .goal_server import GoalServer

# The longest a round waits. A request that arrives while its reader is being re-matched
# (a link that was cut comes back) can leave no wake-up behind; a new round finds it anyway,
# since each wait first looks at what every handle already holds (seen: a client's re-asked
# result request answered only when something else woke the loop).
ROUND_NS = 100_000_000


class GoalLoop:
    """``add`` every server, then ``start``; ``stop`` before the servers are destroyed."""

    def __init__(self, context: Context, threads: int):
        if context.handle is None:
            raise RuntimeError("the goal loop needs an initialized context")
        self._handle = context.handle
        self._context = context
        self._servers: list[GoalServer] = []
        with self._handle:
            self._wake = rcl.guard_condition(self._handle)
        self._pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="mpi-ros-goals")
        self._stopping = False
        self._thread: threading.Thread | None = None

    def endpoints(self, node, action_type, name: str, qos) -> LocalEndpoints:
        """The services of a server this loop will wait on (on ``node``, in this process)."""
        return LocalEndpoints(node, action_type, name, qos)

    def add(self, server: GoalServer) -> None:
        if self._thread is not None:
            raise RuntimeError("goal servers are added before the goal loop starts")
        if not isinstance(server.endpoints, LocalEndpoints):
            raise TypeError("the goal loop waits on services in this process (GoalLoop.endpoints)")
        self._servers.append(server)

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="mpi-ros-goal-loop", daemon=True)
        self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        """Stop taking requests and finish serving what was taken."""
        self._stopping = True
        self._wake.trigger_guard_condition()
        if self._thread is not None:
            self._thread.join(timeout)
        self._pool.shutdown(wait=True)
        self._wake.destroy_when_not_in_use()

    def _run(self) -> None:
        waited = [(server, self._endpoints(server)) for server in self._servers]
        try:
            with ExitStack() as held:  # no server's C handle is destroyed while it is waited on
                for _, endpoints in waited:
                    for kind in KINDS:
                        held.enter_context(endpoints.services[kind])
                held.enter_context(self._handle)
                wait_set = rcl.wait_set(len(KINDS) * len(waited), self._handle)
                while not self._stopping:
                    self._round(wait_set, waited)
        except rcl.RCLError:
            # The context shut down (Ctrl-C) before the loop was stopped: nothing can be
            # waited on any more. Anything else is a real error.
            if self._context.ok():
                raise

    @staticmethod
    def _endpoints(server: GoalServer) -> LocalEndpoints:
        endpoints = server.endpoints
        assert isinstance(endpoints, LocalEndpoints)  # add() checked
        return endpoints

    def _round(self, wait_set, waited: list[tuple[GoalServer, LocalEndpoints]]) -> None:
        """Wait (at most ROUND_NS), then take every request waiting on a ready service and
        look for results due to expire; what a server was given is served on the pool."""
        taken = take_ready(wait_set, self._wake, [endpoints for _, endpoints in waited], ROUND_NS)
        if taken is None or self._stopping:
            return
        for (server, _), given in zip(waited, taken, strict=True):
            if server.deliver(given, server.expire_due()):
                self._pool.submit(server.serve)
