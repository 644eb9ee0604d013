"""Axis status bits, generated exactly as the two tables at the end of MPI 002 say.

settleOnStop (settleOnEstop) = FALSE (the default):

| status             | after S-curve/trapezoidal | during velocity | after STOP (E-STOP)   | after ABORT |
| IN_FINE_POSITION   | target distance (note 3)  | FALSE           | FALSE                 | FALSE |
| IN_COARSE_POSITION | target distance           | FALSE           | FALSE                 | FALSE |
| AT_TARGET          | command = target          | FALSE           | FALSE                 | FALSE |
| DONE               | TC and IN_FINE_POSITION   | FALSE           | command velocity = 0  | TRUE  |

settleOnStop (settleOnEstop) = TRUE: after STOP (E-STOP) IN_FINE_POSITION is based on
position error (note 1) and DONE is the same as IN_FINE_POSITION.

NOTE 1: IN_FINE_POSITION after a stop = trajectory complete, |command - actual| < fine,
|target velocity - actual velocity| < velocity tolerance, all for the settling time.
NOTE 3: after a point-to-point move = trajectory complete, |target - actual| < fine,
|command velocity - actual velocity| < velocity tolerance, all for the settling time.
TC (trajectory complete, note 2) is set when all the move's frames have executed.

SETTLED (MEIEventTypeSETTLED) is the note-1 criterion after any stop of the command
(point-to-point done, or stopped): the axis has come to rest on its command.
AT_VELOCITY (velocity moves): the ramp is done and |command velocity - actual
velocity| < velocity tolerance for the settling time.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, fields
from enum import Enum
from typing import TYPE_CHECKING, Any

import numpy as np

from mpi_ros.mpi.base.params import AxisInPosition

if TYPE_CHECKING:
    from mpi_ros.mpi.axes.scratch import Scratch
    from mpi_ros.mpi.axes.stretch import Stretch
    from mpi_ros.mpi.planning.frames import AxisPlan

_STOPPED_VELOCITY = 1e-9
_NONE = np.zeros(0, dtype=np.int64)  # counts/s: "command velocity = 0"


class StatusMode(Enum):
    POINT_TO_POINT = "POINT_TO_POINT"
    VELOCITY = "VELOCITY"
    STOP = "STOP"
    E_STOP = "E_STOP"
    ABORT = "ABORT"


@dataclass(slots=True)
class AxisStatusBits:
    in_fine_position: bool = False
    in_coarse_position: bool = False
    at_target: bool = False
    done: bool = False
    settled: bool = False
    at_velocity: bool = False
    trajectory_complete: bool = False


BIT_NAMES = tuple(f.name for f in fields(AxisStatusBits))


# The order of the bits in arrays: the six that raise events first, in the order their
# events of one sample are emitted (as the controller has always emitted them).
BITS = ("done", "in_fine_position", "in_coarse_position", "at_target", "settled", "at_velocity",
        "trajectory_complete")
EVENT_BITS = 6
DONE, IN_FINE, IN_COARSE, AT_TARGET, SETTLED, AT_VELOCITY, TC = range(len(BITS))
# The settling counters in arrays: run lengths of the IN_FINE, SETTLED and AT_VELOCITY criteria.
FINE_RUN, SETTLED_RUN, VELOCITY_RUN = range(3)


def bits_of(column: np.ndarray) -> AxisStatusBits:
    """The bits of one axis from a column of an array in :data:`BITS` order."""
    return AxisStatusBits(**dict(zip(BITS, (bool(b) for b in column), strict=True)))


def column_of(bits: AxisStatusBits) -> list[bool]:
    return [getattr(bits, name) for name in BITS]


def settle_samples(in_position: AxisInPosition, sample_rate: float) -> int:
    """Consecutive samples a criterion must hold: the settling time, plus the first."""
    return max(0, math.ceil(in_position.settling_time * sample_rate - 1e-9)) + 1


def run_lengths(criterion: np.ndarray, carry: np.ndarray | int) -> np.ndarray:
    """Length of the run of True ending at each index along the last axis (continuing
    ``carry``, one per row)."""
    n = criterion.shape[-1]
    index = np.arange(1, n + 1)
    last_false = np.maximum.accumulate(np.where(criterion, 0, index), axis=-1)
    runs = index - last_false
    return np.where(last_false == 0, runs + np.asarray(carry)[..., None], runs)


@dataclass(slots=True)
class Runs:
    """Run lengths of one settling criterion over a stretch, one row per axis. A row the
    criterion holds throughout counts on from its carry, one it never holds is 0: only
    the rows that change are accumulated (the costly part)."""

    carry: np.ndarray  # (axes,)
    every: np.ndarray  # (axes,) rows that hold throughout
    mixed: np.ndarray  # indices of the rows that change
    mixed_runs: np.ndarray  # (len(mixed), samples)

    @classmethod
    def never(cls, count: int) -> Runs:
        return _never(count)

    def at(self, index: int, out: np.ndarray) -> None:
        """``out`` = every row's run length at stretch sample ``index``."""
        np.multiply(self.every, self.carry + (index + 1), out=out)
        if len(self.mixed):
            out[self.mixed] = self.mixed_runs[:, index]


