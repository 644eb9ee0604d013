"""The state a motion supervisor's collaborators share, as one explicit object.

The supervisor (motion.py) is made of collaborators: the axis list (axis_list.py), its moves
(moves.py), its actions (actions.py) and its transitions while the controller
steps (stepping.py). What they all read and change, the supervisor's own state
and how it got there, its feedrate clock, the stop under way and its configuration, is
this one object, passed to each of them: no attributes shared through ``self``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from mpi_ros.mpi.base.clock import ProfileClock
from mpi_ros.mpi.base.params import MotionConfig
from mpi_ros.mpi.base.types import ActionSource, MPIState


class SupervisorState:
    """A motion supervisor's own state (MPI 000, MPIState) and what drives it."""

    __slots__ = (
        "_clock",
        "_clock_changed",
        "abort_after_stop",
        "aborted",
        "action_source",
        "config",
        "error_at",
        "last_action",
        "number",
        "own_state",
        "stop_end",
        "unacknowledged",
    )

    def __init__(self, number: int, config: MotionConfig, clock: ProfileClock,
                 clock_changed: Callable[[int, ProfileClock], None]):
        self.number = number
        self.config = config
        self.own_state = MPIState.IDLE
        self.last_action = "NONE"
        self.action_source = ActionSource.USER
        self.stop_end = math.inf  # time at which the stop/e-stop ramp ends
        self.abort_after_stop = False  # E_STOP_ABORT: the amplifiers go off when the E_STOP ends
        self.error_at: int | None = None  # sample at which an ABORT completes
        self.aborted = False  # the amplifiers were turned off (RESET sets command = actual)
        # NO_HANDSHAKE / NO_WAIT (MPI 001): the sample of a start not yet acknowledged, at
        # which status still reads IDLE ("until the controller begins the profile execution").
        self.unacknowledged: int | None = None
        self._clock_changed = clock_changed
        self._clock = clock
        clock_changed(number, clock)

    @property
    def clock(self) -> ProfileClock:
        """The feedrate clock this supervisor's axes read their plans through (clock.py)."""
        return self._clock

    @clock.setter
    def clock(self, clock: ProfileClock) -> None:
        self._clock = clock
        self._clock_changed(self.number, clock)

    def enter(self, state: MPIState, action: str, source: ActionSource) -> None:
        """The supervisor's own state becomes ``state``, by ``action`` from ``source``."""
        self.own_state = state
        self.last_action = action
        self.action_source = source
