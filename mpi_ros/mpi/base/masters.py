"""Master positions for cams (MPI 002, MPIAxisMaster, MPIAxisMasterType, masterCorrection).

A slave axis follows one of:
- MOTOR_FEEDBACK_PRIMARY: the encoder of motor ``number``, the motor of axis ``number`` (the
  simulated plant): its raw reading, origin-free;
- MOTOR_FEEDBACK_SECONDARY: the motor's second encoder input (:class:`SecondaryInputs`), which
  configuration or a service drives, e.g. at the constant speed of a line shaft;
- AXIS_COMMANDED_POSITION / AXIS_ACTUAL_POSITION: axis ``number``'s command or actual position
  (user units: raw minus its origin), of any supervisor; a cam keeps the origins of its start
  (an origin change later is bookkeeping and moves no slave: docs/cams.md);
- ADDRESS: the value of the I/O word ``address`` of the simulated I/O image (io.py).
With masterCorrection >= 0 the command position of that axis is added (docs/cams.md).

Values are read at the sample they are for: a slave follows its master's position of the same
sample (an axis master is traced before its slaves: axes/trace.py).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mpi_ros.mpi.base.io import IoImage
from mpi_ros.mpi.base.params import AxisMaster, SecondaryFeedback
from mpi_ros.mpi.base.types import AxisMasterType, IoSpace

M = AxisMasterType
_AXIS_SOURCES = (M.AXIS_COMMANDED_POSITION, M.AXIS_ACTUAL_POSITION, M.MOTOR_FEEDBACK_PRIMARY)
_USER_SOURCES = (M.AXIS_COMMANDED_POSITION, M.AXIS_ACTUAL_POSITION)  # read in user units: less the origin


def reads(master: AxisMaster) -> set[int]:
    """The axes whose values at a sample this master position needs."""
    axes = {master.number} if master.type in _AXIS_SOURCES else set()
    if master.correction >= 0:
        axes.add(master.correction)
    return axes


@dataclass(frozen=True, slots=True)
class _Input:
    sample: int
    feedback: SecondaryFeedback


class SecondaryInputs:
    """The secondary feedback input of every motor: a reading set at some sample that moves on
    at a constant velocity, read in whole counts (an encoder counts whole lines)."""

    def __init__(self, motors: int):
        self._inputs = [_Input(0, SecondaryFeedback()) for _ in range(motors)]

    def __len__(self) -> int:
        return len(self._inputs)

    def set(self, motor: int, feedback: SecondaryFeedback, sample: int) -> None:
        """From ``sample`` on the input reads ``feedback.position`` and moves at its velocity."""
        self._inputs[motor] = _Input(sample, SecondaryFeedback(float(feedback.position), float(feedback.velocity)))

    def get(self, motor: int) -> tuple[int, SecondaryFeedback]:
        one = self._inputs[motor]
        return one.sample, one.feedback

    def at(self, motor: int, samples: npt.NDArray[np.int64], rate: float) -> npt.NDArray[np.float64]:
        one = self._inputs[motor]
        moved = one.feedback.velocity * ((samples - one.sample) / rate)
        return np.floor(one.feedback.position + moved + 0.5)


@dataclass(frozen=True, slots=True)
class Sources:
    """What master positions are read from: command and actual positions (raw, one row per
    axis, one column per sample), the samples, each axis' origin, the I/O image, the
    secondary inputs and the sample rate."""

    cmd_p: npt.NDArray[np.float64]
    act_p: npt.NDArray[np.float64]
    samples: npt.NDArray[np.int64]
    origin: Callable[[int], float]
    io: IoImage
    secondary: SecondaryInputs
    rate: float

    def frame(self, master: AxisMaster) -> float:
        """The origins a user's reading of ``master`` subtracts now: the master axis' (AXIS_*
        sources) and the masterCorrection axis'."""
        frame = self.origin(master.number) if master.type in _USER_SOURCES else 0.0
        if master.correction >= 0:
            frame += self.origin(master.correction)
        return frame

    def position(self, master: AxisMaster, frame: float | None = None) -> npt.NDArray[np.float64]:
        """The master position at each sample: the raw reading less ``frame`` (by default the
        origins now, :meth:`frame`). A cam reads its master with the frame of its start, so
        that a later mpiAxisOriginSet, bookkeeping only, moves no slave."""
        n, kind = master.number, master.type
        value: npt.NDArray[np.float64]
        if kind is M.AXIS_COMMANDED_POSITION:
            value = self.cmd_p[n] + 0.0  # (a copy)
        elif kind in (M.AXIS_ACTUAL_POSITION, M.MOTOR_FEEDBACK_PRIMARY):
            value = self.act_p[n] + 0.0
        elif kind is M.MOTOR_FEEDBACK_SECONDARY:
            value = self.secondary.at(n, self.samples, self.rate)
        else:
            value = np.full(self.samples.shape, float(self.io.words[IoSpace.IO][master.address]))
        if master.correction >= 0:
            value = value + self.cmd_p[master.correction]
        return value - (self.frame(master) if frame is None else frame)
