"""The one outcome type: how a call, a check, a plan or a move turned out.

Every answer in the project is an :class:`Outcome` (the reference's message and why in words),
from a field's validator through the planner, the controller and the commands to the ROS
result: no tuples of (message, detail), no per-layer copies. Where an answer cannot be
returned (deep in the planner, while a request is read) it is raised as :class:`Refused`,
which carries one. :class:`MoveEnd` is an outcome of a move with where its axes were.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from mpi_ros.mpi.base.messages import Message

# (a module name: Python 3.11 looks a member up on its enum class through a Python-level
# hook, and every check of every command asks ``ok``)
_OK = Message.MPIMessageOK


@dataclass(frozen=True, slots=True)
class Outcome:
    """OK, or the reference's message and why (``detail`` names the field first: "field: why")."""

    message: Message
    detail: str = ""
    # The message is OK: kept with the outcome, as a field, since every check of every command
    # asks (a property would be a Python call each time); not compared, shown or given.
    ok: bool = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "ok", self.message is _OK)  # (the frozen dataclass' way to set it)

    def prefixed(self, prefix: str) -> Outcome:
        """The same outcome with ``prefix`` before the field it names (for nested structs)."""
        return self if self.ok else Outcome(self.message, prefix + self.detail)


VALID = Outcome(Message.MPIMessageOK)


class CarriesOutcome:
    """What carries an outcome with more around it (a raised refusal, a move's end, a
    command's reply) reads its message and detail through to it: ``outcome`` is the one
    attribute a subclass provides."""

    __slots__ = ()
    outcome: Outcome

    @property
    def message(self) -> Message:
        return self.outcome.message

    @property
    def detail(self) -> str:
        return self.outcome.detail


class Refused(CarriesOutcome, Exception):
    """An outcome that is not OK, raised where it cannot be returned (the planner, a request
    being read); caught where the answer is given."""

    def __init__(self, message: Message, detail: str):
        super().__init__(detail)
        self.outcome = Outcome(message, detail)


@dataclass(frozen=True, slots=True)
class MoveEnd(CarriesOutcome):
    """An outcome of a move at a sample, with the supervisor's axis positions then: how the
    move ended, or (a VELOCITY move) that it reached its velocity, which is what its goals
    wait for. A modify keeps the move's serial: an outcome before the modify's sample is not
    its own."""

    serial: int
    outcome: Outcome
    sample: int
    command_position: tuple[float, ...] = ()
    actual_position: tuple[float, ...] = ()
    supervisor: int = -1

    @property
    def succeeded(self) -> bool:
        return self.outcome.ok
