"""Axis: command, actual and error positions, origin, the simulated servo, status.

The command follows the plan of the move loaded on the axis (read through the owning
supervisor's feedrate clock), or rests at a fixed position. An Axis is a view of its
column in the controller's AxisBank (the values at the current sample, status bits,
settling counters) plus what only changes on a command: its plan, the plant anchor,
the mode. From those it writes its rows in the bank (:meth:`refresh`), from which the
controller computes every axis over a stretch at once (trace.py); the few axes that
cannot be written as rows (coasting, command following the actual, a breakpoint inside
the stretch) are traced here one at a time (:meth:`trace`). Values at a sample depend
only on the command history (plant anchors sit at command breakpoints), never on how
the stretch was cut, so stepping 1 sample at a time or 10,000 at once agree exactly.

Positions seen by users are raw positions minus the origin (mpiAxisOriginSet).
"""

from __future__ import annotations

import bisect
import itertools
import math
import operator
from dataclasses import dataclass, field
from enum import Enum
from typing import Generic, Self, TypeVar, overload

import numpy as np

from mpi_ros.mpi.axes.bank import AxisBank, Kind
from mpi_ros.mpi.axes.plant import Forced, Plant, PlantState, compose, servo_effort
from mpi_ros.mpi.axes.status import AxisStatusBits, StatusMode, bits_of, column_of
from mpi_ros.mpi.base import masters
from mpi_ros.mpi.base.clock import ProfileClock
from mpi_ros.mpi.base.events import EventNotify
from mpi_ros.mpi.base.outcome import VALID, Outcome
from mpi_ros.mpi.base.params import AxisInPosition, AxisMaster, PlantConfig, check_position
from mpi_ros.mpi.base.types import MPIState
from mpi_ros.mpi.base.wrap import turn_offset, wrap_position
from mpi_ros.mpi.planning.frames import AxisPlan


@dataclass(slots=True)
class AxisTrace:
    """Every sample of one stretch of an axis' motion (raw positions)."""

    samples: np.ndarray
    t: np.ndarray
    cmd_p: np.ndarray
    cmd_v: np.ndarray
    cmd_a: np.ndarray
    act_p: np.ndarray
    act_v: np.ndarray
    rel: np.ndarray  # profile time into the plan (nan without a plan)
    anchors: list[PlantState] = field(default_factory=list)  # plant state at each piece start
    steady: bool = False  # nothing changes over the stretch

    def __len__(self) -> int:
        return len(self.samples)


@dataclass(slots=True)
class _Command:
    """The command pieces of one plan read from one start through one clock with one held
    feedforward (or of one rest): their boundary times (made when first asked for) and each
    piece's steady response, by its start time."""

    plan: AxisPlan | None  # kept while this lives: its id is in the key, and a plan freed
    # meanwhile could hand its id to a new one (a path extended at the same start and clock)
    times: list[float] | None = None
    forced: dict[float, Forced] = field(default_factory=dict)


_COMMANDS_KEPT = 64  # commands whose pieces an axis keeps (a modify makes a new one)
_PIECES_KEPT = 256  # steady responses kept per command (a long path has a piece per segment)


class CommandMode(Enum):
    SERVO = "SERVO"  # command drives the loop
    FOLLOW_ACTUAL = "FOLLOW_ACTUAL"  # settleOnEstopCmdEqAct: command = previous actual
    COAST = "COAST"  # amplifier off (ABORT): the motor coasts


V = TypeVar("V")


class _Derived(Generic[V]):
    """An attribute (of type V) the axis' rows in the bank derive from: setting it marks them
    stale."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.slot = "_" + name
        # At run time the attribute is a property with this __set__ and a getter in C, since
        # the stepping reads these attributes tens of times per command piece. (__get__ below
        # is what type checkers see.)
        setattr(owner, name, property(operator.attrgetter(self.slot), self.__set__))

    @overload
    def __get__(self, axis: None, owner: type | None = None) -> Self: ...
    @overload
    def __get__(self, axis: Axis, owner: type | None = None) -> V: ...
    def __get__(self, axis: Axis | None, owner: type | None = None) -> Self | V:
        return self if axis is None else getattr(axis, self.slot)

    def __set__(self, axis: Axis, value: V) -> None:
        setattr(axis, self.slot, value)
        axis._bank.stale[axis.number] = True


class _Anchor(_Derived[V]):
    """The plant anchor: moving it changes only the axis' servo rows (a lighter rebuild)."""

    def __set__(self, axis: Axis, value: V) -> None:
        setattr(axis, self.slot, value)
        axis._bank.moved[axis.number] = True