@functools.cache
def _never(count: int) -> Runs:
    """The runs of a criterion that never holds, one for each number of axes (read only:
    a Runs is never changed once made)."""
    carry, every = np.zeros(count, dtype=np.int64), np.zeros(count, dtype=bool)
    carry.flags.writeable = every.flags.writeable = False
    return Runs(carry, every, _NONE, _NONE)


def settle(criterion: np.ndarray | None, carry: np.ndarray, need: np.ndarray, out: np.ndarray) -> Runs:
    """``out`` = the criterion (None: false throughout) has held for ``need`` samples (per
    row), and its runs."""
    if criterion is None or not criterion.any():
        out[...] = False
        return Runs.never(len(carry))
    n = criterion.shape[1]
    # criterion is 2-D, so this is an array; numpy's stubs cannot tell it from a 1-D array's
    # scalar (np.bool | NDArray[np.bool])
    every: np.ndarray = criterion.all(axis=1)  # type: ignore[assignment]
    # A row that holds throughout has run carry + i + 1 at sample i: on from i = need - 1 - carry.
    if every.all():  # (every row holds throughout: a steady bank, often)
        _on_from(need - 1 - carry, n, out)
        return Runs(carry, every, _NONE, _NONE)
    _on_from(np.where(every, need - 1 - carry, n), n, out)
    mixed = np.flatnonzero(criterion.any(axis=1) & ~every)
    if not len(mixed):
        return Runs(carry, every, mixed, _NONE)
    runs = run_lengths(criterion[mixed], carry[mixed])
    out[mixed] = runs >= need[mixed, None]
    return Runs(carry, every, mixed, runs)


_FLAGS = ("stop", "abort", "settle_on", "moving", "velocity", "point_to_point", "tc_always", "at_target_ok")


def _on_from(first: np.ndarray, n: int, out: np.ndarray) -> None:
    """``out`` = per row, true from sample ``first`` on, over ``n`` samples."""
    np.greater_equal(np.arange(n), first[:, None], out=out)


@dataclass(slots=True)
class StatusRows:
    """Per axis, what its status bits depend on besides the trace (MPI 002's two tables,
    see the module docstring), as columns: rebuilt for an axis when its move, mode or
    tolerances change."""

    stop: np.ndarray  # STOP or E_STOP: TC is "command velocity = 0"
    abort: np.ndarray
    settle_on: np.ndarray  # a stop with settling: settleOnStop (STOP) or settleOnEstop (E_STOP)
    moving: np.ndarray  # POINT_TO_POINT or VELOCITY
    velocity: np.ndarray  # a VELOCITY move
    point_to_point: np.ndarray  # moving, not a VELOCITY move: IN_COARSE by distance alone
    tc_always: np.ndarray  # no plan: the trajectory is complete
    tc_after: np.ndarray  # profile time from which TC holds (inf: never)
    ramp_end: np.ndarray
    target: np.ndarray
    at_target_ok: np.ndarray  # AT_TARGET can hold: a point-to-point move, not held
    fine: np.ndarray
    coarse: np.ndarray
    velocity_tol: np.ndarray
    need: np.ndarray  # samples a criterion must hold
    col: dict[str, np.ndarray] = field(default_factory=dict)  # (axes, 1) views of the above
    _any: dict[str, bool] = field(default_factory=dict)  # has any row the flag? (until a row changes)

    @classmethod
    def empty(cls, count: int) -> StatusRows:
        names = [f.name for f in fields(cls) if f.name not in ("col", "_any")]
        arrays: dict[str, Any] = {name: np.zeros(count, dtype=bool if name in _FLAGS else
                                                 (np.int64 if name == "need" else float)) for name in names}
        rows = cls(**arrays)
        rows.col = {name: getattr(rows, name)[:, None] for name in names}
        return rows

    def any(self, flag: str) -> bool:
        found = self._any.get(flag)
        if found is None:
            found = self._any[flag] = bool(getattr(self, flag).any())
        return found

    def set(self, row: int, mode: StatusMode, in_position: AxisInPosition, sample_rate: float,
            target: float, holding: bool, plan: AxisPlan | None) -> None:
        """Row ``row`` for an axis in ``mode`` running ``plan`` (an AxisPlan or None)."""
        self._any.clear()
        stop = mode in (StatusMode.STOP, StatusMode.E_STOP)
        velocity = plan is not None and plan.velocity_target is not None
        # A held move has not started; the last frame of a FINAL_VEL move runs on at the
        # final velocity: neither completes.
        never = holding or (plan is not None and plan.final_velocity != 0.0)
        self.stop[row] = stop
        self.abort[row] = mode is StatusMode.ABORT
        self.settle_on[row] = stop and (in_position.settle_on_stop if mode is StatusMode.STOP
                                        else in_position.settle_on_estop)
        self.moving[row] = moving = mode in (StatusMode.POINT_TO_POINT, StatusMode.VELOCITY)
        self.velocity[row] = moving and velocity
        self.point_to_point[row] = moving and not velocity
        self.tc_always[row] = not never and plan is None
        self.tc_after[row] = plan.duration if plan is not None and not never else math.inf
        self.ramp_end[row] = plan.ramp_end if plan is not None else 0.0
        self.target[row] = target
        self.at_target_ok[row] = moving and not velocity and not holding
        self.fine[row] = in_position.position_fine
        self.coarse[row] = in_position.position_coarse
        self.velocity_tol[row] = in_position.velocity
        self.need[row] = settle_samples(in_position, sample_rate)


