"""The goal loop (mpi_ros/ros/goal_loop.py): the goal servers of every supervisor are waited
on by one thread of their own, not by the nodes' executors."""

from __future__ import annotations

import threading

from .conftest import WAIT


def test_goals_are_served_with_no_node_executor_spinning(ros_context, suite_config):
    from mpi_ros.client import MotionClient
    from mpi_ros.ros.suite import Suite

    suite = Suite(suite_config, time_scale=None, context=ros_context)
    suite.start(spin_in_thread=False)  # the clock and the goal loop run; no executor spins a node
    client = None
    try:
        client = MotionClient(1, context=ros_context, timeout=WAIT, node_name="test_goal_loop_client")
        assert client.wait_for_server(WAIT)
        goal = client.start({"type": "VELOCITY", "trajectory": [{"velocity": 500.0, "acceleration": 50_000.0}]})
        pause = threading.Event()
        limit = suite.runner.ctl.sample + 20_000
        while not goal.done:
            assert suite.runner.ctl.sample < limit, "the goal did not end"
            suite.runner.step(20)
            pause.wait(0.0005)  # lets the output thread hand the result over
        result = goal.wait()
        assert (result.message, result.detail) == ("MPIMessageOK", "at velocity")
    finally:
        if client is not None:
            client.close()
        suite.shutdown()


def test_a_suite_stops_its_goal_loop_before_destroying_the_servers(ros_context, suite_config):
    from mpi_ros.ros.suite import Suite

    suite = Suite(suite_config, time_scale=None, context=ros_context)
    suite.start(spin_in_thread=True)
    suite.shutdown()
    assert not any(t.name == "mpi-ros-goal-loop" and t.is_alive() for t in threading.enumerate())
