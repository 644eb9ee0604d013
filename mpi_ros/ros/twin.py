"""One suite per namespace: before ``mpi-ros run`` creates its nodes, a short-lived probe
node looks for the namespace's controller node on the graph (docs/cell.md, "One suite per
namespace").

Two suites under one namespace would both answer every goal and service (one ``move`` moves
both twins, topics come at twice the rate) while a console shows only one of them. The
graph has no lock to take, so the check is a look: the probe waits up to DISCOVERY for
``<ns>/controller`` to appear. A suite announces itself every 0.1 s (config/fastdds_discovery.xml):
discovery showed a running one 0.29 to 0.59 s after the probe started (10 tries, 2 cores at
load 3 to 4; with Fast DDS's default announcement every 3 s it took 0.23 to 3.2 s, median 0.5 s,
in 45 tries at load 5). DISCOVERY leaves room for a loaded machine. A suite started with a
Fast DDS profile of its own announces itself every 3 s unless the profile says otherwise, and
may then be missed; a twin that discovery has not shown by then starts, and the console warns
about it (``MotionClient.twins_on_graph``).

Who the other suite is: the graph gives its node's enclave; the process is read from the
GUID of one of its endpoints where the middleware is Fast DDS, whose GUID prefix holds the
vendor (bytes 0-1), a host id (bytes 2-3) and the low 16 bits of the process id (bytes 4-5,
little endian; the rest is random). On this host (same host id as the probe's own GUID) the
processes whose pid has those low bits are looked up in /proc. None there: the node is the
ghost of a suite killed less than its DDS lease ago (its nodes stay on the graph until the
lease ends), and the new suite starts with a warning, so a suite restarted after a crash
does not wait out the lease.
"""

from __future__ import annotations

import os
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from rclpy.context import Context
from rclpy.node import Node, NodeNameNonExistentError

DISCOVERY = 1.5  # s the probe waits for an existing suite's controller node (announced every 0.1 s)
POLL = 0.02  # s between looks at the graph
CONTROLLER = "controller"  # the suite's controller node, <ns>/controller (ControllerNode)
FAST_DDS_VENDOR = b"\x01\x0f"  # eProsima's RTPS vendor id, the first two bytes of its GUIDs
PID_SPACE = 1 << 16  # Fast DDS keeps the low 16 bits of the process id


@dataclass(frozen=True, slots=True)
class Origin:
    """Where the process that owns an endpoint runs, as far as its GUID tells."""

    text: str
    # On this host, and no process here has its id: a suite killed (SIGKILL, a crash) less
    # than its DDS lease ago (Fast DDS: 20 s), whose nodes the graph still shows.
    gone: bool = False


@dataclass(frozen=True, slots=True)
class OtherSuite:
    """The controller node of a suite already on the graph, and what the graph tells of it."""

    namespace: str
    domain: int
    enclave: str
    origin: Origin

    def node(self) -> str:
        return f"{self.namespace.rstrip('/')}/{CONTROLLER}"

    def refusal(self) -> str:
        """Why ``mpi-ros run`` will not start, and where the other suite is."""
        return (f"a suite already runs under {self.namespace} on ROS_DOMAIN_ID {self.domain}: its node "
                f"{self.node()} (enclave {self.enclave or '/'}) is on the graph, {self.origin.text}. "
                f"One suite per namespace: stop that one, or start this one with another --namespace")

    def ghost(self) -> str:
        """Why ``mpi-ros run`` starts although the graph shows the node."""
        return (f"warning: {self.node()} is still on the graph of ROS_DOMAIN_ID {self.domain}, "
                f"{self.origin.text}: a suite that ended without leaving the graph (killed) less than "
                f"its DDS lease ago; starting")


def origin(gid: bytes | None, own_gid: bytes | None, proc: Path = Path("/proc")) -> Origin:
    """Where the process that owns endpoint ``gid`` runs (``own_gid``: one of this process'
    endpoints, for this host's host id)."""
    if gid is None:
        return Origin("its process unknown (none of its endpoints was discovered in time)")
    if gid[:2] != FAST_DDS_VENDOR:
        return Origin(f"its process unknown (its middleware, vendor {gid[:2].hex()}, puts no process id in its GUIDs)")
    low = int.from_bytes(gid[4:6], "little")
    if own_gid is None or own_gid[2:4] != gid[2:4]:
        return Origin(f"on another host (DDS host id {gid[2:4].hex()}), in a process whose id is {low} modulo "
                      f"{PID_SPACE} (the part of it Fast DDS puts in its GUID)")
    found = [f"pid {pid}: {command}" for pid, command in candidates(low, proc)]
    if not found:
        return Origin(f"on this host in a process whose id is {low} modulo {PID_SPACE} (from its DDS GUID), "
                      f"which is no longer running", gone=True)
    return Origin("on this host, " + "; or ".join(found))


def candidates(low: int, proc: Path = Path("/proc")) -> list[tuple[int, str]]:
    """The processes here whose id has the low 16 bits ``low``, with their command lines."""
    found = []
    for pid in range(low, _pid_max(proc) + 1, PID_SPACE):
        try:
            raw = (proc / str(pid) / "cmdline").read_bytes()
        except OSError:  # no such process (or not ours to read): not a candidate
            continue
        found.append((pid, " ".join(part.decode(errors="replace") for part in raw.split(b"\0") if part)
                      or "(no command line)"))
    return found


def _pid_max(proc: Path) -> int:
    try:
        return int((proc / "sys" / "kernel" / "pid_max").read_text())
    except (OSError, ValueError):  # not Linux's /proc: pids up to the 32-bit default
        return 1 << 22


def find_suite(context: Context, namespace: str, wait: float = DISCOVERY) -> OtherSuite | None:
    """The suite under ``namespace`` on the graph, if discovery shows its controller node
    within ``wait`` seconds; None otherwise."""
    # Global ROS arguments (an __ns or __node remap) are the suite's, not the probe's.
    probe = Node(f"mpi_ros_probe_{os.getpid()}", context=context, use_global_arguments=False)
    try:
        deadline = time.monotonic() + wait
        pause = threading.Event()  # never set: a wait between looks
        while (enclave := _controller_enclave(probe, namespace)) is None:
            if time.monotonic() >= deadline:
                return None
            pause.wait(POLL)
        gid = _endpoint_gid(probe, CONTROLLER, namespace, deadline, pause)
        own = _endpoint_gid(probe, probe.get_name(), probe.get_namespace(), deadline, pause)
        return OtherSuite(namespace, context.get_domain_id(), enclave, origin(gid, own))
    finally:
        probe.destroy_node()


def _controller_enclave(probe: Node, namespace: str) -> str | None:
    return next((enclave for name, ns, enclave in probe.get_node_names_and_namespaces_with_enclaves()
                 if name == CONTROLLER and ns == namespace), None)


def _endpoint_gid(probe: Node, name: str, namespace: str, deadline: float, pause: threading.Event) -> bytes | None:
    """The GID of one publisher of node ``namespace/name`` (its endpoints may be discovered a
    little after the node itself: looked for until ``deadline``, and once at least)."""
    while True:
        try:
            topics = probe.get_publisher_names_and_types_by_node(name, namespace)
        except NodeNameNonExistentError:  # it left the graph meanwhile: nothing more to learn
            return None
        for topic, _types in topics:
            for info in probe.get_publishers_info_by_topic(topic):
                if info.node_name == name and info.node_namespace == namespace:
                    return bytes(info.endpoint_gid)
        if time.monotonic() >= deadline:
            return None
        pause.wait(POLL)
