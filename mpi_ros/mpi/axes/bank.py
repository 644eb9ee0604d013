"""Every axis' state as arrays across axes, owned by the controller.

The values at the current sample (command and actual position, velocity, acceleration,
profile time), the status bits and the settling counters live here, one column per axis;
an :class:`~.axis.Axis` is a view of its column plus the plan it runs. Beside them sit
the *rows* a stretch is computed from, one per axis: the command piece and plant anchor
in force (:class:`CommandRows`, :class:`PlantRows`), what the status bits depend on
(:class:`~.status.StatusRows`) and each supervisor's feedrate clock (:class:`ClockRows`).
An axis rebuilds its rows only when something they derive from changes (its plan,
anchor, mode, owner, clock or tolerances mark them stale), so a stretch costs array
operations across axes, not Python calls per axis.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable
from dataclasses import dataclass, fields
from enum import IntEnum
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from mpi_ros.mpi.axes.plant import _MAX_DEGREE, Forced, Plant, PlantState, _FreeTable
from mpi_ros.mpi.axes.status import BITS, StatusRows
from mpi_ros.mpi.base.clock import ProfileClock

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

    from mpi_ros.mpi.planning.frames import AxisPlan

VALUES = ("cmd_p", "cmd_v", "cmd_a", "act_p", "act_v", "rel")  # an axis' values at a sample
_MAX_TERMS = _MAX_DEGREE + 1  # coefficients of a piece's steady response
_AT_REST = 1 << 30  # settling counters of an axis that has long been at rest
T = TypeVar("T")
Rows = TypeVar("Rows", bound="DataclassInstance")


class Kind(IntEnum):
    """How a stretch computes an axis."""

    STEADY = 0  # at rest, settled on its command: every sample is the same
    PIECE = 1  # command pieces from a plant anchor: rows of closed forms (one per piece)
    SAMPLED = 2  # coasting, or the command follows the actual: one axis at a time (Axis.trace)


def _arrays(cls: type[Rows], count: int, ints: tuple[str, ...] = (), flags: tuple[str, ...] = (),
            **fill: float) -> Rows:
    """An instance of the row dataclass ``cls`` with every field an array of ``count``."""
    def make(name: str) -> np.ndarray:
        if name in ints:
            return np.zeros(count, dtype=np.int64)
        if name in flags:
            return np.zeros(count, dtype=bool)
        return np.full(count, fill.get(name, 0.0))
    return cls(**{f.name: make(f.name) for f in fields(cls)})


@dataclass(slots=True)
class CommandRows:
    """The command each axis follows. ``planned`` rows run a plan through their owner's
    clock (index ``clock``), evaluated in the segment ``segment`` (valid while the profile
    time stays in [seg_lo, seg_hi)); the others rest at ``rest``."""

    planned: np.ndarray
    clock: np.ndarray
    tau_start: np.ndarray
    duration: np.ndarray
    target: np.ndarray
    final_velocity: np.ndarray
    truncated: np.ndarray  # a frame hit the 16,384,000-sample limit
    segment: np.ndarray  # -1: none chosen yet
    linear: np.ndarray  # its acceleration and jerk are +0.0 (see stretch._linear)
    seg_lo: np.ndarray
    seg_hi: np.ndarray
    seg_start: np.ndarray
    p: np.ndarray
    v: np.ndarray
    a: np.ndarray
    j: np.ndarray
    rest: np.ndarray

    @classmethod
    def empty(cls, count: int) -> CommandRows:
        return _arrays(cls, count, ints=("clock", "segment"), flags=("planned", "truncated", "linear"))

    def set_segment(self, row: int, plan: AxisPlan, index: int) -> None:
        """Evaluate ``row`` in segment ``index`` of ``plan``'s table (the profile times that
        SegmentTable.index maps to it: [end of the one before, its end), open at the ends)."""
        table = plan.table
        self.segment[row] = index
        self.seg_lo[row] = table.end[index - 1] if index > 0 else -math.inf
        self.seg_hi[row] = table.end[index] if index < table.count - 1 else math.inf
        self.seg_start[row] = table.start[index]
        for name in ("p", "v", "a", "j"):
            getattr(self, name)[row] = getattr(table, name)[index]
        a, j = float(table.a[index]), float(table.j[index])
        self.linear[row] = a == 0.0 and j == 0.0 and not math.copysign(1.0, a) < 0.0 and not math.copysign(1.0, j) < 0.0


@dataclass(slots=True)
class PlantRows:
    """The servo of each axis from the anchor of its current command piece: the steady
    response (polynomial coefficients in time from the anchor, low first, zero-padded to
    (axes, 7)) and the transient (plant.Transient; zero where there is none)."""

    steady_y: np.ndarray
    steady_dy: np.ndarray
    anchor_t: np.ndarray
    piece_end: np.ndarray  # time the command piece ends (the next breakpoint)
    terms: np.ndarray  # coefficients in use (the longest row decides how many are evaluated)
    k0: np.ndarray
    v0: np.ndarray
    v1: np.ndarray
    m0: np.ndarray
    m1: np.ndarray
    decayed_after: np.ndarray  # -inf: no transient; inf: never dropped
    vanishing: np.ndarray  # sample from which the transient is exact zeros (inf: never)
    table: np.ndarray  # index into AxisBank.tables
    resolution: np.ndarray
    snap_after: np.ndarray  # at rest: seconds past the anchor from which it snaps onto the command (Axis.commit)

    @classmethod
    def empty(cls, count: int) -> PlantRows:
        rows = _arrays(cls, count, ints=("terms", "k0", "table"), piece_end=math.inf, snap_after=math.inf,
                       vanishing=math.inf)
        rows.steady_y = np.zeros((count, _MAX_TERMS))
        rows.steady_dy = np.zeros((count, _MAX_TERMS))
        return rows

    @classmethod
    def of_pieces(cls, pieces: list[tuple[PlantState, float, Forced, Plant, float]],
                  table_index: Callable[[_FreeTable], int]) -> PlantRows:
        """One row per piece (anchor, end, steady response, plant, rate; see :meth:`set_piece`),
        each column made from a list at once: setting a row's dozen numpy elements one by one
        costs more than computing them."""
        rows = [_piece_row(*piece, table_index) for piece in pieces]
        count = len(rows)
        columns = list(zip(*rows, strict=True)) if rows else [()] * (2 + len(_PIECE_COLUMNS))
        scalars = {name: np.array(column, dtype=np.int64 if name in _INT_COLUMNS else float)
                   for name, column in zip(_PIECE_COLUMNS, columns[2:], strict=True)}
        return cls(steady_y=np.array(columns[0], dtype=float).reshape(count, _MAX_TERMS),
                   steady_dy=np.array(columns[1], dtype=float).reshape(count, _MAX_TERMS),
                   snap_after=np.full(count, math.inf), **scalars)

    def set_piece(self, row: int, anchor: PlantState, end: float, forced: Forced, plant: Plant, rate: float,
                  table_index: Callable[[_FreeTable], int]) -> None:
        """Row ``row``: the servo ``plant`` from ``anchor`` through a command piece ending at
        ``end`` with steady response ``forced`` (``table_index(table)`` numbers free-response
        tables)."""
        steady_y, steady_dy, *scalars = _piece_row(anchor, end, forced, plant, rate, table_index)
        self.steady_y[row] = steady_y
        self.steady_dy[row] = steady_dy
        for name, value in zip(_PIECE_COLUMNS, scalars, strict=True):
            getattr(self, name)[row] = value


# The columns of a piece's row besides its steady response (_piece_row gives them in this order).
_PIECE_COLUMNS = ("anchor_t", "piece_end", "terms", "k0", "v0", "v1", "m0", "m1", "decayed_after", "vanishing",
                  "table", "resolution")
_INT_COLUMNS = ("terms", "k0", "table")
# A piece's row: the steady response's coefficients (y, dy), then _PIECE_COLUMNS' values
PieceRow = tuple[list[float], list[float], float, float, int, int, float, float, float, float, float, float, int, float]


def _piece_row(anchor: PlantState, end: float, forced: Forced, plant: Plant, rate: float,
               table_index: Callable[[_FreeTable], int]) -> PieceRow:
    """A piece's row of PlantRows: the steady response's coefficients (zero-padded: rows are
    evaluated together to the longest one's length, exactly as plant.poly_eval evaluates one:
    trace._steady_response), then
    the values of _PIECE_COLUMNS; without a transient, k0 and the transient's parts 0,
    decayed_after -inf (none), vanishing inf and table 0 (unread)."""
    y, dy = trim_leading_zeros(forced.y), trim_leading_zeros(forced.dy)
    padded_y, padded_dy = y + [0.0] * (_MAX_TERMS - len(y)), dy + [0.0] * (_MAX_TERMS - len(dy))
    resolution = plant.config.encoder_resolution
    transient = plant.transient(anchor, forced, rate)
    if transient is None:
        return padded_y, padded_dy, anchor.t, end, len(y), 0, 0.0, 0.0, 0.0, 0.0, -math.inf, math.inf, 0, resolution
    return (padded_y, padded_dy, anchor.t, end, len(y), transient.k0, transient.v0, transient.v1, transient.m0,
            transient.m1, transient.decayed_after, transient.k0 + transient.table.vanishing_count(),
            table_index(transient.table), resolution)


def trim_leading_zeros(coefficients: list[float]) -> list[float]:
    """Coefficients (low first) that give what Horner's scheme (plant.poly_eval) gives for
    ``coefficients`` at every s > 0, to the bit: a leading -0.0 passes the next coefficient
    on unchanged (-0 s + c is c), a leading +0.0 passes it on as c + 0.0 (only a -0.0
    changes: to +0.0). The list itself when it has nothing to trim (not to be changed)."""
    if len(coefficients) <= 1 or coefficients[-1] != 0.0:  # (nearly every piece's)
        return coefficients
    out = list(coefficients)
    while len(out) > 1 and out[-1] == 0.0:
        leading = out.pop()
        if not math.copysign(1.0, leading) < 0.0:
            out[-1] = out[-1] + 0.0
    return out


@dataclass(slots=True)
class ClockRows:
    """Each supervisor's feedrate clock (clock.ProfileClock) as columns, by supervisor number."""

    t0: np.ndarray
    tau0: np.ndarray
    f0: np.ndarray
    f1: np.ndarray
    t_end: np.ndarray
    rate: np.ndarray

    @classmethod
    def empty(cls, count: int) -> ClockRows:
        return _arrays(cls, count, f0=1.0, f1=1.0)

    def set(self, number: int, clock: ProfileClock) -> None:
        self.t0[number], self.tau0[number], self.t_end[number] = clock.t0, clock.tau0, clock.t_end
        self.f0[number], self.f1[number], self.rate[number] = clock.f0, clock.f1, clock.rate

    def columns(self, numbers: np.ndarray) -> ClockColumns:
        """The clocks ``numbers`` (one per row: each planned row's own) as (rows, 1) columns
        (kept by the bank until a clock changes). A row computes its clock's values by the
        same operations as the clock's own row would: the same bits."""
        t0, tau0, f0, f1 = (a[numbers, None] for a in (self.t0, self.tau0, self.f0, self.f1))
        t_end, rate = self.t_end[numbers, None], self.rate[numbers, None]
        dt = t_end - t0
        tau_end = tau0 + dt * (f0 + 0.5 * rate * dt)  # as ProfileClock.tau sums it at t >= t_end
        return ClockColumns(t0, tau0, f0, f1, t_end, rate, tau_end, float(t_end.max(initial=-math.inf)),
                            np.zeros_like(f1), bool((f1 >= 0.0).all()))


