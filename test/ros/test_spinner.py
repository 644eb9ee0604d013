"""Spinner (mpi_ros/ros/spinner.py): an executor spun in a thread until stopped or failed."""

from __future__ import annotations

import threading

import pytest
from rclpy.executors import MultiThreadedExecutor

WAIT = 10.0


@pytest.fixture
def node_and_executor(ros_context):
    import rclpy

    node = rclpy.create_node("spinner_test", context=ros_context, start_parameter_services=False)
    executor = MultiThreadedExecutor(num_threads=2, context=ros_context)
    executor.add_node(node)
    yield node, executor
    executor.shutdown(timeout_sec=WAIT)
    node.destroy_node()


def test_stop_ends_a_spinner_asleep_in_its_wait(node_and_executor):
    from mpi_ros.ros.spinner import Spinner

    node, executor = node_and_executor
    ran = threading.Event()
    wake = node.create_guard_condition(ran.set)
    spinner = Spinner(node, executor)
    spinner.start()
    wake.trigger()
    assert ran.wait(WAIT), "the spinner runs the node's callbacks"
    assert not spinner.ended
    # nothing else to do: the executor waits with no timeout, and stop must still end it
    assert spinner.stop(WAIT)
    assert spinner.ended
    assert spinner.error is None


def test_stop_before_start_has_nothing_to_wait_for(node_and_executor):
    from mpi_ros.ros.spinner import Spinner

    spinner = Spinner(*node_and_executor)
    assert spinner.stop(WAIT)
    assert not spinner.ended  # it never ran


def test_a_callback_that_raises_ends_the_spinner_with_its_error(node_and_executor):
    from mpi_ros.ros.spinner import Spinner

    node, executor = node_and_executor

    def broken() -> None:
        raise ZeroDivisionError("a bug in a callback")

    wake = node.create_guard_condition(broken)
    spinner = Spinner(node, executor)
    spinner.start()
    wake.trigger()
    # rclpy re-raises a callback's exception in spin_once, in the next round that has work:
    # one more trigger gives it that round
    node.create_guard_condition(lambda: None).trigger()
    assert spinner.join(WAIT)
    assert spinner.ended
    assert isinstance(spinner.error, ZeroDivisionError)


def test_a_context_shut_down_under_a_spinner_ends_it_without_an_error():
    """A client's owner shutting rclpy down (Ctrl-C) ends its spinner quietly: nothing is
    left to serve, and that is not a failure of the node."""
    import rclpy
    from rclpy.context import Context

    from mpi_ros.ros.spinner import Spinner

    context = Context()
    rclpy.init(context=context)
    node = rclpy.create_node("spinner_shutdown_test", context=context, start_parameter_services=False)
    executor = MultiThreadedExecutor(num_threads=2, context=context)
    executor.add_node(node)
    spinner = Spinner(node, executor)
    spinner.start()
    try:
        context.shutdown()
        assert spinner.join(WAIT), "the spinner ends when its context shuts down"
        assert spinner.error is None
    finally:
        spinner.stop(WAIT)
        executor.shutdown(timeout_sec=WAIT)
        node.destroy_node()
