"""Where the time of a one-shot action verb goes, phase by phase (issue 36: at most 1 s from
invocation to effect). Runs what `mpi-ros ACTION` runs (Session, ActionCall, one call) in a
new process per run, as a verb is, with a wall-clock timestamp after each phase; this
process starts the suite, watches /mpi/commands (when the suite applied the command) and,
with --third, runs `mpi-ros events` beside it (a third DDS participant on the graph, as on
any real ROS graph).

  python -P bench/verb_phases.py --runs 20 --third RESET

Prints one line per run: milliseconds from just before the process was started to
  user    the start of user code (after the ros_wheels_bootstrapper's re-exec of Python)
  cli     mpi_ros.cli's console module imported
  rclpy   rclpy imported
  msgs    the service type and ActionCall imported (numpy comes with them)
  init    rclpy.init done
  node    the node and its client created (the DDS participant)
  found   the action service ready (request reader and response writer matched)
  sent    the request handed to rclpy
  recv    /mpi/commands reached this process (an upper bound of the suite receiving it)
  answer  the response received
  closed  the node destroyed and the context shut down
  exit    the process ended
and the stamp of the sample at which the command took effect (``effect``), as bench_verbs.py
reports it.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

START = time.time()
REPO = Path(__file__).resolve().parent.parent
PHASES = ("user", "cli", "rclpy", "msgs", "init", "node", "found", "sent", "recv", "answer", "closed", "exit")


def one(action: str, timeout: float) -> dict[str, float]:
    """One verb's phases in this process, as wall-clock times."""
    marks = {"user": START}

    def mark(what: str) -> None:
        marks[what] = time.time()

    from mpi_ros.cli.console import Session

    mark("cli")
    import rclpy  # noqa: F401 - timed on its own: the biggest import

    mark("rclpy")
    from mpi_ros.action_call import ActionCall

    mark("msgs")
    args = argparse.Namespace(namespace="/mpi", supervisor=0, timeout=timeout, ros_args=[])
    with Session(args) as session:
        mark("init")
        call = session._keep(ActionCall(0, "/mpi", context=session.context, node_name=session.node_name))
        mark("node")
        call.wait_ready(timeout)
        mark("found")
        mark("sent")
        call.call(action, timeout, raise_on_error=False)
        mark("answer")
    mark("closed")
    return marks




def measure(action: str, runs: int, timeout: float, third: bool, compare: bool) -> list[dict[str, float]]:
    """``runs`` verbs against a suite of this tree started here (with ``compare``, each run also
    once with Fast DDS's default profile, alternating); milliseconds per phase each."""
    sys.path.insert(0, str(REPO / "bench"))
    from bench_verbs import DEFAULTS_PROFILE, _env, graph

    with graph(REPO, third) as commands, tempfile.NamedTemporaryFile("w", suffix=".xml") as defaults:
        defaults.write(DEFAULTS_PROFILE)
        defaults.flush()
        variants = {"shipped": _env(REPO)}
        if compare:
            variants["defaults"] = _env(REPO) | {"FASTRTPS_DEFAULT_PROFILES_FILE": defaults.name}
        return [_run(action, timeout, commands, env) | {"variant": name}
                for _ in range(runs) for name, env in variants.items()]


def udp_receive_buffer_errors() -> int:
    """The host's count of UDP datagrams dropped because a socket's receive buffer was full."""
    lines = [line.split() for line in Path("/proc/net/snmp").read_text().splitlines() if line.startswith("Udp:")]
    return int(lines[1][lines[0].index("RcvbufErrors")])


def _run(action: str, timeout: float, commands, env: dict[str, str]) -> dict[str, Any]:
    after = len(commands.seen)
    dropped = udp_receive_buffer_errors()
    begun = time.time()
    done = subprocess.run([sys.executable, "-P", __file__, "--one", action, "--timeout", str(timeout)], cwd=REPO,
                          env=env, check=True, capture_output=True, text=True)
    marks = json.loads(done.stdout) | {"exit": time.time()}
    seen = commands.wait_for(after, "action", action)
    if seen is None:
        raise RuntimeError(f"{action}: no command on /mpi/commands")
    marks["recv"], marks["effect"] = seen
    drops = udp_receive_buffer_errors() - dropped  # the host's, so other processes' drops count as well
    return {what: (at - begun) * 1000.0 for what, at in marks.items()} | {"drops": drops}


def summary(variant: str, rows: list[dict[str, Any]]) -> str:
    """Every run's wait for the endpoint (found - node), its median and max, the effect's."""
    waits = [row["found"] - row["node"] for row in rows]
    effects = [row["effect"] for row in rows]
    return (f"{variant}: endpoint found after the node, ms: {' '.join(f'{wait:.0f}' for wait in waits)}\n"
            f"{variant}: that wait median {statistics.median(waits):.0f} ms, max {max(waits):.0f} ms; effect median "
            f"{statistics.median(effects):.0f} ms, max {max(effects):.0f} ms; runs during which the host dropped "
            f"datagrams {sum(row['drops'] > 0 for row in rows)} of {len(rows)}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("action", nargs="?", default="RESET")
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--timeout", type=float, default=10.0)
    parser.add_argument("--third", action="store_true", help="run `mpi-ros events` beside the suite")
    parser.add_argument("--compare", action="store_true",
                        help="alternate each run with one under Fast DDS's default profile (the verbs before)")
    parser.add_argument("--one", action="store_true", help=argparse.SUPPRESS)  # a child process: one run
    args = parser.parse_args()
    if args.one:
        print(json.dumps(one(args.action, args.timeout)))
        return 0
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    os.environ.setdefault("ROS_DOMAIN_ID", str(150 + os.getpid() % 50))
    rows = measure(args.action, args.runs, args.timeout, args.third, args.compare)
    print(f"{args.action}, {args.runs} runs, third participant: {'mpi-ros events' if args.third else 'none'}, "
          f"1-minute load average {os.getloadavg()[0]:.1f}; ms from just before the process started")
    columns = ("variant", *PHASES, "effect", "drops")
    print("| " + " | ".join(columns) + " |")
    print("|" + " --- |" * len(columns))
    for row in rows:
        print("| " + " | ".join(row[what] if what == "variant" else f"{row[what]:.0f}" for what in columns) + " |")
    for variant in dict.fromkeys(row["variant"] for row in rows):
        print(summary(variant, [row for row in rows if row["variant"] == variant]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
