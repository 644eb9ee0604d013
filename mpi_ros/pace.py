"""Whether the controller keeps to the wall clock, told report by report (/diagnostics).

A simulated controller that cannot keep up does not fail: its clock thread steps every sample
all the same, later and later (on a loaded machine a thread at normal scheduling gets a fair
share of a core, and at 8 axes with status at 1 kHz that share is less than the stepping needs:
bench/RESULTS.md measured it 24-40 % behind real time). Its statuses stay exact, stamped with
controller time, so only a reader that compares their stamps with its own clock could tell
that the run has fallen behind the wall clock. Each report says so: how far behind, the real
time factor since the last report (controller seconds per wall second, as Gazebo reports it:
1.0 in real time, the time scale when it keeps up), and whether it is late.

Late means more than :data:`LATE` of wall time behind: over twice the most the lag varied by
on an idle machine (6-43 ms, bench/bench_suite.py), and twenty times what a status may wait
for the stretch that carries it (ros.publish_period, 5 ms).
"""

from __future__ import annotations

from dataclasses import dataclass

from mpi_ros.runner import ControllerRunner

LATE = 0.1  # s of wall time behind: late


@dataclass(frozen=True, slots=True)
class PaceReport:
    samples_behind: int  # samples the controller is behind its clock (0 without one)
    seconds_behind: float  # the same in wall seconds
    # controller s per wall s since the last report, or the first since the clock started (None: a
    # manual clock, or no wall time yet)
    real_time_factor: float | None
    late: bool  # more than LATE behind
    turned: bool  # late now and not at the last report, or the other way round

    def describe(self) -> str:
        """One line for a log or a diagnostic's message."""
        if not self.late:
            return f"{self.samples_behind} samples behind the wall clock"
        factor = "" if self.real_time_factor is None else f", real time factor {self.real_time_factor:.2f}"
        return f"behind real time: {self.seconds_behind:.2f} s behind the wall clock{factor}"


class Pace:
    """``report()``: how the controller of ``runner`` keeps to the wall clock, since the last
    report. Runner lock held."""

    def __init__(self, runner: ControllerRunner):
        self._runner = runner
        self._mark: tuple[float, int] | None = None  # (wall time, sample) of the last report
        self._factor: float | None = None  # the latest real time factor (None: none yet)
        self._late = False

    def report(self) -> PaceReport:
        runner = self._runner
        now, sample = runner.clock(), runner.ctl.sample
        mark = self._mark or runner.started  # (the first report: since the clock started)
        if mark is None or now > mark[0]:  # (two reports at one instant: the factor of the first)
            if mark is not None and runner.time_scale is not None:  # (a manual clock's pace is its caller's)
                self._factor = (sample - mark[1]) / runner.ctl.rate / (now - mark[0])
            self._mark = (now, sample)
        behind, scale = runner.samples_behind(), runner.time_scale
        seconds = behind / (runner.ctl.rate * scale) if behind and scale else 0.0
        late = seconds > LATE
        report = PaceReport(behind, seconds, self._factor, late, late != self._late)
        self._late = late
        return report
