"""A cell on several hosts (docs/cell.md): two suites on "hosts" a and b and the commanding
client on c, each host a Linux network namespace linked to one switch, discovery as a plant
sets it (ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET, `mpi-ros run --discovery subnet`).

Shows: both suites discovered from c; moves on both at once, statuses and events of both in
order; a bag recorded on c replays exactly for each suite. Then the cut link: during a long
move on a, a's link goes down until the lost-client watchdog has stopped the move (its log
says so), and comes back: the client sees the true state (STOPPED, not a stale MOVING), the
long goal's result (it ended meanwhile), the CLIENT_LOST command among what a applied; new
goals work on both; a's own recording (with the CLIENT_LOST event) replays exactly.

Needs network namespaces (root here); skipped with the machine's own reason where refused.
Run it alone: `sudo -E .venv/bin/python -m pytest test/ros/test_cell_netns.py` (README).
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import pytest

from mpi_ros.bag.reader import BagReader
from mpi_ros.bag.replay import replay

from . import netns

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
DRIVER = HERE / "cell_driver.py"
RECORDER = HERE.parent / "bag" / "graph_recorder.py"
LEASE_PROFILE = REPO / "config" / "fastdds_short_lease.xml"
WAIT = 30.0
WATCHDOG = 1.0  # s: lost_client_timeout of a's ms0
REFUSED = netns.refused()
pytestmark = pytest.mark.skipif(REFUSED is not None, reason=REFUSED or "")


def suite_yaml(path: Path, namespace: str, clock: bool) -> Path:
    path.write_text(f"""
supervisors:
  - {{number: 0, axes: [0, 1], lost_client_timeout: {WATCHDOG}}}
  - {{number: 1, axes: [2, 3]}}
ros:
  namespace: {namespace}
  clock: {str(clock).lower()}
""")
    return path


def plant_env() -> dict:
    # every process: the test's domain, subnet discovery, a 2 s DDS lease (a cut is noticed
    # in 2 s, not Fast DDS's default 20 s), this source tree
    return dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="SUBNET", FASTRTPS_DEFAULT_PROFILES_FILE=str(LEASE_PROFILE),
                PYTHONPATH=os.pathsep.join(filter(None, (str(REPO), os.environ.get("PYTHONPATH")))))


def mpi_ros(*args: str) -> list[str]:
    return [sys.executable, "-P", "-m", "mpi_ros.cli", *args]


def test_a_cell_on_three_hosts_survives_a_cut_link(tmp_path):
    env = plant_env()
    with netns.Plant(["a", "b", "c"]) as plant:
        suites = {
            "a": plant.popen("a", mpi_ros("run", "--config", str(suite_yaml(tmp_path / "a.yaml", "/cell_a", True)),
                                          "--discovery", "subnet", "--record", str(tmp_path / "a_bag")),
                             env, tmp_path / "a.log"),
            "b": plant.popen("b", mpi_ros("run", "--config", str(suite_yaml(tmp_path / "b.yaml", "/cell_b", False)),
                                          "--discovery", "subnet"), env, tmp_path / "b.log"),
        }
        recorder = plant.popen("c", [sys.executable, "-P", str(RECORDER), str(tmp_path / "cell.mcap")], env,
                               tmp_path / "recorder.log")
        recorder.expect_all({f"subscribed /{ns}/{topic} {kind}" for ns in ("cell_a", "cell_b") for topic, kind in (
            ("configuration", "mpi_ros/msg/SuiteConfiguration"), ("commands", "mpi_ros/msg/Command"),
            ("events", "mpi_ros/msg/MotionEvent"), ("ms0/status", "mpi_ros/msg/MotionStatus"))}, WAIT)
        driver = plant.popen("c", [sys.executable, "-P", str(DRIVER), "cell", "/cell_a", "/cell_b"], env,
                             tmp_path / "driver.log")

        def report(key: str) -> dict:
            return json.loads(driver.expect(lambda line: key in json.loads(line), WAIT))

        assert report("discovered")["discovered"] == "/cell_a"
        assert report("discovered")["discovered"] == "/cell_b"
        both = report("phase1")["phase1"]
        for ns in ("/cell_a", "/cell_b"):
            assert both[ns]["message"] == "MPIMessageOK"
            assert both[ns]["position"] == [5000.0, -2500.0]
            assert both[ns]["statuses"] > 0
            assert both[ns]["statuses_in_order"]
            assert both[ns]["events_in_order"]
            assert "MOTION_DONE" in both[ns]["events"]
        assert recorder.interrupt(WAIT) == 0
        assert "recorded" in recorder.expect(lambda line: line.startswith("recorded "), WAIT)
        for ns in ("/cell_a", "/cell_b"):  # the client host's recording of the graph, one suite at a time
            replayed = replay(tmp_path / "cell.mcap", namespace=ns)
            assert replayed.identical, replayed.summary()
            assert replayed.commands >= 1, replayed.summary()
            assert replayed.statuses > 0, replayed.summary()

        driver.send("go")
        assert report("long")["long"]["sample"] > 0
        plant.link("a", up=False)
        try:  # a no longer sees its client: after the DDS lease (2 s) and lost_client_timeout, STOP
            suites["a"].wait_in_log("lost-client watchdog", 2.0 + WATCHDOG + WAIT)
        finally:
            plant.link("a", up=True)
        driver.send("up")
        after = report("after")["after"]
        assert after["fresh_state"] == "STOPPED"
        assert after["fresh_sample"] > after["stale_sample"]
        assert (after["result"], after["result_state"]) == ("MPIMotionMessageSTOPPED", "STOPPED")
        assert after["asked_again"] >= 1  # the result was sent while the link was down: asked again
        assert "client_lost" in after["commands"]
        assert (after["new_goal"], after["new_goal_position"], after["other_suite"]) == (
            "MPIMessageOK", [0.0, 0.0], "MPIMessageOK")
        for host, suite in suites.items():
            assert suite.interrupt(WAIT) == 0, suite.stderr()
            assert "Traceback" not in suite.stderr(), host
    events = [msg.type for _, msg in BagReader(tmp_path / "a_bag").decoded(["/cell_a/events"])]
    assert "CLIENT_LOST" in events
    assert events[events.index("CLIENT_LOST") + 1] == "STOP"
    own = replay(tmp_path / "a_bag")
    assert own.identical, own.summary()
