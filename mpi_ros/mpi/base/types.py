"""Enumerations of the MPI, with the spec's names (prefix dropped: ``MPIState.IDLE``)."""

from __future__ import annotations

from collections.abc import Iterable
from enum import Enum, IntEnum, IntFlag


class MPIState(IntEnum):
    """MPIState; the numbers are the ones of the ROS contract (docs/decisions.md, "The ROS contract: names,
    numbers, arrays")."""

    INVALID = 0
    IDLE = 1
    MOVING = 2
    STOPPING = 3
    STOPPED = 4
    STOPPING_ERROR = 5
    ERROR = 6


# Which state wins when the states of a supervisor's axes differ: the supervisor
# shows the most severe one (its status is derived from each axis' status, MPI 000
# mpiMotionAxisAppend).
STATE_SEVERITY = {
    MPIState.INVALID: -1,
    MPIState.IDLE: 0,
    MPIState.MOVING: 1,
    MPIState.STOPPED: 2,
    MPIState.STOPPING: 3,
    MPIState.STOPPING_ERROR: 5,
    MPIState.ERROR: 4,
}


class MPIAction(IntEnum):
    """MPIAction, plus MEIActionMAP."""

    NONE = 0
    STOP = 1
    E_STOP = 2
    ABORT = 3
    E_STOP_ABORT = 4
    RESET = 5
    RESUME = 6
    MAP = 7


class ActionSource(Enum):
    """Who caused a supervisor's state."""

    USER = "USER"
    CONTROLLER = "CONTROLLER"


class MPIMotionType(IntEnum):
    """MPIMotionType (in the spec's order) and MEIMotionTypeFRAME."""

    INVALID = 0
    PT = 1
    PTF = 2
    PVT = 3
    PVTF = 4
    SPLINE = 5
    BESSEL = 6
    BSPLINE = 7
    BSPLINE2 = 8
    S_CURVE = 9
    TRAPEZOIDAL = 10
    S_CURVE_JERK = 11
    VELOCITY = 12
    VELOCITY_JERK = 13
    CAM_LINEAR = 14
    CAM_CUBIC = 15
    FRAME = 16  # MEIMotionTypeFRAME


# Which types are point-to-point, paths, cams ..., what each may carry and how it is planned:
# one record per type in planning/families.py.


class MotionAttr(IntFlag):
    """MPIMotionAttrMask and MEIMotionAttrMask bits (names without prefix)."""

    NONE = 0
    # MPIMotionAttr
    APPEND = 1 << 0
    AUTO_START = 1 << 1
    DELAY = 1 << 2
    ID = 1 << 3
    ELEMENT_ID = 1 << 4
    RELATIVE = 1 << 5
    SYNC_END = 1 << 6
    SYNC_START = 1 << 7
    REPEAT = 1 << 8
    MASTER_START = 1 << 9
    NO_BACKTRACK = 1 << 10
    NO_BACKTRACK_HOLD = 1 << 11
    # MEIMotionAttr
    EVENT = 1 << 16
    FINAL_VEL = 1 << 17
    NO_REVERSAL = 1 << 18
    HOLD = 1 << 19
    HOLD_LESS = 1 << 20
    HOLD_GREATER = 1 << 21
    OUTPUT = 1 << 22
    # MPIMotionPathAttrMask (MPI 001) bits that are not also MPIMotionAttr bits (ID,
    # ELEMENT_ID, HOLD and OUTPUT mean the same in both masks and are the ones above).
    BEHAVIOR = 1 << 24
    RELATIVE_MOVE = 1 << 25
    RETAIN = 1 << 26
    EMPTY_COUNT = 1 << 27
    LOW_COUNT = 1 << 28
    NO_HANDSHAKE = 1 << 29
    EXPECTED_AXES = 1 << 30
    NO_WAIT = 1 << 31

    @classmethod
    def parse(cls, names: Iterable[object]) -> MotionAttr | None:
        """Attribute names (without prefix) to a mask; None if a name is unknown."""
        mask = cls.NONE
        for name in names:
            member = cls.__members__.get(str(name).strip().upper())
            if member is None or member is cls.NONE:
                return None
            mask |= member
        return mask

    def names(self) -> list[str]:
        # (a member's name is None only for a combination, which iterating the class never gives)
        return [m.name for m in MotionAttr if m is not MotionAttr.NONE and m in self and m.name is not None]


HOLD_ATTRS = MotionAttr.HOLD | MotionAttr.HOLD_LESS | MotionAttr.HOLD_GREATER
PATH_ATTRS = (
    MotionAttr.BEHAVIOR
    | MotionAttr.RELATIVE_MOVE
    | MotionAttr.RETAIN
    | MotionAttr.EMPTY_COUNT
    | MotionAttr.LOW_COUNT
    | MotionAttr.NO_HANDSHAKE
    | MotionAttr.EXPECTED_AXES
    | MotionAttr.NO_WAIT
)
CAM_ATTRS = (
    MotionAttr.REPEAT
    | MotionAttr.MASTER_START
    | MotionAttr.NO_BACKTRACK
    | MotionAttr.NO_BACKTRACK_HOLD
)


class HoldType(IntEnum):
    """MEIMotionAttrHoldType."""

    INVALID = 0
    NONE = 1
    GATE = 2
    INPUT = 3
    MOTOR_GENERAL_IO = 4
    MOTOR_DEDICATED_IO = 5
    AXIS_POSITION_ACTUAL = 6
    AXIS_POSITION_COMMAND = 7
    USER_ADDRESS = 8


class OutputType(IntEnum):
    """MEIMotionAttrOutputType."""

    INVALID = 0
    NONE = 1
    MOTOR = 2
    OUTPUT = 3


class IoSpace(Enum):
    """The words of the simulated I/O image."""

    IO = "IO"
    MOTOR_GENERAL_IO = "MOTOR_GENERAL_IO"
    MOTOR_DEDICATED_IO = "MOTOR_DEDICATED_IO"


class AxisMasterType(IntEnum):
    """MPIAxisMasterType (MPI 002): the source of the master position a cam's slave axis
    follows. The numbers are the enum's order in the reference."""

    MOTOR_FEEDBACK_PRIMARY = 0
    MOTOR_FEEDBACK_SECONDARY = 1
    AXIS_COMMANDED_POSITION = 2
    AXIS_ACTUAL_POSITION = 3
    ADDRESS = 4
