"""Every axis over a stretch of samples at once: (axes, samples) arrays.

The controller computes the samples k0+1 .. k1 of every axis from the rows in its
AxisBank: an axis at rest repeats its values; an axis whose command piece and plant
anchor hold over the whole stretch (nearly every axis, nearly always) is one row of
closed forms evaluated together with the others (its supervisor's feedrate clock, the
constant-jerk segment, the servo's steady response and transient); the rest (coasting,
command following the actual, a breakpoint inside the stretch) are traced one axis at a
time (Axis.trace). Every element is computed by the same operations as the one-axis code
computes it, or by fewer that give the same bits (each such shortcut says why), so a
value never depends on which way it was computed, and so never on how the samples were
batched.

The arrays live in a :class:`Scratch` and are reused by the next stretch.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from mpi_ros.mpi.axes.axis import Axis
from mpi_ros.mpi.axes.bank import VALUES, AxisBank, ClockColumns, CommandRows, Kind, PlantRows
from mpi_ros.mpi.axes.plant import _FreeTable
from mpi_ros.mpi.axes.scratch import Scratch
from mpi_ros.mpi.axes.stretch import Stretch
from mpi_ros.mpi.base.clock import ProfileClock

# A cam slave's inputs over a stretch: its master position and feedrate ratio at each sample,
# read from the stretch as far as it is traced (controller.py).
CamInputs = Callable[[Axis, Stretch], tuple[np.ndarray, np.ndarray]]


def trace(bank: AxisBank, axes: list[Axis], clock_of: Callable[[Axis], ProfileClock | None],
          k0: int, k1: int, rate: float, scratch: Scratch, cam_inputs: CamInputs | None = None) -> Stretch:
    """Samples k0+1 .. k1 of every axis, from the bank's (fresh) rows; changes nothing but
    the cam slaves' progress, kept aside until the controller commits."""
    samples = np.arange(k0 + 1, k1 + 1, dtype=np.int64)
    t = samples / rate
    values = scratch.take("values", (len(VALUES), bank.count, len(samples)))
    cmd_p, cmd_v, cmd_a, act_p, act_v, rel = values  # bank.VALUES order
    out = Stretch(samples, t, cmd_p, cmd_v, cmd_a, act_p, act_v, rel, values=values, scratch=scratch)
    _steady(bank, bank.of_kind(Kind.STEADY), out)
    rows = bank.of_kind(Kind.PIECE)
    if len(rows):
        _command(bank, rows, out)
        servos = bank.memo("servos", lambda: _Servos.of(bank.plant, rows))
        act_p, act_v = _servo(bank.tables, rows, servos, out, direct=True)
        out.place("act_p", rows, act_p)
        out.place("act_v", rows, act_v)
        if t[-1] < servos.first_end:  # (no piece ends inside the stretch: nearly always)
            out.pieces = rows
        else:
            ending = t[-1] >= servos.piece_end
            out.pieces = rows[~ending]
            _following_pieces(bank, axes, clock_of, rows[ending], out)
    for row in _sampled_order(bank.of_kind(Kind.SAMPLED).tolist(), axes):
        axis = axes[row]
        cam = cam_inputs(axis, out) if cam_inputs is not None and axis.camming else None
        one = axis.trace(k0, k1, clock_of(axis), cam)
        out.anchors[row] = one.anchors
        for name in VALUES:
            getattr(out, name)[row] = getattr(one, name)
    return out


def _sampled_order(rows: list[int], axes: list[Axis]) -> list[int]:
    """The axes traced one at a time, in an order in which a cam's slave comes after every
    axis its master position reads (a start refuses a cam whose masters would form a loop)."""
    slaves = [row for row in rows if axes[row].camming]
    if not slaves:
        return rows
    ordered = [row for row in rows if not axes[row].camming]
    waiting = set(slaves)
    while waiting:
        ready = sorted(row for row in waiting if not axes[row].cam_reads() & waiting)
        assert ready, f"cam masters form a loop among axes {sorted(waiting)}"  # refused at the start
        ordered += ready
        waiting -= set(ready)
    return ordered


