"""What the operator-console verbs share: options, the ROS session, errors, result lines.

Exit codes every verb keeps (scripts rely on them): 0 OK; 1 the controller refused or
ended the command with a message other than MPIMessageOK (the message is printed); 2 a
usage or connection problem (what was wrong and what to do is printed on stderr).

rclpy and the client are imported inside functions: ``mpi-ros --help`` must stay fast.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from typing import Any, Self, TextIO

from ..graph_names import DEFAULT_NAMESPACE

OK, REFUSED, USAGE = 0, 1, 2
DEFAULT_TIMEOUT = 5.0

# What to do next when the supervisor's state refused a command.
HINTS = {
    "MPIMotionMessageERROR": "ms{n} is in ERROR (after an E_STOP or ABORT): `mpi-ros reset` leaves it",
    "MPIMotionMessageSTOPPING_ERROR":
        "ms{n} is stopping after an E_STOP or ABORT: wait for ERROR, then `mpi-ros reset`",
    "MPIMotionMessageMOVING": "ms{n} is moving: wait for it, `mpi-ros modify` it or `mpi-ros stop` it",
    "MPIMotionMessageSTOPPING": "ms{n} is stopping: wait for STOPPED",
    "MPIMotionMessageSTOPPED": "ms{n} is STOPPED: `mpi-ros resume` continues the move, `mpi-ros reset` drops it",
    "MPIMotionMessageIDLE": "ms{n} is idle: there is no move to act on",
}


class UsageError(Exception):
    """A usage or connection problem: printed as ``<prog>: <message>``, exit status 2."""


def add_target_options(parser: argparse.ArgumentParser, supervisor_default: int | None = 0) -> None:
    """--namespace, --supervisor and --timeout, as every console verb takes them."""
    where = parser.add_argument_group("where")
    where.add_argument("--namespace", default=DEFAULT_NAMESPACE, metavar="NS",
                       help=f"the suite's namespace (default {DEFAULT_NAMESPACE})")
    shown = "every supervisor" if supervisor_default is None else str(supervisor_default)
    where.add_argument("--supervisor", "-s", type=int, default=supervisor_default, metavar="N",
                       help=f"motion supervisor number: node <namespace>/ms<N> (default {shown})")
    where.add_argument("--timeout", type=float, default=DEFAULT_TIMEOUT, metavar="S",
                       help=f"seconds to wait for the suite to appear on the graph (default {DEFAULT_TIMEOUT:g})")


def prog(args: argparse.Namespace) -> str:
    return getattr(args, "_prog", "mpi-ros")


def fail(args: argparse.Namespace, message: str, status: int = USAGE) -> int:
    print(f"{prog(args)}: {message}", file=sys.stderr)
    return status


class Session:
    """One verb's ROS side: its own context (ROS arguments applied), clean shutdown.

    Its own context (not rclpy's default) so rclpy installs no SIGINT handler: Ctrl-C stays
    a KeyboardInterrupt, and a running goal can still be cancelled over ROS after it.
    """

    def __init__(self, args: argparse.Namespace):
        from mpi_ros import dds_profile

        # Before rclpy creates the participant: receive buffers that hold the burst of the
        # graph's endpoint announcements, which a default buffer dropped (dds_profile)
        dds_profile.use(os.environ, dds_profile.CLIENT)
        import rclpy

        self.args = args
        self.context = rclpy.Context()
        try:
            rclpy.init(args=["mpi-ros", *getattr(args, "ros_args", [])], context=self.context)
        except RuntimeError as exc:  # rclpy's RCLError: the ROS arguments did not parse
            raise UsageError(f"invalid ROS arguments {' '.join(args.ros_args)!r}: "
                             f"{str(exc).split(', at ')[0]}") from exc
        # --no-wait leaves its goal running on purpose: a name the lost-client watchdog
        # (mpi_ros/ros/watchdog.py, DETACHED) knows not to STOP it by when the verb exits
        detached = "_detached" if getattr(args, "no_wait", False) else ""
        self.node_name = f"mpi_ros_cli_{os.getpid()}{detached}"
        self._endpoints: list[Any] = []

    def client(self, supervisor: int):
        """A MotionClient of ``supervisor``, once the suite and that supervisor are on the graph."""
        from mpi_ros import discovery
        from mpi_ros.client import MotionClient

        client = self._keep(MotionClient(supervisor, self.args.namespace, context=self.context,
                                         timeout=self.args.timeout, node_name=self.node_name))
        # The supervisor's own endpoints, not the suite's nodes first: they are what a goal needs
        discovery.wait_for_endpoints(client.node, client.namespace, supervisor, client.servers_ready,
                                 self.args.timeout, "its actions and services")
        warn_twins(self.args, client)
        if not client.wait_for_server(self.args.timeout):
            raise UsageError(f"{client.prefix} is on the graph but its actions and services did not answer "
                             f"within {self.args.timeout:g} s: is the suite shutting down?")
        return client

    def action_call(self, supervisor: int):
        """An ActionCall of ``supervisor``, once its action service is reachable: all a one-shot
        action waits for (a MotionClient would wait for the suite's nodes and both actions)."""
        from mpi_ros.action_call import ActionCall

        call = self._keep(ActionCall(supervisor, self.args.namespace, context=self.context,
                                     node_name=self.node_name))
        call.wait_ready(self.args.timeout)
        return call

    def watcher(self):
        """A Watcher of the suite, once the suite (and --supervisor, if given) is on the graph."""
        from mpi_ros.client import Watcher

        watcher = self._keep(Watcher(self.args.namespace, context=self.context, timeout=self.args.timeout,
                                     node_name=f"{self.node_name}_watch"))
        watcher.wait_for_suite(self.args.timeout, self.args.supervisor)
        warn_twins(self.args, watcher)
        return watcher

    def _keep(self, endpoint):
        self._endpoints.append(endpoint)
        return endpoint

    def close(self) -> None:
        for endpoint in reversed(self._endpoints):
            endpoint.close()
        self.context.try_shutdown()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def twins_warning(endpoint) -> str | None:
    """The warning for nodes of the suite's namespace seen twice on the graph, if any."""
    twins = endpoint.twins_on_graph()
    if not twins:
        return None
    return (f"warning: {len(twins)} node name(s) of {endpoint.namespace} are on ROS_DOMAIN_ID {endpoint.domain_id} "
            f"twice ({', '.join(twins)}): two suites run under one namespace, and both take every command; "
            f"stop one of them")


def suite_warning(watcher) -> str | None:
    """The warning of the suite's /diagnostics entry (``<ns>/suite``), if it is WARN or worse:
    its controller is behind the wall clock, or its clock thread runs without the priority asked
    for (Watcher.follow_suite first)."""
    status = watcher.suite_status()
    if status is None or _level(status.level) < _WARN:
        return None
    return f"warning: the suite ({status.name} on /diagnostics): {status.message}"


_WARN = 1  # diagnostic_msgs/DiagnosticStatus.WARN


def _level(level: bytes | int) -> int:
    return level[0] if isinstance(level, bytes) else level  # (rclpy gives a byte's field as bytes)


def view_warnings(watcher) -> str | None:
    """What a view of the suite should say above its table: two suites in one namespace, a
    suite behind real time (None: nothing)."""
    found = [w for w in (twins_warning(watcher), suite_warning(watcher)) if w is not None]
    return "\n".join(found) or None


def warn_twins(args: argparse.Namespace, endpoint) -> None:
    warning = twins_warning(endpoint)
    if warning is not None:
        print(f"{prog(args)}: {warning}", file=sys.stderr)


def run_verb(args: argparse.Namespace, body) -> int:
    """Run ``body(session)`` with the errors every verb reports the same way."""
    from mpi_ros.errors import NoResponse, NoSuchSupervisor

    try:
        with Session(args) as session:
            return body(session)
    except (UsageError, NoResponse, NoSuchSupervisor) as exc:
        return fail(args, str(exc))


# -- printing answers --------------------------------------------------------------------------
def positions(values) -> str:
    return "[" + ", ".join(f"{v:.1f}" for v in values) + "]"


def print_result(result, supervisor: int, out: TextIO | None = None) -> int:
    """The final lines of a goal: message, code, outcome, state, positions; returns the exit status."""
    out = out or sys.stdout  # looked up now: tests and callers may have replaced it
    detail = f": {result.detail}" if result.detail else ""
    print(f"{result.message} (code {result.code}) {result.outcome}, state {result.state_name}{detail}", file=out)
    print(f"  command position {positions(result.command_position)}", file=out)
    print(f"  actual position  {positions(result.actual_position)}", file=out)
    print(f"  move {result.move_id}, samples {result.sample}..{result.end_sample}", file=out)
    _hint(result.message, supervisor)
    return OK if result.ok else REFUSED


def print_reply(action: str, reply, supervisor: int, out: TextIO | None = None) -> int:
    """An action's answer; returns the exit status."""
    out = out or sys.stdout
    refusal = f": {reply.detail}" if reply.detail and not reply.ok else ""  # e.g. which fault persists
    print(f"{action}: {reply.message} (code {reply.code}), state {reply.state_name}, sample {reply.sample}{refusal}",
          file=out)
    persisting = PERSISTS.findall(reply.detail) if not reply.ok else []
    if persisting:  # a RESET refused: another RESET would be refused as well
        print(f"hint: {persists_hint(persisting, supervisor)}", file=sys.stderr)
    else:
        _hint(reply.message, supervisor)
    return OK if reply.ok else REFUSED


# How the fault monitor words a fault whose condition still holds at a RESET (docs/faults.md).
PERSISTS = re.compile(r"axis (\d+) ([A-Z_]+) persists")
CONDITIONS = ("AMP_FAULT", "ENCODER_FAULT")  # injected conditions: `mpi-ros fault NAME --clear` ends them


def persists_hint(persisting: list[tuple[str, str]], supervisor: int) -> str:
    """What to do when RESET was refused because faults persist: end their causes first."""
    steps = [f"`mpi-ros fault {fault} --axis {axis} --clear`" if fault in CONDITIONS
             else f"bring axis {axis} out of {fault}" for axis, fault in persisting]
    return (f"ms{supervisor} stays in ERROR while the fault persists: first {' and '.join(steps)}, "
            f"then `mpi-ros reset{'' if supervisor == 0 else f' --supervisor {supervisor}'}`")


def _hint(message: str, supervisor: int) -> None:
    if message in HINTS:
        print(f"hint: {HINTS[message].format(n=supervisor)}", file=sys.stderr)
