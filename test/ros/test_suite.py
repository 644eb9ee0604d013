"""Suite (mpi_ros/ros/suite.py): its executors' threads and the order it is taken down in."""

from __future__ import annotations

import re
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


def test_a_controller_behind_the_wall_clock_turns_the_suite_entry_to_warn_and_logs_it(ros_context, suite_config,
                                                                                      set_clock, capfd):
    from diagnostic_msgs.msg import DiagnosticStatus

    from mpi_ros.ros.suite import Suite

    suite = Suite(suite_config, time_scale=1.0, context=ros_context)
    clock = suite.runner.clock = set_clock
    suite.start(spin_in_thread=False)
    try:
        with suite.runner.lock:  # the clock thread cannot step: as on a machine that does not give it the CPU
            first = suite.suite_status()
            assert first.level == DiagnosticStatus.OK
            assert {v.key: v.value for v in first.values}["real_time_factor"] == "unknown"  # no wall time yet
            clock.now += 0.25
            late = suite.suite_status()
        assert late.level == DiagnosticStatus.WARN
        assert late.message == ("behind real time: 0.25 s behind the wall clock, real time factor 0.00; "
                                "on a loaded machine ros.clock_priority keeps it in time")
        values = {v.key: v.value for v in late.values}
        assert (values["samples_behind"], values["real_time_factor"]) == (str(int(0.25 * suite.controller.rate)),
                                                                          "0.0000")
        clock.now += 0.125
        # caught up, to the last status stop due at most (runner._clock_target): within a status period
        period = suite.controller.rate / suite_config.ros.status_rate
        assert suite.runner.wait(lambda ctl: suite.runner.samples_behind() <= period, WAIT)
        with suite.runner.lock:
            back = suite.suite_status()
        assert back.level == DiagnosticStatus.OK
        assert re.fullmatch(r"\d+ samples behind the wall clock", back.message)
        # 0.375 s of controller time in the 0.125 s since the last report, less what is not stepped yet
        factor = float({v.key: v.value for v in back.values}["real_time_factor"])
        assert 3.0 - period / suite.controller.rate / 0.125 <= factor <= 3.0
        logged = capfd.readouterr().err
        assert "controller clock behind real time: 0.25 s behind the wall clock" in logged
        assert "controller clock back in real time" in logged
    finally:
        assert suite.shutdown(WAIT)