def _steady(bank: AxisBank, rows: np.ndarray, out: Stretch) -> None:
    """At rest and settled: the command rests, the encoder reads what it reads now."""
    if not len(rows):
        return
    out.cmd_p[rows] = bank.command.rest[rows, None]
    out.act_p[rows] = bank.act_p[rows, None]
    for values in (out.cmd_v, out.cmd_a, out.act_v):
        values[rows] = 0.0
    out.rel[rows] = math.nan


# -- the command ------------------------------------------------------------------------
def _command(bank: AxisBank, rows: np.ndarray, out: Stretch) -> None:
    """Command of ``rows``: a plan read through the supervisor's clock, or the rest."""
    plans = bank.memo("plans", lambda: _Plans.of(bank.command, rows))
    resting = plans.resting
    if len(resting):
        out.cmd_p[resting] = bank.command.rest[resting, None]
        out.cmd_v[resting] = out.cmd_a[resting] = 0.0
        out.rel[resting] = math.nan
    if len(plans.rows):
        _planned(bank, plans, out)


@dataclass(frozen=True, slots=True)
class _Plans:
    """The pieces' rows that rest and those that run a plan, with what reading the plans
    takes of the command rows besides their segments (once per bank refresh)."""

    resting: np.ndarray
    rows: np.ndarray  # planned
    clocks: bytes  # the clocks the planned rows run on (the key, as a modify keeps them)
    tau_start: np.ndarray  # (rows, 1)
    duration: np.ndarray

    @classmethod
    def of(cls, command: CommandRows, rows: np.ndarray) -> _Plans:
        planned = command.planned[rows]
        chosen = rows[planned]
        return cls(rows[~planned], chosen, command.clock[chosen].tobytes(), _column(command.tau_start, chosen),
                   command.duration[chosen])


def _planned(bank: AxisBank, plans: _Plans, out: Stretch) -> None:
    """Plans read through their supervisor's clock (Axis._command_arrays, AxisPlan.evaluate)."""
    cmd, rows = bank.command, plans.rows
    clocks = bank.clock_memo(plans.clocks, lambda: bank.clocks.columns(cmd.clock[rows]))
    rel, f, df = clocks.evaluate(out.t, out.target("rel", rows))
    rel -= plans.tau_start
    lo, hi = _extremes(rel, clocks, out.t)
    segments = bank.memo("segments", lambda: _Segments.of(cmd, rows))
    if segments.inner(lo, hi):  # (nearly every stretch)
        p, dp, ddp = _polynomials(segments, segments.linear, rel, out.into("cmd_p", rows))
        if segments.all_linear and not clocks.ramping(out.t):
            # Constant velocities on clocks past their ramps: the same rates every stretch,
            # until a row changes (forgotten with the segments).
            velocity, acceleration = bank.memo("rates", lambda: _rates(dp, ddp, f, df, out, rows))
        else:
            velocity, acceleration = _rates(dp, ddp, f, df, out, rows)
    else:
        # AxisPlan.evaluate reads the table at min(rel, duration): its extremes are these.
        duration = plans.duration
        single = _in_one_segment(bank, rows, np.minimum(lo, duration), np.minimum(hi, duration))
        if single.all():
            # (after the segments _in_one_segment chose)
            segments = bank.memo("segments", lambda: _Segments.of(cmd, rows))
            p, dp, ddp = _segment(cmd, rows, segments, rel, lo, hi, out)
        else:
            p, dp, ddp = _segments(bank, rows, rel, lo, hi, single, out)
        velocity, acceleration = _rates(dp, ddp, f, df, out, rows)
    out.place("cmd_p", rows, p)
    out.place("cmd_v", rows, velocity)
    out.place("cmd_a", rows, acceleration)
    out.place("rel", rows, rel)


