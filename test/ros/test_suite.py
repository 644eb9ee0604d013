"""Suite (mpi_ros/ros/suite.py): its executors' threads and the order it is taken down in."""

from __future__ import annotations

import threading

WAIT = 10.0


def test_an_executor_stopped_by_an_error_is_reported_and_the_rest_keep_spinning(ros_context, suite_config):
    from mpi_ros.ros.suite import Suite

    suite = Suite(suite_config, time_scale=None, context=ros_context)
    suite.start()
    try:
        assert suite.failed() == []
        broken = suite.supervisor_nodes[0]
        broken.create_guard_condition(lambda: 1 / 0).trigger()
        broken.create_guard_condition(lambda: None).trigger()  # the round that re-raises it
        [failed] = [s for s in suite.spinners if s.name == broken.get_name()]
        assert failed.join(WAIT)
        assert suite.failed() == [failed]
        assert isinstance(failed.error, ZeroDivisionError)
        # another node's executor still runs its callbacks
        ran = threading.Event()
        suite.supervisor_nodes[1].create_guard_condition(ran.set).trigger()
        assert ran.wait(WAIT)
    finally:
        assert suite.shutdown(WAIT)  # every executor stopped (one had already), every node destroyed
