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

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))  # bench_suite, beside this file (python -P adds nothing)
from bench_suite import REPO, WAIT, Probe, cpu_seconds, load_average, topic_type  # noqa: E402

SUPERVISORS = 8
_SAMPLE = struct.Struct("<Q")  # MotionStatus/AxisStatus: stamp (8 bytes), then uint64 sample, after the CDR header
_SAMPLE_AT = 4 + 8


def suite_yaml(directory: Path, status_rate: float, result_timeout: float) -> Path:
    raw = yaml.safe_load((REPO / "config" / "default.yaml").read_text(encoding="utf-8"))
    raw["axes"]["count"] = SUPERVISORS
    raw["supervisors"] = [{"number": n, "axes": [n]} for n in range(SUPERVISORS)]
    raw["ros"].update(status_rate=status_rate, result_timeout=result_timeout)
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
        (sample,) = _SAMPLE.unpack_from(data, _SAMPLE_AT)
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
    """The latest "<ns>/suite" diagnostic values, and the most samples behind seen."""

    values: dict[str, int] = field(default_factory=dict)
    most_behind: int = 0

    def on_message(self, msg) -> None:
        for status in msg.status:
            if status.name.endswith("/suite"):
                self.values = {v.key: int(v.value) for v in status.values}
                self.most_behind = max(self.most_behind, self.values.get("samples_behind", 0))


def rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


# -- the load (its own process) -------------------------------------------------------------------
def load(domain: str, rate: float, seconds: float, out: str, ready) -> None:
    """Modify goals at ``rate`` per supervisor for ``seconds``, through the action protocol's
    services; then E_STOP each supervisor and wait for every result; writes counts to ``out``."""
    os.environ["ROS_DOMAIN_ID"] = domain
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from unique_identifier_msgs.msg import UUID

    from mpi_ros.action import MotionModify, MotionStart
    from mpi_ros.ros.supervisor_node import ACTION_SERVICE_QOS
    from mpi_ros.srv import MotionAction

    rclpy.init()
    node = Node("soak_load")
    counts: Counter = Counter()
    lock = threading.Lock()
    services = {}
    for n in range(SUPERVISORS):
        base = f"/mpi/ms{n}"
        services[n] = {
            "start": node.create_client(MotionStart.Impl.SendGoalService, f"{base}/motion_start/_action/send_goal",
                                        qos_profile=ACTION_SERVICE_QOS),
            "start_result": node.create_client(MotionStart.Impl.GetResultService,
                                               f"{base}/motion_start/_action/get_result",
                                               qos_profile=ACTION_SERVICE_QOS),
            "modify": node.create_client(MotionModify.Impl.SendGoalService, f"{base}/motion_modify/_action/send_goal",
                                         qos_profile=ACTION_SERVICE_QOS),
            "modify_result": node.create_client(MotionModify.Impl.GetResultService,
                                                f"{base}/motion_modify/_action/get_result",
                                                qos_profile=ACTION_SERVICE_QOS),
            "action": node.create_client(MotionAction, f"{base}/action"),
        }
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinning = threading.Thread(target=executor.spin, daemon=True)
    spinning.start()
    for client in (c for s in services.values() for c in s.values()):
        client.wait_for_service(timeout_sec=WAIT)
    # Each retarget is a move of 4000 counts taking about a second, so every modify finds the
    # supervisor MOVING (modifies come 10 ms to 1 s apart) and the axes never come to rest.
    trajectory = [{"velocity": 5_000.0, "acceleration": 100_000.0, "deceleration": 100_000.0, "jerk_percent": 50.0}]

    def count(key: str) -> None:
        with lock:
            counts[key] += 1

    def on_result(future) -> None:
        count("results")
        response = future.result()
        count(f"result {response.result.message or f'(none: goal status {response.status})'}")

    def send(n: int, kind: str, goal) -> None:
        request = services[n][kind].srv_type.Request(goal_id=UUID(uuid=list(uuid.uuid4().bytes)), goal=goal)
        count("sent")

        def on_answer(future) -> None:
            if not future.result().accepted:
                count("rejected")
                return
            count("accepted")
            result_request = services[n][f"{kind}_result"].srv_type.Request(goal_id=request.goal_id)
            services[n][f"{kind}_result"].call_async(result_request).add_done_callback(on_result)

        services[n][kind].call_async(request).add_done_callback(on_answer)

    from mpi_ros.client import fill

    for n in range(SUPERVISORS):
        send(n, "start", fill(MotionStart.Goal(), {"type": "S_CURVE", "position": [2000.0],
                                                   "trajectory": trajectory}))
    ready.set()
    tick = 0
    period = 1.0 / rate
    began = time.monotonic()
    pause = threading.Event()
    while time.monotonic() - began < seconds:
        target = 2000.0 if tick % 2 else -2000.0
        for n in range(SUPERVISORS):
            send(n, "modify", fill(MotionModify.Goal(), {"type": "S_CURVE", "position": [target], "attributes": [
                "AUTO_START"], "trajectory": trajectory}))  # a modify late enough to find the axis at rest starts
        tick += 1
        pause.wait(max(0.0, began + tick * period - time.monotonic()))  # pacing the load, not a test wait
    for n in range(SUPERVISORS):
        services[n]["action"].call_async(MotionAction.Request(action="E_STOP"))
    deadline = time.monotonic() + 120.0
    while time.monotonic() < deadline:
        with lock:
            if counts["results"] + counts["rejected"] >= counts["sent"]:
                break
        pause.wait(0.1)
    with lock:
        Path(out).write_text(json.dumps({**counts, "ticks": tick, "seconds": time.monotonic() - began}))
    executor.shutdown(timeout_sec=2.0)
    spinning.join(timeout=5.0)
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


