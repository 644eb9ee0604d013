"""Fixtures for driving the node suite in-process through real ROS actions, services and
topics. The controller runs in manual mode: tests step it by samples, and wait on
futures, events and conditions with timeouts (never on fixed sleeps)."""

from __future__ import annotations

import threading

import pytest

WAIT = 10.0  # seconds: the most any ROS round trip may take before a test fails


@pytest.fixture
def suite_config():
    from mpi_ros import config

    return config.load()


@pytest.fixture
def suite(ros_context, suite_config):
    from mpi_ros.ros.suite import Suite

    running = Suite(suite_config, time_scale=None, context=ros_context)
    running.start(spin_in_thread=True)
    try:
        yield running
    finally:
        running.shutdown()


@pytest.fixture
def applied(suite):
    """``applied.wait(n)``: wait until the controller has applied ``n`` commands in all."""

    class Applied:
        def __init__(self):
            self.commands = []
            self._cond = threading.Condition()
            suite.runner.on_command(self._record)

        def _record(self, sample, command, reply):
            with self._cond:
                self.commands.append((sample, command, reply))
                self._cond.notify_all()

        def wait(self, count: int, timeout: float = WAIT):
            with self._cond:
                assert self._cond.wait_for(lambda: len(self.commands) >= count, timeout), (
                    f"only {len(self.commands)} of {count} commands reached the controller")
                return self.commands[count - 1]

    return Applied()


@pytest.fixture
def drive(suite):
    """``drive(done, samples=...)``: step the controller until ``done()`` holds.

    Steps ``chunk`` samples at a time and gives the ROS threads a moment (a wait on the
    runner's condition) between chunks; fails after ``samples`` samples or WAIT seconds.
    """

    def run(done, samples: int = 200_000, chunk: int = 20):
        runner = suite.runner
        limit = runner.ctl.sample + samples
        event = threading.Event()
        while not done():
            assert runner.ctl.sample < limit, f"not done after {samples} samples"
            runner.step(chunk)
            event.wait(0.0005)
        return runner.ctl.sample

    return run


def _client(suite, ros_context, number: int):
    from mpi_ros.client import MotionClient

    client = MotionClient(number, context=ros_context, timeout=WAIT, node_name=f"test_client_ms{number}")
    assert client.wait_for_server(WAIT)
    return client


@pytest.fixture
def client(suite, ros_context):
    """The Python client of supervisor 0."""
    ms0 = _client(suite, ros_context, 0)
    yield ms0
    ms0.close()


@pytest.fixture
def client1(suite, ros_context):
    """The Python client of supervisor 1."""
    ms1 = _client(suite, ros_context, 1)
    yield ms1
    ms1.close()


def call(node, srv_type, name: str, request, timeout: float = WAIT):
    """Call a service from a probe node and wait for the response."""
    cli = node.create_client(srv_type, name)
    assert cli.wait_for_service(timeout_sec=timeout), f"service {name} not available"
    future = cli.call_async(request)
    done = threading.Event()
    future.add_done_callback(lambda _f: done.set())
    assert done.wait(timeout), f"no response from {name}"
    node.destroy_client(cli)
    return future.result()


@pytest.fixture
def service():
    """``service(node, type, name, request)``: a service round trip."""
    return call
