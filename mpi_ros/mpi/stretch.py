"""Every axis over a stretch of samples at once: (axes, samples) arrays.

The controller computes the samples k0+1 .. k1 of every axis from the rows in its
AxisBank: an axis at rest repeats its values; an axis whose command piece and plant
anchor hold over the whole stretch (nearly every axis, nearly always) is one row of
closed forms evaluated together with the others (its supervisor's feedrate clock, the
constant-jerk segment, the servo's steady response and transient); the rest (coasting,
command following the actual, a breakpoint inside the stretch) are traced one axis at a
time (Axis.trace). Every element is computed by the same operations, in the same order,
as the one-axis code computes it, so a value never depends on which way it was computed,
and so never on how the samples were batched.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .axis import Axis, AxisTrace
from .bank import AxisBank, CommandRows, Kind, PlantRows
from .clock import ProfileClock

_VALUES = ("cmd_p", "cmd_v", "cmd_a", "act_p", "act_v", "rel")


@dataclass(slots=True)
class Stretch:
    """Every sample of one stretch of every axis (raw positions), ``values[axis, i]``."""

    samples: np.ndarray
    t: np.ndarray
    cmd_p: np.ndarray
    cmd_v: np.ndarray
    cmd_a: np.ndarray
    act_p: np.ndarray
    act_v: np.ndarray
    rel: np.ndarray  # profile time into the plan (nan without one)
    shape: tuple[int, int] = (0, 0)
    pieces: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))  # rows of one piece
    traced: dict[int, AxisTrace] = field(default_factory=dict)  # axes traced one at a time

    def __len__(self) -> int:
        return len(self.samples)


def trace(bank: AxisBank, axes: list[Axis], clock_of: Callable[[Axis], ProfileClock | None],
          k0: int, k1: int, rate: float) -> Stretch:
    """Samples k0+1 .. k1 of every axis, from the bank's (fresh) rows; changes nothing."""
    samples = np.arange(k0 + 1, k1 + 1, dtype=np.int64)
    t = samples / rate
    shape = (bank.count, len(samples))
    out = Stretch(samples, t, *(np.empty(shape) for _ in _VALUES), shape=shape)
    _steady(bank, np.flatnonzero(bank.kind == Kind.STEADY), out)
    one_piece = (bank.kind == Kind.PIECE) & (t[-1] < bank.plant.piece_end)
    rows, fell = _command(bank, np.flatnonzero(one_piece), t, out)
    _servo(bank, rows, samples, t, out)
    out.pieces = rows
    traced = np.union1d(np.flatnonzero((bank.kind != Kind.STEADY) & ~one_piece), fell)
    for row in traced.tolist():
        axis = axes[row]
        out.traced[row] = one = axis.trace(k0, k1, clock_of(axis))
        for name in _VALUES:
            getattr(out, name)[row] = getattr(one, name)
    return out


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
def _command(bank: AxisBank, rows: np.ndarray, t: np.ndarray, out: Stretch) -> tuple[np.ndarray, np.ndarray]:
    """Command of ``rows``; returns (rows done, rows whose segment changes inside the stretch)."""
    planned = bank.command.planned[rows]
    resting = rows[~planned]
    if len(resting):
        out.cmd_p[resting] = bank.command.rest[resting, None]
        out.cmd_v[resting] = out.cmd_a[resting] = 0.0
        out.rel[resting] = math.nan
    if not planned.any():
        return rows, rows[:0]
    moving = rows[planned]
    kept = _planned(bank, moving, t, out)
    if len(kept) == len(moving):
        return rows, rows[:0]
    return np.union1d(resting, kept), np.setdiff1d(moving, kept, assume_unique=True)


def _planned(bank: AxisBank, rows: np.ndarray, t: np.ndarray, out: Stretch) -> np.ndarray:
    """Plans read through their supervisor's clock (Axis._command_arrays, AxisPlan.evaluate),
    for the rows that stay in one segment; returns those rows."""
    cmd = bank.command
    numbers, which = np.unique(cmd.clock[rows], return_inverse=True)
    tau, f, df = bank.clocks.evaluate(numbers, t)
    rel = tau[which]
    rel -= cmd.tau_start[rows, None]
    lo, hi = rel.min(axis=1), rel.max(axis=1)
    duration = cmd.duration[rows]
    # AxisPlan.evaluate reads the table at min(rel, duration): its extremes are these.
    keep = _in_one_segment(bank, rows, np.minimum(lo, duration), np.minimum(hi, duration))
    if not keep.all():
        rows, which, rel, lo, hi = rows[keep], which[keep], rel[keep], lo[keep], hi[keep]
        if not len(rows):
            return rows
    p, dp, ddp = _segment(cmd, rows, rel, lo, hi)
    f, df = f[which], df[which]
    _place(out, "cmd_p", rows, p)
    _place(out, "cmd_v", rows, dp * f)
    _place(out, "cmd_a", rows, ddp * f * f + dp * df)
    _place(out, "rel", rows, rel)
    return rows


