"""LocalEndpoints (mpi_ros/ros/goal_endpoints.py): a response its client will not receive."""

from __future__ import annotations

import warnings

import pytest


class _GoneClient:
    """A service whose client has gone: rclpy warns, as it does when rmw_fastrtps gives up
    waiting for the client's response reader (RCL_RET_TIMEOUT), from the caller's frame."""

    def __init__(self) -> None:
        self.sent = 0

    def service_send_response(self, response, header) -> None:
        self.sent += 1
        warnings.warn("failed to send response (timeout): client will not receive response, at "
                      "/project/src/rmw_response.cpp:153", RuntimeWarning, stacklevel=2)


@pytest.mark.parametrize("kind", ["goal", "cancel", "result"])
def test_a_response_no_client_will_receive_is_said_in_the_log_not_warned(ros_context, kind, capfd):
    from rclpy.node import Node

    from mpi_ros import graph_names as gn
    from mpi_ros.action import MotionStart
    from mpi_ros.qos import profile
    from mpi_ros.ros.goal_endpoints import LocalEndpoints

    node = Node("endpoints_test", context=ros_context)
    try:
        endpoints = LocalEndpoints(node, MotionStart, "motion_start", profile(gn.ACTION_SERVICE_QOS))
        gone = endpoints.services[kind] = _GoneClient()
        payload = {"goal": (True, 0), "cancel": (0, []), "result": (0, MotionStart.Result())}[kind]
        with warnings.catch_warnings(record=True) as warned:  # (the filters in force, pyproject.toml's among them)
            endpoints.respond(kind, None, payload)
        assert gone.sent == 1
        assert [str(w.message) for w in warned] == []
        assert f"a {kind} response could not be sent (the client may have gone away)" in capfd.readouterr().err
    finally:
        node.destroy_node()
