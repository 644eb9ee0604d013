"""The running suite puts on the graph exactly the names, types and QoS of mpi_ros/graph_names.py
(the ROS contract, docs/architecture.md)."""

from __future__ import annotations

import threading

from rclpy.action import get_action_names_and_types

from mpi_ros import graph_names as gn
from mpi_ros.qos import profile

from .conftest import WAIT


def _graph(probe) -> dict[str, str]:
    """Every name on the graph -> its first type (topics, services and actions)."""
    found = {name: types[0] for name, types in probe.get_topic_names_and_types()}
    found.update((name, types[0]) for name, types in probe.get_service_names_and_types())
    found.update((name, types[0]) for name, types in get_action_names_and_types(probe))
    return found


def test_the_suite_serves_every_endpoint_under_its_name_and_type(suite, probe):
    wanted = {name: e.type for name, e in gn.suite_endpoints("/mpi", [0, 1], [0, 1, 2, 3]).items()}
    found: dict[str, str] = {}
    pause = threading.Event()  # never set: discovery is waited on, not slept through
    for _ in range(int(WAIT / 0.05)):
        found = _graph(probe)
        if wanted.keys() <= found.keys():
            break
        pause.wait(0.05)
    assert {name: found.get(name) for name in wanted} == wanted


def test_the_publishers_offer_the_qos_of_graph_names(suite, probe):
    for name, endpoint in {"/mpi/ms0/status": gn.MOTION_STATUS, "/mpi/commands": gn.COMMANDS,
                           "/clock": gn.CLOCK, "/mpi/configuration": gn.CONFIGURATION}.items():
        wanted = profile(endpoint.qos)
        offered = [p.qos_profile for p in probe.get_publishers_info_by_topic(name)]
        assert offered, name
        assert {(q.reliability, q.durability) for q in offered} == {(wanted.reliability, wanted.durability)}, name
