"""Moves as the controller buffers them: per-axis frames, and frame-buffer accounting.

A move compiles, for each axis, into constant-jerk segments in profile time (motion,
DELAY and SYNC wait frames alike) plus one final frame that holds the end state; a
HOLD adds one hold frame in front. Those frames occupy the axis' frame buffer
(128 by default) from the moment the move is loaded until the axis has executed them.
MPI 000 mpiMotionStart: "Each axis has a 128 frame buffer (FIFO)".
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, cast, overload

import numpy as np
import numpy.typing as npt

from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.params import Hold, Output, Trajectory
from mpi_ros.mpi.base.types import MotionAttr, MPIMotionType
from mpi_ros.mpi.planning.profiles.segment import (
    Row,
    Segment,
    SegmentTable,
    end_time,
    scaled_profile,
)

if TYPE_CHECKING:
    from mpi_ros.mpi.planning.cam_follow import CamFollow
    from mpi_ros.mpi.planning.profiles.path import SplineHistory

# A point's time is a sum of its dts in floating point, off the sample grid by rounding: a
# point counts as reached from the sample within this many seconds of its time (far below
# one sample at any rate the controller takes).
POINT_TIME_TOLERANCE = 1e-9


@overload
def reached(rel: float) -> float: ...
@overload
def reached(rel: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
def reached(rel: float | npt.NDArray[np.float64]) -> float | npt.NDArray[np.float64]:
    """The profile time up to which points count as reached at profile time ``rel``."""
    return rel + POINT_TIME_TOLERANCE


@dataclass(frozen=True, slots=True)
class BlendParts:
    """The two profiles a blended plan adds up (planning/blend.py, MEIMotionConfig.blendLimit),
    kept so that each can be checked on its own (the ruckig and limits checks, crosscheck)."""

    own: tuple[Segment, ...]  # the appended move's profile, as planned alone from the corner
    tail: tuple[Segment, ...]  # the rest of the move before it, from the blend's start, less its target
    tail_limits: Trajectory | None  # the limits that move's profile was planned with


@dataclass(slots=True)
class Listed:
    """Segments listed one by one (every plan but a vector axis' share). ``values``: Segments, or
    Rows (plain tuples, scurve.reshaped(rows=True): an axis' own point-to-point profile) when
    ``rows``, which the stepping reads as they are and which are made Segments the first time
    they are asked for (a cross-check, a plot, a copy): the stepping never needs the names."""

    values: Sequence[Row]
    planned_limits: Trajectory | None = None  # the limits the profile was planned with
    total: float | None = None  # end_time(values), where the planner calculated it with them
    rows: bool = False
    made: list[Segment] | None = field(default=None, repr=False, compare=False)

    def segments(self) -> list[Segment]:
        if self.made is None:
            self.made = list(map(Segment._make, self.values)) if self.rows else cast("list[Segment]", self.values)
        return self.made

    def row_values(self) -> Sequence[Row]:
        return self.values

    def limits(self) -> Trajectory | None:
        return self.planned_limits


@dataclass(slots=True)
class Scaled:
    """A vector axis' share of the vector's 1-D profile (``values``, Rows): ``factor`` times it
    plus ``offset`` (the axis' start, scaled_profile), and of its limits (``vector_limits``). The
    segments and limits are made the first time they are asked for (by the stepping's table, a
    cross-check or a plot), not while the command waits for its plan: a further axis of a
    vector then costs little to plan. ``total``: end_time(values), the segments' durations added
    in the same order, calculated once for the vector's axes."""

    values: list[Row]
    factor: float
    offset: float
    total: float
    vector_limits: Trajectory
    made: list[Segment] | None = field(default=None, repr=False, compare=False)
    shared: Trajectory | None = field(default=None, repr=False, compare=False)

    def segments(self) -> list[Segment]:
        if self.made is None:
            self.made = scaled_profile(self.values, self.factor, self.offset)
        return self.made

    def row_values(self) -> Sequence[Row]:
        return self.segments()

    def limits(self) -> Trajectory:
        if self.shared is None:
            self.shared = self.vector_limits.share(abs(self.factor))
        return self.shared


# Where a plan's segments (and the limits they were planned with) come from. Both kinds hold
# ``values`` (as many as the segments, of the same durations) and ``total`` (their end_time, or
# None where the plan adds them up), which the plan reads as they are: a plan is made for every
# axis of every start and modify while its command waits.
SegmentSource = Listed | Scaled


@dataclass(slots=True)
class AxisPlan:
    """One axis' part of a move; times are profile time from the axis' start. Its segments and
    limits come from ``source`` (:attr:`segments`, :attr:`limits`): every reader sees Segments."""

    axis: int
    source: SegmentSource
    start_position: float
    target: float  # raw (origin-free) position where the plan ends
    final_velocity: float = 0.0
    hold: Hold | None = None
    outputs: list[Output] = field(default_factory=list)
    velocity_target: float | None = None  # VELOCITY moves: the commanded velocity
    ramp_end: float = 0.0  # VELOCITY moves: profile time at which the ramp is done
    truncated: bool = False  # a frame hit the 16,384,000-sample limit
    start_velocity: float = 0.0  # velocity (profile time) the profile starts from
    start_acceleration: float = 0.0
    composite: str = ""  # why the segments are more than one profile (e.g. stop, then a new line)
    # Paths (paths.py): profile time of the first segment (executed points are flushed from
    # a streamed path), the time each point is reached, the element id while running toward
    # each point, outputs applied at a later point (pointIndex > 0) with their times.
    origin_time: float = 0.0
    point_times: np.ndarray | None = None
    element_ids: tuple[int, ...] = ()
    timed_outputs: list[tuple[float, Output]] = field(default_factory=list)
    # PTF/PVTF: the feedforward's knots (profile times, values), linear between them and held
    # after the last; the first value is NaN until the axis fills in the one it holds (the
    # feedforward is kept from move to move: MPI 000, MPIMotionPTF).
    feedforward: tuple[np.ndarray, np.ndarray] | None = None
    # Cams (cams.py): the slave's table, master and progress; its "profile time" is the
    # progress along the table (status, progress and frames read it as they read time).
    cam: CamFollow | None = None
    # BSPLINE/BSPLINE2 (paths.py): the control points and point times of the whole curve, so
    # that points appended to an open path continue the one B-spline of all the points.
    spline: SplineHistory | None = None
    # A blended corner (blend.py): the two profiles whose sum ``segments`` is; None otherwise.
    blended_from: BlendParts | None = None
    duration: float = field(init=False)
    _table: SegmentTable | None = field(init=False, default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        source = self.source
        if not source.values:  # a plan holds at least its end
            source = self.source = Listed([Segment(0.0, self.target, self.final_velocity, 0.0, 0.0)], source.limits())
        if self.cam is not None:
            self.duration = self.cam.duration
        elif source.total is None:
            self.duration = end_time(source.values, self.origin_time)
        else:
            self.duration = self.origin_time + source.total

    @property
    def segments(self) -> list[Segment]:
        return self.source.segments()

    @property
    def limits(self) -> Trajectory | None:
        """The limits this axis' profile was planned with."""
        return self.source.limits()

    @property
    def table(self) -> SegmentTable:
        """The segments as arrays. Built on first use, not with the plan: numpy on a handful of
        segments costs more than planning them, and a modify is planned while its command waits."""
        if self._table is None:
            self._table = SegmentTable(self.source.row_values(), self.origin_time)
        return self._table

    @property
    def is_velocity(self) -> bool:
        return self.velocity_target is not None

    @property
    def frame_count(self) -> int:
        """Frames this plan loads: its segments, the final frame, and a hold frame."""
        if self.cam is not None:
            return self.cam.table.frames  # the whole table stays loaded (a repeat runs it again)
        return self.segment_count + 1 + (1 if self.hold is not None else 0)

    @property
    def segment_count(self) -> int:
        return len(self.source.values)  # (a vector's share: without making its segments)

    def frames_left(self, rel: float) -> int:
        """Frames still in the buffer ``rel`` seconds of profile time into the plan."""
        if self.cam is not None:
            return self.frame_count
        done = bisect.bisect_right(self.table.ends, rel)
        return max(1, self.frame_count - done - (1 if self.hold is not None else 0))

    def points_left(self, rel: float | np.ndarray) -> int | np.ndarray:
        """Points of a path not reached by profile time ``rel`` (0 for other plans)."""
        if self.point_times is None:
            return 0 if np.ndim(rel) == 0 else np.zeros(np.shape(rel), dtype=np.int64)
        left = len(self.point_times) - np.searchsorted(self.point_times, reached(rel), side="right")
        if self.spline is not None:
            # an open B-spline has run out where its points settle the curve (docs/paths.md):
            # the points beyond cannot run until more come
            left = np.where(np.asarray(rel) >= self.duration, 0, left)
            return int(left) if np.ndim(rel) == 0 else left
        return left

    def element_at(self, rel: float) -> int | None:
        """The element id of the point a path runs toward at ``rel`` (its last one once
        there); None without per-point ids."""
        if not self.element_ids or self.point_times is None:
            return None
        i = int(np.searchsorted(self.point_times, reached(rel), side="right"))
        return self.element_ids[min(i, len(self.element_ids) - 1)]

    def start_feedforward(self, held: float) -> None:
        """The axis loads the plan holding feedforward ``held``: its feedforward starts there."""
        if self.feedforward is not None and math.isnan(self.feedforward[1][0]):
            self.feedforward[1][0] = held

    def feedforward_at(self, rel: float, held: float) -> float:
        """The feedforward at profile time ``rel`` (``held`` before the plan's first point, or
        without a feedforward of its own)."""
        if self.feedforward is None:
            return held
        times, values = self.feedforward
        if not math.isfinite(rel) or rel <= times[0]:
            return held if math.isnan(values[0]) else float(values[0])
        return float(np.interp(rel, times, values))

    def evaluate(self, rel: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, d/dtau and d2/dtau2 of the plan at relative profile times.

        From the end on the command is exactly the end state: on target (spec: AT_TARGET
        is "command = target") at the final velocity, with zero acceleration.
        """
        inside = np.minimum(rel, self.duration)
        p, v, a, _ = self.table.evaluate(inside)
        complete = rel >= self.duration
        if complete.any():
            extra = np.maximum(rel - self.duration, 0.0)
            p = np.where(complete, self.target + self.final_velocity * extra, p)
            v = np.where(complete, self.final_velocity, v)
            a = np.where(complete, 0.0, a)
        return p, v, a

    def segment_poly(self, rel: float) -> tuple[float, list[float]]:
        """(start time, polynomial coefficients in time from it) of the piece at ``rel``."""
        if rel >= self.duration:
            return self.duration, [self.target, self.final_velocity]
        table = self.table
        # bisect_right is searchsorted(side="right") for one time (a nan rel too goes past the end)
        i = min(bisect.bisect_right(table.end, rel), table.count - 1)
        _, p, v, a, j = self.source.row_values()[i]  # (the stepping reads Rows as they are)
        return float(table.start[i]), [p, v, a / 2.0, j / 6.0]

    def boundaries(self) -> np.ndarray:
        """Relative profile times at which the command polynomial (or the feedforward) changes."""
        if self.feedforward is None:
            return self.table.end
        return np.union1d(self.table.end, self.feedforward[0])

    def feedforward_poly(self, rel: float, held: float) -> tuple[float, list[float]]:
        """(start time, [value, slope]) of the feedforward's linear piece at ``rel``."""
        if self.feedforward is None:
            return 0.0, [held]
        times, values = self.feedforward
        i = int(np.searchsorted(times, rel, side="right"))
        if i == 0 or i >= len(times):  # before the first knot, or held after the last
            return 0.0, [self.feedforward_at(rel, held)]
        slope = (values[i] - values[i - 1]) / (times[i] - times[i - 1])
        return float(times[i - 1]), [float(values[i - 1]), float(slope)]


@dataclass(slots=True)
class Stream:
    """The streaming state of an open path (MPIMotionPoint, MPIMotionPathAttrMask)."""

    open: bool  # final was false: more points are expected
    empty_count: int  # E_STOP when fewer points are left while open (<= 0: disabled)
    low_count: int  # FRAMES_LOW below this many points while open
    low_sent: bool = False  # FRAMES_LOW sent since the buffer was last refilled
    empty_sent: bool = False
    peaks: list[tuple[float, float]] = field(default_factory=list)  # per axis: max |v|, max |a|
    # Appended points not yet executed: (serial of the append, profile time of its last point
    # on each axis). An append is a command of its own: it ends when its points are done.
    chunks: list[tuple[int, dict[int, float]]] = field(default_factory=list)

    def append(self, chunk: Stream | None, open_: bool) -> None:
        """Points were appended (``chunk``: theirs; None: none, the path is only closed)."""
        self.open = open_
        self.low_sent = self.empty_sent = False
        if chunk is not None:
            self.peaks = [(max(v, cv), max(a, ca)) for (v, a), (cv, ca) in zip(self.peaks, chunk.peaks, strict=True)]

    def describe_peaks(self, axes: Sequence[int]) -> str:
        parts = [f"axis {n}: |v| {v:.6g} counts/s, |a| {a:.6g} counts/s^2"
                 for n, (v, a) in zip(axes, self.peaks, strict=True)]
        return "path peaks " + "; ".join(parts)


@dataclass(slots=True)
class Move:
    """A started (or appended) move of a supervisor."""

    supervisor: int
    type: MPIMotionType
    attributes: MotionAttr
    plans: list[AxisPlan]
    id: int = 0
    element_id: int = 0
    event_mask: MPIEventType = MPIEventType.NONE
    serial: int = 0  # given when a supervisor takes the move (SupervisorHost.next_serial)
    stream: Stream | None = None  # a path move: its streaming state
    blend: float = 0.0  # seconds it starts before the move ahead of it ends (blend.py, blendLimit)
    # Facts the controller asks every stretch (a move's plans never change once compiled).
    is_velocity: bool = field(init=False)  # a VELOCITY move
    ends_moving: bool = field(init=False)  # FINAL_VEL: the axes go on at their final velocity
    plan_axes: tuple[int, ...] = field(init=False)  # the axes of its plans, in order

    def __post_init__(self) -> None:
        # one pass over the plans (a move is made for every start and modify)
        axes, velocity, moving = [], False, False
        for plan in self.plans:
            axes.append(plan.axis)
            velocity = velocity or plan.velocity_target is not None  # AxisPlan.is_velocity
            moving = moving or plan.final_velocity != 0.0
        self.plan_axes, self.is_velocity, self.ends_moving = tuple(axes), velocity, moving

    @property
    def axes(self) -> list[int]:
        return [plan.axis for plan in self.plans]

    def serials(self) -> set[int]:
        """Its serial and those of the appends to it not yet done."""
        chunks = self.stream.chunks if self.stream is not None else ()
        return {self.serial, *(serial for serial, _ in chunks)}

    def plan_for(self, axis: int) -> AxisPlan | None:
        for plan in self.plans:
            if plan.axis == axis:
                return plan
        return None

    @property
    def frame_counts(self) -> dict[int, int]:
        return {plan.axis: plan.frame_count for plan in self.plans}


def frames_needed(moves: Sequence[Move], axis: int) -> int:
    return sum(move.frame_counts.get(axis, 0) for move in moves)
