"""Shared pytest set-up for mpi_ros.

Runs before any test module imports rclpy:
- every test run gets its own DDS domain (ROS_DOMAIN_ID claimed with a lock file, unless set), so
  concurrent runs on one machine do not see each other's nodes;
- discovery stays on this machine (ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST);
- the RMW is rmw_fastrtps_cpp (the one the wheels ship), unless set;
- generated messages check the types of assigned fields (ROS_PYTHON_CHECK_FIELDS=1).
Child processes started by tests inherit these variables and so join the same domain.

Fixtures: `ros_context` gives a fresh, initialised rclpy Context that is shut down after the
test; `probe` a node in it, spun by its own executor thread (subscriptions, service calls);
every test also checks that rclpy's default context was shut down (and shuts it down if a test
left it running).
"""

from __future__ import annotations

import os


def _claim_domain() -> str:
    """A DDS domain no other test run on this machine holds: ids 1..100 (valid for every RMW on
    Linux; 0 is the default everyone uses), each claimed with an exclusive lock on a file in
    the temp directory, held until this process exits (the pid alone collided)."""
    import fcntl
    import tempfile

    start = os.getpid() % 100
    for i in range(100):
        domain = 1 + (start + i) % 100
        lock = open(os.path.join(tempfile.gettempdir(), f"mpi_ros-test-domain-{domain}.lock"), "w")  # noqa: SIM115
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            lock.close()
            continue
        _DOMAIN_LOCKS.append(lock)  # kept open: the lock lasts as long as the run
        return str(domain)
    return str(1 + start)  # every id held: share one, as before


_DOMAIN_LOCKS: list = []
if "ROS_DOMAIN_ID" not in os.environ:
    os.environ["ROS_DOMAIN_ID"] = _claim_domain()
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
os.environ.setdefault("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")
# Generated messages type-check field assignments only with this set (read at import time);
# without it an int assigned to a float64 field silently serialises garbage.
os.environ.setdefault("ROS_PYTHON_CHECK_FIELDS", "1")
# Processes the tests start (mpi-ros run, peers) run this source tree too, not a stale install.
_REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (_REPO, os.environ.get("PYTHONPATH", "")) if p)

import sys  # noqa: E402
import threading  # noqa: E402

import pytest  # noqa: E402

# Markers by directory (pyproject.toml declares them): `scripts/test.sh --fast` leaves out the
# tests that need ROS or start processes, for the edit loop; CI runs everything.
_DIRECTORY_MARKS = {"ros": "ros", "interfaces": "ros", "bag": "ros", "cli": "process"}
_ROS_FIXTURES = {"ros_context", "module_context", "probe", "suite"}
# Modules outside test/cli that start processes (suites, peers, examples, network namespaces).
_PROCESS_MODULES = {"test_examples.py", "test_client.py", "test_robustness.py", "test_suite_process.py",
                    "test_goal_front.py", "test_watchdog.py", "test_cell.py", "test_cell_netns.py",
                    "test_interleavings.py", "test_cross_process.py", "test_killed_recording.py",
                    "test_graph_recording.py", "test_bag.py", "test_lint.py"}


# Tests that take tens of seconds (property searches over many batchings, blends swept over angles,
# long streamed paths): `--fast` leaves them out too. Named by function, so every parameter set.
_SLOW_TESTS = {"test_any_batching_gives_bit_identical_samples_and_events", "test_stepping_is_chunk_invariant",
               "test_a_request_that_cannot_be_read_is_the_users_error", "test_blend_limit_decides_which_turns_blend",
               "test_a_blended_corner_is_the_sum_of_the_two_profiles",
               "test_a_blended_corner_keeps_the_velocity_and_at_most_doubles_the_acceleration",
               "test_append_while_stopped_queues_behind_the_pending_move_and_resume_runs_both",
               "test_append_in_stopped_queues_behind_the_pending_profile",
               "test_a_10000_point_path_streamed_in_chunks_of_50_runs_without_a_gap",
               "test_cams_are_bit_identical_however_the_samples_are_batched"}


def pytest_collection_modifyitems(config, items):
    tests = os.path.dirname(os.path.abspath(__file__))
    for item in items:
        parts = os.path.relpath(str(item.path), tests).split(os.sep)
        mark = _DIRECTORY_MARKS.get(parts[0]) if len(parts) > 1 else None
        if mark is not None:
            item.add_marker(mark)
        if mark != "ros" and _ROS_FIXTURES & set(getattr(item, "fixturenames", ())):
            item.add_marker("ros")
        if mark != "process" and parts[-1] in _PROCESS_MODULES:
            item.add_marker("process")
        if getattr(item, "originalname", item.name) in _SLOW_TESTS:
            item.add_marker("slow")


def pytest_report_header(config):
    return (f"ROS_DOMAIN_ID={os.environ['ROS_DOMAIN_ID']} "
            f"ROS_AUTOMATIC_DISCOVERY_RANGE={os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE']} "
            f"RMW_IMPLEMENTATION={os.environ['RMW_IMPLEMENTATION']}")


def _fresh_context():
    import rclpy

    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        yield context
    finally:
        context.try_shutdown()


@pytest.fixture
def ros_context():
    """A fresh rclpy context, initialised for this test and shut down after it."""
    yield from _fresh_context()


@pytest.fixture(scope="module")
def module_context():
    """A fresh rclpy context shared by one test module (clients of a suite started once)."""
    yield from _fresh_context()


@pytest.fixture(autouse=True)
def _shutdown_default_rclpy_context():
    """After each test: rclpy's default context must not be left running."""
    yield
    rclpy = sys.modules.get("rclpy")
    if rclpy is None:
        return
    if rclpy.ok():
        rclpy.try_shutdown()


@pytest.fixture
def probe(ros_context):
    """A node with its own executor thread for subscriptions and service calls."""
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    node = Node("test_probe", context=ros_context)
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    thread = threading.Thread(target=executor.spin, daemon=True)
    thread.start()
    try:
        yield node
    finally:
        executor.shutdown(timeout_sec=2.0)
        thread.join(timeout=2.0)
        node.destroy_node()


class SetClock:
    """Wall time (s) that moves only when the test says: a ControllerRunner's ``clock``."""

    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def set_clock() -> SetClock:
    return SetClock()
