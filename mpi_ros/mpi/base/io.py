"""The simulated I/O image and the control gates.

HOLD triggers read it (MPI 000 MEIMotionAttrHoldSource: gate 0..31, an input word
ANDed with a mask compared to a pattern, a motor's general or dedicated I/O word) and
OUTPUT writes it (MEIMotionAttrOutput: on/off masks of a motor's output word or of an
I/O word). Words are 32-bit.
"""

from __future__ import annotations

from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.outcome import VALID, Outcome
from mpi_ros.mpi.base.params import MAX_GATES
from mpi_ros.mpi.base.types import IoSpace

_WORD = 0xFFFFFFFF


def _to_int32(value: int) -> int:
    value &= _WORD
    return value - (1 << 32) if value & 0x80000000 else value


class IoImage:
    def __init__(self, io_words: int, motors: int):
        self.words = {
            IoSpace.IO: [0] * io_words,
            IoSpace.MOTOR_GENERAL_IO: [0] * motors,
            IoSpace.MOTOR_DEDICATED_IO: [0] * motors,
        }
        self.gates_closed = [False] * MAX_GATES
        self.version = 0  # bumped on every change (holds re-check on it)

    def _valid(self, space: IoSpace, index: int) -> bool:
        return 0 <= index < len(self.words[space])

    def _check_word(self, space: IoSpace, index: int) -> Outcome:
        if self._valid(space, index):
            return VALID
        return Outcome(Message.MPIMessagePARAM_INVALID,
                       f"index: no {space.value} word {index} ({len(self.words[space])} words)")

    def get(self, space: IoSpace, index: int) -> tuple[Message, int]:
        if not self._valid(space, index):
            return Message.MPIMessagePARAM_INVALID, 0
        return Message.MPIMessageOK, self.words[space][index]

    def set(self, space: IoSpace, index: int, value: int, mask: int = -1) -> Outcome:
        verdict = self._check_word(space, index)
        if not verdict.ok:
            return verdict
        old = self.words[space][index]
        self.words[space][index] = _to_int32((old & ~mask) | (value & mask))
        self.version += 1
        return VALID

    def apply_masks(self, space: IoSpace, index: int, on_mask: int, off_mask: int) -> Outcome:
        """Turn bits on and off (MEIMotionAttrOutput onMask/offMask)."""
        verdict = self._check_word(space, index)
        if not verdict.ok:
            return verdict
        old = self.words[space][index]
        self.words[space][index] = _to_int32((old | on_mask) & ~off_mask)
        self.version += 1
        return VALID

    def matches(self, space: IoSpace, index: int, mask: int, pattern: int) -> bool:
        if not self._valid(space, index):
            return False
        return (self.words[space][index] & mask & _WORD) == (pattern & _WORD)

    # -- gates (meiControlGateSet/Get) -----------------------------------------------
    def gate_set(self, gate: int, closed: bool) -> Outcome:
        """meiControlGateSet."""
        if not 0 <= gate < MAX_GATES:
            return Outcome(Message.MPIMessagePARAM_INVALID, f"gate: no gate {gate} (0..{MAX_GATES - 1})")
        self.gates_closed[gate] = bool(closed)
        self.version += 1
        return VALID

    def gate_get(self, gate: int) -> tuple[Message, bool]:
        if not 0 <= gate < MAX_GATES:
            return Message.MPIMessagePARAM_INVALID, False
        return Message.MPIMessageOK, self.gates_closed[gate]
