"""The controller's status at one sample, read once for every node that publishes it.

The controller node publishes the AxisStatus of every axis and each supervisor node its
MotionStatus, which holds the AxisStatus of its axes: both at the status rate, so at the
same samples, one after the other in the runner's periodic round. Reading the controller
separately for each would take every mapped axis' snapshot twice a sample (an axis
snapshot is the most expensive read of the controller, more than packing and publishing its
message). Here every axis' snapshot is taken once a sample, from one read of the
controller's arrays (Controller.motion_snapshots), and the supervisors' snapshots hold the
same ones: the axis topics and the motion topics show the same reading of an axis at a
sample, so their values cannot differ.

Valid for one sample, and only until a command is applied at it (commands change the
controller without stepping it): a periodic round runs under the runner's lock with no
command in between, and the next round is at a later sample.
"""

from __future__ import annotations

import weakref

from mpi_ros.mpi.base.snapshot import AxisSnapshot, MotionSnapshot
from mpi_ros.mpi.control import Controller

from ..runner import ControllerRunner

_SHARED: weakref.WeakKeyDictionary[ControllerRunner, SampleSnapshots] = weakref.WeakKeyDictionary()


class SampleSnapshots:
    def __init__(self, runner: ControllerRunner):
        self._sample = -1
        self._motions: dict[int, MotionSnapshot] | None = None
        self._axes: dict[int, AxisSnapshot] = {}
        runner.on_command(self._forget)

    def _forget(self, *_applied) -> None:
        self._sample = -1
        self._motions = None
        self._axes = {}

    def motions(self, ctl: Controller) -> dict[int, MotionSnapshot]:
        """Every supervisor's snapshot (mpiMotionStatus) at the controller's sample."""
        if ctl.sample != self._sample:
            self._forget()
            self._sample = ctl.sample
        if self._motions is None:
            self._motions, axes = ctl.motion_snapshots()
            self._axes = {axis.number: axis for axis in axes}
        return self._motions

    def motion(self, ctl: Controller, number: int) -> MotionSnapshot | None:
        return self.motions(ctl).get(number)

    def axis(self, ctl: Controller, number: int) -> AxisSnapshot:
        """An axis' snapshot (mpiAxisStatus) at the controller's sample."""
        self.motions(ctl)
        return self._axes[number]


    def taken_axes(self, ctl: Controller) -> dict[int, AxisSnapshot] | None:
        """Every axis' snapshot if all were taken at the controller's sample (the axis
        topics have been collected), else None: for readers that need not pay for them."""
        if ctl.sample != self._sample or len(self._axes) < len(ctl.axes):
            return None
        return self._axes


def shared(runner: ControllerRunner) -> SampleSnapshots:
    """The one SampleSnapshots of ``runner`` (made on first use)."""
    snapshots = _SHARED.get(runner)
    if snapshots is None:
        snapshots = _SHARED[runner] = SampleSnapshots(runner)
    return snapshots
