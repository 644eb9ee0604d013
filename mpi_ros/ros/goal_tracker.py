"""When a MotionStart/MotionModify goal is over, and how it ended (no ROS here).

A goal follows the move its command made (its serial; a modify keeps the serial of the
move it changed) from the sample its command took effect at. It ends with the first
outcome the controller records for that move at or after that sample (MoveEnd):
- MPIMessageOK when the move is DONE (axis settling rules), or for a VELOCITY move when
  every axis is at the commanded velocity ("at velocity");
- the message recorded when the move was dropped (E_STOP/ABORT end it with
  MPIMotionMessageERROR once in ERROR; a new start, a modify of a queued move or RESET
  drop it).
Outcomes recorded before the goal's sample belong to earlier goals on the same move (a
VELOCITY move at +200 counts/s, then a modify to -300: the +200 "at velocity" is not the
modify's end). The controller records an outcome at the sample it is at; a command given
at sample k takes effect at k + 1 (Controller.effective_sample), and everything recorded
at k (the step to k, or the command itself) happened before it: hence ``>=``.
With no outcome, the supervisor as it is now decides: STOPPED (a STOP has brought the
axes to rest), the move gone, or a FINAL_VEL move at its target going on at its final
velocity (the controller records no outcome for that: the move never becomes DONE).
Never while the axes still move toward the goal's target.

Goals do not wait for their end (a waiting goal would hold an executor thread, and with
more goals than threads nothing else, E_STOP included, would be served). A GoalBook holds
the goals of one supervisor that have not been finished; the runner reviews it, under its
lock, after every step batch and every command, and the node finishes what the review
returns.
"""

from __future__ import annotations

from collections.abc import Callable, Container, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

from ..mpi.control import Controller
from ..mpi.messages import Message
from ..mpi.motion import MoveEnd
from ..mpi.types import MPIState
from ..runner import ControllerRunner


@dataclass(frozen=True, slots=True)
class GoalEnd:
    message: Message
    detail: str
    sample: int
    command_position: tuple[float, ...] | None = None  # at `sample`, when the controller recorded it
    actual_position: tuple[float, ...] | None = None

    @property
    def succeeded(self) -> bool:
        return self.message is Message.MPIMessageOK


def outcome_since(outcomes: Sequence[MoveEnd], since: int) -> GoalEnd | None:
    """The first of a move's outcomes recorded at or after sample ``since``."""
    for outcome in outcomes:
        if outcome.sample >= since:
            return GoalEnd(outcome.message, outcome.detail, outcome.sample,
                           outcome.command_position, outcome.actual_position)
    return None


def pending_serials(ms) -> set[int]:
    """The serials of the supervisor's current and queued moves."""
    pending = {serial for move in ms.queue for serial in move.serials()}
    if ms.current is not None:
        pending |= ms.current.serials()
    return pending


def end_now(ctl: Controller, supervisor: int, serial: int, pending: Container[int] | None = None) -> GoalEnd | None:
    """What the supervisor says now about the goals of move ``serial`` that have no outcome
    of their own: ended (and how), or None while the move runs or waits its turn.
    ``pending``: the supervisor's ``pending_serials``, if already at hand."""
    ms = ctl.supervisor(supervisor)
    if ms is None:
        return GoalEnd(Message.MPIMotionMessageMOTION_INVALID, "supervisor deleted", ctl.sample)
    if serial not in (pending_serials(ms) if pending is None else pending):
        return GoalEnd(Message.MPIMotionMessageIDLE, "the move is no longer on the supervisor", ctl.sample)
    if ms.own_state is MPIState.STOPPED:
        return GoalEnd(Message.MPIMotionMessageSTOPPED,
                       f"stopped by {ms.last_action} ({ms.action_source.value})", ctl.sample)
    if not ms.queue and ms.current is not None and ms.current.serial == serial and ms.cruising():
        return GoalEnd(Message.MPIMessageOK, "at target, going on at the final velocity", ctl.sample)
    return None


@dataclass(eq=False, slots=True)
class TrackedGoal:
    """A goal in the book. Fields change only under the runner's lock."""

    key: bytes
    payload: Any  # what the node needs to finish the goal (its ROS handle, ...)
    serial: int | None = None  # the move it follows, once the controller accepted its command
    sample: int = 0  # the sample its command took effect at
    end: GoalEnd | None = None  # set once, when the end is known
    started: bool = False  # its move has become the supervisor's current move
    cancel: bool = False  # a cancel was accepted (a STOP has been sent)


@dataclass(slots=True)
class Review:
    started: list[TrackedGoal]  # goals whose move has just become current
    ended: list[TrackedGoal]  # goals that ended (removed from the book), `end` set


class GoalBook:
    """The goals of one supervisor that have not been finished. Use under the runner's lock."""

    def __init__(self, runner: ControllerRunner, supervisor: int):
        self.runner = runner
        self.supervisor = supervisor
        self._goals: dict[bytes, TrackedGoal] = {}

    def __len__(self) -> int:
        return len(self._goals)

    def add(self, goal: TrackedGoal) -> None:
        self._goals[goal.key] = goal

    def get(self, key: bytes) -> TrackedGoal | None:
        return self._goals.get(key)

    def running(self) -> Iterator[TrackedGoal]:
        """Goals whose move is (or was) current and whose end is not known."""
        return (g for g in self._goals.values() if g.started and g.end is None)

    def review(self, ctl: Controller, may_end: Callable[[TrackedGoal], bool]) -> Review:
        """Find the goals whose move has started or ended. An ended goal leaves the book
        once ``may_end(goal)`` allows (the node defers a goal whose cancel is under way)."""
        ms = ctl.supervisor(self.supervisor)
        current = ms.current.serial if ms is not None and ms.current is not None else None
        pending = pending_serials(ms) if ms is not None else set()
        outcomes = self.runner.outcomes
        now: dict[int, GoalEnd | None] = {}  # end_now per move: hundreds of goals may follow one
        review = Review([], [])
        for goal in list(self._goals.values()):
            if goal.end is None and goal.serial is not None:
                goal.end = outcome_since(outcomes.get(goal.serial, ()), goal.sample)
                if goal.end is None:
                    if goal.serial not in now:
                        now[goal.serial] = end_now(ctl, self.supervisor, goal.serial, pending)
                    goal.end = now[goal.serial]
            if goal.end is None:
                if goal.serial == current and not goal.started:
                    goal.started = True
                    review.started.append(goal)
            elif may_end(goal):
                del self._goals[goal.key]
                review.ended.append(goal)
        return review

    def end_all(self, end: GoalEnd) -> list[TrackedGoal]:
        """Empty the book: every goal ends (with ``end`` unless it already had one)."""
        goals = list(self._goals.values())
        self._goals.clear()
        for goal in goals:
            if goal.end is None:
                goal.end = end
        return goals
