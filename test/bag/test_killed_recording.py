"""The suite SIGKILLed while recording (issue 14, "Lost clients"): the bag is read up to its
last complete record, `mpi-ros replay` says it is truncated (no traceback) and replays what
it holds; restarted, the suite comes up with its configuration."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
from pathlib import Path

import yaml
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from mpi_ros.bag.reader import BagReader

WAIT = 20.0
CONFIG = """
supervisors:
  - {number: 0, axes: [0, 1]}
ros:
  namespace: /killed
  feedback_rate: 25.0
"""


# The suites run at twice real time: at 5x a suite on a slow 2-core machine fell behind its
# clock and its shutdown (SIGINT) then outlasted WAIT while it caught up.


def mpi_ros(*args: str) -> list[str]:
    return [sys.executable, "-P", "-m", "mpi_ros.cli", *args]


def wait_for_record(bag: Path, topic: str, process: subprocess.Popen) -> None:
    """Until a chunk holding a message of ``topic`` is on disk while ``process`` runs: the
    writer flushes whole compressed chunks, so the message is then safe from a SIGKILL."""
    pause = threading.Event()
    for _ in range(int(WAIT / 0.1)):
        assert process.poll() is None, process.stderr.read() if process.stderr else ""
        if (bag / "bag_0.mcap").is_file() and any(True for _ in BagReader(bag).decoded([topic])):
            return
        pause.wait(0.1)
    raise AssertionError(f"no {topic} message on disk in {bag} within {WAIT} s")


def test_a_killed_recording_replays_as_truncated_and_the_suite_restarts(tmp_path, ros_context):
    from mpi_ros.client import MotionClient
    from mpi_ros.msg import SuiteConfiguration

    config = tmp_path / "cell.yaml"
    config.write_text(CONFIG)
    bag = tmp_path / "bag"
    suite = subprocess.Popen(mpi_ros("run", "--config", str(config), "--time-scale", "2", "--record", str(bag)),
                             cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        with MotionClient(0, namespace="/killed", context=ros_context, timeout=WAIT) as ms0:
            assert ms0.wait_for_server(WAIT)
            assert ms0.move([20000.0, -5000.0], velocity=50000.0, acceleration=500000.0,
                            deceleration=500000.0).message == "MPIMessageOK"
        wait_for_record(bag, "/killed/commands", suite)  # its chunk is written; more may follow
    finally:
        suite.send_signal(signal.SIGKILL)
        suite.wait(timeout=WAIT)
    assert not (bag / "metadata.yaml").exists()  # written on a clean close only

    reader = BagReader(bag)
    assert "was not finished by its writer" in reader.truncated
    commands = [msg.operation for _, msg in reader.decoded(["/killed/commands"])]
    assert commands == ["motion_start"]  # everything up to the last complete record is there
    replayed = subprocess.run(mpi_ros("replay", str(bag)), capture_output=True, text=True, timeout=120)
    assert "Traceback" not in replayed.stderr
    assert "truncated bag" in replayed.stderr
    assert "read up to its last complete record" in replayed.stderr
    assert replayed.returncode == 0, replayed.stdout + replayed.stderr
    assert "zero differences" in replayed.stdout, replayed.stdout + replayed.stderr

    restarted = subprocess.Popen(mpi_ros("run", "--config", str(config), "--time-scale", "2"), cwd=tmp_path,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        with MotionClient(0, namespace="/killed", context=ros_context, timeout=WAIT) as ms0:
            assert ms0.wait_for_server(WAIT)
            got: list = []
            arrived = threading.Event()
            latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                                 durability=DurabilityPolicy.TRANSIENT_LOCAL)
            ms0.node.create_subscription(SuiteConfiguration, "/killed/configuration",
                                         lambda msg: (got.append(msg), arrived.set()), latched)
            assert arrived.wait(WAIT), "no configuration from the restarted suite"
            running = yaml.safe_load(got[0].config)
            assert running["ros"]["feedback_rate"] == 25.0
            assert got[0].ros_namespace == "/killed"
            assert ms0.move([0.0, 0.0], velocity=50000.0, acceleration=500000.0,
                            deceleration=500000.0).message == "MPIMessageOK"
    finally:
        restarted.send_signal(signal.SIGINT)
        _, err = restarted.communicate(timeout=WAIT)
    assert restarted.returncode == 0
    assert "Traceback" not in err
