"""When a MotionStart/MotionModify goal is over, and how it ended (no ROS here).

A goal follows the move its command made (its serial; a modify keeps the serial of the
move it changed). It ends:
- with MPIMessageOK when the move is DONE (axis settling rules), or for a VELOCITY move
  when every axis is at the commanded velocity;
- with MPIMotionMessageSTOPPED once a STOP has brought the axes to rest (STOPPED);
- with the message the controller recorded when the move was dropped (E_STOP/ABORT end
  it with MPIMotionMessageERROR once in ERROR, a new start or RESET drops it).
Never while the axes still move toward its target.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..mpi.control import Controller
from ..mpi.messages import Message
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


class GoalTracker:
    def __init__(self, runner: ControllerRunner, supervisor: int, serial: int):
        self.runner = runner
        self.supervisor = supervisor
        self.serial = serial

    def _pending(self, ctl: Controller):
        """The move if it is still current or queued on the supervisor, else None."""
        ms = ctl.supervisor(self.supervisor)
        if ms is None:
            return None, None
        if ms.current is not None and ms.current.serial == self.serial:
            return ms, ms.current
        for move in ms.queue:
            if move.serial == self.serial:
                return ms, move
        return ms, None

    def end(self, ctl: Controller) -> GoalEnd | None:
        """How the goal ended, or None while it runs (call under the runner's lock)."""
        outcome = self.runner.outcomes.get(self.serial)
        if outcome is not None:
            return GoalEnd(outcome.message, outcome.detail, outcome.sample,
                           outcome.command_position, outcome.actual_position)
        ms, move = self._pending(ctl)
        if ms is None:
            return GoalEnd(Message.MPIMotionMessageMOTION_INVALID, "supervisor deleted", ctl.sample)
        if move is None:
            return GoalEnd(Message.MPIMotionMessageIDLE, "the move is no longer on the supervisor", ctl.sample)
        if ms.own_state is MPIState.STOPPED:
            return GoalEnd(Message.MPIMotionMessageSTOPPED,
                           f"stopped by {ms.last_action} ({ms.action_source.value})", ctl.sample)
        if move is ms.current and move.is_velocity and self._at_velocity(ctl, move):
            return GoalEnd(Message.MPIMessageOK, "at velocity", ctl.sample)
        if move is ms.current and not ms.queue and ms.cruising():
            return GoalEnd(Message.MPIMessageOK, "at target, going on at the final velocity", ctl.sample)
        return None

    @staticmethod
    def _at_velocity(ctl: Controller, move) -> bool:
        return all(ctl.axes[plan.axis].status.at_velocity for plan in move.plans)

    def wait(self, timeout: float) -> GoalEnd | None:
        """Wait up to ``timeout`` s for the goal to end."""
        found: list[GoalEnd] = []

        def ended(ctl: Controller) -> bool:
            end = self.end(ctl)
            if end is not None:
                found.append(end)
            return end is not None

        self.runner.wait(ended, timeout)
        return found[0] if found else None
