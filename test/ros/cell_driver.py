"""The commanding client of a cell, run on its own "host" (a network namespace) by
test_cell_netns.py and bench/bench_cell.py; one JSON object per line on stdout.

    python cell_driver.py cell NS_A NS_B     the multi-host scenario (below)
    python cell_driver.py bench NS COUNT     discovery time, goal and E_STOP round trips, status rate

cell: discovers both suites; moves on both at once and checks their statuses and events
arrive in order ("phase1"); waits for a line on stdin (the test has stopped its recorder),
starts a long move on NS_A ("long") and waits for "up" on stdin (the test cut the link and
restored it); then reports what it sees ("after": the stale and the fresh status, the long
goal's result, the commands NS_A applied meanwhile) and shows new goals work on both.
"""

from __future__ import annotations

import itertools
import json
import statistics
import sys
import threading
import time

from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from mpi_ros.client import EVENTS_QOS, MotionClient
from mpi_ros.msg import Command, MotionEvent, MotionStatus

WAIT = 20.0
FAST = {"velocity": 200000.0, "acceleration": 2000000.0, "deceleration": 2000000.0, "jerk_percent": 0.0}


def say(**fields) -> None:
    print(json.dumps(fields), flush=True)


class Inbox:
    """Every message of a topic, in arrival order."""

    def __init__(self, node, msg_type, topic: str, qos):
        self.messages: list = []
        self.arrived: list[float] = []
        self._lock = threading.Condition()
        node.create_subscription(msg_type, topic, self._add, qos)

    def _add(self, msg) -> None:
        with self._lock:
            self.messages.append(msg)
            self.arrived.append(time.monotonic())
            self._lock.notify_all()

    def since(self, start: int) -> list:
        with self._lock:
            return self.messages[start:]

    def wait_for(self, predicate, timeout: float) -> bool:
        """Wait (up to ``timeout`` s) until a message for which ``predicate`` holds has arrived."""
        with self._lock:
            return self._lock.wait_for(lambda: any(predicate(m) for m in self.messages), timeout)


def in_order(samples: list[int]) -> bool:
    return all(a <= b for a, b in itertools.pairwise(samples))


def discover(namespace: str) -> tuple[MotionClient, float]:
    began = time.monotonic()
    client = MotionClient(0, namespace=namespace, timeout=WAIT, node_name=f"cell_driver_{namespace.strip('/')}")
    if not client.wait_for_server(WAIT):
        raise SystemExit(f"no suite in {namespace}")
    return client, time.monotonic() - began


def phase1(clients: dict[str, MotionClient]) -> dict:
    inboxes = {ns: (Inbox(c.node, MotionStatus, f"{ns}/ms0/status", 100),
                    Inbox(c.node, MotionEvent, f"{ns}/events", EVENTS_QOS)) for ns, c in clients.items()}
    for client in clients.values():
        client.status(WAIT)  # statuses flow
    goals = {ns: c.move([5000.0, -2500.0], wait=False, **FAST) for ns, c in clients.items()}
    results = {ns: goal.wait(WAIT) for ns, goal in goals.items()}
    report = {}
    for ns, (statuses, events) in inboxes.items():
        done_sample = results[ns].end_sample
        clients[ns].status(WAIT, newer_than=done_sample)  # a status after the move's end arrived
        # the result and the events are different topics: MOTION_DONE may arrive after the result
        events.wait_for(lambda m: m.supervisor == 0 and m.type == "MOTION_DONE", WAIT)
        status_samples = [m.sample for m in statuses.since(0)]
        event_samples = [m.sample for m in events.since(0)]
        report[ns] = {"message": results[ns].message, "position": list(results[ns].command_position),
                      "statuses": len(status_samples), "statuses_in_order": in_order(status_samples)
                      and len(set(status_samples)) == len(status_samples),
                      "events": [m.type for m in events.since(0) if m.supervisor == 0],
                      "events_in_order": in_order(event_samples)}
    return report


