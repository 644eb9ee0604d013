"""ROS-level figures of the suite in real time (time scale 1), in one process:

- E_STOP latency: samples between the sample due when the client sends the E_STOP service
  request and the sample at which the controller applied it (docs/quality.md, "Fast": within one
  sample of the request arriving). Includes DDS transport and executor scheduling.
- status rate: MotionStatus messages per wall-clock second at 100 Hz and 1 kHz (target: within 2 %).
- idle CPU of the suite (all threads), as a share of one core.
"""

from __future__ import annotations

import os
import statistics
import sys
import threading
import time

os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 100))
# This source tree, not the copy scripts/setup.sh last installed into the venv (run with -P).
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import rclpy
from rclpy.executors import SingleThreadedExecutor

from mpi_ros import config
from mpi_ros.commands import Command
from mpi_ros.msg import MotionStatus
from mpi_ros.ros.suite import Suite
from mpi_ros.srv import MotionAction

VELOCITY = {"type": "VELOCITY", "trajectory": [{"velocity": 1000.0, "acceleration": 100000.0}]}


def _suite(context, status_rate: float = 100.0) -> Suite:
    cfg = config.load(overrides={"ros": {"status_rate": status_rate}})
    suite = Suite(cfg, time_scale=1.0, context=context)
    suite.start(spin_in_thread=True)
    return suite


def _probe(context):
    node = rclpy.create_node("bench_probe", context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    thread = threading.Thread(target=executor.spin, daemon=True)
    thread.start()
    return node, executor


def e_stop_latency(context, cycles: int = 200) -> tuple[list[int], list[int]]:
    """(send -> effect, arrival -> effect) in samples, per request."""
    suite = _suite(context)
    arrivals = []
    node0 = suite.supervisor_nodes[0]
    handler = node0._on_action

    def timed(request, response):  # when the request reaches the node's callback
        arrivals.append(suite.runner.due_sample())
        return handler(request, response)

    node0._on_action = timed
    node0.destroy_service(next(s for s in node0.services if s.srv_name.endswith("/action")))
    node0._service(MotionAction, "action", timed)
    node, executor = _probe(context)
    client = node.create_client(MotionAction, "/mpi/ms0/action")
    client.wait_for_service(timeout_sec=10.0)
    latencies, after_arrival = [], []
    try:
        for _ in range(cycles):
            suite.runner.submit(Command("motion_start", 0, request=VELOCITY))
            suite.runner.wait(lambda ctl: ctl.axes[0].cmd_v > 0.0, 5.0)
            due = suite.runner.due_sample()
            future = client.call_async(MotionAction.Request(action="E_STOP"))
            done = threading.Event()
            future.add_done_callback(lambda _f, done=done: done.set())
            assert done.wait(5.0), "no answer"
            latencies.append(future.result().sample - due)
            after_arrival.append(future.result().sample - arrivals[-1])
            suite.runner.wait(lambda ctl: ctl.supervisor(0).state.name == "ERROR", 5.0)
            suite.runner.submit(Command("action", 0, request={"action": "RESET"}))
    finally:
        executor.shutdown()
        node.destroy_node()
        suite.shutdown()
    return latencies, after_arrival


def status_rate(context, rate: float, seconds: float = 5.0) -> float:
    suite = _suite(context, rate)
    node, executor = _probe(context)
    stamps = []
    node.create_subscription(MotionStatus, "/mpi/ms0/status", lambda m: stamps.append(time.monotonic()), 1000)
    try:
        deadline = time.monotonic() + 2.0
        while not stamps and time.monotonic() < deadline:
            threading.Event().wait(0.01)
        threading.Event().wait(seconds)
        window = [t for t in stamps if t >= stamps[0] + 0.5]
        measured = (len(window) - 1) / (window[-1] - window[0])
    finally:
        executor.shutdown()
        node.destroy_node()
        suite.shutdown()
    return measured


def idle_cpu(context, seconds: float = 10.0) -> float:
    suite = _suite(context)
    try:
        threading.Event().wait(1.0)
        cpu0, wall0 = time.process_time(), time.monotonic()
        threading.Event().wait(seconds)
        return (time.process_time() - cpu0) / (time.monotonic() - wall0)
    finally:
        suite.shutdown()


def main() -> list[str]:
    rows = []
    for name, run in (("e_stop", None), ("status100", 100.0), ("status1000", 1000.0), ("idle", None)):
        context = rclpy.Context()
        rclpy.init(context=context)
        try:
            if name == "e_stop":
                sent, arrived = (sorted(x) for x in e_stop_latency(context))
                for what, lat in (("from the client's send", sent), ("from arrival at the node", arrived)):
                    rows.append(f"| E_STOP latency {what} to the sample it took effect ({len(lat)} requests) | "
                                f"median {statistics.median(lat):.0f}, p99 {lat[int(len(lat) * 0.99)]}, max {lat[-1]} "
                                f"samples (1 sample = 0.5 ms) |")
            elif name.startswith("status"):
                measured = status_rate(context, run)
                rows.append(f"| MotionStatus rate at {run:g} Hz (wall clock, 5 s) | {measured:.2f} Hz "
                            f"({(measured / run - 1) * 100:+.2f} %) |")
            else:
                rows.append(f"| idle CPU of the suite (4 axes, 2 supervisors, 10 s) | {idle_cpu(context) * 100:.1f} % "
                            f"of one core |")
        finally:
            context.try_shutdown()
    return ["| measure | result |", "| --- | --- |", *rows]


if __name__ == "__main__":
    print("\n".join(main()))
