"""Random interleavings from several client processes on shared axes (issue 14, "Random
interleavings"): `mpi-ros run` in its own process with three supervisors, two of them sharing
an axis; three client processes (interleaver.py), each with its own seed, send starts,
modifies, STOP, E_STOP, ABORT, E_STOP_ABORT, RESET, RESUME and cancels to all three at once.

Checked: every status shows one of the reference's six states (MPI 000, MPIState) and never a
supervisor at IDLE while one of its axes is commanded to move; status samples come in order;
every goal ends with a result and every answer is one of the reference's messages; nothing
raises in a client or in the suite's log; afterwards the suite still moves and exits cleanly
on Ctrl-C.

The normal suite runs the clients for INTERLEAVE_SECONDS (20 s); for minutes:
    MPI_ROS_INTERLEAVE_SECONDS=300 scripts/test.sh test/ros/test_interleavings.py
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
from collections import Counter
from pathlib import Path

import pytest

WAIT = 30.0
SECONDS = float(os.environ.get("MPI_ROS_INTERLEAVE_SECONDS", "20"))
SEEDS = (1401, 1402, 1403)
STATES = {"IDLE", "MOVING", "STOPPING", "STOPPED", "STOPPING_ERROR", "ERROR"}
CONFIG = """\
axes:
  count: 4
supervisors:
  - number: 0
    axes: [0, 1]
  - number: 1
    axes: [1, 2]
  - number: 2
    axes: [3]
"""
SUPERVISORS = {0: 2, 1: 2, 2: 1}  # number -> axis count


@pytest.fixture
def shared_suite(tmp_path):
    config = tmp_path / "shared.yaml"
    config.write_text(CONFIG)
    exe = Path(sys.executable).with_name("mpi-ros")
    log = (tmp_path / "suite.log").open("w+")
    process = subprocess.Popen([str(exe), "run", "--config", str(config), "--time-scale", "1"], cwd=tmp_path,
                               stdout=log, stderr=subprocess.STDOUT, text=True)
    try:
        yield process, log
    finally:
        if process.poll() is None:
            process.kill()
            process.wait(timeout=10)
        log.close()


class StatusCheck:
    """Every MotionStatus of the supervisors: states seen, samples in order, and the
    statuses that broke a rule (at most a few kept, with the count)."""

    def __init__(self, node):
        from mpi_ros.graph_names import STATUS_QOS
        from mpi_ros.msg import MotionStatus
        from mpi_ros.qos import profile

        self.states: Counter = Counter()
        self.broken: list[str] = []
        self.count = 0
        self._last: dict[int, int] = {}
        self._lock = threading.Lock()
        for n in SUPERVISORS:
            node.create_subscription(MotionStatus, f"/mpi/ms{n}/status", self._check, profile(STATUS_QOS))

    def _check(self, msg) -> None:
        with self._lock:
            self.count += 1
            self.states[msg.state_name] += 1
            problems = []
            if msg.state_name not in STATES:
                problems.append(f"state {msg.state_name!r}")
            if msg.sample <= self._last.get(msg.number, -1):
                problems.append(f"sample {msg.sample} after {self._last[msg.number]}")
            self._last[msg.number] = msg.sample
            moving = [a.number for a in msg.axes if a.command_velocity != 0.0]
            if msg.state_name == "IDLE" and moving:
                problems.append(f"IDLE while axes {moving} are commanded to move")
            if problems and len(self.broken) < 20:
                self.broken.append(f"ms{msg.number} sample {msg.sample}: {'; '.join(problems)}")


def _clients(tmp_path) -> list[tuple[subprocess.Popen, Path]]:
    script = Path(__file__).with_name("interleaver.py")
    started = []
    for seed in SEEDS:
        out = tmp_path / f"client-{seed}.json"
        command = [sys.executable, "-P", str(script), "--seed", str(seed), "--seconds", str(SECONDS),
                   "--supervisors", *map(str, SUPERVISORS), "--axes", *map(str, SUPERVISORS.values()),
                   "--out", str(out)]
        started.append((subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True), out))
    return started


def test_random_interleavings_from_several_clients_on_shared_axes(shared_suite, probe, tmp_path):
    from mpi_ros.client import MotionClient
    from mpi_ros.mpi.base.messages import Message

    process, log = shared_suite
    with MotionClient(0, context=probe.context, timeout=WAIT, node_name="interleavings_check") as ms0:
        assert ms0.wait_for_server(WAIT), "the suite did not come up"
        check = StatusCheck(probe)
        summaries = []
        for client, out in _clients(tmp_path):
            output, _ = client.communicate(timeout=SECONDS + 240)
            assert client.returncode == 0, output
            summaries.append(json.loads(out.read_text()))

        known = {m.name for m in Message}
        for summary in summaries:
            assert not summary["errors"], summary["errors"]
            assert not summary["missing"], f"goals without a result: {summary['missing'][:10]}"
            assert summary["results"] == summary["goals"] > 20, summary
            assert set(summary["messages"]) <= known, summary["messages"]
            assert set(summary["states"]) <= STATES, summary["states"]
        outcomes = sum((Counter(s["outcomes"]) for s in summaries), Counter())
        print("interleavings:", {k: sum(s[k] for s in summaries) for k in ("requests", "goals", "actions", "cancels")},
              dict(outcomes), dict(sum((Counter(s["messages"]) for s in summaries), Counter())), dict(check.states))
        # the seeds reach every way a goal can end
        assert all(outcomes[o] > 0 for o in ("DONE", "REFUSED", "ENDED", "CANCELED")), outcomes
        assert not check.broken, check.broken
        assert check.count > 100, check.states
        assert set(check.states) >= {"IDLE", "MOVING", "ERROR"}, check.states

        # the suite still moves
        for n in SUPERVISORS:
            with MotionClient(n, context=probe.context, timeout=WAIT, node_name=f"interleavings_after_{n}") as ms:
                assert ms.wait_for_server(WAIT)
                ms.reset()
        result = ms0.move([100.0, -100.0], velocity=5000.0, acceleration=50000.0, deceleration=50000.0, timeout=WAIT)
        assert (result.message, result.state_name) == ("MPIMessageOK", "IDLE")

    process.send_signal(signal.SIGINT)
    assert process.wait(timeout=WAIT) == 0
    log.seek(0)
    text = log.read()
    for sign in ("Traceback", "internal error", "Exception"):
        assert sign not in text, text[-3000:]
