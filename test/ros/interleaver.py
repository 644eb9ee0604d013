"""One client process of the interleavings test (test_interleavings.py; issue 14, "Random
interleavings"): for a given time it sends a seeded random mix of MotionStart and MotionModify
goals, the MPI actions (STOP, E_STOP, ABORT, E_STOP_ABORT, RESET, RESUME) and cancels of its
own goals to the supervisors it is given, then waits for the result of every goal it sent and
writes a summary as JSON.

    python -P test/ros/interleaver.py --seed 1 --seconds 20 --supervisors 0 1 --out summary.json

Several of these run at once against one suite whose supervisors share axes, so each command
meets whatever state the others left. Pacing: each request waits for its answer (a goal for
the goal response, which comes after its command was applied), so a client sends as fast as
the suite answers; nothing sleeps.
"""

from __future__ import annotations

import argparse
import json
import random
import sys
import time
import traceback
from collections import Counter
from dataclasses import dataclass, field
from typing import Any

# Weights: RESET and the moves most of the time, so that the supervisors spend their time moving
# and the actions meet moving axes (each E_STOP or ABORT needs a RESET to move again).
ACTIONS = (("STOP", 3), ("E_STOP", 1), ("ABORT", 1), ("E_STOP_ABORT", 1), ("RESET", 6), ("RESUME", 3))
OPERATIONS = (("start", 8), ("modify", 5), ("action", 5), ("cancel", 2))
TYPES = ("S_CURVE", "TRAPEZOIDAL", "VELOCITY", "S_CURVE", "TRAPEZOIDAL")
ATTRIBUTES = ((), (), (), ("APPEND",), ("AUTO_START",), ("DELAY",))
RESULT_WAIT = 120.0  # s: the longest a goal may take to end after the last request (moves are short)


@dataclass
class Summary:
    seed: int
    supervisors: list[int]
    requests: int = 0
    goals: int = 0
    results: int = 0
    cancels: int = 0
    actions: int = 0
    messages: Counter = field(default_factory=Counter)  # goal results and action answers, by message
    outcomes: Counter = field(default_factory=Counter)  # goal outcomes (DONE, REFUSED, ENDED, CANCELED)
    states: Counter = field(default_factory=Counter)  # states in results and answers
    missing: list[str] = field(default_factory=list)  # goals without a result
    errors: list[str] = field(default_factory=list)  # exceptions raised in this client


def _goal(rng: random.Random, axes: int, kind: str) -> dict[str, Any]:
    motion_type = rng.choice(TYPES)
    velocity = rng.uniform(500.0, 20_000.0) * (rng.choice((1, -1)) if motion_type == "VELOCITY" else 1)
    acceleration = rng.uniform(5_000.0, 200_000.0)
    goal: dict[str, Any] = {
        "type": motion_type,
        "trajectory": [{"velocity": velocity, "acceleration": acceleration,
                        "deceleration": rng.uniform(5_000.0, 200_000.0), "jerk_percent": rng.choice((0.0, 50.0))}],
        "attributes": list(rng.choice(ATTRIBUTES if kind == "start" else (*ATTRIBUTES, ("AUTO_START",)))),
    }
    if motion_type != "VELOCITY":
        goal["position"] = [rng.uniform(-5_000.0, 5_000.0) for _ in range(axes)]
    if "DELAY" in goal["attributes"]:
        goal["delay"] = [rng.uniform(0.0, 0.05) for _ in range(axes)]
    return goal


def run(seed: int, seconds: float, supervisors: list[int], axes: dict[int, int]) -> Summary:
    from mpi_ros.client import MotionClient

    rng = random.Random(seed)
    summary = Summary(seed, supervisors)
    clients = {n: MotionClient(n, timeout=30.0, node_name=f"interleaver_{seed}_ms{n}") for n in supervisors}
    goals: list[tuple[str, Any]] = []
    try:
        for client in clients.values():
            if not client.wait_for_server(30.0):
                raise RuntimeError(f"{client.prefix} did not come up")
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            number = rng.choice(supervisors)
            _one(rng, clients[number], axes[number], goals, summary)
        for client in clients.values():
            _answered(client.e_stop(), summary)  # never refused (docs/state-machine.md)
        _collect(goals, summary)
    except Exception:  # noqa: BLE001 - reported in the summary, which the test asserts empty
        summary.errors.append(traceback.format_exc())
    finally:
        for client in clients.values():
            client.close()
    return summary


def _one(rng: random.Random, client: Any, axes: int, goals: list[tuple[str, Any]], summary: Summary) -> None:
    operation = rng.choices([o for o, _ in OPERATIONS], [w for _, w in OPERATIONS])[0]
    summary.requests += 1
    if operation in ("start", "modify"):
        goal = _goal(rng, axes, operation)
        running = (client.start if operation == "start" else client.modify)(goal)
        goals.append((f"{client.prefix} {operation} {goal['type']} {goal['attributes']}", running))
        summary.goals += 1
    elif operation == "action":
        action = rng.choices([a for a, _ in ACTIONS], [w for _, w in ACTIONS])[0]
        _answered(client.action(action, raise_on_error=False), summary)
    else:
        unfinished = [g for _, g in goals if not g.done]
        if unfinished:
            rng.choice(unfinished).cancel(30.0)
            summary.cancels += 1


def _answered(reply: Any, summary: Summary) -> None:
    summary.actions += 1
    summary.messages[reply.message] += 1
    summary.states[reply.state_name] += 1


def _collect(goals: list[tuple[str, Any]], summary: Summary) -> None:
    deadline = time.monotonic() + RESULT_WAIT
    for label, running in goals:
        if not running.result_ready(max(0.0, deadline - time.monotonic())):
            summary.missing.append(label)
            continue
        result = running.wait(30.0, raise_on_error=False)  # ready: the done callback comes from the executor
        summary.results += 1
        summary.messages[result.message] += 1
        summary.outcomes[result.outcome.value] += 1
        summary.states[result.state_name] += 1


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, required=True)
    parser.add_argument("--seconds", type=float, required=True)
    parser.add_argument("--supervisors", type=int, nargs="+", required=True)
    parser.add_argument("--axes", type=int, nargs="+", required=True, help="axis count of each supervisor")
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    summary = run(args.seed, args.seconds, args.supervisors, dict(zip(args.supervisors, args.axes, strict=True)))
    with open(args.out, "w") as out:
        json.dump({k: dict(v) if isinstance(v, Counter) else v for k, v in vars(summary).items()}, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
