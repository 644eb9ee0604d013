"""E_STOP with hundreds of goals in flight (issue 9, "E_STOP starvation"), as users see it.

Three processes, so that each figure is the suite's and not the GIL of a shared client:
the suite (`mpi-ros run --time-scale 1`, the default config: 2 supervisors of 2 axes), a
storm client that sends the goals and collects every result, and this process, which
times service round trips (call to response, wall clock).

Each round measures the idle suite, then a storm, side by side (the machine is shared and
its load shifts; compare the medians):
- idle: E_STOP round trips on ms0 (each followed by RESET once in ERROR), and MotionAction
  RESUME round trips on ms1 (IDLE: refused, nothing changes);
- storm, on each supervisor: a crawling S-curve, MODIFIES MotionModify goals retargeting it
  (all follow that one move) and APPENDS queued moves: every goal in flight at once, more
  than the executor has threads (32); after SETTLE s, RESUME round trips on ms1 (MOVING:
  refused), then E_STOP on ms0 and ms1; every goal must end (ABORTED, MPIMotionMessageERROR);
  the time from the last E_STOP's answer to the last result;
- the suite's CPU (utime + stime from /proc) over the settle window, idle and in a storm.

    .venv/bin/python -P bench/goal_storm.py [--rounds 10] [--modifies 140] [--appends 10]
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import random
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter, deque
from functools import partial
from pathlib import Path

# This source tree, not a stale installed copy (the installed package still supplies the
# generated interfaces: mpi_ros/__init__.py), here and in the suite's process.
_REPO = str(Path(__file__).resolve().parent.parent)
sys.path.insert(0, _REPO)
os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (_REPO, os.environ.get("PYTHONPATH", "")) if p)
# Its own DDS domain (a pid-based one may be taken by a suite of a concurrent test run).
os.environ.setdefault("ROS_DOMAIN_ID", str(random.Random(os.getpid()).randint(101, 200)))
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
os.environ.setdefault("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")

WAIT = 30.0
SETTLE = 1.0  # s after the last goal is answered: feedback for every goal flows
IDLE_E_STOPS = 5  # E_STOP/RESET cycles on the idle suite per round
PROBES = 25  # RESUME round trips per round, idle and in the storm
BASE = 1_000_000.0
CRAWL = {"type": "S_CURVE", "trajectory": [{"velocity": 100.0, "acceleration": 1000.0,
                                             "deceleration": 1000.0, "jerk_percent": 50.0}]}
STEP = {"type": "TRAPEZOIDAL", "attributes": ["APPEND"],
        "trajectory": [{"velocity": 2000.0, "acceleration": 20000.0, "deceleration": 20000.0}]}


# -- the storm client (a process of its own) -----------------------------------------------------
class _Storm:
    def __init__(self, context):
        from rclpy.action import ActionClient
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node

        from mpi_ros.action import MotionModify, MotionStart
        from mpi_ros.client import ACTION_QOS

        self.types = {"start": MotionStart, "modify": MotionModify}
        self.node = Node("goal_storm_bench_sender", context=context)
        self.clients = {(n, kind): ActionClient(self.node, self.types[kind], f"/mpi/ms{n}/motion_{kind}", **ACTION_QOS)
                        for n in (0, 1) for kind in self.types}
        self.cond = threading.Condition()
        self.answers: dict[int, object] = {}
        self.results: dict[int, tuple[float, int, str]] = {}  # index -> (arrival, status, message)
        self.count = 0
        self._batches: deque = deque()
        self.executor = SingleThreadedExecutor(context=context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self.executor.spin, daemon=True)
        self.thread.start()
        assert all(c.wait_for_server(timeout_sec=WAIT) for c in self.clients.values()), "no action servers"

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=2.0)
        self.thread.join(timeout=2.0)
        self.node.destroy_node()

    def send(self, supervisor: int, kind: str, goals: list[dict]) -> list[int]:
        from mpi_ros.ros import convert

        first, self.count = self.count, self.count + len(goals)
        self._batches.append((self.clients[(supervisor, kind)], first,
                              [convert.fill(self.types[kind].Goal(), g) for g in goals]))
        self.executor.create_task(self._send_oldest)  # tasks run in no set order: send the oldest batch
        return list(range(first, self.count))

    def _send_oldest(self) -> None:
        client, first, messages = self._batches.popleft()
        for index, message in enumerate(messages, first):
            client.send_goal_async(message).add_done_callback(partial(self._answered, index))

    def _answered(self, index: int, future) -> None:
        handle = future.result()
        with self.cond:
            self.answers[index] = handle
            self.cond.notify_all()
        if handle.accepted:
            handle.get_result_async().add_done_callback(partial(self._ended, index))

    def _ended(self, index: int, future) -> None:
        response = future.result()
        with self.cond:
            self.results[index] = (time.monotonic(), response.status, response.result.message)
            self.cond.notify_all()

    def wait(self, table: dict, indices: list[int]) -> None:
        with self.cond:
            assert self.cond.wait_for(lambda: all(i in table for i in indices), WAIT * 2), (
                f"{sum(i in table for i in indices)} of {len(indices)}")

    def storm(self, modifies: int, appends: int) -> list[int]:
        goals = []
        for n in (0, 1):
            # A goal is applied before it is answered: the modifies find the move, and the
            # appends queue behind the last modify (a modify drops what is queued).
            started = self.send(n, "start", [{**CRAWL, "position": [BASE, BASE]}])
            self.wait(self.answers, started)
            modified = self.send(n, "modify", [{**CRAWL, "position": [BASE + i, BASE - i]}
                                               for i in range(1, modifies + 1)])
            self.wait(self.answers, modified)
            goals += started + modified
            goals += self.send(n, "start",
                               [{**STEP, "position": [BASE + 10.0 * i, BASE]} for i in range(1, appends + 1)])
        self.wait(self.answers, goals)
        return goals


def _storm_process(conn) -> None:
    import rclpy

    context = rclpy.Context()
    rclpy.init(context=context)
    storm = _Storm(context)
    conn.send("ready")
    goals: list[int] = []
    while True:
        command = conn.recv()
        if command[0] == "storm":
            began = time.monotonic()
            goals = storm.storm(*command[1:])
            conn.send((len(goals), sum(storm.answers[i].accepted for i in goals), time.monotonic() - began))
        elif command[0] == "results":
            storm.wait(storm.results, goals)
            ends = [storm.results[i] for i in goals]
            conn.send((max(t for t, _, _ in ends), Counter((s, m) for _, s, m in ends)))
        else:
            break
    storm.close()
    context.try_shutdown()


# -- the probe (this process) --------------------------------------------------------------------
class _Probe:
    def __init__(self, context):
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node

        from mpi_ros.msg import MotionStatus
        from mpi_ros.srv import MotionAction

        self.MotionAction = MotionAction
        self.node = Node("goal_storm_bench_probe", context=context)
        self.clients = {n: self.node.create_client(MotionAction, f"/mpi/ms{n}/action") for n in (0, 1)}
        self.states: dict[int, str] = {}
        self.cond = threading.Condition()
        for n in (0, 1):
            self.node.create_subscription(MotionStatus, f"/mpi/ms{n}/status", partial(self._status, n), 10)
        self.executor = SingleThreadedExecutor(context=context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self.executor.spin, daemon=True)
        self.thread.start()
        assert all(c.wait_for_service(timeout_sec=WAIT) for c in self.clients.values()), "no suite"

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=2.0)
        self.thread.join(timeout=2.0)
        self.node.destroy_node()

    def _status(self, number: int, message) -> None:
        with self.cond:
            self.states[number] = message.state_name
            self.cond.notify_all()

    def wait_state(self, number: int, state: str) -> None:
        with self.cond:
            assert self.cond.wait_for(lambda: self.states.get(number) == state, WAIT), (number, state, self.states)

    def action(self, number: int, action: str) -> tuple[float, str]:
        done = threading.Event()
        began = time.perf_counter()
        future = self.clients[number].call_async(self.MotionAction.Request(action=action))
        future.add_done_callback(lambda _f: done.set())
        assert done.wait(WAIT), f"no answer to {action}"
        return time.perf_counter() - began, future.result().message


def _cpu(pid: int) -> float:
    """utime + stime of the process, in seconds."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _cpu_share(pid: int, seconds: float) -> float:
    cpu0, wall0 = _cpu(pid), time.monotonic()
    threading.Event().wait(seconds)
    return (_cpu(pid) - cpu0) / (time.monotonic() - wall0)


