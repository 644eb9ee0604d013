"""A cell on one graph (docs/cell.md): suites in their own namespaces neither collide nor
interleave; the namespace comes from the YAML, `mpi-ros run --namespace` or an __ns remap;
`mpi-ros run` keeps discovery on the host unless told otherwise."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs.msg import JointState

from mpi_ros import config
from mpi_ros.cli import run as run_cli
from mpi_ros.msg import Command as CommandMsg
from mpi_ros.msg import MotionEvent, MotionStatus

from .conftest import WAIT

PROCESS_WAIT = 20.0


def cell_config(namespace: str, clock: bool):
    return config.load(overrides={"ros": {"namespace": namespace, "clock": clock}})


@pytest.fixture
def cell(ros_context):
    """Two suites, /cell_a (the cell's clock) and /cell_b, in manual time."""
    from mpi_ros.ros.suite import Suite

    suites = [Suite(cell_config("/cell_a", True), time_scale=None, context=ros_context),
              Suite(cell_config("/cell_b", False), time_scale=None, context=ros_context)]
    for suite in suites:
        suite.start(spin_in_thread=True)
    try:
        yield suites
    finally:
        for suite in suites:
            suite.shutdown()


class Latest:
    """The messages of a topic, per condition."""

    def __init__(self, node, msg_type, topic: str):
        self.messages: list = []
        self._cond = threading.Condition()
        node.create_subscription(msg_type, topic, self._add, 10)

    def _add(self, msg) -> None:
        with self._cond:
            self.messages.append(msg)
            self._cond.notify_all()

    def wait(self, predicate, timeout: float = WAIT):
        with self._cond:
            assert self._cond.wait_for(lambda: any(predicate(m) for m in self.messages), timeout), (
                f"no such message in {len(self.messages)}")
            return next(m for m in self.messages if predicate(m))


def step_all(suites, done, limit: int = 400_000) -> None:
    pause = threading.Event()
    for _ in range(limit // 20):
        if done():
            return
        for suite in suites:
            suite.runner.step(20)
        pause.wait(0.0005)
    raise AssertionError("not done")


def test_two_namespaced_suites_share_a_graph_without_colliding(cell, probe, ros_context):
    from mpi_ros.client import MotionClient

    a, b = cell
    joints_a = Latest(probe, JointState, "/cell_a/joint_states")
    joints_b = Latest(probe, JointState, "/cell_b/joint_states")
    diagnostics = Latest(probe, DiagnosticArray, "/diagnostics")
    statuses = {ns: Latest(probe, MotionStatus, f"/{ns}/ms0/status") for ns in ("cell_a", "cell_b")}
    events = {ns: Latest(probe, MotionEvent, f"/{ns}/events") for ns in ("cell_a", "cell_b")}
    commands = {ns: Latest(probe, CommandMsg, f"/{ns}/commands") for ns in ("cell_a", "cell_b")}
    clients = [MotionClient(0, namespace=ns, context=ros_context, timeout=WAIT, node_name=f"cell_client_{ns[1:]}")
               for ns in ("/cell_a", "/cell_b")]
    try:
        for client in clients:
            assert client.wait_for_server(WAIT)
        goals = [client.move([1000.0 * (i + 1), 0.0], velocity=20000.0, acceleration=200000.0,
                              deceleration=200000.0, wait=False)
                 for i, client in enumerate(clients)]
        step_all(cell, lambda: all(goal.done for goal in goals))
        results = [goal.wait(WAIT) for goal in goals]
        assert [list(r.command_position) for r in results] == [[1000.0, 0.0], [2000.0, 0.0]]
        for suite in cell:  # the periodic topics go out once more after the moves
            suite.runner.step(int(suite.runner.ctl.rate))
        seen_a = joints_a.wait(lambda m: m.position[0] == a.runner.ctl.axes[0].actual_position)
        seen_b = joints_b.wait(lambda m: m.position[0] == b.runner.ctl.axes[0].actual_position)
        assert seen_a.name == [f"cell_a/axis{k}" for k in range(4)]
        assert seen_b.name == [f"cell_b/axis{k}" for k in range(4)]
        for ns in ("cell_a", "cell_b"):  # one shared /diagnostics, each suite's statuses named by its namespace
            array = diagnostics.wait(lambda m, ns=ns: bool(m.status) and m.status[0].name == f"{ns}/ms0")
            names = [s.name for s in array.status]
            assert all(name.startswith(f"{ns}/") for name in names)
            assert {f"{ns}/ms0", f"{ns}/ms1", *(f"{ns}/axis{k}" for k in range(4))} <= set(names)
        for ns in ("cell_a", "cell_b"):  # the headers name their sources in the suite's namespace
            status = statuses[ns].wait(lambda m: True)
            assert status.header.frame_id == f"{ns}/ms0"
            assert [a.header.frame_id for a in status.axes] == [f"{ns}/axis0", f"{ns}/axis1"]
            assert events[ns].wait(lambda m: m.type == "MOTION_DONE").header.frame_id == f"{ns}/ms0"
            settled = events[ns].wait(lambda m: m.type == "SETTLED")  # an axis' event: the axis
            assert settled.axis >= 0
            assert settled.header.frame_id == f"{ns}/axis{settled.axis}"
            assert commands[ns].wait(lambda m: m.operation == "motion_start").header.frame_id == f"{ns}/ms0"
        topics = dict(probe.get_topic_names_and_types())
        assert "/joint_states" not in topics  # the default topic is left to a suite in /mpi
        assert probe.count_publishers("/clock") == 1  # ros.clock: one clock source for the cell
        assert {"/cell_a/ms0/status", "/cell_b/ms0/status", "/cell_a/commands", "/cell_b/commands"} <= set(topics)
    finally:
        for client in clients:
            client.close()


def test_the_namespace_and_discovery_keys_are_validated():
    for bad in ("cell_a", "/", "/cell a", "/1cell", "/cell_a/", "/cell-a"):
        with pytest.raises(config.ConfigError, match=r"ros\.namespace"):
            cell_config(bad, True)
    assert config.load(overrides={"ros": {"namespace": "/plant/cell_a"}}).ros.joint_prefix == "plant/cell_a/"
    assert config.load().ros.joint_states_topic == "/joint_states"
    assert config.load().ros.joint_prefix == ""
    with pytest.raises(config.ConfigError, match=r"ros\.discovery: one of localhost, subnet"):
        config.load(overrides={"ros": {"discovery": "everywhere"}})
    with pytest.raises(config.ConfigError, match=r"ros\.clock: expected true or false"):
        config.load(overrides={"ros": {"clock": "yes"}})
    assert run_cli.DISCOVERY_RANGES == config.DISCOVERY_RANGES  # (kept apart so `mpi-ros --help` stays fast)


def test_run_keeps_discovery_on_the_host_unless_told(tmp_path):
    subnet = tmp_path / "subnet.yaml"
    subnet.write_text("ros:\n  discovery: subnet\n")
    assert run_cli.discovery_range(None, None, {}) == ("LOCALHOST", "ros.discovery")
    assert run_cli.discovery_range(None, str(subnet), {}) == ("SUBNET", "ros.discovery")
    told = {"ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"}
    assert run_cli.discovery_range(None, None, told) == ("SUBNET", "ROS_AUTOMATIC_DISCOVERY_RANGE")
    assert run_cli.discovery_range("localhost", str(subnet), told) == ("LOCALHOST", "--discovery")


@pytest.mark.parametrize("how", [["--namespace", "/cell_a"], ["--ros-args", "-r", "__ns:=/cell_a"]])
def test_mpi_ros_run_takes_the_namespace(how, ros_context, tmp_path):
    from mpi_ros.client import MotionClient

    exe = Path(sys.executable).with_name("mpi-ros")
    process = subprocess.Popen([str(exe), "run", "--time-scale", "5", *how], cwd=tmp_path,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        with MotionClient(0, namespace="/cell_a", context=ros_context, timeout=PROCESS_WAIT) as ms0:
            assert ms0.wait_for_server(PROCESS_WAIT), "the suite did not come up in /cell_a"
            result = ms0.move([500.0, 0.0], velocity=5000.0, acceleration=50000.0, deceleration=50000.0,
                              timeout=PROCESS_WAIT)
            assert result.message == "MPIMessageOK"
            configuration = ms0.node.get_topic_names_and_types()
            assert "/cell_a/joint_states" in dict(configuration)
            status = ms0.status(timeout=PROCESS_WAIT)  # the headers name the sources in the namespace in effect
            assert status.header.frame_id == "cell_a/ms0"
            assert [a.header.frame_id for a in status.axes] == ["cell_a/axis0", "cell_a/axis1"]
    finally:
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=PROCESS_WAIT)
    assert process.returncode == 0, err
    assert "namespace /cell_a, discovery LOCALHOST (ROS_AUTOMATIC_DISCOVERY_RANGE)" in err