def soak(minutes: float, modify_rate: float, status_rate: float, result_timeout: float) -> tuple[list[Minute], dict]:
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray

    seconds = minutes * 60.0
    with tempfile.TemporaryDirectory(prefix="soak_") as tmp:
        config = suite_yaml(Path(tmp), status_rate, result_timeout)
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
    return sum(1 for line in log.splitlines() if "Traceback" in line or "[ERROR]" in line)


def _minutes(pid: int, topics: dict[str, SampleOrder], diagnostics: Diagnostics, minutes: float) -> list[Minute]:
    rows = []
    pause = threading.Event()
    began = time.monotonic()
    cpu0 = cpu_seconds(pid)
    for minute in range(1, int(minutes) + 1):
        pause.wait(max(0.0, began + 60.0 * minute - time.monotonic()))
        cpu1 = cpu_seconds(pid)
        rows.append(Minute(minute, rss_mb(pid), (cpu1 - cpu0) / 60.0, sum(t.count for t in topics.values()),
                           sum(t.gaps for t in topics.values()), dict(diagnostics.values)))
        cpu0 = cpu1
        print(f"minute {minute}: RSS {rows[-1].rss_mb:.0f} MB, CPU {rows[-1].cpu:.0%}, statuses {rows[-1].statuses:,}, "
              f"gaps {rows[-1].gaps}, {rows[-1].diagnostics}", flush=True)
    return rows


def report(rows: list[Minute], totals: dict, args) -> str:
    sent = totals.get("sent", 0)
    lines = [
        f"## Soak (bench/soak.py): {args.minutes:g} min, {SUPERVISORS} supervisors, {args.modify_rate:g} modifies/s "
        f"each, status {args.status_rate:g} Hz, result_timeout {args.result_timeout:g} s",
        "",
        f"`python -P bench/soak.py --minutes {args.minutes:g} --modify-rate {args.modify_rate:g} --status-rate "
        f"{args.status_rate:g} --result-timeout {args.result_timeout:g}` on {time.strftime('%Y-%m-%d')} "
        f"(2 cores, load {load_average()} at the end).",
        "",
        "| minute | suite RSS MB | suite CPU (one core) | statuses received | gaps | samples behind | "
        "goals tracked / kept / requests unfiled (all supervisors) | publications queued |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        d = row.diagnostics
        tracked = sum(v for k, v in d.items() if k.endswith("goals_tracked"))
        kept = sum(v for k, v in d.items() if k.endswith("goals_kept"))
        unfiled = sum(v for k, v in d.items() if k.endswith("requests_unfiled"))
        lines.append(f"| {row.minute} | {row.rss_mb:.0f} | {row.cpu:.0%} | {row.statuses:,} | {row.gaps} | "
                     f"{d.get('samples_behind', '?')} | {tracked} / {kept} / {unfiled} | "
                     f"{d.get('outputs_queued', '?')} |")
    lines += ["", f"Goals: {sent:,} sent ({totals.get('ticks', 0) * SUPERVISORS / max(totals.get('seconds', 1), 1):.0f}"
              f"/s offered), {totals.get('accepted', 0):,} accepted, {totals.get('rejected', 0):,} rejected, "
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
    parser.add_argument("--append", action="store_true", help="append the report to bench/RESULTS.md")
    args = parser.parse_args()
    rows, totals = soak(args.minutes, args.modify_rate, args.status_rate, args.result_timeout)
    text = report(rows, totals, args)
    print(text)
    print("per topic (received, gaps, missing):", totals["per_topic"])
    if args.append:
        with open(REPO / "bench" / "RESULTS.md", "a", encoding="utf-8") as results:
            results.write("\n" + text)


if __name__ == "__main__":
    main()
