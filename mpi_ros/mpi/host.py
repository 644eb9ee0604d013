"""What a motion supervisor (and the fault monitor) needs of its controller, and nothing more.

A supervisor and its collaborators (supervisor/: axis_list.py, moves.py, actions.py,
stepping.py) are given a :class:`SupervisorHost`, never the Controller itself:
the controller's time, its axes and I/O, its events and move outcomes, and the answers
that concern other supervisors (who commands an axis, in what state, on what clock).
Questions across supervisors are the controller's to answer; a supervisor does not reach
into another one.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from mpi_ros.mpi.axes.axis import Axis
    from mpi_ros.mpi.base.clock import ProfileClock
    from mpi_ros.mpi.base.events import MPIEventType
    from mpi_ros.mpi.base.io import IoImage
    from mpi_ros.mpi.base.masters import Sources
    from mpi_ros.mpi.base.outcome import MoveEnd, Outcome
    from mpi_ros.mpi.base.params import ControllerConfig
    from mpi_ros.mpi.base.snapshot import AxisSnapshot
    from mpi_ros.mpi.base.types import ActionSource, MPIAction, MPIState


class ControllerView(Protocol):
    """What the supervisors and the fault monitor both see of the controller."""

    @property
    def axes(self) -> Sequence[Axis]: ...
    @property
    def config(self) -> ControllerConfig: ...
    @property
    def rate(self) -> float: ...
    @property
    def time(self) -> float: ...

    def emit(self, kind: MPIEventType, supervisor: int = -1, axis: int = -1, move_id: int = 0,
             element_id: int = 0, detail: str = "", extra_mask: MPIEventType = ..., sample: int | None = None
             ) -> None: ...
    # other supervisors, as the controller answers for them
    def clock_of(self, supervisor: int) -> ProfileClock | None: ...
    def act_on(self, supervisor: int, action: MPIAction, source: ActionSource) -> Outcome: ...


class SupervisorFaults(Protocol):
    """What a supervisor asks of the fault monitor (faults/monitor.py's FaultMonitor): RESET
    reads and clears the latched faults of its axes, an open path reports an empty buffer."""

    def latched_on(self, numbers: list[int]) -> bool: ...
    def persisting(self, numbers: list[int]) -> list[str]: ...
    def clear(self, numbers: list[int]) -> set[int]: ...
    def watches_underflow(self, numbers: Sequence[int]) -> bool: ...
    def underflow(self, numbers: Sequence[int]) -> None: ...


class SupervisorHost(ControllerView, Protocol):
    """The controller as a supervisor sees it (Controller implements it)."""

    @property
    def io(self) -> IoImage: ...
    @property
    def faults(self) -> SupervisorFaults: ...
    @property
    def sample(self) -> int: ...

    # -- this supervisor's own bookkeeping, kept by the controller
    def next_serial(self) -> int: ...
    def record_end(self, end: MoveEnd) -> None: ...
    def clock_changed(self, supervisor: int, clock: ProfileClock) -> None: ...

    # -- reads of the controller
    def master_sources(self) -> Sources: ...
    def axis_snapshots(self, numbers: Sequence[int] | None = None) -> list[AxisSnapshot]: ...
    def frame_count(self, number: int) -> int: ...
    def own_state_of(self, supervisor: int) -> MPIState | None: ...


class FaultHost(ControllerView, Protocol):
    """The controller as its fault monitor (faults/monitor.py) sees it (Controller implements it)."""

    def responsible_for(self, axis: int) -> list[int]: ...