def cut(clients: dict[str, MotionClient], ns_a: str, ns_b: str) -> dict:
    a = clients[ns_a]
    goal = a.move([500000.0, 0.0], velocity=2000.0, acceleration=20000.0, deceleration=20000.0, wait=False)
    if not goal.wait_started(WAIT):
        raise SystemExit("the long move did not start")
    moving = a.wait_for_state("MOVING", WAIT)
    say(long={"sample": moving.sample})
    sys.stdin.readline()  # the link was cut and is back
    stale = a.status(WAIT)  # what the client held (may predate the cut)
    result = goal.wait(WAIT, raise_on_error=False)
    fresh = a.status(WAIT, newer_than=max(stale.sample, result.end_sample))
    commands = Inbox(a.node, Command, f"{ns_a}/commands",  # latched: the history of what was applied
                     QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                                durability=DurabilityPolicy.TRANSIENT_LOCAL))
    back = a.move([0.0, 0.0], wait=True, timeout=WAIT, **FAST)
    other = clients[ns_b].move([0.0, 0.0], wait=True, timeout=WAIT, **FAST)
    commands.wait_for(lambda m: m.operation == "client_lost", WAIT)  # the caller checks it is there
    return {"stale_state": stale.state_name, "stale_sample": stale.sample, "result": result.message,
            "result_state": result.state_name, "result_detail": result.detail, "asked_again": goal.asked_again,
            "fresh_state": fresh.state_name, "fresh_sample": fresh.sample,
            "commands": [m.operation for m in commands.since(0)], "new_goal": back.message,
            "new_goal_position": list(back.command_position), "other_suite": other.message}


def bench(namespace: str, count: int, discoveries: int = 5) -> dict:
    found = []
    for _ in range(discoveries):  # a new DDS participant each time: discovery from scratch
        client, took = discover(namespace)
        found.append(took)
        client.close()
    client, took = discover(namespace)
    found.append(took)
    statuses = Inbox(client.node, MotionStatus, f"{namespace}/ms0/status", 100)
    goal_trips, e_stop_trips = [], []
    for i in range(count):
        began = time.monotonic()
        goal = client.start({"type": "TRAPEZOIDAL", "position": [float(100 * ((i + 1) % 2)), 0.0],
                             "trajectory": [{"velocity": 200000.0, "acceleration": 2000000.0,
                                             "deceleration": 2000000.0}]})
        goal_trips.append(time.monotonic() - began)  # sent, applied by the controller, accepted
        goal.wait(WAIT)
    for _ in range(count):
        began = time.monotonic()
        applied = client.e_stop()  # answered once applied (at the sample after the request arrived)
        e_stop_trips.append(time.monotonic() - began)
        client.wait_for_state("ERROR", WAIT, newer_than=applied.sample)
        client.reset()
    window, began = 5.0, len(statuses.since(0))
    time.sleep(window)  # the status messages of a quiet window (a measurement, not a wait for something)
    taken = statuses.since(began)
    rate = len(taken) / window
    samples = [m.sample for m in statuses.since(0)]
    steps = {b - a for a, b in itertools.pairwise(samples)}
    period = round(2000.0 / 100.0)  # samples between statuses at the default rates
    missed = sum(max(0, (b - a) // period - 1) for a, b in itertools.pairwise(samples))
    client.close()
    ms = 1000.0
    return {"namespace": namespace, "discovery_s": round(statistics.median(found), 3),
            "discovery_s_max": round(max(found), 3),
            "goal_ms_median": round(statistics.median(goal_trips) * ms, 2),
            "goal_ms_max": round(max(goal_trips) * ms, 2),
            "e_stop_ms_median": round(statistics.median(e_stop_trips) * ms, 2),
            "e_stop_ms_max": round(max(e_stop_trips) * ms, 2),
            "status_hz": rate, "status_steps": sorted(steps), "statuses_missed": missed,
            "statuses": len(samples)}


def main(argv: list[str]) -> int:
    if argv[1] == "bench":
        say(bench=bench(argv[2], int(argv[3])))
        return 0
    ns_a, ns_b = argv[2], argv[3]
    clients = {}
    for ns in (ns_a, ns_b):
        clients[ns], took = discover(ns)
        say(discovered=ns, seconds=round(took, 3))
    say(phase1=phase1(clients))
    sys.stdin.readline()  # the recorder has stopped
    say(after=cut(clients, ns_a, ns_b))
    for client in clients.values():
        client.close()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