def _ms(values: list[float]) -> str:
    values = sorted(values)
    return (f"median {statistics.median(values) * 1e3:.2f}, p90 {values[int(len(values) * 0.9)] * 1e3:.2f}, "
            f"max {values[-1] * 1e3:.2f} ms ({len(values)})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rounds", type=int, default=10)
    parser.add_argument("--modifies", type=int, default=140, help="MotionModify goals per supervisor")
    parser.add_argument("--appends", type=int, default=10, help="appended MotionStart goals per supervisor")
    parser.add_argument("--feedback-rate", type=float, default=None, help="ros.feedback_rate (default: the config's)")
    args = parser.parse_args()

    import rclpy
    import yaml

    from mpi_ros import config

    data = yaml.safe_load(config.default_config_path().read_text(encoding="utf-8"))
    if args.feedback_rate is not None:
        data.setdefault("ros", {})["feedback_rate"] = args.feedback_rate
    feedback_rate = config.parse(data, "bench").ros.feedback_rate
    tmp = tempfile.TemporaryDirectory()
    suite_yaml = Path(tmp.name, "suite.yaml")
    suite_yaml.write_text(yaml.safe_dump(data), encoding="utf-8")
    exe = Path(sys.executable).with_name("mpi-ros")
    suite = subprocess.Popen([str(exe), "run", "--time-scale", "1", "--config", str(suite_yaml)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    spawn = multiprocessing.get_context("spawn")
    conn, child_conn = spawn.Pipe()
    sender = spawn.Process(target=_storm_process, args=(child_conn,), daemon=True)
    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        probe = _Probe(context)
        sender.start()
        assert conn.poll(WAIT * 2) and conn.recv() == "ready", "the storm client did not start"
        threading.Event().wait(SETTLE)
        idle_e_stop, idle_probe, idle_cpu = [], [], []
        storm_e_stop, storm_probe, to_last_result, storm_cpu, client_cpu, accept_time = [], [], [], [], [], []
        goals = 0
        for _ in range(args.rounds):  # idle and storm side by side: the machine's load shifts
            idle_cpu.append(_cpu_share(suite.pid, SETTLE))
            for _ in range(IDLE_E_STOPS):
                elapsed, message = probe.action(0, "E_STOP")
                assert message == "MPIMessageOK", message
                idle_e_stop.append(elapsed)
                probe.wait_state(0, "ERROR")
                assert probe.action(0, "RESET")[1] == "MPIMessageOK"
                probe.wait_state(0, "IDLE")
            for _ in range(PROBES):
                elapsed, message = probe.action(1, "RESUME")
                assert message == "MPIMotionMessageIDLE", message
                idle_probe.append(elapsed)

            conn.send(("storm", args.modifies, args.appends))
            goals, accepted, seconds = conn.recv()
            assert accepted == goals, f"{accepted} of {goals} goals accepted"
            accept_time.append(seconds)
            cpu0 = _cpu(sender.pid)
            storm_cpu.append(_cpu_share(suite.pid, SETTLE))
            client_cpu.append((_cpu(sender.pid) - cpu0) / SETTLE)
            for _ in range(PROBES):
                elapsed, message = probe.action(1, "RESUME")
                assert message == "MPIMotionMessageMOVING", message
                storm_probe.append(elapsed)
            for n in (0, 1):
                elapsed, message = probe.action(n, "E_STOP")
                assert message == "MPIMessageOK", message
                storm_e_stop.append(elapsed)
            answered = time.monotonic()
            conn.send(("results",))
            last, outcomes = conn.recv()
            assert set(outcomes) == {(6, "MPIMotionMessageERROR")}, outcomes  # 6: ABORTED
            to_last_result.append(last - answered)
            for n in (0, 1):
                probe.wait_state(n, "ERROR")
                assert probe.action(n, "RESET")[1] == "MPIMessageOK"
                probe.wait_state(n, "IDLE")
        conn.send(("quit",))
        sender.join(timeout=10.0)
        probe.close()
    finally:
        if sender.is_alive():
            sender.kill()
        suite.send_signal(signal.SIGINT)  # Ctrl-C: the suite's clean stop
        try:
            suite.wait(timeout=20)
        except subprocess.TimeoutExpired:
            suite.kill()
            suite.wait(timeout=10)
        context.try_shutdown()
        tmp.cleanup()

    per = (f"{goals} goals in flight ({args.modifies} modifies + 1 start + {args.appends} appends "
           f"on each of 2 supervisors)")
    print(f"{args.rounds} storms of {per}; `mpi-ros run --time-scale 1`, default config "
          f"(feedback {feedback_rate:g} Hz to every goal, executor 32 threads).")
    print()
    print("| measure | idle suite | in a storm | storm / idle (medians) |")
    print("| --- | --- | --- | --- |")
    print(f"| E_STOP round trip (MotionAction, call to response) | {_ms(idle_e_stop)} | {_ms(storm_e_stop)} | "
          f"{statistics.median(storm_e_stop) / statistics.median(idle_e_stop):.2f} |")
    print(f"| MotionAction RESUME round trip on ms1 (refused) | {_ms(idle_probe)} | {_ms(storm_probe)} | "
          f"{statistics.median(storm_probe) / statistics.median(idle_probe):.2f} |")
    print(f"| suite CPU, share of one core ({SETTLE:g} s per round) | "
          f"median {statistics.median(idle_cpu) * 100:.0f} % | "
          f"median {statistics.median(storm_cpu) * 100:.0f} % (the storm client: "
          f"{statistics.median(client_cpu) * 100:.0f} %) | |")
    print(f"| all {goals} goals sent and answered | | median {statistics.median(accept_time):.2f} s | |")
    print(f"| last E_STOP answered -> last goal result (all ABORTED, MPIMotionMessageERROR) | | "
          f"median {statistics.median(to_last_result) * 1e3:.0f} ms, max {max(to_last_result) * 1e3:.0f} ms | |")


if __name__ == "__main__":
    main()
