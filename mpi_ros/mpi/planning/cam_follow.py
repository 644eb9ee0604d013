"""How a cam's slave follows its master, sample by sample: the backtrack rule, the progress
along the table and what a stop does to it (planning/cams.py plans a cam; its docstring gives
the recurrence, MPI 000 MPIMotionCam, REPEAT, MASTER_START, NO_BACKTRACK, NO_BACKTRACK_HOLD)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from mpi_ros.mpi.base.params import AxisMaster
from mpi_ros.mpi.base.types import MotionAttr
from mpi_ros.mpi.planning.profiles.cam import CamTable


class Backtrack(Enum):
    """What the slave does when the master reverses (MPI 000, MPIMotionAttrMask)."""

    FOLLOW = "FOLLOW"  # neither attribute: the slave follows the master back
    NO_BACKTRACK = "NO_BACKTRACK"
    NO_BACKTRACK_HOLD = "NO_BACKTRACK_HOLD"

    @classmethod
    def of(cls, attrs: MotionAttr) -> Backtrack:
        if MotionAttr.NO_BACKTRACK in attrs:
            return cls.NO_BACKTRACK
        if MotionAttr.NO_BACKTRACK_HOLD in attrs:
            return cls.NO_BACKTRACK_HOLD
        return cls.FOLLOW


@dataclass(frozen=True, slots=True)
class CamState:
    """A slave's progress at one sample: the master's travel ``x`` (before the start, never
    past it), the reference ``r``, the offset, the progress ``u`` = r + offset, started (the
    master reached the start), finished (the end of a non-repeating table reached), and above
    (MASTER_START with the master past ``masterStart`` when the cam started: it starts when
    the master comes back to it)."""

    x: float
    r: float
    offset: float
    u: float
    started: bool
    finished: bool
    above: bool = False

    @classmethod
    def at_start(cls, x: float) -> CamState:
        """At the start, with the master at travel ``x`` (0 unless MASTER_START)."""
        return cls(min(x, 0.0), min(x, 0.0), 0.0, min(x, 0.0), x == 0.0, False, x > 0.0)


@dataclass(slots=True)
class Progress:
    """The progress over a stretch, and the state at each of its samples (kept until the
    controller commits one of them)."""

    x: np.ndarray
    r: np.ndarray
    offset: np.ndarray
    u: np.ndarray
    started: np.ndarray
    finished: np.ndarray

    def state(self, i: int, above: bool) -> CamState:
        return CamState(float(self.x[i]), float(self.r[i]), float(self.offset[i]), float(self.u[i]),
                        bool(self.started[i]), bool(self.finished[i]), above)


def progress(mode: Backtrack, x: np.ndarray, scale: np.ndarray, state: CamState, end: float | None) -> Progress:
    """The slave's progress at travels ``x`` with feedrate ratios ``scale``, from ``state``
    (the sample before the first); ``end``: the travel at which the cam is complete."""
    # MASTER_START: the cam starts once the master reaches the start from the side it was on
    # (as a HOLD's position trigger: docs/decisions.md); until then its travel counts as at
    # most 0, so the slave waits at its start and no backtrack rule remembers a travel beyond.
    started = state.started | np.logical_or.accumulate((x <= 0.0) if state.above else (x >= 0.0))
    pre = ~started
    x = np.where(started, x, np.minimum(x, 0.0))
    r, step = _reference(mode, x, state, started)
    step = np.where(pre, 0.0, step)
    if np.all(scale == 1.0):
        offset = np.full_like(x, state.offset)
        u = np.where(pre, x, r + state.offset)
    else:
        u, offset = _scaled(x, r, step, scale, pre, state)
    if end is None:
        finished = np.full(x.shape, state.finished)
    else:
        finished = np.logical_or.accumulate(u >= end) | state.finished
        u = np.where(finished, end, u)
    return Progress(x, r, offset, u, started, finished)


def _reference(mode: Backtrack, x: np.ndarray, state: CamState, started: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(reference, its step at each sample) under the backtrack rule; before the start r = x."""
    previous = np.concatenate(([state.x], x[:-1]))
    if mode is Backtrack.FOLLOW:
        return x, x - previous
    if mode is Backtrack.NO_BACKTRACK_HOLD:
        # furthest point reached; before the start x <= 0, so the first x >= 0 is past all of them
        r = np.maximum.accumulate(np.concatenate(([state.r], x)))[1:]
        r = np.where(started, r, x)
        return r, r - np.concatenate(([state.r], r[:-1]))
    # NO_BACKTRACK: the forward steps, summed from the start (a cumulative sum adds one step
    # after the other, as a sample-by-sample loop would)
    forward = np.maximum(x - previous, 0.0)
    first = int(np.argmax(started)) if started.any() else len(x)
    seed = state.r if first == 0 else float(x[first - 1])
    r = x.copy()
    r[first:] = np.cumsum(np.concatenate(([seed], forward[first:])))[1:]
    return r, forward


def _scaled(x: np.ndarray, r: np.ndarray, step: np.ndarray, scale: np.ndarray, pre: np.ndarray,
            state: CamState) -> tuple[np.ndarray, np.ndarray]:
    """Progress while the feedrate is off its normal value somewhere in the stretch, sample by
    sample: at the normal feedrate u = r + offset (as :func:`progress` computes it), else u
    grows by the scaled step and the offset follows."""
    n = len(x)
    u = np.empty(n)
    offset = np.empty(n)
    u_prev, off = state.u, state.offset
    for k in range(n):
        if pre[k]:
            value = float(x[k])
        elif scale[k] == 1.0:
            value = float(r[k]) + off
        else:
            value = u_prev + float(scale[k]) * float(step[k])
            off = value - float(r[k])
        u[k], offset[k], u_prev = value, off, value
    return u, offset


@dataclass(slots=True)
class CamFollow:
    """One slave axis' part of a cam move: its table, its master (MPIAxisConfig.master as it
    was when the cam started), the table's direction along the master (+1 or -1), the master
    position at travel 0, the backtrack rule, the slave's raw command at the start, and its
    progress at the last committed sample. ``frame``: the origins the master was read less at
    the start (masters.Sources.frame); it is read so for the whole cam."""

    table: CamTable
    master: AxisMaster
    direction: float
    origin: float
    mode: Backtrack
    start: float
    state: CamState
    frame: float = 0.0
    pending: tuple[np.ndarray, Progress] | None = None  # the last stretch traced: (times, progress)

    def travel(self, master: np.ndarray) -> np.ndarray:
        """The master's travel along the table at master positions ``master``."""
        return (master - self.origin) * self.direction

    def follow(self, t: np.ndarray, master: np.ndarray, scale: np.ndarray) -> np.ndarray:
        """The slave's raw command at times ``t`` where the master is at ``master``; the
        progress is kept until :meth:`commit`."""
        done = progress(self.mode, self.travel(master), scale, self.state, self.table.end)
        self.pending = (t, done)
        return self.start + self.table.position(done.u)

    def commit(self, t: float) -> None:
        """The controller keeps the stretch up to time ``t``: so does the progress."""
        if self.pending is None:
            return
        times, done = self.pending
        i = int(np.searchsorted(times, t, side="right")) - 1
        if i >= 0:
            self.state = done.state(i, self.state.above)
        self.pending = None

    @property
    def target(self) -> float:
        """The raw position at the table's end (a repeating cam: the end of its first pass)."""
        return self.start + float(self.table.slave[-1])

    @property
    def duration(self) -> float:
        """The progress at which the cam is complete: its 'trajectory complete' (inf: never)."""
        end = self.table.end
        return math.inf if end is None else end
