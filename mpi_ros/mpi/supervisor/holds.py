"""HOLD: a move waits on an axis until its trigger (MPI 000 MEIMotionAttrHOLD).

Triggers: a closed gate opening, an I/O word matching a pattern under a mask, or an
axis' actual/command position crossing a value (HOLD_LESS: <=, HOLD_GREATER: >=;
neither: the position is reached from the side it starts on). A non-zero timeout
(seconds) starts the move anyway when it expires. Holds with the same trigger release
in the same sample, whichever supervisor they belong to.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mpi_ros.mpi.base.io import IoImage
from mpi_ros.mpi.base.params import Hold
from mpi_ros.mpi.base.types import HoldType, IoSpace, MotionAttr
from mpi_ros.mpi.planning.frames import AxisPlan

_IO_SPACES = {
    HoldType.INPUT: IoSpace.IO,
    HoldType.USER_ADDRESS: IoSpace.IO,
    HoldType.MOTOR_GENERAL_IO: IoSpace.MOTOR_GENERAL_IO,
    HoldType.MOTOR_DEDICATED_IO: IoSpace.MOTOR_DEDICATED_IO,
}


@dataclass(slots=True)
class HoldWait:
    axis: int
    plan: AxisPlan
    hold: Hold
    deadline: int | None  # sample at which the timeout starts the move anyway
    greater: bool  # position triggers: True for >=, False for <=

    @classmethod
    def begin(cls, plan: AxisPlan, attrs: MotionAttr, sample: int, rate: float, position_now: float) -> HoldWait:
        hold = plan.hold
        assert hold is not None  # only a held plan waits
        deadline = sample + max(1, math.ceil(hold.timeout * rate - 1e-9)) if hold.timeout > 0.0 else None
        if MotionAttr.HOLD_GREATER in attrs:
            greater = True
        elif MotionAttr.HOLD_LESS in attrs:
            greater = False
        else:
            greater = position_now <= hold.position
        return cls(plan.axis, plan, hold, deadline, greater)

    @staticmethod
    def watches(hold: Hold) -> bool:
        """Does ``hold`` trigger on an axis position?"""
        return hold.type in (HoldType.AXIS_POSITION_ACTUAL, HoldType.AXIS_POSITION_COMMAND)

    @property
    def watches_position(self) -> bool:
        return self.watches(self.hold)

    def static_trigger(self, io: IoImage) -> bool:
        """Trigger state of a non-position hold (constant between commands)."""
        kind = self.hold.type
        if kind is HoldType.NONE:
            return True
        if kind is HoldType.GATE:
            return not io.gates_closed[self.hold.gate]
        space = _IO_SPACES[kind]
        index = self.hold.address if space is IoSpace.IO else self.hold.number
        return io.matches(space, index, self.hold.mask, self.hold.pattern)

    def position_trigger(self, positions: npt.NDArray[np.float64]) -> npt.NDArray[np.bool_]:
        """Trigger state per sample given the watched axis' positions (user units)."""
        if self.greater:
            return positions >= self.hold.position
        return positions <= self.hold.position

    def timed_out(self, samples: npt.NDArray[np.int64]) -> npt.NDArray[np.bool_]:
        if self.deadline is None:
            return np.zeros(len(samples), dtype=bool)
        return samples >= self.deadline
