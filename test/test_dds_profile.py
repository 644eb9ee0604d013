"""The Fast DDS profiles shipped in config/ and when they apply (mpi_ros/dds_profile.py; issue 36:
a one-shot verb within 1 s, docs/reliability.md "How soon a one-shot verb acts")."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

from mpi_ros import config_paths, dds_profile
from mpi_ros import graph_names as gn

REPO = Path(__file__).resolve().parents[1]
NS = {"p": "http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"}


def in_a_process_of_its_own(code: str) -> str:
    """What ``code`` prints, run by this tree's Python with no profile file chosen (Fast DDS
    reads the profile once per process, at its first participant)."""
    env = {k: v for k, v in os.environ.items() if k not in dds_profile.PROFILE_VARIABLES}
    done = subprocess.run([sys.executable, "-P", "-c", code], cwd=REPO, env=env | {"PYTHONPATH": str(REPO)},
                          capture_output=True, text=True, timeout=60, check=True)
    return done.stdout.strip()


def test_a_tool_gets_the_client_profile_when_nothing_was_chosen():
    environ: dict[str, str] = {}
    chosen = dds_profile.use(environ, dds_profile.CLIENT)
    assert chosen is not None
    assert chosen.endswith("fastdds_client.xml")
    assert environ == {"FASTRTPS_DEFAULT_PROFILES_FILE": chosen}


def test_a_profile_of_the_operators_own_or_another_middleware_is_left_alone(tmp_path):
    own = {"FASTDDS_DEFAULT_PROFILES_FILE": str(tmp_path / "mine.xml")}
    assert dds_profile.use(own, dds_profile.CLIENT) is None
    assert own == {"FASTDDS_DEFAULT_PROFILES_FILE": str(tmp_path / "mine.xml")}
    cyclone = {"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}
    assert dds_profile.use(cyclone, dds_profile.CLIENT) is None
    assert cyclone == {"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}


def test_a_suite_started_from_a_tools_environment_replaces_the_tools_profile_with_its_own():
    environ: dict[str, str] = {}
    client = dds_profile.use(environ, dds_profile.CLIENT)
    suite = dds_profile.use(environ, dds_profile.SUITE)
    assert suite is not None
    assert suite != client
    assert suite.endswith("fastdds_discovery.xml")
    assert environ == {"FASTRTPS_DEFAULT_PROFILES_FILE": suite}


def test_the_client_profile_declares_a_large_udp_receive_buffer_and_keeps_shared_memory():
    root = ET.parse(config_paths.find(dds_profile.CLIENT)).getroot()
    kinds = {d.findtext("p:transport_id", namespaces=NS): d for d in root.iterfind(".//p:transport_descriptor", NS)}
    assert [d.findtext("p:type", namespaces=NS) for d in kinds.values()] == ["SHM", "UDPv4"]
    udp = next(d for d in kinds.values() if d.findtext("p:type", namespaces=NS) == "UDPv4")
    assert int(udp.findtext("p:receiveBufferSize", namespaces=NS)) == 4 * 1024 * 1024
    participant = root.find("p:participant", NS)
    assert participant is not None
    assert participant.get("is_default_profile") == "true"
    assert [t.text for t in participant.iterfind("p:rtps/p:userTransports/p:transport_id", NS)] == list(kinds)
    assert participant.findtext("p:rtps/p:useBuiltinTransports", namespaces=NS) == "false"


def test_the_suite_profile_lets_its_writers_wake_the_event_thread_once_a_burst():
    # The tree's own file (config_paths.find may give an installed copy of another tree's).
    root = ET.parse(REPO / "config" / dds_profile.SUITE).getroot()
    writer = root.find("p:data_writer", NS)
    assert writer is not None
    assert writer.get("is_default_profile") == "true"  # every writer rmw_fastrtps creates starts from it
    window = writer.find("p:times/p:nackSupressionDuration", NS)
    assert window is not None
    seconds = int(window.findtext("p:sec", namespaces=NS)) + int(window.findtext("p:nanosec", namespaces=NS)) / 1e9
    # longer than a status period at 100 Hz (one wake for a burst of them), a tenth at most of
    # what a status writer keeps at the fastest status rate: a NACK-ed status can be sent again
    fastest = 1000.0  # Hz: ros.status_rate's upper bound (mpi_ros/settings.py)
    assert 1 / 100.0 < seconds <= gn.MOTION_STATUS.qos.depth / fastest / 10
    assert gn.AXIS_STATUS.qos.depth == gn.MOTION_STATUS.qos.depth
    announcement = root.find("p:participant/p:rtps/p:builtin/p:discovery_config/p:leaseAnnouncement", NS)
    assert announcement is not None
    assert announcement.findtext("p:nanosec", namespaces=NS) == "100000000"


def test_a_profile_of_ours_from_another_place_it_is_looked_for_counts_as_ours():
    # e.g. a tool that found the source tree's copy, a suite that finds the installed one
    for place in config_paths.candidates(dds_profile.CLIENT):
        environ = {"FASTRTPS_DEFAULT_PROFILES_FILE": str(place)}
        assert dds_profile.use(environ, dds_profile.SUITE) == str(config_paths.find(dds_profile.SUITE))


def test_a_verbs_session_sets_the_client_profile_before_its_participant_exists():
    code = ("import argparse, os\n"
            "from mpi_ros.cli.console import Session\n"
            "with Session(argparse.Namespace(ros_args=[])) as session:\n"
            "    print(os.environ['FASTRTPS_DEFAULT_PROFILES_FILE'])\n")
    assert in_a_process_of_its_own(code) == str(config_paths.find(dds_profile.CLIENT))


def test_a_verbs_sockets_get_the_larger_receive_buffer():
    # What the profile is for, seen from inside a verb's process: its UDP sockets' SO_RCVBUF.
    # Linux doubles the request after capping it at net.core.rmem_max; a socket left at the
    # default has net.core.rmem_default.
    rmem_max = int(Path("/proc/sys/net/core/rmem_max").read_text())
    code = ("import argparse, os, socket\n"
            "from rclpy.node import Node\n"
            "from mpi_ros.cli.console import Session\n"
            "with Session(argparse.Namespace(ros_args=[])) as session:\n"
            "    node = Node('buffers', context=session.context)\n"
            "    sizes = []\n"
            "    for fd in os.listdir('/proc/self/fd'):\n"
            "        try:\n"
            "            if not os.readlink(f'/proc/self/fd/{fd}').startswith('socket:'):\n"
            "                continue\n"
            "            sock = socket.socket(fileno=os.dup(int(fd)))\n"
            "        except OSError:\n"
            "            continue\n"
            "        if sock.type == socket.SOCK_DGRAM:\n"
            "            sizes.append(sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF))\n"
            "        sock.close()\n"
            "    node.destroy_node()\n"
            "    print(max(sizes))\n")
    assert int(in_a_process_of_its_own(code)) == 2 * min(4 * 1024 * 1024, rmem_max)