class _Value:
    """A value of the axis at the current sample, kept in the bank's arrays."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, axis: None, owner: type | None = None) -> Self: ...
    @overload
    def __get__(self, axis: Axis, owner: type | None = None) -> float: ...
    def __get__(self, axis: Axis | None, owner: type | None = None) -> Self | float:
        return self if axis is None else float(getattr(axis._bank, self.name)[axis.number])

    def __set__(self, axis: Axis, value: float) -> None:
        getattr(axis._bank, self.name)[axis.number] = value


class Axis:
    # command
    plan: _Derived[AxisPlan | None] = _Derived()
    tau_start: _Derived[float] = _Derived()
    rest: _Derived[float] = _Derived()  # raw command when no plan is loaded
    mode: _Derived[CommandMode] = _Derived()
    holding: _Derived[bool] = _Derived()  # a hold frame is waiting for its trigger
    # plant, anchored at the start of the current command piece
    state: _Anchor[PlantState] = _Anchor()
    plant: _Derived[Plant] = _Derived()
    # status
    status_mode: _Derived[StatusMode] = _Derived()
    target: _Derived[float] = _Derived()
    in_position: _Derived[AxisInPosition] = _Derived()  # replaced whole, never changed in place
    # values at the current sample (floats)
    cmd_p = _Value()
    cmd_v = _Value()
    cmd_a = _Value()
    act_p = _Value()
    act_v = _Value()
    rel = _Value()  # profile time into the plan (nan without one)

    def __init__(self, number: int, bank: AxisBank, sample_rate: float, in_position: AxisInPosition,
                 plant: PlantConfig):
        self.number = number
        # an Axis object the application holds (mpiAxisCreate; mpiAxisDelete clears it): the
        # firmware axis runs either way, an invalid one is no one's to command (Controller.axis_delete)
        self.valid = True
        self._bank = bank
        self.rate = sample_rate
        self.in_position = in_position.copy()
        self.master = AxisMaster()  # MPIAxisConfig.master and masterCorrection (cams)
        self.plant = Plant(plant)
        self.origin = 0.0
        self.enabled = True  # the amplifier enable the host set (amp_enable_set; OBJECT_NOT_ENABLED when off)
        self.events = EventNotify()  # mpiAxisEventNotifySet/Reset: no host notification until asked
        self.plan = None
        self.tau_start = 0.0
        self.rest = 0.0
        self.mode = CommandMode.SERVO
        self.holding = False
        self.owner = -1
        self.move_id = 0
        self.element_id = 0
        self._held_feedforward = 0.0  # PTF/PVTF feedforward kept from move to move
        self.state = PlantState(0.0, 0.0, 0.0)
        self._cache: dict[tuple[float | None, ...], _Command] = {}  # (_command_of)
        self._sampled: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None  # a cam slave's last trace
        self.status_mode = StatusMode.POINT_TO_POINT
        self.target = 0.0

    @property
    def owner(self) -> int:
        """The supervisor commanding the axis (-1: none); its clock drives the plan."""
        return int(self._bank.owner[self.number])

    @owner.setter
    def owner(self, number: int) -> None:
        self._bank.owner[self.number] = number
        self._bank.stale[self.number] = True

    @property
    def status(self) -> AxisStatusBits:
        return bits_of(self._bank.bits[:, self.number])

    @status.setter
    def status(self, bits: AxisStatusBits) -> None:
        self._bank.bits[:, self.number] = column_of(bits)

    def command_values(self) -> tuple[float, float, float]:
        """The command's raw position, velocity and acceleration now (one read of the bank)."""
        p, v, a = self._bank.values[:3, self.number].tolist()  # (VALUES order: cmd_p, cmd_v, cmd_a)
        return p, v, a

    # -- positions (user coordinates) ------------------------------------------------
    # What the controller reports is 32-bit (wrap.py): the command_/actual_/target_position
    # getters wrap; faults, holds and cam masters follow the continuous unwrapped_ values.
    @property
    def unwrapped_command(self) -> float:
        return self.cmd_p - self.origin

    @property
    def unwrapped_actual(self) -> float:
        return self.act_p - self.origin

    @property
    def command_position(self) -> float:
        """mpiAxisCommandPositionGet: in [-2^31, 2^31)."""
        return wrap_position(self.cmd_p - self.origin)

    @property
    def actual_position(self) -> float:
        """mpiAxisActualPositionGet: in [-2^31, 2^31)."""
        return wrap_position(self.act_p - self.origin)

    @property
    def position_error(self) -> float:
        return self.cmd_p - self.act_p

    @property
    def target_position(self) -> float:
        return wrap_position(self.target - self.origin)

    def turn_origin(self, raw: float) -> float:
        """The origin an absolute position of a move starting at ``raw`` is read with: the
        axis' origin plus the turns (multiples of 2^32) the command has made, so that the
        distance of a move is its target minus the position the controller reports."""
        offset = turn_offset(raw - self.origin)
        return self.origin if offset == 0.0 else self.origin + offset

    def set_origin(self, origin: float) -> Outcome:
        """mpiAxisOriginSet: reported positions are raw positions minus the origin."""
        verdict = check_position("origin", origin)
        if not verdict.ok:
            return verdict
        self.origin = float(origin)
        return VALID

    def set_actual_position(self, position: float, t: float, clock: ProfileClock | None = None) -> Outcome:
        """mpiAxisActualPositionSet: the encoder now reads ``position``. The command is
        untouched, so the loop sees the new error and moves to remove it. ``clock`` is the
        owning supervisor's: the plant is re-anchored along the plan the axis follows."""
        verdict = check_position("position", position)
        if not verdict.ok:
            return verdict
        delta = (float(position) + self.origin) - self.act_p
        if clock is None:  # without the clock only a resting command can be followed
            self._retire_finished_plan(t, None)
        self.rebase(t, clock)
        self.state = PlantState(self.state.t, self.state.y + delta, self.state.dy)
        self.act_p += delta
        return VALID

    def can_set_command(self, state: MPIState) -> bool:
        """The one rule of mpiAxisCommandPositionSet (MPI 002, "mpiAxisCommandPositionSet(...)
        Error Check"), for the axis service and mpiMotionPositionSet alike; ``state`` is the
        axis' state (its supervisor's). Refused while the controller computes a new command
        every sample: in a MOVING, STOPPING or STOPPED state (STOPPING_ERROR is a stopping
        state too), while the command follows the actual position (settleOnEstopCmdEqAct,
        the simulator's "CMD_EQ_ACT with the amp disabled"), while a loaded move still
        changes the command, or while a hold waits. ERROR and IDLE are not on the list: there
        the command rests and can be set, also at the end of a finished move (002: "set the
        command position when the motion is in an IDLE state")."""
        if state in (MPIState.MOVING, MPIState.STOPPING, MPIState.STOPPED, MPIState.STOPPING_ERROR):
            return False
        return self.command_at_rest and not self.holding and self.mode is not CommandMode.FOLLOW_ACTUAL

    @property
    def camming(self) -> bool:
        """A cam's slave: its command follows a master position sample by sample (cams.py)."""
        plan = self.plan
        return plan is not None and plan.cam is not None

    def cam_reads(self) -> set[int]:
        """The axes whose values at a sample this cam slave's master position reads."""
        plan = self.plan
        return masters.reads(plan.cam.master) if plan is not None and plan.cam is not None else set()

    @property
    def command_at_rest(self) -> bool:
        """The command no longer changes: no plan, or a point-to-point plan whose last frame
        holds its end position (the plan stays loaded after its move is done)."""
        plan = self.plan
        return plan is None or (not plan.is_velocity and plan.final_velocity == 0.0 and self.rel >= plan.duration)

    def _retire_finished_plan(self, t: float, clock: ProfileClock | None) -> None:
        """Before a setter re-anchors the plant: a finished plan is dropped and the command
        rests where it ended. Without the supervisor's clock the plant then follows the
        resting command, exactly as the plan's last frame would (its anchor is at or after
        the plan's end: anchors sit at command breakpoints)."""
        if self.plan is not None and self.command_at_rest:
            if clock is not None:
                self.rebase(t, clock)
            self.plan = None
            self.rest = self.cmd_p

    def set_command_position(self, position: float, t: float, clock: ProfileClock | None = None) -> None:
        """Command steps to ``position``; the loop follows (check ``can_set_command`` and the
        range, params.check_position, first). A finished plan is dropped: the command now
        rests at ``position``."""
        self._retire_finished_plan(t, clock)
        self.rebase(t, clock)
        self.rest = position + self.origin
        self.cmd_p = self.rest
        self.cmd_v = self.cmd_a = 0.0
        self.target = self.rest

    # -- command ---------------------------------------------------------------------
    def rebase(self, t: float, clock: ProfileClock | None = None) -> None:
        """Re-anchor the plant at ``t``: a command takes effect from here on."""
        if t == self.state.t:
            return
        state = self.state
        for _start, end, forced in self._pieces(state.t, t, clock):
            stop = min(end, t)
            state = self._advance_piece(state, forced, stop)
            if end >= t:
                break
        self.state = state

    def _advance_piece(self, state: PlantState, forced: Forced | None, t: float) -> PlantState:
        if self.mode is CommandMode.COAST:
            return self.plant.coast_to(state, t)
        assert forced is not None  # only a coasting axis has no steady response (_pieces)
        return self.plant.advance(state, forced, t)

    def load(self, plan: AxisPlan, tau_start: float, t: float, clock: ProfileClock) -> None:
        """Start executing ``plan`` at profile time ``tau_start`` (time ``t``)."""
        self.rebase(t, clock)
        self._hold_feedforward()
        plan.start_feedforward(self._held_feedforward)
        self.plan = plan
        self.tau_start = tau_start
        self.holding = False
        self.target = plan.target
        self._bank.reset_counters(self.number)

    def extend(self, plan: AxisPlan, t: float, clock: ProfileClock) -> None:
        """The path it runs, with points appended (paths.extend): the same profile up to now,
        so it goes on from here in the same profile time, status counters and all."""
        self.rebase(t, clock)
        self._hold_feedforward()
        self.plan = plan
        self.target = plan.target

    @property
    def feedforward(self) -> float:
        """The PTF/PVTF feedforward (raw DAC counts) now: interpolated along the plan that has
        one, else the value the last one left (MPI 000, MPIMotionPTF: not zeroed by other moves)."""
        plan = self.plan
        if plan is None or plan.feedforward is None:  # (the held value: no profile time to read)
            return self._held_feedforward
        return plan.feedforward_at(self.rel, self._held_feedforward)

    def feedforward_at(self, rel: float) -> float:
        """:attr:`feedforward` at profile time ``rel`` of the plan."""
        plan = self.plan
        if plan is None:
            return self._held_feedforward
        return plan.feedforward_at(rel, self._held_feedforward)

    def servo_effort(self) -> float:
        """The simulated servo's control effort now, counts/s^2 (plant.servo_effort); 0 while
        the amplifier is off (after ABORT the motor coasts)."""
        if not self.amp_enabled:
            return 0.0
        return self.effort_of(self.cmd_p - self.act_p, self.cmd_v, self.act_v, self.cmd_a, self.feedforward)

    def effort_of(self, error: float, cmd_v: float, act_v: float, cmd_a: float, feedforward: float) -> float:
        """The servo's effort for these values of the axis (amplifier on)."""
        return servo_effort(self.plant.config, error, cmd_v, act_v, cmd_a, feedforward)

    def _hold_feedforward(self) -> None:
        """Before the plan changes: keep the feedforward it has reached."""
        self._held_feedforward = self.feedforward

    @property
    def current_element_id(self) -> int:
        """The element id of the point a path runs toward (ELEMENT_ID per point), else the
        move's."""
        return self.element_id_at(self.rel)

    def element_id_at(self, rel: float) -> int:
        """:attr:`current_element_id` at profile time ``rel`` of the plan (nan: none)."""
        plan = self.plan
        if plan is not None and plan.element_ids:
            found = plan.element_at(rel if math.isfinite(rel) else -math.inf)
            if found is not None:
                return found
        return self.element_id

    def unload(self, t: float, clock: ProfileClock | None) -> None:
        """Drop the plan; the command rests where it is now."""
        self.rebase(t, clock)
        self._hold_feedforward()
        self.plan = None
        self.rest = self.cmd_p
        self.target = self.rest
        self.holding = False

    # -- tracing ---------------------------------------------------------------------
    def _command_arrays(
        self, t: np.ndarray, clock: ProfileClock | None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        n = len(t)
        if self.plan is None or clock is None:
            const = np.full(n, self.rest)
            zero = np.zeros(n)
            return const, zero, zero, np.full(n, math.nan)
        rel = clock.tau(t) - self.tau_start
        p, dp, ddp = self.plan.evaluate(rel)
        f, df = clock.feedrates(t)
        return p, dp * f, ddp * f * f + dp * df, rel

    def _command_of(self, clock: ProfileClock | None) -> _Command:
        """The command pieces of the plan (or rest) the axis follows now through ``clock``,
        found by what they derive from (as a flat tuple of values that hash without Python
        calls: the clock's fields, which are what its equality compares; not the mode, which
        they do not depend on). Looked up once per question, not per piece."""
        plan = self.plan
        if plan is None or clock is None:
            key: tuple[float | None, ...] = (None, self.rest, self._held_feedforward)
        else:
            key = (id(plan), self.tau_start, clock.t0, clock.tau0, clock.f0, clock.f1, clock.t_end,
                   self._held_feedforward)
        command = self._cache.get(key)
        if command is None:
            if len(self._cache) >= _COMMANDS_KEPT:
                self._cache.clear()
            command = self._cache[key] = _Command(plan)
        return command

    def _boundary_times(self, command: _Command, clock: ProfileClock | None) -> list[float]:
        """All times at which the command polynomial changes (sorted)."""
        if command.times is not None:
            return command.times
        times: list[float] = []
        plan, tau_start = self.plan, self.tau_start
        if plan is not None and clock is not None:
            times.append(clock.t_end)
            times += clock.times_of_tau([tau_start + b for b in plan.boundaries().tolist()], clock.t0)
            times = sorted({x for x in times if -math.inf < x < math.inf})  # (the finite ones)
        command.times = times
        return times

    def _forced(self, command: _Command, ts: float, te: float, clock: ProfileClock | None) -> Forced:
        """Steady response of the loop for the command piece [ts, te)."""
        cached = command.forced.get(ts)
        if cached is not None:
            return cached
        plan, held = self.plan, self._held_feedforward
        if plan is None or clock is None:
            poly, dac = [self.rest], [held]
        else:
            tau_start = self.tau_start
            mid = ts + 0.5 * (te - ts) if math.isfinite(te) else ts + 1.0
            rel = clock.tau_at(mid) - tau_start
            seg_start, seg_poly = plan.segment_poly(rel)
            q0, q1, q2 = clock.local_quadratic(ts)
            poly = compose(seg_poly, (q0 - tau_start - seg_start, q1, q2))
            ff_start, ff_poly = plan.feedforward_poly(rel, held)
            dac = compose(ff_poly, (q0 - tau_start - ff_start, q1, q2))
        forced = self.plant.prepare(poly, dac)
        if len(command.forced) >= _PIECES_KEPT:
            command.forced.clear()
        command.forced[ts] = forced
        return forced

    def _pieces(
        self, t_from: float, t_to: float, clock: ProfileClock | None,
    ) -> list[tuple[float, float, Forced | None]]:
        """[(start, end, steady response)] of the command pieces covering [t_from, t_to]."""
        if self.mode is CommandMode.COAST:
            return [(t_from, math.inf, None)]
        command = self._command_of(clock)
        times = self._boundary_times(command, clock)
        i = bisect.bisect_right(times, t_from)
        cuts = [t_from]
        while i < len(times) and cuts[-1] <= t_to:
            cuts.append(times[i])
            i += 1
        if cuts[-1] <= t_to:
            cuts.append(math.inf)
        return [(a, b, self._forced(command, a, b, clock)) for a, b in itertools.pairwise(cuts)]

    def steady(self, clock: ProfileClock | None) -> bool:
        """At rest with the loop settled: every coming sample is the same."""
        if self.plan is not None or self.holding or self.mode is not CommandMode.SERVO:
            return False
        return self.state.y == self.rest_position and self.state.dy == 0.0

    def trace(self, k0: int, k1: int, clock: ProfileClock | None,
              cam: tuple[np.ndarray, np.ndarray] | None = None) -> AxisTrace:
        """Samples k0+1 .. k1, computed from the current anchor (no state changes but a
        cam's progress, kept aside until :meth:`keep_anchor`). ``cam``: a cam slave's master
        position and feedrate ratio at each of the samples."""
        samples = np.arange(k0 + 1, k1 + 1, dtype=np.int64)
        t = samples / self.rate
        if cam is not None and self.camming and self.mode is CommandMode.SERVO:
            return self._trace_cam(samples, t, *cam)
        if self.steady(clock):
            n = len(t)
            zero = np.zeros(n)
            return AxisTrace(samples, t, np.full(n, self.rest), zero, zero,
                             np.full(n, self.act_p), zero, np.full(n, math.nan), [self.state], steady=True)
        cmd_p, cmd_v, cmd_a, rel = self._command_arrays(t, clock)
        if self.mode is CommandMode.FOLLOW_ACTUAL:
            y, dy, anchors = self._trace_follow(t)
            cmd_p = np.concatenate(([self.act_p], self.plant.read(y)[:-1]))
            cmd_v = np.zeros_like(t)
            cmd_a = np.zeros_like(t)
        else:
            y, dy, anchors = self._trace_plant(samples, t, clock)
        return AxisTrace(samples, t, cmd_p, cmd_v, cmd_a, self.plant.read(y), dy, rel, anchors)

    def _trace_plant(
        self, samples: np.ndarray, t: np.ndarray, clock: ProfileClock | None,
    ) -> tuple[np.ndarray, np.ndarray, list[PlantState]]:
        y = np.empty_like(t)
        dy = np.empty_like(t)
        state = self.state
        anchors = [state]
        for start, end, forced in self._pieces(state.t, float(t[-1]), clock):
            lo = int(np.searchsorted(t, start, side="left"))
            hi = int(np.searchsorted(t, end, side="left"))
            if hi > lo:
                if self.mode is CommandMode.COAST:
                    y[lo:hi], dy[lo:hi] = self.plant.coast(state, samples[lo:hi], self.rate)
                else:
                    assert forced is not None  # only a coasting axis has no steady response (_pieces)
                    y[lo:hi], dy[lo:hi] = self.plant.response(state, forced, samples[lo:hi], self.rate)
            if end > t[-1] or not math.isfinite(end):
                break
            state = self._advance_piece(state, forced, end)
            anchors.append(state)
        return y, dy, anchors

    def _trace_cam(self, samples: np.ndarray, t: np.ndarray, master: np.ndarray, scale: np.ndarray) -> AxisTrace:
        """A cam's slave: the command from the cam at each sample's master position, its
        velocity and acceleration as the differences from sample to sample, the loop stepped
        sample by sample with the command linear in between (Plant.sample_step). The plant
        states are kept aside, as the cam's progress is, until :meth:`keep_anchor`."""
        plan = self.plan
        assert plan is not None and plan.cam is not None  # (camming)
        cmd_p = plan.cam.follow(t, master, scale)
        cmd_v = (cmd_p - np.concatenate(([self.cmd_p], cmd_p[:-1]))) * self.rate
        cmd_a = (cmd_v - np.concatenate(([self.cmd_v], cmd_v[:-1]))) * self.rate
        y, dy = self._trace_steps(cmd_p)
        self._sampled = (t, y, dy)
        assert plan.cam.pending is not None  # (follow keeps the progress)
        return AxisTrace(samples, t, cmd_p, cmd_v, cmd_a, self.plant.read(y), dy, plan.cam.pending[1].u, [self.state])

    def _trace_steps(self, cmd_p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The loop driven by a command known at each sample, linear in between, from the
        anchor (at the sample before the first: a cam's slave is anchored every sample). Plain
        floats: a few multiplications per sample."""
        (a0, a1, a2, a3, a4), (b0, b1, b2, b3, b4) = self.plant.sample_step(self.rate)
        feedforward = self._held_feedforward
        y, dy, p0 = self.state.y, self.state.dy, self.cmd_p
        a_ff, b_ff = a4 * feedforward, b4 * feedforward
        ys, dys = [], []
        for p1 in cmd_p.tolist():
            y, dy = (a0 * y + a1 * dy + a2 * p0 + a3 * p1 + a_ff,
                     b0 * y + b1 * dy + b2 * p0 + b3 * p1 + b_ff)
            ys.append(y)
            dys.append(dy)
            p0 = p1
        return np.array(ys), np.array(dys)

    def _trace_follow(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[PlantState]]:
        """settleOnEstopCmdEqAct: each sample the command is the previous actual."""
        y = np.empty_like(t)
        dy = np.empty_like(t)
        state = self.state
        anchors = [state]
        held = self.act_p
        for i, ti in enumerate(t):
            state = self.plant.advance(state, self.plant.prepare([held]), float(ti))
            anchors.append(state)
            y[i], dy[i] = state.y, state.dy
            held = float(self.plant.read(np.array([state.y]))[0])
        return y, dy, anchors

    def keep_anchor(self, anchors: list[PlantState], t: float) -> None:
        """After a stretch traced here (:meth:`trace`): the plant anchor in force at time ``t``
        of it (the controller keeps the values)."""
        plan = self.plan
        if plan is not None and plan.cam is not None and self._sampled is not None:
            plan.cam.commit(t)
            times, y, dy = self._sampled
            i = int(np.searchsorted(times, t, side="right")) - 1
            self._sampled = None
            if i >= 0:
                self.state = PlantState(float(times[i]), float(y[i]), float(dy[i]))
            return
        anchor = self.state
        for candidate in anchors:
            if candidate.t <= t:
                anchor = candidate
            else:
                break
        if self.plan is None and self.mode is CommandMode.SERVO and not self.holding:
            anchor = self._settle_anchor(anchor, t)
        if anchor is not self.state:
            self.state = anchor

    def snap(self, t: float) -> None:
        """The rest the loop has reached by ``t`` (see :meth:`_settle_anchor`), for an axis
        computed in rows: PlantRows.snap_after says when."""
        self.state = PlantState(t, self.rest_position, 0.0)

    # -- rows ------------------------------------------------------------------------
    def refresh(self, clock: ProfileClock | None) -> None:
        """Write this axis' rows in the bank from its plan, anchor, mode and tolerances."""
        bank, row = self._bank, self.number
        bank.stale[row] = False
        bank.command.truncated[row] = self.plan is not None and self.plan.truncated
        bank.command.duration[row] = self.plan.duration if self.plan is not None else math.inf
        bank.status.set(row, self.status_mode, self.in_position, self.rate, self.target, self.holding, self.plan)
        self._write_command(clock)
        self.reanchor(clock)

    def reanchor(self, clock: ProfileClock | None) -> None:
        """Rewrite the rows that depend on the plant anchor (all that changed)."""
        bank, row = self._bank, self.number
        bank.moved[row] = False
        if self.steady(clock):
            bank.kind[row] = Kind.STEADY
        elif self.mode is CommandMode.SERVO and not self.camming:
            bank.kind[row] = Kind.PIECE
            self._write_piece(clock)
        else:
            bank.kind[row] = Kind.SAMPLED

    def _write_piece(self, clock: ProfileClock | None) -> None:
        """The command piece that starts at the anchor (what :meth:`_pieces` gives first)."""
        command = self._command_of(clock)
        times = self._boundary_times(command, clock)
        i = bisect.bisect_right(times, self.state.t)
        end = times[i] if i < len(times) else math.inf
        forced = self._forced(command, self.state.t, end, clock)
        bank, row = self._bank, self.number
        bank.plant.set_piece(row, self.state, end, forced, self.plant, self.rate, bank.table_index)
        at_rest = self.plan is None and not self.holding
        bank.plant.snap_after[row] = self.plant.quiet_after(self.state, forced.y) if at_rest else math.inf

    def continuations(self, t_last: float, clock: ProfileClock | None) -> list[tuple[PlantState, float, float, Forced]]:
        """The command pieces after the current one that start by ``t_last``, each with the
        plant anchor at its start: (anchor, start, end, steady response), the anchors
        advanced from piece to piece as :meth:`_trace_plant` advances them."""
        state = self.state
        pieces = self._pieces(state.t, t_last, clock)
        following: list[tuple[PlantState, float, float, Forced]] = []
        for (_, end, forced), (start, nxt_end, nxt_forced) in itertools.pairwise(pieces):
            assert nxt_forced is not None  # (a coasting axis has its one piece: no continuation)
            state = self._advance_piece(state, forced, end)
            following.append((state, start, nxt_end, nxt_forced))
        return following

    def _write_command(self, clock: ProfileClock | None) -> None:
        rows, row, plan = self._bank.command, self.number, self.plan
        rows.rest[row] = self.rest
        rows.planned[row] = planned = plan is not None and clock is not None
        if self._bank.plans[row] is not plan:
            self._bank.plans[row] = plan
            rows.segment[row] = -1  # chosen where the profile time is, when the controller steps
            rows.seg_lo[row], rows.seg_hi[row] = math.inf, -math.inf
        if planned:
            assert plan is not None  # (planned: a plan and a clock)
            rows.clock[row] = self.owner
            rows.tau_start[row] = self.tau_start
            rows.target[row] = plan.target
            rows.final_velocity[row] = plan.final_velocity

    def _settle_anchor(self, anchor: PlantState, t: float) -> PlantState:
        """Once the loop at rest has decayed below the quiet level, snap it exactly onto
        the command: from then on every sample is the same (the steady fast path). The
        decision depends only on the anchor and the sample time, never on batching."""
        forced = self._rest_response()
        if anchor.y == forced.y[0] and anchor.dy == 0.0:
            return anchor
        if t - anchor.t >= self.plant.quiet_after(anchor, forced.y):
            return PlantState(t, forced.y[0], 0.0)
        return anchor

    def _rest_response(self) -> Forced:
        """The loop's steady response with the command at rest (and the feedforward held)."""
        return self.plant.prepare([self.rest], [self._held_feedforward])

    @property
    def rest_position(self) -> float:
        """Where the motor rests with the command at rest: on it, or off it by what a held
        DAC feedforward pushes against the loop."""
        if self._held_feedforward == 0.0:
            return self.rest
        return self._rest_response().y[0]

    # -- amplifier ---------------------------------------------------------------------
    def disable(self, t: float, clock: ProfileClock | None) -> None:
        """ABORT: amplifier off; the command freezes, the motor coasts."""
        self.rebase(t, clock)
        self.plan = None
        self.holding = False
        self.rest = self.cmd_p
        self.mode = CommandMode.COAST

    def amp_fault(self, t: float, clock: ProfileClock | None) -> None:
        """An amplifier fault (faults.py): the amplifier is off and the motor coasts, while
        the command goes on along its plan until the fault's action stops the motion."""
        self.rebase(t, clock)
        self.mode = CommandMode.COAST

    def enable(self, t: float, command_equals_actual: bool) -> None:
        """RESET: amplifier back on (after ABORT the command is set to the actual)."""
        self.rebase(t)
        if command_equals_actual:
            self.rest = self.act_p
            self.cmd_p = self.act_p
        self.cmd_v = self.cmd_a = 0.0
        self.target = self.rest
        self.mode = CommandMode.SERVO

    def amp_enable_set(self, enabled: bool, t: float, clock: ProfileClock | None, servo: bool) -> None:
        """The host's amplifier enable (a motion that moves the axis is ABORTed first:
        Controller.axis_amp_enable_set). Off: the amplifier goes off and the motor coasts, as
        after an ABORT. On, with ``servo``: the amplifier is back on with the command at the
        actual position (the motor may have moved while it coasted); without (the axis'
        supervisor is in ERROR) RESET turns it on, as after any ABORT."""
        self.enabled = bool(enabled)
        if not enabled and self.amp_enabled:
            self.disable(t, clock)
        elif enabled and servo and not self.amp_enabled:
            self.enable(t, command_equals_actual=True)

    def follow_actual(self, t: float, clock: ProfileClock | None) -> None:
        self.rebase(t, clock)
        self.plan = None
        self.holding = False
        self.mode = CommandMode.FOLLOW_ACTUAL

    @property
    def amp_enabled(self) -> bool:
        return self.mode is not CommandMode.COAST
