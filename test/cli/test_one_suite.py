"""One suite per namespace (docs/cell.md; mpi_ros/ros/twin.py): a second `mpi-ros run` under
a namespace whose suite is on the graph refuses to start, says where the other one runs and
exits 2; a suite in another namespace starts; the console warns about node names seen twice."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

from .conftest import WAIT


def test_a_second_suite_in_the_namespace_is_refused_and_another_namespace_starts(running):
    first = running("run", "--time-scale", "2")
    first.expect("suite up", "stderr")
    second = running("run", "--time-scale", "2")
    code, _, err = second.finish(WAIT + 10.0)
    assert code == 2, err
    domain = os.environ["ROS_DOMAIN_ID"]
    assert f"mpi-ros run: a suite already runs under /mpi on ROS_DOMAIN_ID {domain}: its node /mpi/controller " \
           f"(enclave /) is on the graph, on this host, pid {first.process.pid}: " in err
    assert "One suite per namespace: stop that one, or start this one with another --namespace" in err
    assert "suite up" not in err
    assert "Traceback" not in err

    other = running("run", "--time-scale", "2", "--namespace", "/other")
    other.expect("namespace /other", "stderr")
    for process in (other, first):
        process.process.send_signal(signal.SIGINT)
        code, _, err = process.finish()
        assert code == 0, err


@pytest.fixture
def suite_process(running):
    process = running("run", "--time-scale", "2")
    process.expect("suite up", "stderr")
    return process


def test_the_probe_finds_a_suite_within_the_discovery_time_and_says_so_when_none_is_there(suite_process,
                                                                                            ros_context):
    from mpi_ros.ros import twin

    began = time.monotonic()
    found = twin.find_suite(ros_context, "/mpi")
    took = time.monotonic() - began
    assert found is not None
    assert took < twin.DISCOVERY + 1.0
    assert found.enclave == "/"
    assert found.origin.text.startswith(f"on this host, pid {suite_process.process.pid}: ")
    assert not found.origin.gone

    began = time.monotonic()
    assert twin.find_suite(ros_context, "/nobody", wait=0.5) is None
    assert 0.5 <= time.monotonic() - began < 0.5 + WAIT


def test_the_console_warns_about_nodes_on_the_graph_twice(suite_process, ros_context):
    from rclpy.node import Node

    from mpi_ros.cli.console import twins_warning
    from mpi_ros.cli.status import render
    from mpi_ros.client import Watcher

    watcher = Watcher(context=ros_context, timeout=WAIT, node_name="twin_watcher")
    try:
        watcher.wait_for_suite(WAIT)
        assert watcher.twins_on_graph() == []
        assert twins_warning(watcher) is None
        twin = Node("controller", namespace="/mpi", context=ros_context)  # what a second suite shows
        try:
            pause, deadline = threading.Event(), time.monotonic() + WAIT
            while not watcher.twins_on_graph() and time.monotonic() < deadline:
                pause.wait(0.05)
            assert watcher.twins_on_graph() == ["/mpi/controller"]
            warning = twins_warning(watcher)
            assert warning == (f"warning: 1 node name(s) of /mpi are on ROS_DOMAIN_ID {os.environ['ROS_DOMAIN_ID']} "
                               f"twice (/mpi/controller): two suites run under one namespace, and both take every "
                               f"command; stop one of them")
            # under the status table's header, wrapped to the terminal's width
            assert render({}, {}, "/mpi", None, width=300, warning=warning)[1] == warning
            narrow = render({}, {}, "/mpi", None, width=80, warning=warning)
            wrapped = narrow[1:1 + len(narrow) - len(render({}, {}, "/mpi", None, width=80))]
            assert all(len(line) < 80 for line in wrapped)
            assert " ".join(wrapped) == warning
        finally:
            twin.destroy_node()
    finally:
        watcher.close()


def test_the_views_follow_the_suites_diagnostics_entry(suite_process, ros_context):
    from mpi_ros.cli.console import suite_warning
    from mpi_ros.client import Watcher

    watcher = Watcher(context=ros_context, timeout=WAIT, node_name="suite_watcher")
    try:
        watcher.wait_for_suite(WAIT)
        assert watcher.suite_status() is None  # not followed yet
        watcher.follow_suite()
        pause, deadline = threading.Event(), time.monotonic() + WAIT
        while watcher.suite_status() is None and time.monotonic() < deadline:
            pause.wait(0.05)
        status = watcher.suite_status()
        assert status is not None
        assert status.name == "mpi/suite"
        assert {"samples_behind", "real_time_factor", "clock_scheduling"} <= {v.key for v in status.values}
        # said above the views' tables when WARN (a loaded machine may put this suite behind)
        level = status.level[0] if isinstance(status.level, bytes) else status.level
        expected = None if level == 0 else f"warning: the suite (mpi/suite on /diagnostics): {status.message}"
        assert suite_warning(watcher) == expected
    finally:
        watcher.close()


def test_where_the_other_process_runs_is_read_from_its_guid(tmp_path):
    from mpi_ros.ros.twin import origin

    proc = tmp_path / "proc"
    (proc / "sys" / "kernel").mkdir(parents=True)
    (proc / "sys" / "kernel" / "pid_max").write_text("200000\n")
    (proc / "70000").mkdir()  # 70000 = 4464 + 65536: the same low 16 bits
    (proc / "70000" / "cmdline").write_bytes(b"python\0-m\0mpi_ros.cli\0run\0")

    def gid(vendor: bytes, host: bytes, pid: int) -> bytes:
        return vendor + host + pid.to_bytes(2, "little") + b"\x12\x34" + bytes(8)

    fast, here = b"\x01\x0f", b"\x78\xfd"
    mine = gid(fast, here, 1)
    assert origin(gid(fast, here, 4464), mine, proc).text == "on this host, pid 70000: python -m mpi_ros.cli run"
    gone = origin(gid(fast, here, 4465), mine, proc)
    assert gone.gone
    assert "4465 modulo 65536" in gone.text
    assert "no longer running" in gone.text
    elsewhere = origin(gid(fast, b"\x00\x01", 4464), mine, proc)
    assert not elsewhere.gone
    assert elsewhere.text.startswith("on another host (DDS host id 0001)")
    assert origin(gid(b"\x01\x10", here, 4464), mine, proc).text.startswith("its process unknown (its middleware")
    assert origin(None, mine, proc).text.startswith("its process unknown (none of its endpoints")
