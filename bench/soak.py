"""Load and soak (issue 14): the suite for minutes under a stream of modifies, as a user sees it.

Three processes, so that every figure is the suite's:
- the suite: ``mpi-ros run --time-scale 1`` with SUPERVISORS one-axis supervisors, status at
  ``--status-rate`` (this source tree);
- the load: on every supervisor an S-curve move, then ``--modify-rate`` MotionModify goals a
  second retargeting it (alternating targets 4000 counts apart, each about a second away, so the
  axes never rest and every modify meets a moving supervisor), sent through the
  action protocol's services (send_goal, then get_result for every accepted goal; no status
  or feedback subscriptions, so the load process keeps up); every goal's result is awaited;
- this process, the monitor: counts every MotionStatus and AxisStatus raw (the sample read
  from the CDR bytes) and checks that each topic's samples come in order with no gap (each
  exactly sample_rate / status_rate after the one before); reads /diagnostics ("<ns>/suite":
  samples behind the wall clock, publications queued, goals tracked / kept / unfiled per
  supervisor) and the suite's RSS and CPU from /proc every minute.

At the end the load E-stops every supervisor and waits for every goal's result.

    bench/soak.sh MINUTES            (= python -P bench/soak.py --minutes MINUTES --append)
    python -P bench/soak.py --minutes 10 [--modify-rate 100] [--status-rate 1000] [--append]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import multiprocessing
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))  # bench_suite, beside this file (python -P adds nothing)
from bench_suite import (
    REPO,
    WAIT,
    Probe,
    cpu_seconds,
    idle_seconds,
    load_average,
    runnable_wait_seconds,
    topic_type,
)

SUPERVISORS = 8
_SAMPLE = struct.Struct("<Q")
_LENGTH = struct.Struct("<I")
CDR_HEADER = 4


def sample_of(data: bytes) -> int:
    """The sample of a MotionStatus/AxisStatus in CDR: after the 4-byte CDR header, the
    std_msgs/Header (stamp: 8 bytes; frame_id: uint32 length, then that many bytes), then the
    uint64 sample, aligned to 8 from the start of the data."""
    (length,) = _LENGTH.unpack_from(data, CDR_HEADER + 8)
    at = 8 + 4 + length
    return _SAMPLE.unpack_from(data, CDR_HEADER + at + -at % 8)[0]


def suite_yaml(directory: Path, status_rate: float, result_timeout: float, goal_process: bool) -> Path:
    raw = yaml.safe_load((REPO / "config" / "default.yaml").read_text(encoding="utf-8"))
    raw["axes"]["count"] = SUPERVISORS
    raw["supervisors"] = [{"number": n, "axes": [n]} for n in range(SUPERVISORS)]
    raw["ros"].update(status_rate=status_rate, result_timeout=result_timeout, goal_process=goal_process)
    path = directory / "soak.yaml"
    path.write_text(yaml.safe_dump(raw, sort_keys=False), encoding="utf-8")
    return path


# -- the monitor ---------------------------------------------------------------------------------
@dataclass
class SampleOrder:
    """One status topic: messages counted; gaps (a sample further than ``step`` after the one
    before: status points missing) and samples out of order or repeated."""

    step: int
    count: int = 0
    gaps: int = 0
    missing: int = 0  # status points missing in all the gaps
    disorder: int = 0
    last: int = -1
    lock: threading.Lock = field(default_factory=threading.Lock)

    def on_message(self, data: bytes, _info: dict) -> None:
        sample = sample_of(data)
        with self.lock:
            self.count += 1
            if self.last >= 0:
                if sample <= self.last:
                    self.disorder += 1
                elif sample - self.last != self.step:
                    self.gaps += 1
                    self.missing += (sample - self.last) // self.step - 1
            self.last = max(self.last, sample)


@dataclass
class Diagnostics:
    """The latest "<ns>/suite" diagnostic values (published every second), and the most
    samples behind seen: in the whole run, and since :meth:`minute_most` was last asked."""

    values: dict[str, int] = field(default_factory=dict)
    most_behind: int = 0
    _minute_most: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)

    def on_message(self, msg) -> None:
        for status in msg.status:
            if status.name.endswith("/suite"):
                values = {v.key: int(v.value) for v in status.values}
                behind = values.get("samples_behind", 0)
                with self.lock:
                    self.values = values
                    self.most_behind = max(self.most_behind, behind)
                    self._minute_most = max(self._minute_most, behind)

    def minute_most(self) -> int:
        """The most samples behind since the last call (a minute's worst, not its last)."""
        with self.lock:
            most, self._minute_most = self._minute_most, 0
        return most


def rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


# -- the load (its own process) -------------------------------------------------------------------
class Load:
    """The clients of the load, served by one thread without an executor.

    rclpy's executor costs a round per response (its wait set rebuilt in Python from the
    node's 40 clients), and every goal has two responses (its answer, its result): the load
    would take CPU that the suite, on the same two cores, needs. Here one thread waits on the
    clients' handles itself, takes every response ready, sends each accepted goal's result
    request at once, and sends the next round of modifies when it is due. The goal messages
    are made once per target (each request only gets a fresh goal id)."""

    def __init__(self, node, rclpy_impl):
        from mpi_ros.action import MotionModify, MotionStart
        from mpi_ros.ros.goal_endpoints import ACTION_SERVICE_QOS
        from mpi_ros.srv import MotionAction

        self._rclpy = rclpy_impl
        self._context = node.context
        self.counts: Counter = Counter()
        self.clients: dict[tuple[int, str], Any] = {}
        self._pending: dict[tuple[int, int], tuple] = {}  # (client id, sequence) -> what to do with the answer
        actions = {"start": (MotionStart, "motion_start"), "modify": (MotionModify, "motion_modify")}
        for n in range(SUPERVISORS):
            base = f"/mpi/ms{n}"
            for kind, (action, name) in actions.items():
                self.clients[n, kind] = node.create_client(action.Impl.SendGoalService,
                                                           f"{base}/{name}/_action/send_goal",
                                                           qos_profile=ACTION_SERVICE_QOS)
                self.clients[n, f"{kind}_result"] = node.create_client(action.Impl.GetResultService,
                                                                       f"{base}/{name}/_action/get_result",
                                                                       qos_profile=ACTION_SERVICE_QOS)
            self.clients[n, "action"] = node.create_client(MotionAction, f"{base}/action")
        self._by_pointer = {client.handle.pointer: client for client in self.clients.values()}
        self._wait_set = None
        self._answered: set = set()  # result clients that answered a round trip (wait_for_services)

    def wait_for_services(self) -> None:
        """Every service seen, then a round trip on each action: a new client's first request
        can be answered before the server has matched the client's response reader, and the
        answer is lost (docs/reliability.md, "A client's first goal and the middleware's
        discovery"). A result request for a goal that does not exist changes nothing; it is
        sent again each second until answered, as MotionClient.wait_for_server does."""
        for client in self.clients.values():
            client.wait_for_service(timeout_sec=WAIT)
        probes = [client for (_, kind), client in self.clients.items() if kind.endswith("_result")]
        deadline = time.monotonic() + WAIT
        while probes and time.monotonic() < deadline:
            for client in probes:
                request = client.srv_type.Request()
                request.goal_id.uuid = list(uuid.uuid4().bytes)
                self._send(client, request, ("probe", client))
            until = time.monotonic() + 1.0
            while probes and time.monotonic() < until:
                self.serve(until - time.monotonic())
                probes = [client for client in probes if client not in self._answered]
        if probes:
            raise RuntimeError(f"{len(probes)} result service(s) never answered a round trip")

    def send_goal(self, n: int, kind: str, request) -> None:
        """``request``: a SendGoal request whose goal is set; it gets a new goal id here."""
        request.goal_id.uuid = list(uuid.uuid4().bytes)
        self._send(self.clients[n, kind], request, ("answer", n, kind, bytes(request.goal_id.uuid)))
        self.counts["sent"] += 1

    def send_action(self, n: int, action: str) -> None:
        client = self.clients[n, "action"]
        self._send(client, client.srv_type.Request(action=action), ("action",))

    def _send(self, client, request, then: tuple) -> None:
        with client.handle:
            sequence = client.handle.send_request(request)
        self._pending[id(client), sequence] = (client, then)

    def serve(self, timeout: float) -> None:
        """Wait up to ``timeout`` s for responses; handle every one ready."""
        if self._wait_set is None:
            with self._context.handle:
                self._wait_set = self._rclpy.WaitSet(0, 0, 0, len(self.clients), 0, 0, self._context.handle)
        wait_set = self._wait_set
        wait_set.clear_entities()
        for client in self.clients.values():
            wait_set.add_client(client.handle)
        wait_set.wait(max(0, int(timeout * 1e9)))
        for pointer in wait_set.get_ready_entities("client"):
            client = self._by_pointer[pointer]
            while True:
                with client.handle:
                    header, response = client.handle.take_response(client.srv_type.Response)
                if header is None:
                    break
                found = self._pending.pop((id(client), header.request_id.sequence_number), None)
                if found is not None:
                    self._on_response(found[1], response)

    def _on_response(self, then: tuple, response) -> None:
        if then[0] == "answer":
            _, n, kind, goal_id = then
            if not response.accepted:
                self.counts["rejected"] += 1
                return
            self.counts["accepted"] += 1
            client = self.clients[n, f"{kind}_result"]
            request = client.srv_type.Request()
            request.goal_id.uuid = list(goal_id)
            self._send(client, request, ("result",))
        elif then[0] == "probe":
            self._answered.add(then[1])
        elif then[0] == "result":
            self.counts["results"] += 1
            self.counts[f"result {response.result.message or f'(none: goal status {response.status})'}"] += 1

    def settled(self) -> bool:
        return self.counts["results"] + self.counts["rejected"] >= self.counts["sent"]


def load(domain: str, rate: float, seconds: float, out: str, ready) -> None:
    """Modify goals at ``rate`` per supervisor for ``seconds``, through the action protocol's
    services; then E_STOP each supervisor and wait for every result; writes counts to ``out``."""
    os.environ["ROS_DOMAIN_ID"] = domain
    import rclpy
    from rclpy.impl.implementation_singleton import rclpy_implementation
    from rclpy.node import Node

    from mpi_ros.action import MotionModify, MotionStart
    from mpi_ros.client import fill

    rclpy.init()
    node = Node("soak_load")
    clients = Load(node, rclpy_implementation)
    clients.wait_for_services()
    # Each retarget is a move of 4000 counts taking about a second, so every modify finds the
    # supervisor MOVING (modifies come 10 ms to 1 s apart) and the axes never come to rest.
    trajectory = [{"velocity": 5_000.0, "acceleration": 100_000.0, "deceleration": 100_000.0, "jerk_percent": 50.0}]
    start = MotionStart.Impl.SendGoalService.Request(
        goal=fill(MotionStart.Goal(), {"type": "S_CURVE", "position": [2000.0], "trajectory": trajectory}))
    modifies = [MotionModify.Impl.SendGoalService.Request(goal=fill(MotionModify.Goal(), {
        "type": "S_CURVE", "position": [target], "attributes": ["AUTO_START"], "trajectory": trajectory}))
        for target in (-2000.0, 2000.0)]  # a modify late enough to find the axis at rest starts
    for n in range(SUPERVISORS):
        clients.send_goal(n, "start", start)
    ready.set()
    tick = 0
    period = 1.0 / rate
    began = time.monotonic()
    while time.monotonic() - began < seconds:
        due = began + tick * period
        if time.monotonic() >= due:
            for n in range(SUPERVISORS):
                clients.send_goal(n, "modify", modifies[tick % 2])
            tick += 1
            continue
        clients.serve(due - time.monotonic())  # pacing the load: waits for responses until the next round
    sending = time.monotonic() - began
    for n in range(SUPERVISORS):
        clients.send_action(n, "E_STOP")
    deadline = time.monotonic() + 120.0
    while time.monotonic() < deadline and not clients.settled():
        clients.serve(0.1)
    Path(out).write_text(json.dumps({**clients.counts, "ticks": tick, "sending": sending,
                                     "load_cpu": time.process_time()}))
    node.destroy_node()
    rclpy.try_shutdown()


# -- the run ---------------------------------------------------------------------------------------
@dataclass
class Minute:
    minute: int
    rss_mb: float
    cpu: float  # share of one core over the minute
    statuses: int
    gaps: int
    diagnostics: dict[str, int]
    most_behind: int  # the most samples behind in the minute (diagnostics every second)
    children_cpu: float  # share of one core the suite's child processes used (the goal front)
    children_rss_mb: float
    waited: float  # share of the minute the suite's threads, summed, were ready to run but had no core
    idle: float  # share of the machine's cores idle over the minute


def soak(minutes: float, modify_rate: float, status_rate: float, result_timeout: float,
         goal_process: bool) -> tuple[list[Minute], dict]:
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray

    seconds = minutes * 60.0
    with tempfile.TemporaryDirectory(prefix="soak_") as tmp:
        config = suite_yaml(Path(tmp), status_rate, result_timeout, goal_process)
        log_path = Path(tmp) / "suite.log"
        with open(log_path, "w") as log:
            suite = subprocess.Popen([sys.executable, "-P", "-m", "mpi_ros.cli", "run", "--time-scale", "1",
                                      "--config", str(config)], cwd=tmp, stdout=subprocess.DEVNULL, stderr=log)
        context = rclpy.Context()
        rclpy.init(context=context)
        step = round(2000.0 / status_rate)
        topics = {f"/mpi/ms{n}/status": SampleOrder(step) for n in range(SUPERVISORS)}
        topics.update({f"/mpi/axis{n}/status": SampleOrder(step) for n in range(SUPERVISORS)})
        probe = Probe(context, [(topic_type(name), name, counter) for name, counter in topics.items()])
        diagnostics = Diagnostics()
        # A node of its own: an executor spinning the probe's node would take the status
        # messages too, through rclpy's callbacks, and make the probe a slow reader (the suite's
        # reliable writers then block in publish).
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node

        watcher = Node("soak_diagnostics", context=context)
        watcher.create_subscription(DiagnosticArray, "/diagnostics", diagnostics.on_message, 10)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(watcher)
        threading.Thread(target=executor.spin, daemon=True).start()
        out = Path(tmp) / "load.json"
        spawn = multiprocessing.get_context("spawn")
        ready = spawn.Event()
        loader = spawn.Process(target=load, args=(os.environ["ROS_DOMAIN_ID"], modify_rate, seconds, str(out), ready))
        loader.start()
        try:
            if not ready.wait(WAIT * 2):
                raise RuntimeError(f"the load did not start:\n{log_path.read_text()}")
            rows = _minutes(suite.pid, topics, diagnostics, minutes)
            loader.join(seconds + 300)
            counts = json.loads(out.read_text())
        finally:
            if loader.is_alive():
                loader.kill()
            executor.shutdown(timeout_sec=2.0)
            probe.close()
            context.try_shutdown()
            suite.send_signal(2)
            try:
                suite.wait(WAIT)
            except subprocess.TimeoutExpired:  # reported: suite_exit None
                suite.kill()
                suite.wait(WAIT)
        totals = {"statuses": sum(t.count for t in topics.values()), "gaps": sum(t.gaps for t in topics.values()),
                  "missing": sum(t.missing for t in topics.values()),
                  "disorder": sum(t.disorder for t in topics.values()), "most_behind": diagnostics.most_behind,
                  "per_topic": {name: (t.count, t.gaps, t.missing) for name, t in topics.items()},
                  "suite_exit": suite.returncode if suite.returncode != -9 else "killed after 30 s",
                  "log_errors": _errors(log_path.read_text()), **counts}
        shutil.copyfile(log_path, Path(tempfile.gettempdir()) / "soak-suite.log")  # for a look after the run
    return rows, totals


def _errors(log: str) -> int:
    """Error lines, and answers the middleware could not deliver (a lost answer is a goal its
    client never hears of)."""
    return sum(1 for line in log.splitlines()
               if "Traceback" in line or "[ERROR]" in line or "failed to send response" in line)


def _minutes(pid: int, topics: dict[str, SampleOrder], diagnostics: Diagnostics, minutes: float) -> list[Minute]:
    rows = []
    pause = threading.Event()
    began = time.monotonic()
    cpu0, waited0, idle0 = cpu_seconds(pid), runnable_wait_seconds(pid), idle_seconds()
    children0 = _children_cpu(pid)
    cores = os.cpu_count() or 1
    for minute in range(1, int(minutes) + 1):
        pause.wait(max(0.0, began + 60.0 * minute - time.monotonic()))
        cpu1, waited1, idle1 = cpu_seconds(pid), runnable_wait_seconds(pid), idle_seconds()
        children1 = _children_cpu(pid)
        children = sum(cpu - children0.get(child, (0.0, 0.0))[0] for child, (cpu, _) in children1.items()) / 60.0
        rows.append(Minute(minute, rss_mb(pid), (cpu1 - cpu0) / 60.0, sum(t.count for t in topics.values()),
                           sum(t.gaps for t in topics.values()), dict(diagnostics.values), diagnostics.minute_most(),
                           children, sum(rss for _, rss in children1.values()), (waited1 - waited0) / 60.0,
                           (idle1 - idle0) / 60.0 / cores))
        cpu0, waited0, idle0, children0 = cpu1, waited1, idle1, children1
        print(f"minute {minute}: RSS {rows[-1].rss_mb:.0f} MB, CPU {rows[-1].cpu:.0%} (its children "
              f"{rows[-1].children_cpu:.0%}, {rows[-1].children_rss_mb:.0f} MB), waited for a core "
              f"{rows[-1].waited:.0%}, machine idle {rows[-1].idle:.0%}, statuses {rows[-1].statuses:,}, "
              f"gaps {rows[-1].gaps}, at most {rows[-1].most_behind} behind, {rows[-1].diagnostics}", flush=True)
    return rows


def _children_cpu(pid: int) -> dict[int, tuple[float, float]]:
    """(CPU seconds, RSS MB) of each child process of ``pid`` (the goal front,
    multiprocessing's resource tracker); none when the suite has no children."""
    found = {}
    for task in Path(f"/proc/{pid}/task").iterdir():
        for child in map(int, (task / "children").read_text().split()):
            with contextlib.suppress(OSError):  # a child that ended meanwhile is not counted
                found[child] = (cpu_seconds(child), rss_mb(child))
    return found


def suite_tree() -> str:
    """Which suite runs: this tree (bench_suite puts it first on the suite's PYTHONPATH, so a
    PYTHONPATH given by hand does not choose it) and its revision, marked if it has changes."""
    try:
        revision = subprocess.run(["git", "-C", str(REPO), "describe", "--always", "--dirty"], capture_output=True,
                                  text=True, timeout=30, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        revision = "no git history"
    return f"{REPO} at {revision}"


def report(rows: list[Minute], totals: dict, args, tree: str) -> str:
    sent = totals.get("sent", 0)
    lines = [
        f"## Soak (bench/soak.py): {args.minutes:g} min, {SUPERVISORS} supervisors, {args.modify_rate:g} modifies/s "
        f"each, status {args.status_rate:g} Hz, result_timeout {args.result_timeout:g} s"
        + (", goal front (ros.goal_process)" if args.goal_process else ""),
        "",
        f"`python -P bench/soak.py --minutes {args.minutes:g} --modify-rate {args.modify_rate:g} --status-rate "
        f"{args.status_rate:g} --result-timeout {args.result_timeout:g}"
        f"{' --goal-process' if args.goal_process else ''}` "
        f"on {time.strftime('%Y-%m-%d')} "
        f"(2 cores, load {load_average()} at the end), the suite from {tree}.",
        "",
        "| minute | suite RSS MB | suite CPU (one core) | its child processes (goal front): CPU, RSS MB | "
        "suite waited for a core | machine idle | statuses received | gaps | "
        "samples behind (at the mark, most in the minute) | "
        "goals tracked / kept / requests unfiled (all supervisors) | publications queued | "
        "Python's blocks (sys.getallocatedblocks) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        d = row.diagnostics
        tracked = sum(v for k, v in d.items() if k.endswith("goals_tracked"))
        kept = sum(v for k, v in d.items() if k.endswith("goals_kept"))
        unfiled = sum(v for k, v in d.items() if k.endswith("requests_unfiled"))
        lines.append(f"| {row.minute} | {row.rss_mb:.0f} | {row.cpu:.0%} | {row.children_cpu:.0%}, "
                     f"{row.children_rss_mb:.0f} | {row.waited:.0%} | {row.idle:.0%} | {row.statuses:,} | {row.gaps} | "
                     f"{d.get('samples_behind', '?')}, {row.most_behind} | {tracked} / {kept} / {unfiled} | "
                     f"{d.get('outputs_queued', '?')} | {d.get('python_blocks', '?')} |")
    lines += ["", f"Goals: {sent:,} sent ({totals.get('ticks', 0) * SUPERVISORS / max(totals.get('sending', 1), 1):.0f}"
              f"/s offered while sending; the load process used {totals.get('load_cpu', 0):.0f} s of CPU), "
              f"{totals.get('accepted', 0):,} accepted, {totals.get('rejected', 0):,} rejected, "
              f"{totals.get('results', 0):,} results; "
              + ", ".join(f"{k[7:]} {v:,}" for k, v in sorted(totals.items()) if k.startswith("result ")) + ".",
              f"Statuses: {totals['statuses']:,} received, {totals['gaps']} gaps ({totals['missing']} status points "
              f"missing), {totals['disorder']} out of order; at most {totals['most_behind']} samples behind the wall "
              f"clock; suite exit {totals['suite_exit']}, {totals['log_errors']} error lines in its log (copied to "
              "/tmp/soak-suite.log).", ""]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--modify-rate", type=float, default=100.0, help="modify goals per second per supervisor")
    parser.add_argument("--status-rate", type=float, default=1000.0)
    parser.add_argument("--result-timeout", type=float, default=60.0, help="ros.result_timeout of the suite (s)")
    parser.add_argument("--goal-process", action="store_true",
                        help="ros.goal_process: the action servers' services in the goal front, a process of their own")
    parser.add_argument("--append", action="store_true", help="append the report to bench/RESULTS.md")
    args = parser.parse_args()
    tree = suite_tree()  # read once, before the run: what the report names is what ran
    print(f"the suite from {tree}", flush=True)
    rows, totals = soak(args.minutes, args.modify_rate, args.status_rate, args.result_timeout, args.goal_process)
    text = report(rows, totals, args, tree)
    print(text)
    print("per topic (received, gaps, missing):", totals["per_topic"])
    if args.append:
        with open(REPO / "bench" / "RESULTS.md", "a", encoding="utf-8") as results:
            results.write("\n" + text)


if __name__ == "__main__":
    main()
