"""A supervisor's mpiMotionStatus, split by how long each part holds (MPI 000, mpiMotionStatus).

Between two discrete changes (a command, a transition, a fault) a supervisor's state, move,
queue, last action and feedrate clock stay as they are: the controller steps in stretches
that stop at every such change (Controller._status_events). Only what follows its axes'
values changes from sample to sample: their status, the element id of a path's point, the
progress along the move, the feedrate along a ramp and the events latched so far.
:class:`MotionTemplate` holds the first part and builds the snapshot of any sample of the
stretch from the second; the live status (MotionSupervisor.snapshot) is built the same way
at the current sample, so both are one definition.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from mpi_ros.mpi.axes.axis import Axis
from mpi_ros.mpi.base.clock import ProfileClock
from mpi_ros.mpi.base.snapshot import AxisSnapshot, MotionSnapshot
from mpi_ros.mpi.base.types import MPIState

RelOf = Callable[[int], float]  # an axis' profile time (Axis.rel) at the sample, by axis number
# axis snapshots by axis number: every axis' (a list), or at least a supervisor's (a dict)
AxisSnapshots = Sequence[AxisSnapshot] | Mapping[int, AxisSnapshot]


@dataclass(slots=True)
class Progress:
    """0..1 along a move as its axes' profile times give it: the smallest of ``fixed`` (an
    axis not running its plan of the move yet: 0; a move over: 1) and, for each axis that
    runs its plan, its profile time over ``span`` (the plan's duration, or a velocity move's
    ramp), clipped to 0..1 (1 for a span of 0). 0 without any. (Part of a template, so not
    frozen either: frozen costs a call a field.)"""

    fixed: tuple[float, ...]
    spans: tuple[tuple[int, float], ...]  # (axis number, span)

    def __post_init__(self) -> None:
        if self.fixed and any(not 0.0 <= f <= 1.0 for f in self.fixed):  # (a move in progress: none)
            raise ValueError(f"progress fractions must be within 0..1, not {self.fixed}")

    def at(self, rel: RelOf) -> float:
        fractions = [1.0 if span <= 0.0 else min(1.0, max(0.0, rel(n) / span)) for n, span in self.spans]
        fractions += self.fixed  # (the order does not matter: none is NaN or -0.0)
        return min(fractions) if fractions else 0.0


@dataclass(slots=True)
class MotionTemplate:
    """What a supervisor's mpiMotionStatus holds until its next discrete change, and how the
    rest follows from a sample's axis snapshots and profile times. (A template lives for one
    status read or one stretch, so it is not frozen: frozen costs a call a field.)"""

    number: int
    state: MPIState  # the state shown (Moves.shown_state)
    own_moving: bool  # its own state is MOVING (then status is not done)
    unacknowledged: int | None  # the sample of a start not acknowledged yet (state reads IDLE)
    axis_numbers: tuple[int, ...]
    move_id: int
    element_axis: Axis | None  # the axis whose path point gives the element id, if any
    element_id: int  # the element id otherwise
    motion_type: str
    moves_pending: int
    last_action: str
    action_source: str
    progress: Progress
    clock: ProfileClock
    rate: float  # samples per second (the controller's time is sample / rate)

    def __post_init__(self) -> None:
        if self.rate <= 0.0:
            raise ValueError(f"the sample rate must be above 0, not {self.rate}")

    def at(self, sample: int, axis_snapshots: AxisSnapshots, rel: RelOf,
           latched_events: tuple[str, ...]) -> MotionSnapshot:
        """The snapshot at ``sample``: ``axis_snapshots`` by axis number (every axis, or at
        least the mapped ones), ``rel`` the axes' profile times there, ``latched_events`` the
        events latched by then."""
        axes = tuple([axis_snapshots[n] for n in self.axis_numbers])
        element = self.element_axis
        return MotionSnapshot(
            sample=sample,
            number=self.number,
            state=self._reported_state(sample),
            axis_numbers=self.axis_numbers,
            axes=axes,
            done=all([a.done for a in axes]) and not self.own_moving,  # (all of none: True)
            at_target=all([a.at_target for a in axes]),
            settled=all([a.settled for a in axes]),
            move_id=self.move_id,
            element_id=self.element_id if element is None else element.element_id_at(rel(element.number)),
            feedrate=self.clock.feedrate(sample / self.rate),
            last_action=self.last_action,
            action_source=self.action_source,
            moves_pending=self.moves_pending,
            motion_type=self.motion_type,
            progress=self.progress.at(rel),
            latched_events=latched_events,
        )

    def _reported_state(self, sample: int) -> MPIState:
        """IDLE at the sample of a start given NO_HANDSHAKE or NO_WAIT (MPI 001 remarks: "the
        state is reported as MPIStateIDLE until the controller begins the profile
        execution"), the state otherwise."""
        if self.unacknowledged == sample and self.state is MPIState.MOVING:
            return MPIState.IDLE
        return self.state
