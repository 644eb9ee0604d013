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

# What is kept is bounded, so that a suite that runs for days holds no more than one that ran a
# minute. Goals read their ends at the review after every step batch and every command
# (mpi_ros/ros/goal_tracker.py), so they need an end only until then; the bounds are far above
# what one review can meet.
KEPT = 10_000  # moves whose ends are kept (the oldest go first)
ENDS_PER_MOVE = 64  # the latest ends kept of one move: a move modified for hours ends again at every DONE
RECENT = 1024  # ends kept in the order they came, for a look at what ended lately


class MoveLog:
    """The ends of the last KEPT moves, by serial, in the order they were recorded (the
    latest ENDS_PER_MOVE of each)."""

    def __init__(self, kept: int = KEPT, ends_per_move: int = ENDS_PER_MOVE):
        self._kept = kept
        self._ends_per_move = ends_per_move
        # A tuple per move: most moves end once, and a deque each would weigh ten times as much.
        self._ends: OrderedDict[int, tuple[MoveEnd, ...]] = OrderedDict()
        self._recent: deque[MoveEnd] = deque(maxlen=RECENT)

    def __len__(self) -> int:
        return len(self._ends)

    def record(self, end: MoveEnd) -> None:
        ends = (*self._ends.get(end.serial, ()), end)
        self._ends[end.serial] = ends[-self._ends_per_move:]  # a move's place in the order stays its first end's
        self._recent.append(end)
        while len(self._ends) > self._kept:
            self._ends.popitem(last=False)

    def ends(self, serial: int) -> tuple[MoveEnd, ...]:
        """The ends recorded for move ``serial`` (a modified move can have several), at
        most the latest ENDS_PER_MOVE."""
        return self._ends.get(serial, ())

    def since(self, serial: int, sample: int) -> MoveEnd | None:
        """The first end of move ``serial`` recorded at or after ``sample``."""
        return next((end for end in self._ends.get(serial, ()) if end.sample >= sample), None)

    def recent(self, supervisor: int | None = None) -> list[MoveEnd]:
        """The latest ends (at most RECENT), oldest first; of one supervisor if given."""
        return [end for end in self._recent if supervisor is None or end.supervisor == supervisor]
