"""The MotionStart/MotionModify goals of one supervisor that are not finished yet (no ROS here).

A goal follows the move its command made (its serial) from the sample its command took
effect at; when it is over, and how, is the controller's answer (Controller.move_ends;
mpi_ros/mpi/move_log.py says when). Goals do not wait for their end (a waiting goal would
hold an executor thread, and with more goals than threads nothing else, E_STOP included,
would be served). A GoalBook holds the goals of one supervisor that have not been finished;
the runner reviews it, under its lock, after every step batch and every command, and the
node finishes what the review returns.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from mpi_ros.mpi.base.outcome import MoveEnd
from mpi_ros.mpi.control import Controller


@dataclass(eq=False, slots=True)
class TrackedGoal:
    """A goal in the book. Fields change only under the runner's lock."""

    key: bytes
    payload: Any  # what the node needs to finish the goal (its ROS handle, ...)
    serial: int | None = None  # the move it follows, once the controller accepted its command
    sample: int = 0  # the sample its command took effect at
    end: MoveEnd | None = None  # set once, when the end is known
    started: bool = False  # its move has become the supervisor's current move
    cancel: bool = False  # a cancel was accepted (a STOP has been sent)


@dataclass(slots=True)
class Review:
    started: list[TrackedGoal]  # goals whose move has just become current
    ended: list[TrackedGoal]  # goals that ended (removed from the book), `end` set


class GoalBook:
    """The goals of one supervisor that have not been finished. Use under the runner's lock."""

    def __init__(self, supervisor: int):
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
        open_goals = [g for g in self._goals.values() if g.end is None and g.serial is not None]
        ends = ctl.move_ends(self.supervisor, [(g.serial, g.sample) for g in open_goals if g.serial is not None])
        for goal, end in zip(open_goals, ends, strict=True):
            goal.end = end
        current = ctl.current_serial(self.supervisor)
        review = Review([], [])
        for goal in list(self._goals.values()):
            if goal.end is None:
                if goal.serial == current and not goal.started:
                    goal.started = True
                    review.started.append(goal)
            elif may_end(goal):
                del self._goals[goal.key]
                review.ended.append(goal)
        return review

    def end_all(self, end: MoveEnd) -> list[TrackedGoal]:
        """Empty the book: every goal ends (with ``end`` unless it already had one)."""
        goals = list(self._goals.values())
        self._goals.clear()
        for goal in goals:
            if goal.end is None:
                goal.end = end
        return goals
