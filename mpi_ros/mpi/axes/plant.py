"""The simulated servo: why actual position lags command and settling takes real time.

The closed position loop is a second-order system with velocity and acceleration
feed-forward:

    y'' + 2 zeta w y' + w^2 y = w^2 u + 2 zeta w kv u' + ka u''

driven by the command u(t), which is a polynomial in time between breakpoints (frame
boundaries, feedrate ramps, commands). Between breakpoints the response is exact:
a polynomial particular solution sum_m g_m u^(m)(t), with g_m the Taylor coefficients
of the loop's transfer function, plus the decaying homogeneous solution. So the actual
position at a sample is a function of the command history only, whatever batches the
controller is stepped in; that is what makes replay exact.

After ABORT the amplifier is off and the motor coasts: y'' = -y'/tau_c.
The encoder reads y in whole counts (``encoder_resolution``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeVar

import numpy as np
import numpy.typing as npt
from numpy.lib.stride_tricks import sliding_window_view

from mpi_ros.mpi.base.params import PlantConfig

if TYPE_CHECKING:
    from mpi_ros.mpi.axes.scratch import Scratch

Effort = TypeVar("Effort", float, npt.NDArray[np.float64])  # servo_effort's values: one, or arrays of them
_MAX_DEGREE = 6  # cubic segments composed with a quadratic feedrate time warp
_QUIET = 1e-12  # homogeneous amplitude below which the loop counts as settled (counts)


@dataclass(frozen=True, slots=True)
class Forced:
    """Particular (steady) solution of the loop for one input piece: y(s), y'(s)."""

    y: list[float]
    dy: list[float]


@dataclass(slots=True)
class PlantState:
    """Continuous state of the motor at time ``t``: position and velocity (counts)."""

    t: float
    y: float
    dy: float


