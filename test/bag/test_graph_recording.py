"""A bag recorded from the graph by any recorder replays exactly with `mpi-ros replay`.

The suite publishes every applied command (/mpi/commands, with the sample at which it took
effect) and its configuration (/mpi/configuration, latched): that is all replay needs beside
the statuses. Here a separate process that knows nothing of mpi_ros (graph_recorder.py:
subscribes to every topic it finds, as `ros2 bag record -a` does, and writes its own MCAP)
records a live run; a second one joins late, after the first moves, and still gets the
configuration and the commands given before it started (both are transient local).
"""

from __future__ import annotations

import queue
import signal
import subprocess
import sys
import threading
from pathlib import Path

from mpi_ros.bag.reader import BagReader
from mpi_ros.bag.replay import replay

RECORDER = Path(__file__).resolve().parent / "graph_recorder.py"
WAIT = 20.0
SUITE_TOPICS = {"/mpi/commands", "/mpi/configuration", "/mpi/events", "/mpi/ms0/status", "/mpi/ms1/status",
                "/mpi/axis0/status", "/mpi/axis1/status", "/mpi/axis2/status", "/mpi/axis3/status",
                "/joint_states", "/diagnostics", "/clock"}
S_CURVE = {"velocity": 3000.0, "acceleration": 30000.0, "deceleration": 30000.0, "jerk_percent": 50.0}


class RecorderProcess:
    """graph_recorder.py in its own process; ``listening()`` waits until it subscribed to ``topics``."""

    def __init__(self, output: Path):
        self.output = output
        self.process = subprocess.Popen([sys.executable, "-P", str(RECORDER), str(output)],
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.lines: queue.Queue = queue.Queue()
        self.subscribed: set[str] = set()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        for line in self.process.stdout:
            self.lines.put(line.strip())
        self.lines.put(None)

    def listening(self, topics: set[str], timeout: float = WAIT) -> None:
        while not topics <= self.subscribed:
            try:
                line = self.lines.get(timeout=timeout)
            except queue.Empty:
                raise AssertionError(f"recorder did not subscribe to {sorted(topics - self.subscribed)}") from None
            assert line is not None, f"recorder ended: {self.process.stderr.read()}"
            if line.startswith("subscribed "):
                self.subscribed.add(line.split()[1])

    def stop(self) -> str:
        self.process.send_signal(signal.SIGINT)
        self.process.wait(timeout=60)
        err = self.process.stderr.read()
        assert self.process.returncode == 0, err
        rest = []
        while (line := self.lines.get(timeout=10)) is not None:
            rest.append(line)
        return "\n".join(rest)

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait(timeout=10)


def _visible_publishers(suite):
    return [pub for node in suite.nodes for pub in node.publishers
            if not any(part.startswith("_") for part in pub.topic_name.split("/"))]


def _wait_matched(suite, recorders: int) -> None:
    """Every (visible) publisher of the suite has the recorders as subscribers."""
    import time

    deadline = time.monotonic() + WAIT
    pause = threading.Event()
    while True:
        short = [p.topic_name for p in _visible_publishers(suite) if p.get_subscription_count() < recorders]
        if not short:
            return
        assert time.monotonic() < deadline, f"recorders not matched on {short}"
        pause.wait(0.02)


def _run(suite, at: int, operation: str, request: dict) -> None:
    """Step the (manual) suite to sample ``at`` in chunks, then give it a command."""
    from mpi_ros.commands import Command

    runner = suite.runner
    while runner.ctl.sample < at:
        runner.step(min(200, at - runner.ctl.sample))
    reply, _ = runner.submit(Command(operation, 0, request=request))
    assert reply.message.name == "MPIMessageOK", (operation, request, reply)


def test_a_bag_recorded_by_a_separate_generic_recorder_replays_exactly(tmp_path, ros_context):
    from rclpy.duration import Duration

    from mpi_ros import config
    from mpi_ros.ros.suite import Suite

    early, late = RecorderProcess(tmp_path / "early.mcap"), None
    # manual time: the controller advances only when the test steps it (deterministic on a
    # loaded machine); commands go in as the nodes give them (runner.submit)
    suite = Suite(config.load(), time_scale=None, context=ros_context)
    try:
        suite.start()
        early.listening(SUITE_TOPICS)
        _wait_matched(suite, 1)
        _run(suite, 10, "motion_start", {"type": "S_CURVE", "position": [2000.0, 500.0], "trajectory": [S_CURVE]})
        _run(suite, 3000, "motion_start", {"type": "TRAPEZOIDAL", "position": [-3000.0, 0.0],
                                           "trajectory": [{"velocity": 3000.0, "acceleration": 12000.0,
                                                                           "deceleration": 12000.0}]})
        # a recorder that joins now gets the configuration and the commands given before it
        late = RecorderProcess(tmp_path / "late.mcap")
        late.listening(SUITE_TOPICS)
        _wait_matched(suite, 2)
        _run(suite, 3600, "action", {"action": "STOP"})
        _run(suite, 5000, "action", {"action": "RESUME"})
        _run(suite, 5600, "action", {"action": "E_STOP"})
        _run(suite, 6000, "action", {"action": "RESET"})
        _run(suite, 6010, "motion_start", {"type": "S_CURVE", "position": [0.0, 0.0], "trajectory": [S_CURVE]})
        suite.runner.step(6000)  # to rest, settled
        for pub in _visible_publishers(suite):  # everything published has reached both recorders
            if pub.qos_profile.reliability.name == "RELIABLE":
                assert pub.wait_for_all_acked(Duration(seconds=WAIT)), pub.topic_name
        events = suite.runner.read(lambda ctl: len(ctl.events))
        early_out, late_out = early.stop(), late.stop()
    finally:
        early.kill()
        if late is not None:
            late.kill()
        suite.shutdown()
    assert "recorded" in early_out
    assert "recorded" in late_out

    bag = BagReader(tmp_path / "early.mcap")
    assert bag.metadata("mpi_ros") is None  # no help from mpi-ros record: the graph only
    assert set(bag.topics()) >= SUITE_TOPICS
    report = replay(tmp_path / "early.mcap")
    assert report.identical, report.summary()
    assert report.commands == 7
    assert report.statuses > 1000
    assert report.events == events > 10

    # the late recorder missed the first moves' statuses and events, not their commands
    late_bag = BagReader(tmp_path / "late.mcap")
    late_report = replay(tmp_path / "late.mcap")
    assert late_report.identical, late_report.summary()
    assert late_report.commands == 7
    assert 0 < late_report.events < report.events
    first_status = min(msg.sample for _, msg in late_bag.decoded(["/mpi/ms0/status"]))
    assert first_status > 3000
