"""How moves ended, kept by the controller: what tells a goal that follows a move that it
is over, and how (Controller.move_end).

A goal follows the move its command made (its serial; a modify keeps the serial of the
move it changed) from the sample its command took effect at. It ends with the first end
recorded for that move at or after that sample (MoveEnd):
- MPIMessageOK when the move is DONE (axis settling rules), or for a VELOCITY move when
  every axis is at the commanded velocity ("at velocity");
- the message recorded when the move was dropped (E_STOP/ABORT end it with
  MPIMotionMessageERROR once in ERROR; a new start, a modify of a queued move or RESET
  drop it).
Ends recorded before the goal's sample belong to earlier goals on the same move (a
VELOCITY move at +200 counts/s, then a modify to -300: the +200 "at velocity" is not the
modify's end). The controller records an end at the sample it is at; a command given at
sample k takes effect at k + 1 (Controller.effective_sample), and everything recorded at k
(the step to k, or the command itself) happened before it: hence ``>=``.
With no end recorded, the supervisor as it is now decides (MotionSupervisor.end_now):
STOPPED (a STOP has brought the axes to rest), the move gone, or a FINAL_VEL move at its
target going on at its final velocity (it never becomes DONE). Never while the axes still
move toward the goal's target.
"""

from __future__ import annotations

from collections import OrderedDict, deque

from .outcome import MoveEnd

KEPT = 100_000  # moves whose ends are kept (the oldest go first): far more than goals wait at once
RECENT = 1024  # ends kept in the order they came, for a look at what ended lately


class MoveLog:
    """The ends of the last KEPT moves, by serial, in the order they were recorded."""

    def __init__(self, kept: int = KEPT):
        self._kept = kept
        self._ends: OrderedDict[int, list[MoveEnd]] = OrderedDict()
        self._recent: deque[MoveEnd] = deque(maxlen=RECENT)

    def __len__(self) -> int:
        return len(self._ends)

    def record(self, end: MoveEnd) -> None:
        self._ends.setdefault(end.serial, []).append(end)
        self._recent.append(end)
        while len(self._ends) > self._kept:
            self._ends.popitem(last=False)

    def ends(self, serial: int) -> tuple[MoveEnd, ...]:
        """Every end recorded for move ``serial`` (a modified move can have several)."""
        return tuple(self._ends.get(serial, ()))

    def since(self, serial: int, sample: int) -> MoveEnd | None:
        """The first end of move ``serial`` recorded at or after ``sample``."""
        return next((end for end in self._ends.get(serial, ()) if end.sample >= sample), None)

    def recent(self, supervisor: int | None = None) -> list[MoveEnd]:
        """The latest ends (at most RECENT), oldest first; of one supervisor if given."""
        return [end for end in self._recent if supervisor is None or end.supervisor == supervisor]
