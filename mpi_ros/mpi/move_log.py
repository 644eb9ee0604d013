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

from mpi_ros.mpi.base.outcome import MoveEnd

# What is kept is bounded, so that a suite that runs for days holds no more than one that ran a
# minute. Goals read their ends at the review after every step batch and every command
# (mpi_ros/ros/goal_tracker.py); the runner then says so (Controller.ends_read), and from then on
# no goal needs them: a goal follows its move from the sample its command took effect at, later
# than every end recorded before it. So the log keeps ends that were read only up to KEPT_READ
# moves, and the ends of one batch that nobody has read yet, however many, up to KEPT moves (a
# stream ended at once ends every unreached chunk's serial together). Without a runner (the core
# used on its own) nothing is marked read, and KEPT bounds the log.
KEPT = 10_000  # moves whose ends are kept at most, read or not (the least recently ended go first)
KEPT_READ = 1_024  # moves whose ends are kept once read (Controller.ends_read)
ENDS_PER_MOVE = 64  # the latest ends kept of one move: a move modified for hours ends again at every DONE
RECENT = 1024  # ends kept in the order they came, for a look at what ended lately


class MoveLog:
    """The ends of the moves that ended last, by serial (the latest ENDS_PER_MOVE of each):
    KEPT_READ moves once their ends are read, at most KEPT."""

    def __init__(self, kept: int = KEPT, ends_per_move: int = ENDS_PER_MOVE, kept_read: int = KEPT_READ):
        self._kept = kept
        self._kept_read = min(kept_read, kept)
        self._ends_per_move = ends_per_move
        # A tuple per move: most moves end once, and a deque each would weigh ten times as much.
        # In the order the moves last ended, so that the first are the ones ended longest ago.
        self._ends: OrderedDict[int, tuple[MoveEnd, ...]] = OrderedDict()
        self._unread: set[int] = set()  # moves that ended since the last mark_read
        self._recent: deque[MoveEnd] = deque(maxlen=RECENT)

    def __len__(self) -> int:
        return len(self._ends)

    def record(self, end: MoveEnd) -> None:
        ends = (*self._ends.pop(end.serial, ()), end)
        self._ends[end.serial] = ends[-self._ends_per_move:]
        self._unread.add(end.serial)
        self._recent.append(end)
        self._trim()

    def mark_read(self) -> None:
        """Every end recorded so far has been read by those who follow moves: beyond
        KEPT_READ moves, the log may let them go."""
        self._unread.clear()
        self._trim()

    def _trim(self) -> None:
        ends, unread = self._ends, self._unread
        while len(ends) > self._kept_read and next(iter(ends)) not in unread:
            ends.popitem(last=False)
        while len(ends) > self._kept:
            unread.discard(ends.popitem(last=False)[0])

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
