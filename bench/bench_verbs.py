"""One-shot verbs from invocation to effect (issue 36): how long after an operator presses
Enter on `mpi-ros e-stop` does the E_STOP take effect?

Per run: the time is read just before the verb's process is started (``python -P -m
mpi_ros.cli VERB``, what the installed ``mpi-ros`` script runs); the effect is the sample at
which the controller applied the command, as the suite publishes it on ``/mpi/commands``
(``stamp = epoch + sample / rate``, controller time anchored to the wall clock; the suite
runs in real time). Also given: when that message reached this process, and when the verb's
process had ended (it printed the answer), and the CPU time the process used (what it
costs whatever the load: on a machine whose cores are taken by others, wall time is
several times that).

Each run is a cycle on ms0: ``move --no-wait`` (a 200-count S-curve), ``e-stop``, ``reset``.
The suite of each source tree (this one and ``--baseline``, extracted with git archive) runs
in turn, each with its own verbs; the trees alternate ``--rounds`` times, since the machine
is shared and its load changes by the minute (the load average is printed with the figures).

With ``--third``, ``mpi-ros events`` of the same tree runs beside each suite: one more DDS
participant on the graph (this process is one already), as on any real ROS graph; it was
what brought out the slow runs (docs/reliability.md).

With ``--defaults``, every cycle runs twice in a row against the same suite: with the verbs'
own Fast DDS profile (config/fastdds_client.xml) and with a profile file that leaves Fast DDS
at its defaults (the verbs before it), under the same load.

    python -P bench/bench_verbs.py [--runs 8] [--rounds 2] [--baseline REV|none] [--third] [--defaults]
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import os
import random
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))  # run with -P: the sibling bench_controller
from bench_controller import compared_trees  # noqa: E402 - after the path it is found on

os.environ.setdefault("ROS_DOMAIN_ID", str(random.Random(os.getpid()).randint(150, 200)))
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
BASELINE = "e99f630"  # before issue 36
SUITE_UP = 60.0  # s the suite may take to come up on a busy machine
EFFECT_WAIT = 10.0  # s a verb's command may take to show on /mpi/commands
CYCLE = (("move", ["move", "--no-wait", "--position", "200", "0", "--velocity", "2000", "--acceleration",
                   "20000", "--deceleration", "20000", "--jerk-percent", "50"], "motion_start", ""),
         ("e-stop", ["e-stop"], "action", "E_STOP"),
         ("reset", ["reset"], "action", "RESET"))


# A profile file with no settings: Fast DDS's defaults (208 KiB UDP receive buffers here), as
# the verbs ran before config/fastdds_client.xml; a file named by the environment wins over it.
DEFAULTS_PROFILE = ('<?xml version="1.0"?><profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">'
                    '<participant profile_name="fast_dds_defaults" is_default_profile="true"><rtps/></participant>'
                    '</profiles>')
DEFAULTS = "Fast DDS defaults"  # the name of the verbs run with DEFAULTS_PROFILE


@dataclass(frozen=True)
class Run:
    verb: str
    effect: float  # s from the process' start to the stamp of the sample the command took effect at
    arrival: float  # s from the process' start to /mpi/commands reaching this process
    exited: float  # s from the process' start to its end
    status: int
    cpu: float  # s of CPU the process used (user + system), whatever the machine's load


class Commands:
    """/mpi/commands as it arrives: (arrival time, stamp in s, operation, request)."""

    def __init__(self) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node
        from rclpy.qos import QoSProfile, ReliabilityPolicy

        from mpi_ros.msg import Command

        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = Node("bench_verbs", context=self.context)
        self.seen: list[tuple[float, float, str, str]] = []
        self.arrived = threading.Condition()
        self.node.create_subscription(Command, "/mpi/commands", self._on_command,
                                      QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE))
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self.executor.spin, daemon=True)
        self.thread.start()

    def _on_command(self, msg: Any) -> None:
        with self.arrived:
            stamp = msg.header.stamp if hasattr(msg, "header") else msg.stamp  # (a baseline from before the headers)
            self.seen.append((time.time(), stamp.sec + stamp.nanosec * 1e-9, msg.operation, msg.request))
            self.arrived.notify_all()

    def wait_for(self, after: int, operation: str, word: str) -> tuple[float, float] | None:
        """(arrival, stamp) of the first command after index ``after`` of ``operation`` naming ``word``."""
        def found() -> tuple[float, float] | None:
            return next(((arrival, stamp) for arrival, stamp, op, request in self.seen[after:]
                         if op == operation and word in request), None)

        with self.arrived:
            self.arrived.wait_for(lambda: found() is not None, EFFECT_WAIT)
            return found()

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=2.0)
        self.node.destroy_node()
        self.context.try_shutdown()


def start_suite(tree: Path) -> subprocess.Popen:
    suite = subprocess.Popen([sys.executable, "-P", "-m", "mpi_ros.cli", "run"], cwd=tree, env=_env(tree),
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    up = threading.Event()

    def read() -> None:
        for line in suite.stdout:  # type: ignore[union-attr]
            if "suite up" in line:
                up.set()

    threading.Thread(target=read, daemon=True).start()
    if not up.wait(SUITE_UP):
        suite.kill()
        raise RuntimeError(f"the suite of {tree} did not come up within {SUITE_UP:g} s")
    return suite


def _env(tree: Path) -> dict[str, str]:
    return dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (str(tree), os.environ.get("PYTHONPATH", "")) if p))


def one(tree: Path, commands: Commands, verb: str, argv: list[str], operation: str, word: str,
        profile: str | None = None) -> Run:
    after = len(commands.seen)
    start = time.time()
    verb_process = subprocess.Popen([sys.executable, "-P", "-m", "mpi_ros.cli", *argv, "--timeout", "10"], cwd=tree,
                                    env=_env(tree) | ({"FASTRTPS_DEFAULT_PROFILES_FILE": profile} if profile else {}),
                                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, wait_status, usage = os.wait4(verb_process.pid, 0)  # its CPU time too
    exited = time.time() - start
    status = os.waitstatus_to_exitcode(wait_status)
    verb_process.returncode = status
    errors = verb_process.stderr.read().decode() if verb_process.stderr else ""
    effect = commands.wait_for(after, operation, word)
    if effect is None:
        raise RuntimeError(f"{verb}: no command on /mpi/commands (exit {status}: {errors.strip()})")
    return Run(verb, effect[1] - start, effect[0] - start, exited, status, usage.ru_utime + usage.ru_stime)


@contextlib.contextmanager
def graph(tree: Path, third: bool) -> Iterator[Commands]:
    """A suite of ``tree`` and this process' /mpi/commands (with ``third``, `mpi-ros events` of
    the tree beside them), taken down on leaving."""
    suite = start_suite(tree)
    commands = Commands()
    events = subprocess.Popen([sys.executable, "-P", "-m", "mpi_ros.cli", "events"], cwd=tree, env=_env(tree),
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) if third else None
    try:
        yield commands
    finally:
        if events is not None:
            events.terminate()
            events.wait(timeout=10)
        commands.close()
        suite.terminate()
        suite.wait(timeout=30)


def measure(tree: Path, runs: int, third: bool = False, defaults: str | None = None) -> list[Run]:
    """``runs`` cycles against a suite of ``tree``; with ``defaults`` (a profile file's path),
    each cycle again with the verbs under it, their runs named DEFAULTS."""
    profiles = [None] if defaults is None else [None, defaults]
    with graph(tree, third) as commands:
        one(tree, commands, *CYCLE[2])  # a first RESET: the suite and this process (and events) have met
        return [_named(one(tree, commands, *step, profile=profile), profile)
                for _ in range(runs) for profile in profiles for step in CYCLE]


def _named(run: Run, profile: str | None) -> Run:
    return run if profile is None else dataclasses.replace(run, verb=f"{run.verb} ({DEFAULTS})")


def table(results: dict[str, list[Run]]) -> list[str]:
    lines = ["| tree | verb | runs | effect median | effect max | command received median | command received max | "
             "process ended median | CPU of the process median |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for tree, runs in results.items():
        for verb in dict.fromkeys(run.verb for run in runs):
            mine = [run for run in runs if run.verb == verb]
            failed = sum(run.status not in (0, 1) for run in mine)
            effect = [run.effect for run in mine]
            lines.append(f"| {tree} | {verb} | {len(mine)}{f' ({failed} failed)' if failed else ''} | "
                         f"{statistics.median(effect):.2f} s | {max(effect):.2f} s | "
                         f"{statistics.median(run.arrival for run in mine):.2f} s | "
                         f"{max(run.arrival for run in mine):.2f} s | "
                         f"{statistics.median(run.exited for run in mine):.2f} s | "
                         f"{statistics.median(run.cpu for run in mine):.2f} s |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=8, help="cycles per round and tree (default 8)")
    parser.add_argument("--rounds", type=int, default=2, help="rounds, the trees alternating (default 2)")
    parser.add_argument("--baseline", default=BASELINE, help=f"revision to compare with (default {BASELINE}), or none")
    parser.add_argument("--third", action="store_true", help="run `mpi-ros events` beside each suite")
    parser.add_argument("--defaults", action="store_true",
                        help="run each cycle again with the verbs at Fast DDS's default profile (the verbs before)")
    args = parser.parse_args()
    results: dict[str, list[Run]] = {}
    with tempfile.TemporaryDirectory(prefix="bench_verbs_") as scratch:
        defaults = Path(scratch) / "fast_dds_defaults.xml"
        defaults.write_text(DEFAULTS_PROFILE)
        trees = compared_trees(args.baseline, Path(scratch))
        loads = [os.getloadavg()[0]]
        for _ in range(args.rounds):
            for tree, name in trees:
                results.setdefault(name, []).extend(
                    measure(tree, args.runs, args.third, str(defaults) if args.defaults else None))
                loads.append(os.getloadavg()[0])
    print(f"ROS_DOMAIN_ID {os.environ['ROS_DOMAIN_ID']}, {os.cpu_count()} cores, 1-minute load average "
          f"{min(loads):.1f} to {max(loads):.1f} during the runs, `mpi-ros events` beside the suite: "
          f"{'yes' if args.third else 'no'}")
    print()
    print("\n".join(table(results)))
    for tree, runs in results.items():  # every run, so that a slow one shows as one or as a tail
        for verb in dict.fromkeys(run.verb for run in runs):
            mine = [run for run in runs if run.verb == verb]
            print(f"{tree}, {verb}, effect: " + " ".join(f"{run.effect:.2f}" for run in mine))
            print(f"{tree}, {verb}, command received: " + " ".join(f"{run.arrival:.2f}" for run in mine))


if __name__ == "__main__":
    main()