@dataclass(slots=True)
class StretchStatus:
    """The status bits of every axis at every sample of a stretch: ``bits[b, axis, i]``
    (b in :data:`BITS` order), and the settling runs to carry on from any sample."""

    bits: np.ndarray
    runs: tuple[Runs | _PickedRuns, Runs, Runs]  # FINE_RUN, SETTLED_RUN, VELOCITY_RUN
    _ever: dict[int, list[bool]] = field(default_factory=dict)

    def ever(self, bit: int) -> list[bool]:
        """Per axis: is ``bit`` set anywhere in the stretch? (cheap tests before a scan)"""
        found = self._ever.get(bit)
        if found is None:
            found = self._ever[bit] = self.bits[bit].any(axis=1).tolist()
        return found

    def counters_at(self, index: int, out: np.ndarray) -> None:
        """``out`` = the (3, axes) settling counters at stretch sample ``index``."""
        for row, runs in zip(out, self.runs, strict=True):
            runs.at(index, row)


class _Arrays:
    """Named scratch arrays of a stretch's shape (stretch.Scratch), reused by the next one."""

    def __init__(self, scratch: Scratch, shape: tuple[int, int], cmd_v: np.ndarray) -> None:
        self.scratch, self.shape = scratch, shape
        self._cmd_v = cmd_v
        self._stopped: np.ndarray | None = None

    def stopped(self) -> np.ndarray:
        """|command velocity| < _STOPPED_VELOCITY: made the first time it is read (a stop's
        TC and DONE, AT_TARGET, the settling at rest; none of them during velocity moves)."""
        if self._stopped is None:
            speed = np.abs(self._cmd_v, out=self.real("speed"))
            self._stopped = np.less(speed, _STOPPED_VELOCITY, out=self.flag("stopped"))
        return self._stopped

    def real(self, name: str) -> np.ndarray:
        return self.scratch.take("status." + name, self.shape)

    def flag(self, name: str) -> np.ndarray:
        return self.scratch.take("status." + name, self.shape, bool)

    def absolute_difference(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        difference = np.subtract(a, b, out=self.real("difference"))
        absolute: np.ndarray = np.abs(difference, out=difference)  # (numpy's stubs: Any with out=)
        return absolute


def compute(trace: Stretch, rows: StatusRows, counters: np.ndarray, scratch: Scratch) -> StretchStatus:
    """Status bits of every axis at every sample of a stretch (``trace`` has (axes, samples)
    arrays cmd_p, cmd_v, act_p, act_v, rel; ``counters`` the (3, axes) carried runs). A
    criterion that cannot hold anywhere (say, no trajectory complete) is not computed."""
    col = rows.col
    work = _Arrays(scratch, trace.cmd_p.shape, trace.cmd_v)
    bits = scratch.take("status.bits", (len(BITS), *trace.cmd_p.shape), bool)
    velocity_ok = np.less(work.absolute_difference(trace.cmd_v, trace.act_v), col["velocity_tol"],
                          out=work.flag("velocity_ok"))
    tc = _trajectory_complete(trace.rel, work, rows, bits[TC])
    complete = bool(tc.any())
    # Note 1: at rest on the command (SETTLED; IN_FINE after a stop with settling on).
    at_rest = np.logical_and(tc, work.stopped(), out=work.flag("at_rest")) if complete else None
    if at_rest is not None and at_rest.any():
        at_rest &= np.less(work.absolute_difference(trace.cmd_p, trace.act_p), col["fine"], out=work.flag("near"))
        at_rest &= velocity_ok
        at_rest &= ~col["abort"]
    settled_runs = settle(at_rest, counters[SETTLED_RUN], rows.need, bits[SETTLED])
    in_position_runs = _in_position(trace, rows, tc, complete, velocity_ok, counters, bits, work)
    fine_runs: Runs | _PickedRuns = in_position_runs
    if rows.any("settle_on"):
        # After a stop with settling on, IN_FINE is the note-1 criterion.
        np.copyto(bits[IN_FINE], bits[SETTLED], where=rows.col["settle_on"])
        fine_runs = _PickedRuns(rows.settle_on, settled_runs, in_position_runs)
    velocity_runs = _at_velocity(trace, rows, tc if complete else None, velocity_ok, counters, bits, work)
    # AT_TARGET: "TRUE when command = target" (002's table), at rest there; an axis of a
    # SYNC_START move that arrives early is at its target while the others still move.
    if rows.any("at_target_ok"):
        at_target = np.equal(trace.cmd_p, col["target"], out=bits[AT_TARGET])
        at_target &= work.stopped()
        at_target &= col["at_target_ok"]
    else:
        bits[AT_TARGET] = False
    _done(rows, tc if complete else None, work, bits)
    return StretchStatus(bits, (fine_runs, settled_runs, velocity_runs))


def _trajectory_complete(rel: np.ndarray, work: _Arrays, rows: StatusRows, out: np.ndarray) -> np.ndarray:
    """TC: every frame executed (after a stop: the command has stopped)."""
    np.greater_equal(rel, rows.col["tc_after"], out=out)
    if rows.any("tc_always"):
        out |= rows.col["tc_always"]
    if rows.any("stop"):
        np.copyto(out, work.stopped(), where=rows.col["stop"])
    return out


def _in_position(trace: Stretch, rows: StatusRows, tc: np.ndarray, complete: bool, velocity_ok: np.ndarray,
                 counters: np.ndarray, bits: np.ndarray, work: _Arrays) -> Runs:
    """Note 3 (after a point-to-point move, distance to the target): IN_FINE and
    IN_COARSE, which during a velocity move (until its frame ends) are FALSE."""
    col = rows.col
    coarse_possible = complete or rows.any("point_to_point")
    distance = work.absolute_difference(col["target"], trace.act_p) if coarse_possible else None
    fine = None
    if complete and distance is not None:  # (complete: coarse is possible, there is a distance)
        fine = np.less(distance, col["fine"], out=work.flag("fine"))
        fine &= tc
        fine &= velocity_ok
        fine &= col["moving"]
    runs = settle(fine, counters[FINE_RUN], rows.need, bits[IN_FINE])
    if distance is not None:  # coarse_possible
        coarse = np.less(distance, col["coarse"], out=bits[IN_COARSE])
        coarse &= col["moving"]
        coarse &= np.logical_or(tc, ~col["velocity"], out=work.flag("complete_or_not_velocity"))
    else:
        bits[IN_COARSE] = False
    return runs


def _at_velocity(trace: Stretch, rows: StatusRows, tc: np.ndarray | None, velocity_ok: np.ndarray,
                 counters: np.ndarray, bits: np.ndarray, work: _Arrays) -> Runs:
    """AT_VELOCITY (velocity moves): the ramp done, at the velocity for the settling time,
    the trajectory not complete (``tc``; None: complete nowhere)."""
    ramp_done = None
    if rows.any("velocity"):
        ramp_done = np.greater_equal(trace.rel, rows.col["ramp_end"], out=work.flag("ramp_done"))
        if tc is not None:
            ramp_done &= np.logical_not(tc, out=work.flag("incomplete"))
        ramp_done &= velocity_ok
        ramp_done &= rows.col["velocity"]
    return settle(ramp_done, counters[VELOCITY_RUN], rows.need, bits[AT_VELOCITY])


def _done(rows: StatusRows, tc: np.ndarray | None, work: _Arrays, bits: np.ndarray) -> None:
    """DONE: TC (None: complete nowhere) and IN_FINE after a move; after a stop, command
    velocity = 0 (or, settling on, IN_FINE); always after ABORT."""
    col = rows.col
    done = bits[DONE]
    if tc is None:
        done[...] = False
    else:
        np.logical_and(tc, bits[IN_FINE], out=done)
        done &= col["moving"]
    if rows.any("stop"):
        done |= col["stop"] & ~col["settle_on"] & work.stopped()
        done |= col["settle_on"] & bits[IN_FINE]
    if rows.any("abort"):
        done |= col["abort"]


@dataclass(slots=True)
class _PickedRuns:
    """Runs that are ``chosen``'s on ``rows`` and ``other``'s elsewhere."""

    rows: np.ndarray
    chosen: Runs
    other: Runs

    def at(self, index: int, out: np.ndarray) -> None:
        chosen = np.empty_like(out)
        self.chosen.at(index, chosen)
        self.other.at(index, out)
        np.copyto(out, chosen, where=self.rows)