def _extremes(rel: np.ndarray, clocks: ClockColumns, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each row's least and greatest profile time over the stretch."""
    if clocks.forward and not clocks.ramping(t):
        # tau = tau_end + f1 (t - t_end) never decreases along the sorted times (each step
        # rounds monotonically, f1 >= 0), nor does rel: its extremes are its ends.
        return rel[:, 0], rel[:, -1]
    return rel.min(axis=1), rel.max(axis=1)


def _rates(dp: np.ndarray, ddp: np.ndarray, f: np.ndarray, df: np.ndarray, out: Stretch,
           rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The command's velocity dp f and acceleration ddp f f + dp df (columns if all their
    operands are; dp and ddp are both columns or both full, f and df likewise)."""
    velocity = np.multiply(dp, f, out=out.into_if_full("cmd_v", rows, dp, f))
    acceleration = np.multiply(ddp, f, out=out.into_if_full("cmd_a", rows, ddp, f))
    acceleration *= f
    acceleration += dp * df
    return velocity, acceleration


def _segments(bank: AxisBank, rows: np.ndarray, rel: np.ndarray, lo: np.ndarray, hi: np.ndarray,
              single: np.ndarray, out: Stretch) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_segment` for the rows that stay in one segment; the plan's own evaluation
    (AxisPlan.evaluate, one row at a time) for those that move on to another inside the stretch."""
    shape = rel.shape
    p, dp, ddp = np.empty(shape), np.empty(shape), np.empty(shape)
    if single.any():
        chosen = rows[single]
        p[single], dp[single], ddp[single] = _segment(bank.command, chosen, _Segments.of(bank.command, chosen),
                                                      rel[single], lo[single], hi[single], None)
    for i in np.flatnonzero(~single).tolist():
        plan = bank.plans[int(rows[i])]
        assert plan is not None  # (a planned row: written for its plan)
        p[i], dp[i], ddp[i] = plan.evaluate(rel[i])
    return p, dp, ddp


def _in_one_segment(bank: AxisBank, rows: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Per row: does the whole stretch (profile times ``lo`` .. ``hi`` in the table) fall in
    one segment of the plan? A row that moved on to another segment gets it here (one axis
    at a time, only when that happens)."""
    cmd = bank.command
    segments = bank.memo("segments", lambda: _Segments.of(cmd, rows))
    keep: np.ndarray = (lo >= segments.lo) & (hi < segments.hi)
    if keep.all():
        return keep
    bank.forget("segments")  # (a row may move on to its next segment)
    bank.forget("rates")
    for i in np.flatnonzero(~keep).tolist():
        row = int(rows[i])
        plan = bank.plans[row]
        assert plan is not None  # (a planned row: written for its plan)
        table = plan.table
        # SegmentTable.index of the two times (bisect_right is its searchsorted, for one value)
        first, last = (min(bisect.bisect_right(table.end, x), table.count - 1) for x in (lo[i], hi[i]))
        if first == last:
            cmd.set_segment(row, plan, first)
            keep[i] = True
    return keep


@dataclass(frozen=True, slots=True)
class _Segments:
    """The segment each of some rows is evaluated in (CommandRows.set_segment), gathered:
    ``lo``, ``hi``, ``linear`` and ``duration`` per row, the rest as (rows, 1) columns."""

    lo: np.ndarray
    hi: np.ndarray
    linear: np.ndarray
    duration: np.ndarray
    start: np.ndarray
    p: np.ndarray
    v: np.ndarray
    a: np.ndarray
    j: np.ndarray
    velocity: np.ndarray  # v + 0.0, a linear segment's velocity (see _linear)
    zeros: np.ndarray  # its acceleration
    # Every row inside its segment and its plan all the stretch, when its profile times
    # are in [inner_lo, inner_hi): [max(lo, start), min(hi, duration)), where the tests
    # of _in_one_segment, _linear and _segment all come out the same way (one way each)
    inner_lo: np.ndarray
    inner_hi: np.ndarray
    all_linear: bool

    @classmethod
    def of(cls, cmd: CommandRows, rows: np.ndarray) -> _Segments:
        return cls.gathered(cmd.seg_lo[rows], cmd.seg_hi[rows], cmd.linear[rows], cmd.duration[rows],
                            *(_column(x, rows) for x in (cmd.seg_start, cmd.p, cmd.v, cmd.a, cmd.j)))

    @classmethod
    def gathered(cls, lo: np.ndarray, hi: np.ndarray, linear: np.ndarray, duration: np.ndarray, start: np.ndarray,
                 p: np.ndarray, v: np.ndarray, a: np.ndarray, j: np.ndarray) -> _Segments:
        return cls(lo, hi, linear, duration, start, p, v, a, j, v + 0.0, np.zeros_like(v), np.maximum(lo, start[:, 0]),
                   np.minimum(hi, duration), bool(linear.all()))

    def inner(self, lo: np.ndarray, hi: np.ndarray) -> bool:
        """Does every row stay inside (``lo``, ``hi``: the extremes of its profile times)?"""
        return bool((lo >= self.inner_lo).all() and (hi < self.inner_hi).all())

    def of_group(self, group: np.ndarray) -> _Segments:
        """Those of the rows ``group`` (a mask) picks."""
        return _Segments.gathered(self.lo[group], self.hi[group], self.linear[group], self.duration[group],
                                  self.start[group], self.p[group], self.v[group], self.a[group], self.j[group])


def _segment(cmd: CommandRows, rows: np.ndarray, segments: _Segments, rel: np.ndarray, lo: np.ndarray,
             hi: np.ndarray, out: Stretch | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, d/dtau, d2/dtau2 of each row's plan at profile times ``rel`` (whose extremes
    are ``lo``, ``hi``): its segment (SegmentTable.evaluate, ``segments``) until the plan's
    end, the end state from there on (AxisPlan.evaluate). Velocity and acceleration may come
    back as (rows, 1) columns, constant over the stretch."""
    duration = segments.duration
    inside = rel if (hi < duration).all() else np.minimum(rel, duration[:, None])
    linear = _linear(segments, np.minimum(lo, duration))
    pos, vel, acc = _polynomials(segments, linear, inside, out.into("cmd_p", rows) if out is not None else None)
    if (hi >= duration).any():
        duration = duration[:, None]
        complete = rel >= duration
        target, final = cmd.target[rows, None], cmd.final_velocity[rows, None]
        extra = np.maximum(rel - duration, 0.0)
        pos = np.where(complete, target + final * extra, pos)
        vel = np.where(complete, final, vel)
        acc = np.where(complete, 0.0, acc)
    return pos, vel, acc


def _polynomials(segments: _Segments, linear: np.ndarray, inside: np.ndarray,
                 into: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """SegmentTable.evaluate of each row's segment at profile times ``inside`` (in it),
    the ``linear`` rows' (see :func:`_linear`) by the sums they reduce to."""
    if linear.all():
        return _linear_segment(segments, inside, into)
    if not linear.any():
        return _cubic_segment(segments, inside, into)
    pos, vel, acc = np.empty_like(inside), np.empty_like(inside), np.empty_like(inside)
    for group, evaluate in ((linear, _linear_segment), (~linear, _cubic_segment)):
        pos[group], vel[group], acc[group] = evaluate(segments.of_group(group), inside[group], None)
    return pos, vel, acc


def _linear(segments: _Segments, lo: np.ndarray) -> np.ndarray:
    """Rows whose segment has acceleration and jerk +0.0 (CommandRows.linear) and whose
    stretch starts in it (dt >= +0): SegmentTable.evaluate's sums reduce there to p + dt v'
    and v', v' = v + 0.0, to the bit (+0 times a finite dt >= +0 is +0, and x + +0 is x but
    for x = -0.0)."""
    linear: np.ndarray = segments.linear & (lo >= segments.start[:, 0])
    return linear


def _linear_segment(segments: _Segments, inside: np.ndarray,
                    into: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    pos = np.subtract(inside, segments.start, out=into)
    pos *= segments.velocity
    pos += segments.p
    return pos, segments.velocity, segments.zeros


def _cubic_segment(segments: _Segments, inside: np.ndarray,
                   into: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """SegmentTable.evaluate's sums, operation for operation (x + y and x y commute)."""
    start, p, v, a, j = segments.start, segments.p, segments.v, segments.a, segments.j
    dt = inside - start
    jerk = dt * j
    pos = np.divide(jerk, 6.0, out=into)
    pos += a / 2.0
    pos *= dt
    pos += v
    pos *= dt
    pos += p
    vel = jerk / 2.0
    vel += a
    vel *= dt
    vel += v
    jerk += a
    return pos, vel, jerk


# -- the servo ----------------------------------------------------------------------------
@dataclass(frozen=True, slots=True)
class _Servos:
    """What the servo of some rows of PlantRows reads of them, gathered (once per bank
    refresh for the bank's pieces: bank.memo)."""

    anchor_t: np.ndarray  # (rows, 1)
    piece_end: np.ndarray
    first_end: float  # the first of them
    terms: int  # the longest row's count of coefficients (see _steady_response)
    steady_y: np.ndarray  # (rows, _MAX_TERMS)
    steady_dy: np.ndarray
    resolution: np.ndarray
    one_resolution: bool  # is the encoder resolution of every row the same?
    transients: _Transients

    @classmethod
    def of(cls, plant: PlantRows, rows: np.ndarray) -> _Servos:
        resolution, piece_end = plant.resolution[rows], plant.piece_end[rows]
        return cls(_column(plant.anchor_t, rows), piece_end, min(piece_end.tolist(), default=math.inf),
                   max(plant.terms[rows].tolist(), default=1), plant.steady_y[rows], plant.steady_dy[rows],
                   resolution, _one_of(resolution) is not None, _Transients.of(plant, rows))


def _one_of(values: np.ndarray) -> float | None:
    """The value all of ``values`` have (None: they differ, or there are none). On the few
    rows of a bank, a set of their Python numbers costs less than numpy's comparison and
    reduction (the values are counts, indices and validated resolutions: no NaN)."""
    distinct = set(values.tolist())
    return distinct.pop() if len(distinct) == 1 else None


def _column(values: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``values[rows, None]``: the rows' values as a column (gathered, then viewed as one:
    numpy's mixed index costs several times more)."""
    column: np.ndarray = values[rows][:, None]
    return column


def _servo(tables: list[_FreeTable], rows: np.ndarray, servos: _Servos, out: Stretch, direct: bool,
           following: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Actual position and velocity (Plant.response, read) of ``rows`` (whose servos are
    ``servos``), at every sample of the stretch; ``direct``: into the stretch's own arrays
    where it can; ``following``: pieces that start inside the stretch (the samples before a
    row's anchor come out meaningless, to be left out)."""
    s = np.subtract(out.t, servos.anchor_t, out=out.temporary("s", rows))
    y, dy = _steady_response(servos, rows, s, out)
    y, dy = _add_transient(tables, servos.transients, s, y, dy, out, following)
    return _read(servos, y, out.into("act_p", rows) if direct else None), dy


def _following_pieces(bank: AxisBank, axes: list[Axis], clock_of: Callable[[Axis], ProfileClock | None],
                      rows: np.ndarray, out: Stretch) -> None:
    """Axes whose command piece ends inside the stretch: every following piece, from its
    plant anchor (advanced from piece to piece by the scalar code), is one more row, all
    evaluated together, each kept over the samples of its piece."""
    t = out.t
    pieces: list[tuple[int, float, float]] = []  # axis, start, end
    followers = []
    for row in rows.tolist():
        axis = axes[row]
        out.anchors[row] = [axis.state]
        for anchor, start, end, forced in axis.continuations(float(t[-1]), clock_of(axis)):
            followers.append((anchor, end, forced, axis.plant, axis.rate))
            pieces.append((row, start, end))
            out.anchors[row].append(anchor)
    rows_of = PlantRows.of_pieces(followers, bank.table_index)
    every = np.arange(len(pieces))
    act_p, act_v = _servo(bank.tables, every, _Servos.of(rows_of, every), out, direct=False, following=True)
    shape = (len(pieces), len(t))
    act_p, act_v = _as_rows(act_p, shape), _as_rows(act_v, shape)  # constants may be columns
    spans = np.searchsorted(t, [(start, end) for _, start, end in pieces], side="left").tolist()
    for i, ((row, _, _), (first, last)) in enumerate(zip(pieces, spans, strict=True)):
        out.act_p[row, first:last] = act_p[i, first:last]
        out.act_v[row, first:last] = act_v[i, first:last]


def _as_rows(values: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """``values`` read as ``shape`` (a column broadcast; full rows as they are, nearly always)."""
    return values if values.shape == shape else np.broadcast_to(values, shape)


def _steady_response(servos: _Servos, rows: np.ndarray, s: np.ndarray, out: Stretch) -> tuple[np.ndarray, np.ndarray]:
    """The steady response's polynomials, every row at once to the longest row's count of
    coefficients (constants as a column where every row is one). A shorter row comes out as
    plant.poly_eval gives it: Horner's scheme carries its zero padding as +0.0 (+0.0 s + 0.0,
    s >= +0) to its own top coefficient c, where +0.0 s + c is c, as no coefficient is -0.0
    (Plant.prepare's sums start from +0.0 and trim_leading_zeros leaves none). (A following
    piece's samples before its anchor, s < 0, are left out.)"""
    return _steady_group(servos.steady_y, servos.steady_dy, s, servos.terms, out.temporary("y", rows))


def _steady_group(steady_y: np.ndarray, steady_dy: np.ndarray, s: np.ndarray, terms: int,
                  into: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    return _horner(steady_y[:, :terms], s, into), _horner(steady_dy[:, :max(1, terms - 1)], s, None)


def _horner(coefficients: np.ndarray, s: np.ndarray, into: np.ndarray | None) -> np.ndarray:
    """plant.poly_eval, one polynomial per row (coefficients low first); a constant stays
    a column."""
    count = coefficients.shape[1]
    if count == 1:
        return coefficients.copy()
    out: np.ndarray = np.multiply(coefficients[:, -1:], s, out=into)
    out += coefficients[:, -2, None]
    for k in range(count - 3, -1, -1):
        out *= s
        out += coefficients[:, k, None]
    return out


@dataclass(frozen=True, slots=True)
class _Transients:
    """The rows with a transient among some rows of PlantRows, and what adding it reads of
    them (gathered once per bank refresh for the bank's pieces: bank.memo)."""

    where: slice | np.ndarray  # those rows among the rows: all of them (a slice), or their indices
    rows: np.ndarray  # their rows of PlantRows
    v0: np.ndarray  # (rows, 1) columns of the Transient's parts
    m0: np.ndarray
    v1: np.ndarray
    m1: np.ndarray
    decayed: np.ndarray  # (rows, 1): PlantRows.decayed_after
    vanishing: np.ndarray  # PlantRows.vanishing
    k0: np.ndarray
    table: np.ndarray
    dropped: bool  # may one be dropped once decayed (a finite decayed_after)?
    first_vanishing: float  # the first sample from which one of them is exact zeros
    last_vanishing: float  # the first from which every one is
    one_table: int  # the free-response table every one reads (-1: not one for all)

    @classmethod
    def of(cls, plant: PlantRows, rows: np.ndarray) -> _Transients:
        live = plant.decayed_after[rows] > -math.inf
        where = slice(None) if live.all() else np.flatnonzero(live)
        picked = rows[where]
        return cls.gathered(where, picked, _column(plant.v0, picked), _column(plant.m0, picked),
                            _column(plant.v1, picked), _column(plant.m1, picked),
                            _column(plant.decayed_after, picked), plant.vanishing[picked], plant.k0[picked],
                            plant.table[picked])

    @classmethod
    def gathered(cls, where: slice | np.ndarray, rows: np.ndarray, v0: np.ndarray, m0: np.ndarray, v1: np.ndarray,
                 m1: np.ndarray, decayed: np.ndarray, vanishing: np.ndarray, k0: np.ndarray,
                 table: np.ndarray) -> _Transients:
        one = _one_of(table)
        ends = vanishing.tolist()
        # dropped: one decays (not every decayed_after is inf; a NaN is not inf either)
        return cls(where, rows, v0, m0, v1, m1, decayed, vanishing, k0, table,
                   bool(set(decayed[:, 0].tolist()) - {math.inf}), min(ends, default=math.inf),
                   max(ends, default=-math.inf), -1 if one is None else int(one))

    def kept(self, keep: np.ndarray) -> _Transients:
        """Those at indices ``keep`` among them."""
        where = keep if isinstance(self.where, slice) else self.where[keep]
        return self.gathered(where, self.rows[keep], self.v0[keep], self.m0[keep], self.v1[keep], self.m1[keep],
                             self.decayed[keep], self.vanishing[keep], self.k0[keep], self.table[keep])


def _add_transient(tables: list[_FreeTable], transients: _Transients, s: np.ndarray, y: np.ndarray,
                   dy: np.ndarray, out: Stretch, following: bool) -> tuple[np.ndarray, np.ndarray]:
    """Plant.response's transient added to the rows that have one (``transients``)."""
    added = transients if following else _not_vanished(transients, int(out.samples[0]), y, dy)
    if added is None or not len(added.rows):
        return y, dy
    transients = added
    y, dy = _full(y, s.shape, out, "y"), _full(dy, s.shape, out, "dy")
    sub, rows = transients.where, transients.rows
    p, q = _free(tables, transients, out.samples, out.scratch, following)
    h0 = np.multiply(p, transients.v0, out=out.temporary("h0", rows))
    h0 += np.multiply(q, transients.m0, out=out.temporary("product", rows))
    h1 = np.multiply(p, transients.v1, out=out.temporary("h1", rows))
    h1 += np.multiply(q, transients.m1, out=out.temporary("product", rows))
    if not transients.dropped:
        y[sub] += h0
        dy[sub] += h1
        return y, dy
    # At rest on a constant command the transient is dropped once it has decayed.
    settled = s[sub] >= transients.decayed
    y[sub] = np.where(settled, y[sub], y[sub] + h0)
    dy[sub] = np.where(settled, dy[sub], dy[sub] + h1)
    return y, dy


def _full(values: np.ndarray, shape: tuple[int, int], out: Stretch, name: str) -> np.ndarray:
    """``values`` (or a column) as a full array of ``shape`` that may be changed in place."""
    if values.shape == shape:
        return values
    full = out.scratch.take("~full." + name, shape)
    full[...] = values
    return full


def _not_vanished(transients: _Transients, first: int, y: np.ndarray, dy: np.ndarray) -> _Transients | None:
    """The transients that must be added from sample ``first`` on (None: none): not those
    whose free response has underflowed to exact zeros over the whole stretch (a
    long-settled loop), since adding a zero changes nothing, unless a value is itself a
    zero (whose sign it might flip): there it is added as ever."""
    if first < transients.first_vanishing:  # (none has vanished yet)
        return transients
    sub = transients.where
    if first >= transients.last_vanishing and not (_zero_in(y[sub]) or _zero_in(dy[sub])):
        return None  # (every one has vanished and no value is a zero: a settled bank, nearly always)
    vanished: np.ndarray = first >= transients.vanishing
    vanished &= ~(_has_zero(y[sub]) | _has_zero(dy[sub]))
    if not vanished.any():
        return transients
    return None if vanished.all() else transients.kept(np.flatnonzero(~vanished))


def _zero_in(values: np.ndarray) -> bool:
    return bool((values == 0.0).any())


def _has_zero(values: np.ndarray) -> np.ndarray:
    """Per row: does it hold a zero?"""
    has: np.ndarray = (values == 0.0).any(axis=1)
    return has


def _free(tables: list[_FreeTable], transients: _Transients, samples: np.ndarray, scratch: Scratch,
          following: bool) -> tuple[np.ndarray, np.ndarray]:
    """(p, q) of the free response at every sample of each of ``transients``' rows, from its
    loop's table (for ``following`` rows, sample counts before the anchor read as 0)."""
    first, n, k0 = int(samples[0]), len(samples), transients.k0
    one = transients.one_table
    if one >= 0:  # (one loop for all: nearly always)
        if following:
            return tables[one].at(np.maximum(samples - k0[:, None], 0))
        return tables[one].window(first - k0, n, scratch)
    which = transients.table
    p, q = np.empty((len(k0), n)), np.empty((len(k0), n))
    for index in sorted(set(which.tolist())):  # (as np.unique gives them)
        group = np.flatnonzero(which == index)
        if following:
            p[group], q[group] = tables[index].at(np.maximum(samples - k0[group, None], 0))
        else:
            p[group], q[group] = tables[index].window(first - k0[group], n)
    return p, q


def _read(servos: _Servos, y: np.ndarray, into: np.ndarray | None) -> np.ndarray:
    """Plant.read, one encoder per row (y/1.0 and x*1.0 are x to the bit: skipped)."""
    resolution = servos.resolution
    if servos.one_resolution:
        step = float(resolution[0])
        if step <= 0.0:
            return y
        if step == 1.0:
            out: np.ndarray = np.add(y, 0.5, out=into if y.shape[1] > 1 else None)
            floored: np.ndarray = np.floor(out, out=out)  # (numpy's stubs: Any with out=)
            return floored
        out = np.divide(y, step, out=into if y.shape[1] > 1 else None)
        out += 0.5
        np.floor(out, out=out)
        out *= step
        return out
    out = np.broadcast_to(y, (len(resolution), y.shape[1])).copy()
    counted = np.flatnonzero(resolution > 0.0)
    steps = resolution[counted, None]
    out[counted] = np.floor(out[counted] / steps + 0.5) * steps
    return out