@dataclass(frozen=True, slots=True)
class ClockColumns:
    t0: np.ndarray
    tau0: np.ndarray
    f0: np.ndarray
    f1: np.ndarray
    t_end: np.ndarray
    rate: np.ndarray
    tau_end: np.ndarray
    last_end: float
    no_slope: np.ndarray
    forward: bool  # is every final feedrate >= 0 (tau never decreases past the ramps)?

    def ramping(self, t: np.ndarray) -> bool:
        """Does a clock ramp at a time of ``t`` (sorted)?"""
        return bool(t[0] < self.last_end)

    def evaluate(self, t: np.ndarray, into: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """tau, feedrate and its slope at times ``t``, each element computed exactly as
        ProfileClock.tau and .feedrates compute it: tau as (rows, samples) (``into``), the
        feedrate and slope as (rows, 1) columns where no clock ramps (the same arrays every
        time)."""
        if not self.ramping(t):
            # Past every ramp min(t, t_end) is t_end and max(t - t_end, 0) is t - t_end, to the
            # bit: tau = tau_end + f1 (t - t_end).
            tau = np.subtract(t, self.t_end, out=into)
            tau *= self.f1
            tau += self.tau_end
            return tau, self.f1, self.no_slope
        t0, f0, f1, t_end, rate = self.t0, self.f0, self.f1, self.t_end, self.rate
        dt = np.minimum(t, t_end) - t0
        tau = np.add(self.tau0, dt * (f0 + 0.5 * rate * dt), out=into)
        tau += f1 * np.maximum(t - t_end, 0.0)
        in_ramp = t < t_end
        f = np.where(in_ramp, f0 + rate * (t - t0), f1)
        return tau, f, np.where(in_ramp, rate, 0.0)


class AxisBank:
    """The axes' state and rows (see the module docstring), indexed by axis number."""

    def __init__(self, axis_count: int, supervisor_count: int):
        self.count = axis_count
        # values at the controller's current sample (raw positions), in VALUES order, one block
        self.values = np.zeros((len(VALUES), axis_count))
        self.cmd_p, self.cmd_v, self.cmd_a, self.act_p, self.act_v, self.rel = self.values
        self.rel[:] = math.nan  # profile time into the plan (nan without one)
        # A new controller's axes rest settled on their command.
        self.bits = np.ones((len(BITS), axis_count), dtype=bool)
        self.bits[BITS.index("at_velocity")] = False
        self.runs = np.zeros((3, axis_count), dtype=np.int64)  # status.FINE_RUN, SETTLED_RUN, VELOCITY_RUN
        self.runs[:2] = _AT_REST
        # rows
        self.stale = np.ones(axis_count, dtype=bool)  # rebuild every row of the axis
        self.moved = np.zeros(axis_count, dtype=bool)  # its plant anchor moved: rebuild those rows
        self.kind = np.full(axis_count, Kind.SAMPLED, dtype=np.int8)
        self.owner = np.full(axis_count, -1, dtype=np.int64)
        self.plans: list[AxisPlan | None] = [None] * axis_count  # the AxisPlan each row was written for
        self.command = CommandRows.empty(axis_count)
        self.plant = PlantRows.empty(axis_count)
        self.status = StatusRows.empty(axis_count)
        self.clocks = ClockRows.empty(supervisor_count)
        self.tables: list[_FreeTable] = []
        # (values of any type, each the type its caller's compute gives: memo, command_memo, clock_memo)
        self._memo: dict[Hashable, Any] = {}
        self._command_memo: dict[Hashable, Any] = {}  # derived from the command rows: kept while an anchor moves
        self._clock_memo: dict[Hashable, Any] = {}  # derived from the clocks alone: kept while no clock changes

    def refresh(self, refresh_row: Callable[[int], None], reanchor_row: Callable[[int], None]) -> None:
        """Rebuild the stale rows (``refresh_row(number)`` does an axis), and those of the
        axes whose anchor moved (``reanchor_row(number)``)."""
        if not (self.stale.any() or self.moved.any()):  # (most stretches: one test each)
            return
        stale, moved = np.flatnonzero(self.stale), np.flatnonzero(self.moved & ~self.stale)
        if len(stale):
            self._command_memo.clear()
        if len(stale) or len(moved):
            # A moved anchor changes only the axes' kinds and plant rows: what derives from
            # the command rows alone (command_memo: the truncated plans) stands, and is not
            # redone at every piece an axis starts (each sample, stepped a sample at a time).
            self._memo.clear()
            for row in stale.tolist():
                refresh_row(row)
            for row in moved.tolist():
                reanchor_row(row)

    def of_kind(self, kind: Kind) -> np.ndarray:
        """The axes (sorted) a stretch computes as ``kind``."""
        return self.memo(kind, lambda: np.flatnonzero(self.kind == kind))

    def memo(self, key: Hashable, compute: Callable[[], T]) -> T:
        """A value derived from the rows, kept until one changes (``compute()`` makes it)."""
        return _memoised(self._memo, key, compute)

    def forget(self, key: Hashable) -> None:
        """Drop what :meth:`memo` keeps for ``key`` (a row it derives from changed)."""
        self._memo.pop(key, None)

    def command_memo(self, key: Hashable, compute: Callable[[], T]) -> T:
        """:meth:`memo` for a value derived from the command rows alone: kept while only
        plant anchors move, until an axis' rows are rebuilt."""
        return _memoised(self._command_memo, key, compute)

    def clock_memo(self, key: Hashable, compute: Callable[[], T]) -> T:
        """:meth:`memo` for a value derived from the clocks (ClockRows) and ``key`` alone:
        kept across changes of the rows (a modify's new plan), until a clock changes."""
        if len(self._clock_memo) >= 64 and key not in self._clock_memo:  # (keys of rows no longer planned)
            self._clock_memo.clear()
        return _memoised(self._clock_memo, key, compute)

    def table_index(self, table: _FreeTable) -> int:
        """A small number for a free-response table (axes with identical loops share one)."""
        for i, known in enumerate(self.tables):
            if known is table:
                return i
        self.tables.append(table)
        return len(self.tables) - 1

    def clock_changed(self, number: int, clock: ProfileClock) -> None:
        """Supervisor ``number`` runs a new clock: its axes' pieces end here."""
        self.clocks.set(number, clock)
        self.stale |= self.owner == number
        self._memo.clear()
        self._command_memo.clear()
        self._clock_memo.clear()

    def reset_counters(self, row: int) -> None:
        self.runs[:, row] = 0


def _memoised(store: dict[Hashable, Any], key: Hashable, compute: Callable[[], T]) -> T:
    """``store[key]``, made by ``compute()`` the first time it is asked."""
    value: T | None = store.get(key)
    if value is None:
        value = store[key] = compute()
    return value
