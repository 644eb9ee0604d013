"""A real suite (`mpi-ros run` in its own process) for the operator-console tests, and
helpers to run `mpi-ros` verbs against it as a user does: a process per command, its
output and exit status.

The suite runs on this test run's ROS_DOMAIN_ID (test/conftest.py), under /mpi, scaled
(TIME_SCALE) so moves take a fraction of a second. Waits are on process output, futures
and statuses with timeouts, never fixed sleeps.
"""

from __future__ import annotations

import os
import queue
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest

WAIT = 20.0  # s: the most any command, answer or status may take before a test fails
TIME_SCALE = 2.0  # the suite keeps up on a busy 2-core machine (about 20 % of a core)
REPO = Path(__file__).resolve().parents[2]


def _default_sigint() -> None:
    # A process started from a shell's background job inherits an ignored SIGINT; the
    # tests that press Ctrl-C need Python's handler in the child.
    signal.signal(signal.SIGINT, signal.SIG_DFL)


# The verbs that look for the suite on the graph (--timeout, default 5 s). The tests give
# them longer: on a busy machine DDS discovery can take seconds, and a verb that finds the
# suite goes on at once, so only a test that fails waits the whole time.
CONSOLE_VERBS = {"move", "modify", "stop", "e-stop", "abort", "reset", "resume", "fault", "status", "events", "echo"}


def with_timeout(argv: tuple[str, ...] | list[str]) -> list[str]:
    """``argv`` with ``--timeout WAIT`` for a console verb that was given none."""
    argv = list(argv)
    if argv and argv[0] in CONSOLE_VERBS and "--timeout" not in argv:
        argv[1:1] = ["--timeout", str(WAIT)]  # before any --ros-args, which run to the end
    return argv


def command(*argv: str) -> list[str]:
    """The `mpi-ros` command line, run from this source tree."""
    return [sys.executable, "-m", "mpi_ros.cli", *with_timeout(argv)]


def console(*argv: str) -> int:
    """`mpi-ros ARGV` in this process (``main(argv)``, faster than a process); its exit status."""
    from mpi_ros.cli import main

    return main(with_timeout(argv))


def mpi_ros(*argv: str, timeout: float = WAIT) -> subprocess.CompletedProcess:
    """Run `mpi-ros ARGV` to its end; its stdout, stderr and exit status."""
    return subprocess.run(command(*argv), check=False, capture_output=True, text=True, timeout=timeout, cwd=REPO,
                          env=dict(os.environ), stdin=subprocess.DEVNULL)


class Running:
    """`mpi-ros ARGV` running in the background; its output lines as they come."""

    def __init__(self, *argv: str, cwd: Path = REPO):
        self.process = subprocess.Popen(command(*argv), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        stdin=subprocess.DEVNULL, text=True, cwd=cwd, env=dict(os.environ),
                                        preexec_fn=_default_sigint)
        self.stdout: queue.Queue = queue.Queue()
        self.stderr: queue.Queue = queue.Queue()
        self.out_lines: list[str] = []
        self.err_lines: list[str] = []
        self._readers = [threading.Thread(target=self._read, args=(stream, lines, store), daemon=True)
                         for stream, lines, store in ((self.process.stdout, self.stdout, self.out_lines),
                                                      (self.process.stderr, self.stderr, self.err_lines))]
        for reader in self._readers:
            reader.start()

    @staticmethod
    def _read(stream, lines: queue.Queue, store: list[str]) -> None:
        try:
            for line in stream:
                store.append(line)
                lines.put(line)
        except (OSError, ValueError):
            pass  # the test closed the pipe (a reader that leaves)
        lines.put(None)  # end of the stream

    def expect(self, text: str, stream: str = "stdout", timeout: float = WAIT) -> str:
        """The first (next) line of ``stream`` that contains ``text``; fails on timeout or end."""
        lines: queue.Queue = getattr(self, stream)
        while True:
            try:
                line = lines.get(timeout=timeout)
            except queue.Empty:
                pytest.fail(f"no line with {text!r} on {stream} within {timeout:g} s")
            if line is None:
                pytest.fail(f"{stream} ended without a line with {text!r}; stderr: {''.join(self.err_lines)}")
            if text in line:
                return line

    def finish(self, timeout: float = WAIT) -> tuple[int, str, str]:
        """Wait for the end; (exit status, whole stdout, whole stderr)."""
        self.process.wait(timeout)
        for reader in self._readers:
            reader.join(timeout)
        return self.process.returncode, "".join(self.out_lines), "".join(self.err_lines)

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait(WAIT)


@pytest.fixture
def running():
    """``running(*argv)``: start `mpi-ros ARGV` in the background (killed after the test if still running)."""
    started: list[Running] = []

    def start(*argv: str, **kwargs) -> Running:
        started.append(Running(*argv, **kwargs))
        return started[-1]

    yield start
    for process in started:
        process.kill()


@pytest.fixture(scope="module")
def suite_process():
    """`mpi-ros run --time-scale 2` for the whole module, up (ms0 answering) before the first test."""
    process = Running("run", "--time-scale", str(TIME_SCALE))
    try:
        yield process
    finally:
        if process.process.poll() is None:
            process.process.send_signal(signal.SIGINT)
            try:
                process.process.wait(WAIT)
            except subprocess.TimeoutExpired:
                process.kill()


@pytest.fixture(scope="module")
def clients(suite_process, module_context):
    """The test's own MotionClients of ms0 and ms1 (to set up and check what the verbs do)."""
    from mpi_ros.client import MotionClient

    made = {n: MotionClient(n, context=module_context, timeout=WAIT, node_name=f"console_test_ms{n}")
            for n in (0, 1)}
    try:
        for client in made.values():
            client.wait_for_suite(WAIT, client.supervisor)
            assert client.wait_for_server(WAIT), "the suite did not come up"
        yield made
    finally:
        for client in made.values():
            client.close()


def make_idle(client) -> None:
    """Bring a supervisor to IDLE from whatever state a test left it in."""
    status = client.status(WAIT)
    if status.state_name in ("MOVING", "STOPPING"):
        client.action("STOP", raise_on_error=False)
        status = client.wait_for(lambda s: s.state_name in ("STOPPED", "ERROR", "IDLE"), WAIT, "at rest")
    if status.state_name == "STOPPING_ERROR":
        status = client.wait_for_state("ERROR", WAIT)
    if status.state_name != "IDLE":
        reply = client.reset()
        client.wait_for_state("IDLE", WAIT, newer_than=reply.sample)


@pytest.fixture
def ms0(clients):
    """ms0's client, the supervisor IDLE before and after the test."""
    make_idle(clients[0])
    yield clients[0]
    make_idle(clients[0])


@pytest.fixture
def ms1(clients):
    make_idle(clients[1])
    yield clients[1]
    make_idle(clients[1])
