"""Pace (mpi_ros/pace.py): whether the controller keeps to the wall clock, report by report.

The runner runs on a clock the test sets (ControllerRunner's ``clock``, conftest's set_clock),
so "a quarter of a second passes" is exact; while the test holds the runner's lock the clock
thread cannot step, which is how a controller falls behind on a machine that does not give it
the CPU."""

from __future__ import annotations

import pytest

from mpi_ros import config
from mpi_ros.pace import LATE, Pace, PaceReport
from mpi_ros.runner import ControllerRunner

WAIT = 10.0


def started(clock, time_scale: float | None) -> ControllerRunner:
    runner = ControllerRunner(config.load().build_controller(), time_scale=time_scale, clock=clock)
    runner.start()
    return runner


def test_a_controller_kept_from_stepping_is_late_and_back_in_time_once_it_catches_up(set_clock):
    clock = set_clock
    runner = started(clock, 1.0)
    pace = Pace(runner)
    rate = runner.ctl.rate
    try:
        with runner.lock:  # the clock thread cannot step
            start = runner.ctl.sample
            assert pace.report() == PaceReport(0, 0.0, None, late=False, turned=False)
            clock.now += 0.25
            late = pace.report()
            assert late == PaceReport(int(0.25 * rate), 0.25, 0.0, late=True, turned=True)
            assert late.describe() == "behind real time: 0.25 s behind the wall clock, real time factor 0.00"
            # reported again at the same instant: still late, no longer news
            assert pace.report() == PaceReport(int(0.25 * rate), 0.25, 0.0, late=True, turned=False)
        clock.now += 0.125
        due = start + int(0.375 * rate)
        assert runner.wait(lambda ctl: ctl.sample >= due, WAIT)  # caught up
        with runner.lock:
            back = pace.report()
        # 0.375 s of controller time stepped in the 0.125 s since the last report: three times real time
        assert back == PaceReport(0, 0.0, 3.0, late=False, turned=True)
        assert back.describe() == "0 samples behind the wall clock"
    finally:
        runner.stop()


def test_the_first_report_counts_from_the_clocks_start(set_clock):
    clock = set_clock
    runner = started(clock, 1.0)
    pace = Pace(runner)
    try:
        clock.now += 0.5
        assert runner.wait(lambda ctl: ctl.sample >= runner.ctl.rate // 2, WAIT)  # in time: no status to wait for
        with runner.lock:
            assert pace.report() == PaceReport(0, 0.0, 1.0, late=False, turned=False)
    finally:
        runner.stop()


def test_late_is_more_than_a_tenth_of_a_second_of_wall_time_at_any_time_scale(set_clock):
    clock = set_clock
    runner = started(clock, 2.0)  # two controller seconds a wall second
    pace = Pace(runner)
    rate = runner.ctl.rate
    try:
        with runner.lock:
            pace.report()
            clock.now += LATE
            on_the_line = pace.report()
            assert on_the_line.samples_behind == pytest.approx(2 * LATE * rate, abs=1)
            assert on_the_line.seconds_behind == pytest.approx(LATE, abs=1 / rate)
            assert not on_the_line.late
            clock.now += 4.0 / rate  # four samples more of wall time: eight of the controller's
            past = pace.report()
            assert past.samples_behind == pytest.approx(on_the_line.samples_behind + 8, abs=1)
            assert past.late
    finally:
        runner.stop()


@pytest.mark.parametrize("time_scale", [None, 0.0], ids=["manual", "as fast as possible"])
def test_without_a_clock_to_keep_nothing_is_behind(set_clock, time_scale):
    clock = set_clock
    runner = started(clock, time_scale)
    pace = Pace(runner)
    try:
        with runner.lock:
            pace.report()
            clock.now += 5.0
            report = pace.report()
        assert (report.samples_behind, report.seconds_behind, report.late, report.turned) == (0, 0.0, False, False)
        if time_scale is None:
            assert report.real_time_factor is None  # a manual clock's pace is its caller's
    finally:
        runner.stop()


def test_a_runner_not_started_is_not_behind(set_clock):
    clock = set_clock
    runner = ControllerRunner(config.load().build_controller(), time_scale=1.0, clock=clock)
    clock.now += 5.0
    assert runner.samples_behind() == 0
    assert not Pace(runner).report().late