def _in_one_segment(bank: AxisBank, rows: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Per row: does the whole stretch (profile times ``lo`` .. ``hi`` in the table) fall in
    one segment of the plan? A row that moved on to another segment gets it here (one axis
    at a time, only when that happens)."""
    cmd = bank.command
    keep = (lo >= cmd.seg_lo[rows]) & (hi < cmd.seg_hi[rows])
    for i in np.flatnonzero(~keep).tolist():
        row = int(rows[i])
        plan = bank.plans[row]
        first, last = plan.table.index(np.array([lo[i], hi[i]])).tolist()
        if first == last:
            cmd.set_segment(row, plan, first)
            keep[i] = True
    return keep


def _segment(cmd: CommandRows, rows: np.ndarray, rel: np.ndarray, lo: np.ndarray,
             hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, d/dtau, d2/dtau2 of each row's plan at profile times ``rel`` (whose extremes
    are ``lo``, ``hi``): its segment (SegmentTable.evaluate) until the plan's end, the end
    state from there on (AxisPlan.evaluate). Velocity and acceleration may come back as
    (rows, 1) columns, constant over the stretch."""
    duration = cmd.duration[rows]
    inside = rel if (hi < duration).all() else np.minimum(rel, duration[:, None])
    linear = _linear(cmd, rows, np.minimum(lo, duration))
    if linear.all():
        pos, vel, acc = _linear_segment(cmd, rows, inside)
    elif not linear.any():
        pos, vel, acc = _cubic_segment(cmd, rows, inside)
    else:
        pos, vel, acc = np.empty_like(rel), np.empty_like(rel), np.empty_like(rel)
        for group, evaluate in ((linear, _linear_segment), (~linear, _cubic_segment)):
            pos[group], vel[group], acc[group] = evaluate(cmd, rows[group], inside[group])
    if (hi >= duration).any():
        duration = duration[:, None]
        complete = rel >= duration
        target, final = cmd.target[rows, None], cmd.final_velocity[rows, None]
        extra = np.maximum(rel - duration, 0.0)
        pos = np.where(complete, target + final * extra, pos)
        vel = np.where(complete, final, vel)
        acc = np.where(complete, 0.0, acc)
    return pos, vel, acc


def _linear(cmd: CommandRows, rows: np.ndarray, lo: np.ndarray) -> np.ndarray:
    """Rows whose segment has acceleration and jerk +0.0 and whose stretch starts in it
    (dt >= +0): SegmentTable.evaluate's sums reduce there to p + dt v' and v', v' = v + 0.0,
    to the bit (+0 times a finite dt >= +0 is +0, and x + +0 is x but for x = -0.0)."""
    a, j = cmd.a[rows], cmd.j[rows]
    return (a == 0.0) & (j == 0.0) & ~np.signbit(a) & ~np.signbit(j) & (lo >= cmd.seg_start[rows])


def _linear_segment(cmd: CommandRows, rows: np.ndarray, inside: np.ndarray):
    velocity = cmd.v[rows, None] + 0.0
    pos = inside - cmd.seg_start[rows, None]
    pos *= velocity
    pos += cmd.p[rows, None]
    return pos, velocity, np.zeros_like(velocity)


def _cubic_segment(cmd: CommandRows, rows: np.ndarray, inside: np.ndarray):
    """SegmentTable.evaluate's sums, operation for operation."""
    start, p, v, a, j = (x[rows, None] for x in (cmd.seg_start, cmd.p, cmd.v, cmd.a, cmd.j))
    dt = inside - start
    jerk = dt * j
    pos = jerk / 6.0
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


def _place(out: Stretch, name: str, rows: np.ndarray, values: np.ndarray) -> None:
    """Rows (or columns, constant over the stretch) of values into the stretch; a fresh
    full array for every axis (``rows`` are sorted) is taken as it is."""
    if len(rows) == out.shape[0] and values.shape == out.shape:
        setattr(out, name, values)
    else:
        getattr(out, name)[rows] = values


# -- the servo ----------------------------------------------------------------------------
def _servo(bank: AxisBank, rows: np.ndarray, samples: np.ndarray, t: np.ndarray, out: Stretch) -> None:
    """Actual position and velocity of ``rows`` from their anchors (Plant.response, read)."""
    if not len(rows):
        return
    plant = bank.plant
    s = t - plant.anchor_t[rows, None]
    y, dy = _steady_response(plant, rows, s)
    y, dy = _add_transient(bank, rows, samples, s, y, dy)
    _place(out, "act_p", rows, _read(plant.resolution[rows], y))
    _place(out, "act_v", rows, dy)


def _steady_response(plant: PlantRows, rows: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The steady response's polynomials, rows of the same length at once (a constant one
    as a column)."""
    terms = plant.terms[rows]
    if (terms == terms[0]).all():
        return _steady_group(plant, rows, s, int(terms[0]))
    y, dy = np.empty_like(s), np.empty_like(s)
    for count in np.unique(terms).tolist():
        group = np.flatnonzero(terms == count)
        y[group], dy[group] = _steady_group(plant, rows[group], s[group], count)
    return y, dy


def _steady_group(plant: PlantRows, rows: np.ndarray, s: np.ndarray, terms: int) -> tuple[np.ndarray, np.ndarray]:
    return (_horner(plant.steady_y[rows, :terms], s),
            _horner(plant.steady_dy[rows, :max(1, terms - 1)], s))


def _horner(coefficients: np.ndarray, s: np.ndarray) -> np.ndarray:
    """plant.poly_eval, one polynomial per row (coefficients low first); a constant stays
    a column."""
    count = coefficients.shape[1]
    if count == 1:
        return coefficients.copy()
    out = coefficients[:, -1:] * s
    out += coefficients[:, -2, None]
    for k in range(count - 3, -1, -1):
        out *= s
        out += coefficients[:, k, None]
    return out


def _add_transient(bank: AxisBank, rows: np.ndarray, samples: np.ndarray, s: np.ndarray,
                   y: np.ndarray, dy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Plant.response's transient added to the rows that have one."""
    plant = bank.plant
    live = _live_transients(bank, rows, int(samples[0]), y, dy)
    if not live.any():
        return y, dy
    y, dy = _full(y, s.shape), _full(dy, s.shape)
    sub = slice(None) if live.all() else np.flatnonzero(live)
    rows, decayed = rows[sub], plant.decayed_after[rows[sub]]
    p, q = _free(bank, rows, int(samples[0]), len(samples))
    h0 = p * plant.v0[rows, None]
    h0 += q * plant.m0[rows, None]
    h1 = p * plant.v1[rows, None]
    h1 += q * plant.m1[rows, None]
    if np.isposinf(decayed).all():
        y[sub] += h0
        dy[sub] += h1
        return y, dy
    # At rest on a constant command the transient is dropped once it has decayed.
    settled = s[sub] >= decayed[:, None]
    y[sub] = np.where(settled, y[sub], y[sub] + h0)
    dy[sub] = np.where(settled, dy[sub], dy[sub] + h1)
    return y, dy


def _full(values: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """``values`` as a full array of ``shape`` that may be changed in place."""
    return values if values.shape == shape else np.broadcast_to(values, shape).copy()


def _live_transients(bank: AxisBank, rows: np.ndarray, first: int, y: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Per row: must its transient be added? Not without one; nor where the free response
    has underflowed to exact zeros over the whole stretch (a long-settled loop), since
    adding a zero changes nothing, unless a value is itself a zero (whose sign it might
    flip): there it is added as ever."""
    plant = bank.plant
    live = plant.decayed_after[rows] > -math.inf
    if not live.any():
        return live
    vanished = np.zeros(len(rows), dtype=bool)
    m0 = first - plant.k0[rows]
    tables = plant.table[rows]
    for index in np.unique(tables[live]).tolist():
        group = live & (tables == index)
        vanished[group] = bank.tables[index].vanished(m0[group])
    if vanished.any():
        zeros = (np.broadcast_to(y, (len(rows), y.shape[1]))[vanished] == 0.0).any(axis=1)
        zeros |= (np.broadcast_to(dy, (len(rows), dy.shape[1]))[vanished] == 0.0).any(axis=1)
        vanished[np.flatnonzero(vanished)[zeros]] = False
    return live & ~vanished


def _free(bank: AxisBank, rows: np.ndarray, first: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(p, q) of the free response at every sample of each row, from its loop's table."""
    tables = bank.plant.table[rows]
    m0 = first - bank.plant.k0[rows]
    if (tables == tables[0]).all():
        return bank.tables[int(tables[0])].window(m0, n)
    p, q = np.empty((len(rows), n)), np.empty((len(rows), n))
    for index in np.unique(tables).tolist():
        group = np.flatnonzero(tables == index)
        p[group], q[group] = bank.tables[index].window(m0[group], n)
    return p, q


def _read(resolution: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Plant.read, one encoder per row (y/1.0 and x*1.0 are x to the bit: skipped)."""
    if (resolution == resolution[0]).all():
        step = float(resolution[0])
        if step <= 0.0:
            return y
        if step == 1.0:
            out = y + 0.5
            return np.floor(out, out=out)
        out = y / step
        out += 0.5
        np.floor(out, out=out)
        out *= step
        return out
    out = np.broadcast_to(y, (len(resolution), y.shape[1])).copy()
    counted = np.flatnonzero(resolution > 0.0)
    step = resolution[counted, None]
    out[counted] = np.floor(out[counted] / step + 0.5) * step
    return out
