"""The axis list of a motion supervisor (MPI 000, mpiMotionAxis*): the coordinate system as
the host holds it (``listed``), and the mapping last written to the controller (``mapped``,
MEIActionMAP).

Pure list logic: the supervisor checks its handle and passes the state a change must respect;
what a new mapping does to a motion in progress is the moves' business (moves.Moves.remap).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import VALID, Outcome
from mpi_ros.mpi.base.params import MAX_COORD_AXES
from mpi_ros.mpi.base.types import MPIState

if TYPE_CHECKING:
    from mpi_ros.mpi.axes.axis import Axis
    from mpi_ros.mpi.base.params import ControllerConfig

OK = Message.MPIMessageOK


class AxisList:
    """mpiMotionAxisAppend/Insert/Remove/ListSet/ListGet/Count/Index/First/Next/... over the
    controller's ``axes``."""

    def __init__(self, axes: Sequence[Axis], config: ControllerConfig):
        self._axes = axes
        self._config = config  # the axes' frame buffer sizes
        self.listed: list[int] = []
        self.mapped: list[int] = []

    @property
    def frame_buffer_size(self) -> int:
        """The frame buffer size of the listed axes (one size: see :meth:`_frame_sizes_differ`)."""
        config = self._config
        return config.frame_buffer_size_of(self.listed[0]) if self.listed else config.frame_buffer_size

    def _frame_sizes_differ(self, numbers: list[int]) -> bool:
        """MPI 000, MPIMotionMessageAXIS_FRAME_COUNT: "All axes appended to a Motion object must
        have the same frame buffer size". Answered where axes are appended (append, insert,
        list set), so a list never holds two sizes and MAP and the moves need not ask."""
        return len({self._config.frame_buffer_size_of(n) for n in numbers}) > 1

    def _check_axis(self, number: int) -> Outcome:
        # MPI 000, mpiMotionAxisAppend: HANDLE_INVALID for no such axis or a deleted Axis object
        if not 0 <= number < len(self._axes):
            return Outcome(Message.MPIMessageHANDLE_INVALID, f"axis: no axis {number} ({len(self._axes)} axes)")
        if not self._axes[number].valid:
            return Outcome(Message.MPIMessageHANDLE_INVALID, f"axis: axis {number} was deleted (mpiAxisDelete)")
        if not self._axes[number].enabled:
            return Outcome(Message.MPIMessageOBJECT_NOT_ENABLED, f"axis: axis {number} is not enabled")
        return VALID

    def _check_new(self, numbers: list[int], unchecked: list[int]) -> Outcome:
        """What a new list of ``numbers`` must be (insert, append and list set alike);
        ``unchecked``: its axes not yet known to exist and be enabled."""
        if len(numbers) > MAX_COORD_AXES:
            return Outcome(Message.MPIMessageUNSUPPORTED,
                           f"axis_numbers: {len(numbers)} axes, a motion coordinates at most {MAX_COORD_AXES}")
        repeated = sorted({n for n in numbers if numbers.count(n) > 1})
        if repeated:
            return Outcome(Message.MPIMessageOBJECT_ON_LIST, f"axis_numbers: axis {repeated[0]} is on the list twice")
        for number in unchecked:
            verdict = self._check_axis(number)
            if not verdict.ok:
                return verdict
        if self._frame_sizes_differ(numbers):
            sizes = {n: self._config.frame_buffer_size_of(n) for n in numbers}
            return Outcome(Message.MPIMotionMessageAXIS_FRAME_COUNT,
                           f"axis_numbers: the axes' frame buffer sizes differ ({sizes})")
        return VALID

    def append(self, number: int) -> Outcome:
        """mpiMotionAxisAppend."""
        return self.insert(self.listed[-1] if self.listed else None, number)

    def insert(self, after: int | None, number: int) -> Outcome:
        """mpiMotionAxisInsert: insert ``number`` just after axis ``after`` (None: first)."""
        verdict = self._check_axis(number)
        if verdict.ok and number in self.listed:
            verdict = Outcome(Message.MPIMessageOBJECT_ON_LIST, f"axis: axis {number} is already on the list")
        if not verdict.ok:
            return verdict
        verdict = self._check_new([*self.listed, number], [])
        if not verdict.ok:
            return verdict
        if after is None:
            self.listed.insert(0, number)
            return VALID
        if after not in self.listed:
            return _not_listed("after_axis", after)
        self.listed.insert(self.listed.index(after) + 1, number)
        return VALID

    def remove(self, number: int, own_state: MPIState, refusal: Outcome) -> Outcome:
        """mpiMotionAxisRemove; ``refusal``: the answer of the state the supervisor shows."""
        verdict = self._check_axis(number)
        if not verdict.ok:
            return verdict
        if number not in self.listed:
            return _not_listed("axis", number)
        if number not in self.mapped:
            # MPI 002, MPIAxisMessageNOT_MAPPED_TO_MS: on the list but not mapped.
            return Outcome(Message.MPIAxisMessageNOT_MAPPED_TO_MS,
                           f"axis: axis {number} is listed but not mapped (MAP the list first)")
        if own_state not in (MPIState.IDLE, MPIState.ERROR):
            return refusal
        self.listed.remove(number)
        return VALID

    def set(self, numbers: list[int], own_state: MPIState, refusal: Outcome) -> Outcome:
        """mpiMotionAxisListSet: the coordinate system is completely replaced."""
        verdict = self._check_new(numbers, numbers)
        if not verdict.ok:
            return verdict
        if own_state not in (MPIState.IDLE, MPIState.ERROR, MPIState.STOPPED):
            return refusal
        self.listed = list(numbers)
        return VALID

    def index(self, number: int) -> int:
        """mpiMotionAxisIndex: -1 if not on the list."""
        return self.listed.index(number) if number in self.listed else -1

    def at(self, index: int) -> tuple[Message, int | None]:
        """mpiMotionAxis: the axis at ``index`` (None = MPIHandleVOID)."""
        if not 0 <= index < len(self.listed):
            return Message.MEIListMessageELEMENT_NOT_FOUND, None
        return OK, self.listed[index]

    def neighbour(self, number: int, step: int) -> tuple[Message, int | None]:
        """mpiMotionAxisNext (step +1) / mpiMotionAxisPrevious (-1)."""
        if number not in self.listed:
            return Message.MPIMessageHANDLE_INVALID, None
        index = self.listed.index(number) + step
        return OK, self.listed[index] if 0 <= index < len(self.listed) else None

    def leaving(self, axes: Sequence[int]) -> list[int]:
        """Those of ``axes`` a mapping of the list now would leave out."""
        return [n for n in axes if n not in self.listed]

    def commit_mapping(self) -> list[int]:
        """Write the list as the mapping (MEIActionMAP); returns it."""
        self.mapped = list(self.listed)
        return self.mapped


def _not_listed(field: str, number: int) -> Outcome:
    return Outcome(Message.MPIMotionMessageAXIS_NOT_FOUND, f"{field}: axis {number} is not on the list")