@dataclass(frozen=True, slots=True)
class Transient:
    """The decaying (homogeneous) part of a piece's response, from its anchor: at whole
    sample k it adds Phi((k - k0) dt) v = p v + q M v, with v the free state at the
    first whole sample k0 at or after the anchor and (p, q) from the loop's table."""

    k0: int
    v0: float
    v1: float
    m0: float  # M v
    m1: float
    decayed_after: float  # seconds past the anchor from which it is dropped (inf: never)
    table: _FreeTable

    def at(self, samples: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Its position and velocity parts at whole ``samples``."""
        p, q = self.table.at(samples - self.k0)
        return p * self.v0 + q * self.m0, p * self.v1 + q * self.m1


class Plant:
    def __init__(self, config: PlantConfig):
        if config.bandwidth_hz <= 0.0 or config.damping <= 0.0:
            raise ValueError("plant bandwidth and damping must be positive")
        if config.coast_time_constant <= 0.0:
            raise ValueError("plant coast time constant must be positive")
        self.config = config
        w = 2.0 * math.pi * config.bandwidth_hz
        z = config.damping
        self._w2 = w * w
        self._c = 2.0 * z * w  # damping term
        self._sigma = -z * w
        self._kind, self._q = self._modes(z, w)
        # Lists of floats, not arrays: the particular solution is a few scalar products per
        # piece, and numpy's scalars multiply many times slower (to the same bits).
        self._gains = self._taylor(
            num=(w * w, 2.0 * z * w * config.velocity_feedforward, config.acceleration_feedforward),
            den=(w * w, 2.0 * z * w, 1.0),
        ).tolist()
        # A DAC feedforward d drives the motor directly: y'' + c y' + w^2 y = ... + K d, whose
        # steady response to a polynomial d has the gains of K / (w^2 + c s + s^2).
        self._dac_gains = self._taylor(num=(config.dac_acceleration,), den=(w * w, 2.0 * z * w, 1.0)).tolist()
        self._resolution = config.encoder_resolution
        self._coast = config.coast_time_constant
        self._steps: dict[tuple[str, float], tuple[tuple[float, ...], tuple[float, ...]]] = {}  # sample_step, per rate
        self._tables: dict[float, _FreeTable] = {}  # table, per rate
        # transient: (id(state), id(forced), rate) -> (state, forced, transient)
        self._transients: dict[tuple[int, int, float], tuple[PlantState, Forced, Transient | None]] = {}
        # M^2 = kappa I (Cayley-Hamilton: A's eigenvalues are sigma +- i q, sigma +- q, or sigma twice)
        self._kappa = {"under": -self._q * self._q, "over": self._q * self._q}.get(self._kind, 0.0)

    @staticmethod
    def _modes(z: float, w: float) -> tuple[str, float]:
        if abs(z - 1.0) < 1e-9:
            return "critical", 0.0
        if z < 1.0:
            return "under", w * math.sqrt(1.0 - z * z)
        return "over", w * math.sqrt(z * z - 1.0)

    @staticmethod
    def _taylor(num: Sequence[float], den: Sequence[float]) -> np.ndarray:
        """Coefficients g_0.. of num(s)/den(s) = sum g_m s^m."""
        g = np.zeros(_MAX_DEGREE + 1)
        for m in range(_MAX_DEGREE + 1):
            acc = num[m] if m < len(num) else 0.0
            for i in range(1, min(m, len(den) - 1) + 1):
                acc -= den[i] * g[m - i]
            g[m] = acc / den[0]
        return g

    # -- servo on ----------------------------------------------------------------
    def particular(self, u: list[float]) -> list[float]:
        """Polynomial particular solution for a polynomial input (coefficients, low first)."""
        return self._particular(u, self._gains)

    @staticmethod
    def _particular(u: list[float], gains: list[float]) -> list[float]:
        """sum_m g_m u^(m): out[i] = 0.0 + g_0 u[i] + g_1 u'[i] + ..., summed in that order
        (the 0.0 first: a -0.0 product comes out +0.0), each derivative as poly_der makes it.
        Written out in place, since it runs for every command piece."""
        out = [0.0 + gains[0] * c for c in u]
        deriv = u
        for m in range(1, min(len(u), len(gains))):
            deriv = [i * c for i, c in enumerate(deriv) if i]  # poly_der (never empty here)
            g = gains[m]
            for i, c in enumerate(deriv):
                out[i] += g * c
        return out

    def _free(self, s: float) -> tuple[float, float]:
        """Free response over ``s`` seconds as Phi(s) = p I + q M (M = A - sigma I): (p, q)."""
        decay = math.exp(self._sigma * s)
        if self._kind == "under":
            return decay * math.cos(self._q * s), decay * math.sin(self._q * s) / self._q
        if self._kind == "over":
            return decay * math.cosh(self._q * s), decay * math.sinh(self._q * s) / self._q
        return decay, decay * s

    def _apply_m(self, e0: float, e1: float) -> tuple[float, float]:
        """M e for M = A - sigma I, A = [[0, 1], [-w^2, -c]]."""
        return -self._sigma * e0 + e1, -self._w2 * e0 + (-self._c - self._sigma) * e1

    def _homogeneous_at(self, e0: float, e1: float, s: float) -> tuple[float, float]:
        """Free response from error state (e0, e1) after ``s`` seconds (scalar)."""
        p, q = self._free(s)
        m0, m1 = self._apply_m(e0, e1)
        return p * e0 + q * m0, p * e1 + q * m1

    def table(self, rate: float) -> _FreeTable:
        """The free response of this loop at whole samples of ``rate`` (shared by identical loops)."""
        table = self._tables.get(rate)  # (every transient asks)
        if table is None:
            key = (self.config.bandwidth_hz, self.config.damping, self._coast, rate)
            table = _TABLES.get(key)
            if table is None:
                table = _TABLES[key] = _FreeTable.build(self, rate)
            self._tables[rate] = table
        return table

    def prepare(self, u: list[float], dac: list[float] | None = None) -> Forced:
        """The loop's steady response to a polynomial command ``u`` and DAC feedforward
        ``dac`` (PTF/PVTF; None or zero: none), reusable for a piece."""
        yp = self.particular(u)
        if dac is not None and any(dac):
            yp = _poly_add(yp, self._particular(dac, self._dac_gains))
        return Forced(yp, poly_der(yp))

    def transient(self, state: PlantState, forced: Forced, rate: float) -> Transient | None:
        """The decaying part of the response of a piece anchored at ``state``, reduced to
        what every whole sample needs (None: below the quiet level from the anchor on).
        The one place the anchor's free state is computed, for one axis and for rows of
        axes alike, so both give the same bits. The last few are kept: a piece that starts
        inside a stretch is made into rows there (stretch._following_pieces) and again once
        the axis is anchored at its start, with the same anchor and steady response."""
        key = (id(state), id(forced), rate)
        known = self._transients.get(key)
        if known is not None and known[0] is state and known[1] is forced:
            return known[2]
        transient = self._transient(state, forced, rate)
        if len(self._transients) >= 64:
            self._transients.clear()
        self._transients[key] = (state, forced, transient)  # (kept: their ids stay theirs)
        return transient

    def _transient(self, state: PlantState, forced: Forced, rate: float) -> Transient | None:
        e0 = state.y - forced.y[0]
        e1 = state.dy - forced.dy[0]
        size = abs(e0) + abs(e1) / (-self._sigma)
        if size <= _QUIET:
            return None
        # The sample grid is reached from the anchor in a way that depends only on the
        # anchor: a first step to the first sample at or after it (scalar), then whole
        # samples (tables, see _FreeTable).
        k0 = _first_sample(state.t, rate)
        v0, v1 = self._homogeneous_at(e0, e1, k0 / rate - state.t)
        m0, m1 = self._apply_m(v0, v1)
        # At rest on a constant command the loop counts as settled exactly once its
        # transient has decayed below the quiet level. Where that is depends only on the
        # anchor, so an anchor taken later (see Axis.commit) gives the same values.
        decayed = self._settle_after(size) if len(forced.y) == 1 else math.inf
        return Transient(k0, v0, v1, m0, m1, decayed, self.table(rate))

    def response(self, state: PlantState, forced: Forced, samples: np.ndarray,
                 rate: float) -> tuple[np.ndarray, np.ndarray]:
        """Position and velocity at whole ``samples`` (at ``rate``) from ``state``."""
        s = samples / rate - state.t
        y = poly_eval(forced.y, s)
        dy = poly_eval(forced.dy, s)
        transient = self.transient(state, forced, rate)
        if transient is None:
            return y, dy
        h0, h1 = transient.at(samples)
        if math.isinf(transient.decayed_after):
            return y + h0, dy + h1
        settled = s >= transient.decayed_after
        return np.where(settled, y, y + h0), np.where(settled, dy, dy + h1)

    def _settle_after(self, size: float) -> float:
        """Time for a transient of ``size`` to decay below the quiet level."""
        return math.log(size / _QUIET) / -self._sigma if size > _QUIET else 0.0

    def quiet_after(self, state: PlantState, yp: list[float]) -> float:
        """Seconds past ``state`` from which the loop counts as settled onto the steady
        solution ``yp`` (the test :meth:`response` applies sample by sample)."""
        dyp0 = yp[1] if len(yp) > 1 else 0.0
        size = abs(state.y - yp[0]) + abs(state.dy - dyp0) / (-self._sigma)
        return self._settle_after(size)

    def advance(self, state: PlantState, forced: Forced, t: float) -> PlantState:
        """State at time ``t`` (within the piece that starts at ``state.t``); scalar math."""
        s = t - state.t
        y = _poly_eval_scalar(forced.y, s)
        dy = _poly_eval_scalar(forced.dy, s)
        e0 = state.y - forced.y[0]
        e1 = state.dy - forced.dy[0]
        size = abs(e0) + abs(e1) / (-self._sigma)
        if size <= _QUIET or (len(forced.y) == 1 and s >= self._settle_after(size)):
            return PlantState(t, y, dy)
        h0, h1 = self._homogeneous_at(e0, e1, s)
        return PlantState(t, y + h0, dy + h1)

    def sample_step(self, rate: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """The loop over one sample of a command that goes linearly from p0 to p1 with a constant
        DAC feedforward d (a cam's slave: its command is known only sample by sample): rows r0,
        r1 with y' = r0 . (y, dy, p0, p1, d) and dy' = r1 . (y, dy, p0, p1, d). The closed form
        of :meth:`advance` for that piece, which is linear in those five values, so the rows are
        its responses to each of them alone. Cached per rate."""
        key = ("step", rate)
        cached = self._steps.get(key)
        if cached is not None:
            return cached
        span = 1.0 / rate

        def after(y: float, dy: float, p0: float, p1: float, d: float) -> tuple[float, float]:
            yp = self.particular([p0, (p1 - p0) * rate])
            if d:
                yp = _poly_add(yp, self._particular([d], self._dac_gains))
            dyp = poly_der(yp)
            h0, h1 = self._homogeneous_at(y - yp[0], dy - _poly_eval_scalar(dyp, 0.0), span)
            return _poly_eval_scalar(yp, span) + h0, _poly_eval_scalar(dyp, span) + h1

        columns = [after(*(1.0 if i == j else 0.0 for j in range(5))) for i in range(5)]
        step = (tuple(float(c[0]) for c in columns), tuple(float(c[1]) for c in columns))
        self._steps[key] = step
        return step

    # -- servo off (ABORT) ---------------------------------------------------------
    def coast(self, state: PlantState, samples: np.ndarray, rate: float) -> tuple[np.ndarray, np.ndarray]:
        """Position and velocity of the coasting motor at whole ``samples`` (y'' = -y'/tau_c),
        reached from the anchor like :meth:`_homogeneous` (tables, no vectorised exp)."""
        k0 = _first_sample(state.t, rate)
        first = math.exp(-(k0 / rate - state.t) / self._coast)
        k = first * self.table(rate).coast_at(samples - k0)
        return state.y + state.dy * self._coast * (1.0 - k), state.dy * k

    def coast_to(self, state: PlantState, t: float) -> PlantState:
        k = math.exp(-(t - state.t) / self._coast)
        return PlantState(t, state.y + state.dy * self._coast * (1.0 - k), state.dy * k)

    # -- encoder ---------------------------------------------------------------------
    def read(self, y: np.ndarray) -> np.ndarray:
        """Encoder reading of motor position(s)."""
        if self._resolution <= 0.0:
            return y
        return np.floor(y / self._resolution + 0.5) * self._resolution


def servo_effort(config: PlantConfig, error: Effort, cmd_v: Effort, act_v: Effort, cmd_a: Effort,
                 feedforward: float) -> Effort:
    """The position loop's control effort, in counts/s^2: ``w^2 (u - y) + 2 zeta w (kv u' -
    y') + ka u''`` (u the command, y the motor; w, zeta, kv, ka the bandwidth, damping and
    feed-forwards), the acceleration it demands of a motor of unit inertia, which is what the
    simulated motor then does; a PTF/PVTF feedforward adds its DAC counts times
    ``dac_acceleration``. Computed as a real servo computes it: from the encoder's reading of
    the position (``error``, so it carries the encoder's quantisation) and the actual velocity.
    The values may be arrays (one feedforward for them all): the same operations, element by
    element, give the same bits as one at a time (status snapshots take a stretch's at once)."""
    w = 2.0 * math.pi * config.bandwidth_hz
    effort = (w * w * error + 2.0 * config.damping * w * (config.velocity_feedforward * cmd_v - act_v)
              + config.acceleration_feedforward * cmd_a)
    if feedforward:
        effort += config.dac_acceleration * feedforward
    return effort


def _first_sample(t: float, rate: float) -> int:
    """The first whole sample at or after time ``t``."""
    k = math.ceil(t * rate)
    while k / rate < t:
        k += 1
    while (k - 1) / rate >= t:
        k -= 1
    return k


_TABLES: dict[tuple[float, float, float, float], _FreeTable] = {}  # shared by identical loops
_TABLE = 4096  # samples of free response tabulated; further ones are products of two
_BLOCKS_WATCHED = 64  # blocks of _TABLE samples searched for an exact underflow (about 2 min at 2 kHz)
_LONG_BLOCKS = 8  # blocks of Phi kept as one table (16 s at 2 kHz), or up to its underflow if sooner


class _FreeTable:
    """Phi(m dt) = p_m I + q_m M and the coast decay exp(-m dt / tau_c) for m < _TABLE,
    from the C library's scalar functions (the same on every CPU); beyond, products
    Phi((a + b) dt) = Phi(a dt) Phi(b dt), using M^2 = kappa I."""

    __slots__ = ("_bp", "_bq", "_long", "_pq", "_pq2", "_vanishing", "block_k", "block_p", "block_q", "k", "kappa", "p",
                 "q")

    def __init__(
        self, p: npt.NDArray[np.float64], q: npt.NDArray[np.float64], k: npt.NDArray[np.float64], kappa: float,
    ) -> None:
        self.p, self.q, self.k, self.kappa = p, q, k, kappa
        self.block_p: list[float] = [1.0]  # Phi(n _TABLE dt) for n = 0, 1, ... (grown on demand)
        self.block_q: list[float] = [0.0]
        self.block_k: list[float] = [1.0]
        # p and q as the two rows of one array, so a window reads both at once; and twice
        # over: the remainders of a run of samples that crosses a block boundary are then
        # one contiguous window.
        self._pq = np.stack((p, q))
        self._pq2 = np.concatenate((self._pq[:, :_TABLE], self._pq[:, :_TABLE]), axis=1)
        self._bp = np.array(self.block_p)
        self._bq = np.array(self.block_q)
        self._vanishing: float | None = None
        self._long: np.ndarray | None = None

    @classmethod
    def build(cls, plant: Plant, rate: float) -> _FreeTable:
        pq = [plant._free(m / rate) for m in range(_TABLE + 1)]
        p = np.array([x for x, _ in pq])
        q = np.array([y for _, y in pq])
        k = np.array([math.exp(-(m / rate) / plant._coast) for m in range(_TABLE + 1)])
        return cls(p, q, k, plant._kappa)

    def _blocks(self, n: int) -> None:
        if len(self.block_p) > n:
            return
        while len(self.block_p) <= n:
            a, b = self.block_p[-1], self.block_q[-1]
            c, d = float(self.p[_TABLE]), float(self.q[_TABLE])
            self.block_p.append(a * c + self.kappa * b * d)
            self.block_q.append(a * d + b * c)
            self.block_k.append(self.block_k[-1] * float(self.k[_TABLE]))
        self._bp = np.array(self.block_p)
        self._bq = np.array(self.block_q)

    def at(self, m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(p, q) of Phi(m dt) for sample counts m >= 0 (any shape)."""
        if m.size == 0 or m.max() < _TABLE:
            return self.p[m], self.q[m]
        n, r = np.divmod(m, _TABLE)
        self._blocks(int(n.max()))
        bp, bq = self._bp[n], self._bq[n]
        pr, qr = self.p[r], self.q[r]
        return bp * pr + self.kappa * bq * qr, bp * qr + bq * pr

    def window(self, m0: np.ndarray, n: int, scratch: Scratch | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(p, q) of Phi((m0_r + i) dt) for rows r and 0 <= i < n <= _TABLE: for each row
        what :meth:`at` gives for m0_r + arange(n). Rows read the long table directly while
        every count stays inside it, else as blocks x remainders; the two agree where
        both apply (block 0 is exactly Phi(0) = I), so any mix of rows is exact. The
        arrays come from ``scratch`` (stretch.Scratch) if given."""
        def take(name: str, *shape: int) -> np.ndarray | None:
            return None if scratch is None else scratch.take("free." + name, (*shape, len(m0), n))
        long = self._long_table()
        if int(m0.max()) + n <= long.shape[1]:
            p, q = _windows(long, m0, n, take("pq", 2))
            return p, q
        blocks, r0 = np.divmod(m0, _TABLE)
        self._blocks(int(blocks.max()) + 1)
        bp, bq = self._block_rows(blocks, r0, n)
        pr, qr = _windows(self._pq2, r0, n, take("pqr", 2))
        # bp pr + kappa bq qr and bp qr + bq pr, as `at` sums them
        p = np.multiply(bp, pr, out=take("p"))
        p += np.multiply(self.kappa * bq, qr, out=take("product"))
        q = np.multiply(bp, qr, out=take("q"))
        q += np.multiply(bq, pr, out=take("product"))
        return p, q

    def _long_table(self) -> npt.NDArray[np.float64]:
        """(p, q) of Phi(m dt) as two rows for m below _LONG_BLOCKS blocks, or below the
        underflow (from which they are zeros): the table, then the products :meth:`at` and
        the blocks of :meth:`window` compute beyond it (the same operations element for
        element), computed once, so that a window that stays below reads them directly."""
        if self._long is None:
            end = int(min(self.vanishing_count(), _LONG_BLOCKS * _TABLE))
            beyond = np.stack(self.at(np.arange(_TABLE, max(end, _TABLE), dtype=np.int64)))
            self._long = np.concatenate((self._pq[:, :_TABLE], beyond), axis=1)
        return self._long

    def vanishing_count(self) -> float:
        """The sample count from which Phi(m dt) is exactly zero: the start of the first block
        whose factor has underflowed to zeros (every later one is zero too, as products of
        it); inf if none has within _BLOCKS_WATCHED blocks (a slow loop)."""
        if self._vanishing is None:
            self._vanishing = math.inf
            for n in range(1, _BLOCKS_WATCHED):
                self._blocks(n)
                if self.block_p[n] == 0.0 and self.block_q[n] == 0.0:
                    self._vanishing = float(n * _TABLE)
                    break
        return self._vanishing

    def _block_rows(self, blocks: np.ndarray, r0: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
        """The block factor of every count of each row: one block per row (a column),
        or, for a row that crosses into the next block, two runs of a full row."""
        bp, bq = self._bp[blocks][:, None], self._bq[blocks][:, None]
        crossing = np.flatnonzero(r0 + n > _TABLE)
        if not len(crossing):
            return bp, bq
        bp, bq = np.repeat(bp, n, axis=1), np.repeat(bq, n, axis=1)
        for row in crossing.tolist():
            split, nxt = _TABLE - int(r0[row]), int(blocks[row]) + 1
            bp[row, split:] = self._bp[nxt]
            bq[row, split:] = self._bq[nxt]
        return bp, bq

    def coast_at(self, m: npt.NDArray[np.int64]) -> npt.NDArray[np.float64]:
        if len(m) == 0 or m[-1] < _TABLE:
            return self.k[m]
        n, r = np.divmod(m, _TABLE)
        self._blocks(int(n[-1]))
        return np.array(self.block_k)[n] * self.k[r]


def _windows(
    tables: npt.NDArray[np.float64], starts: npt.NDArray[np.int64], n: int, out: npt.NDArray[np.float64] | None = None,
) -> npt.NDArray[np.float64]:
    """(tables, starts, n): rows tables[:, s : s + n] for each start s (copies of contiguous
    runs), into ``out`` if given. Short rows are gathered by index (s + 0 .. n-1), which
    costs less to set up than a window view (a stretch of a few samples pays little else);
    long rows are copied one by one (np.take on a window view would first copy the whole
    virtual view)."""
    if n < 256:
        return np.take(tables, starts[:, None] + np.arange(n), axis=1, out=out)
    if out is None:
        return sliding_window_view(tables, n, axis=1)[:, starts]
    for row, start in enumerate(starts.tolist()):
        out[:, row] = tables[:, start:start + n]
    return out


def _poly_eval_scalar(c: list[float], s: float) -> float:
    out = c[-1]
    for coefficient in reversed(c[:-1]):
        out = out * s + coefficient
    return out


def poly_der(c: list[float]) -> list[float]:
    return [i * c[i] for i in range(1, len(c))] or [0.0]


def poly_eval(c: list[float], s: np.ndarray) -> np.ndarray:
    out = np.full(len(s), c[-1])
    for coefficient in reversed(c[:-1]):
        out *= s
        out += coefficient
    return out


def _poly_mul(a: list[float], b: list[float]) -> list[float]:
    out = [0.0] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        for k, y in enumerate(b, i):  # k = i + j
            out[k] += x * y
    return out


def _poly_add(a: list[float], b: list[float]) -> list[float]:
    """a + b (coefficients, low first)."""
    longer, shorter = (a, b) if len(a) >= len(b) else (b, a)
    return [x + (shorter[i] if i < len(shorter) else 0.0) for i, x in enumerate(longer)]


def compose(segment_poly: list[float], quadratic: tuple[float, float, float]) -> list[float]:
    """segment_poly(q0 + q1 s + q2 s^2) as coefficients in s (low first)."""
    if len(segment_poly) == 1:  # a constant (no feedforward: [held]) stays itself
        return [segment_poly[0]]
    if len(segment_poly) == 4 and quadratic[2] == 0.0:
        return _cubic_of_linear(segment_poly, quadratic[0], quadratic[1])
    q = list(quadratic) if quadratic[2] != 0.0 else list(quadratic[:2])
    out = [segment_poly[-1]]
    for c in reversed(segment_poly[:-1]):
        out = _poly_mul(out, q)
        out[0] += c
    return out


def _cubic_of_linear(cubic: list[float], q0: float, q1: float) -> list[float]:
    """:func:`compose` of a cubic with q0 + q1 s (a segment while the feedrate does not ramp:
    nearly every command piece), its loop written out: each product of _poly_mul summed in
    its order (coefficient k: 0.0 + out[k-1] q1 + out[k] q0), then the next coefficient added."""
    c0, c1, c2, c3 = cubic
    a0, a1 = 0.0 + c3 * q0 + c2, 0.0 + c3 * q1
    b0, b1, b2 = 0.0 + a0 * q0 + c1, 0.0 + a0 * q1 + a1 * q0, 0.0 + a1 * q1
    return [0.0 + b0 * q0 + c0, 0.0 + b0 * q1 + b1 * q0, 0.0 + b1 * q1 + b2 * q0, 0.0 + b2 * q1]
