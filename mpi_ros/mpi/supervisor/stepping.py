"""What happens to a motion supervisor while the controller steps: moves done, stops
complete, errors entered, holds released, each at the exact sample its condition holds.

The controller asks :meth:`Transitions.scan` for the samples of a stretch at which a
transition happens, stops there, and calls :meth:`Transitions.transition`.
"""

from __future__ import annotations

from collections.abc import Callable
from enum import IntEnum
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from mpi_ros.mpi.axes.axis import Axis, CommandMode
from mpi_ros.mpi.axes.status import AT_VELOCITY, DONE, StatusMode
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import Message
from mpi_ros.mpi.base.types import ActionSource, HoldType, MPIState
from mpi_ros.mpi.planning.frames import reached
from mpi_ros.mpi.supervisor.holds import HoldWait

if TYPE_CHECKING:
    from mpi_ros.mpi.axes.status import StretchStatus
    from mpi_ros.mpi.axes.stretch import Stretch
    from mpi_ros.mpi.host import SupervisorHost
    from mpi_ros.mpi.planning.frames import Move, Stream
    from mpi_ros.mpi.supervisor.actions import Actions
    from mpi_ros.mpi.supervisor.moves import Moves
    from mpi_ros.mpi.supervisor.state import SupervisorState

OK = Message.MPIMessageOK


class Condition(IntEnum):
    """What a stretch may bring about for a supervisor. At one sample, :meth:`Transitions.transition`
    applies them in this order (a HOLD or an OUTPUT per axis, in axis order)."""

    HOLD = 0  # a held move's trigger (or timeout): released
    OUTPUT = 1  # a path point's output is due
    CHUNK = 2  # the points of the oldest streamed request are done
    FRAMES_LOW = 3
    FRAMES_EMPTY = 4
    STARVING = 5  # fewer than emptyCount points left: E_STOP, before the underflow fault of that sample
    UNDERFLOW = 6
    MOVE_DONE = 7
    AT_VELOCITY = 8
    STOPPED = 9  # a STOP complete
    ERROR = 10  # an E_STOP or ABORT complete


Key = tuple[Condition, int]  # a condition and its axis (-1: the supervisor's)
_BUFFER_EVENTS = (Condition.FRAMES_LOW, Condition.FRAMES_EMPTY, Condition.STARVING)


class Transitions:
    """The transitions of one motion supervisor while the controller steps: on its ``state``
    and ``moves``; ``actions`` for the E_STOP a starving path gets."""

    def __init__(self, host: SupervisorHost, state: SupervisorState, moves: Moves, actions: Actions):
        self._host = host
        self._state = state
        self._moves = moves
        self._actions = actions
        # what :meth:`scan` found for :meth:`transition`, per sample of the stretch
        self._conditions: dict[Key, np.ndarray] = {}

    def scan(self, stretch: Stretch, status: StretchStatus) -> int | None:
        """The first sample of a stretch (stretch.Stretch, status.StretchStatus) at which a
        transition of this supervisor happens, or None.

        The conditions are kept until :meth:`transition` applies them.
        """
        conditions: dict[Key, np.ndarray] = {}
        self._conditions = conditions
        state = self._state.own_state
        if self._moves.holds and state in (MPIState.MOVING, MPIState.STOPPED):
            for axis_number, wait in self._moves.holds.items():
                conditions[Condition.HOLD, axis_number] = self._hold_trigger(wait, stretch)
        if state is MPIState.MOVING and self._moves.current is not None and not self._moves.holds:
            self._scan_move(self._moves.current, stretch, status, conditions)
        if state is MPIState.STOPPING:
            conditions[Condition.STOPPED, -1] = self._stop_complete(stretch.t, status,
                                                                     lambda a: a.in_position.settle_on_stop)
        elif state is MPIState.STOPPING_ERROR:
            if self._state.error_at is not None:
                conditions[Condition.ERROR, -1] = stretch.samples >= self._state.error_at
            else:
                conditions[Condition.ERROR, -1] = self._stop_complete(stretch.t, status,
                                                                      lambda a: a.in_position.settle_on_estop)
        if not conditions:  # (a move under way that nothing can end in this stretch)
            return None
        firsts = [int(np.argmax(fired)) for fired in conditions.values() if fired.any()]
        return min(firsts) if firsts else None

    def _scan_move(self, move: Move, stretch: Stretch, status: StretchStatus,
                   conditions: dict[Key, np.ndarray]) -> None:
        """A move done; a velocity move at its velocity; a path's outputs and buffer (``move``:
        the current one)."""
        if move.stream is not None:
            self._scan_path(move, move.stream, stretch, conditions)
            if move.stream.open:
                return  # an open path is never done: more points are expected
        # A move that ends moving (FINAL_VEL) is never DONE: the next appended move takes
        # over at its trajectory's end; with none, the axes go on at the final velocity
        # (MOVING) until a modify, an append or a stop.
        if move.ends_moving:
            if self._moves.queue:
                conditions[Condition.MOVE_DONE, -1] = np.logical_and.reduce(
                    [stretch.rel[plan.axis] >= plan.duration for plan in move.plans])
        elif self._moves.queue and self._moves.queue[0].blend > 0.0:
            # blendLimit (planning/blend.py): the next move starts while this one decelerates
            overlap = self._moves.queue[0].blend
            conditions[Condition.MOVE_DONE, -1] = np.logical_and.reduce(
                [stretch.rel[plan.axis] >= plan.duration - overlap for plan in move.plans])
        else:
            self._all_axes(move, conditions, Condition.MOVE_DONE, status, DONE)
        if move.is_velocity and not self._moves.at_velocity_sent:
            # MPIEventTypeMOTION_AT_VELOCITY: every axis of the move at the commanded velocity.
            self._all_axes(move, conditions, Condition.AT_VELOCITY, status, AT_VELOCITY)

    def _scan_path(self, move: Move, stream: Stream, stretch: Stretch, conditions: dict[Key, np.ndarray]) -> None:
        """Outputs due at a later point; while the path is open, the points left in the
        buffer: FRAMES_LOW below lowCount, FRAMES_EMPTY at none, and the E_STOP of MPI 000,
        MPIMotionPoint, emptyCount ("If the number of points in the buffer is below
        emptyCount, an E_STOP action will occur"; <= 0 disables, MotionParams.empty_count_disabled).
        ``move``: the current one, a path; ``stream``: its streaming state."""
        left: np.ndarray | None = None
        for plan in move.plans:
            axis = self._moves.axis(plan.axis)
            if axis.plan is not plan:
                continue
            rel = np.nan_to_num(stretch.rel[plan.axis], nan=-np.inf)
            if plan.timed_outputs:
                conditions[Condition.OUTPUT, plan.axis] = reached(rel) >= min(when for when, _ in plan.timed_outputs)
            counts = np.asarray(plan.points_left(rel))  # (rel is an array: so is the count)
            left = counts if left is None else np.minimum(left, counts)
            if stream.chunks and plan.axis in stream.chunks[0][1]:
                done = reached(rel) >= stream.chunks[0][1][plan.axis]
                conditions[Condition.CHUNK, -1] = done & conditions.get((Condition.CHUNK, -1), True)
        if left is None or not stream.open:
            return
        if not stream.low_sent:
            conditions[Condition.FRAMES_LOW, -1] = left < stream.low_count
        if not stream.empty_sent:
            conditions[Condition.FRAMES_EMPTY, -1] = left == 0
        if stream.empty_count > 0:
            conditions[Condition.STARVING, -1] = left < stream.empty_count
        if self._state.own_state is MPIState.MOVING and self._host.faults.watches_underflow(move.plan_axes):
            conditions[Condition.UNDERFLOW, -1] = left == 0

    def _all_axes(self, move: Move, conditions: dict[Key, np.ndarray], condition: Condition, status: StretchStatus,
                  bit: int) -> None:
        """``conditions[condition]``: per sample, is ``bit`` set on every axis of ``move`` (the current
        one)? (left out where it never is: an axis without it anywhere in the stretch)"""
        ever = status.ever(bit)
        axes = move.plan_axes
        for number in axes:
            if not ever[number]:
                return
        conditions[condition, -1] = np.logical_and.reduce(status.bits[bit, list(axes)], axis=0)

    def _stop_complete(self, t: np.ndarray, status: StretchStatus, settle: Callable[[Axis], bool]) -> np.ndarray:
        ready = t >= self._state.stop_end - 1e-12
        for axis in self._moves.axes:
            if settle(axis):
                ready = ready & status.bits[DONE, axis.number]
        return ready

    def _hold_trigger(self, wait: HoldWait, stretch: Stretch) -> np.ndarray:
        fired: npt.NDArray[np.bool_]
        if wait.watches_position:
            number = wait.hold.number
            raw = stretch.act_p[number] if wait.hold.type is HoldType.AXIS_POSITION_ACTUAL else stretch.cmd_p[number]
            fired = wait.position_trigger(raw - self._moves.axis(number).origin)
        else:
            fired = np.full(len(stretch), wait.static_trigger(self._host.io))
        return fired | wait.timed_out(stretch.samples)

    def transition(self, index: int, samples: np.ndarray) -> None:
        """Apply what :meth:`scan` found at stretch sample ``index`` (the controller is there)."""
        conditions, self._conditions = self._conditions, {}
        for condition, axis in sorted(key for key, fired in conditions.items() if fired[index]):
            if condition is Condition.HOLD:
                wait = self._moves.holds.get(axis)
                if wait is not None:
                    timed_out = bool(wait.timed_out(samples[index:index + 1])[0])
                    self._moves.release(axis, wait, timed_out=timed_out)
            elif condition is Condition.OUTPUT:
                self._due_outputs(axis)
            elif condition in _BUFFER_EVENTS:
                self._buffer_event(condition)
            elif condition is Condition.UNDERFLOW:
                self._underflow()
            elif condition is Condition.CHUNK:
                self._chunk_done()
            elif condition is Condition.MOVE_DONE:
                self._move_done()
            elif condition is Condition.AT_VELOCITY:
                self._moves.at_velocity_reached()
            elif condition is Condition.STOPPED:
                self._state.enter(MPIState.STOPPED, self._state.last_action, self._state.action_source)
            elif condition is Condition.ERROR:
                self._stop_on_error_complete()

    def _due_outputs(self, axis_number: int) -> None:
        """Apply the outputs whose point the path has reached (the controller is there)."""
        axis = self._moves.axis(axis_number)
        plan = axis.plan
        if plan is None or self._moves.current is None or plan not in self._moves.current.plans:
            return
        now = reached(axis.rel)
        due = [out for when, out in plan.timed_outputs if when <= now]
        plan.timed_outputs = [(when, out) for when, out in plan.timed_outputs if when > now]
        for out in due:
            self._moves.fire_output(out)

    def _chunk_done(self) -> None:
        """The last point of the oldest pending append is reached: that append is done."""
        move = self._moves.current
        assert move is not None and move.stream is not None  # scan found it on the current path
        chunks = move.stream.chunks
        if chunks:
            serial, _ = chunks.pop(0)
            self._moves.end_serial(serial, OK, "points executed")

    def _buffer_event(self, condition: Condition) -> None:
        move = self._moves.current
        assert move is not None and move.stream is not None  # scan found it on the current path
        stream = move.stream
        if condition is Condition.FRAMES_LOW and not stream.low_sent:
            stream.low_sent = True
            self._moves.emit(MPIEventType.FRAMES_LOW, detail=f"fewer than {stream.low_count} points left: append more")
        elif condition is Condition.FRAMES_EMPTY and not stream.empty_sent:
            stream.empty_sent = True
            self._moves.emit(MPIEventType.FRAMES_EMPTY, detail="no points left; the path rests on its last point")
        elif condition is Condition.STARVING and self._state.own_state is MPIState.MOVING:
            self._actions.e_stop(ActionSource.CONTROLLER, reason=f"fewer than emptyCount = {stream.empty_count} "
                                                                 "points left while more are expected (final false)")

    def _underflow(self) -> None:
        """The frame buffer of the open path ran empty while moving (faults.py): the fault of
        each of its axes, unless an E_STOP (emptyCount) at this sample got there first."""
        move = self._moves.current
        if self._state.own_state is MPIState.MOVING and move is not None:
            self._host.faults.underflow(move.plan_axes)

    def _stop_on_error_complete(self) -> None:
        """E_STOP (or ABORT) has run its course: disable what must be, enter ERROR."""
        t = self._host.time
        if self._state.error_at is None:
            if self._state.abort_after_stop:
                self._actions.generated_abort(t)
            for axis in self._moves.axes:
                if axis.mode is CommandMode.FOLLOW_ACTUAL:
                    # settleOnEstopCmdEqAct: "After the Estop time elapses, the axis'
                    # motors will disable the amplifiers."
                    axis.disable(t, None)
                    axis.status_mode = StatusMode.ABORT
        self._state.error_at = None
        self._moves.rebase(t)
        state = self._state
        self._moves.drop_pending(Message.MPIMotionMessageERROR, f"{state.last_action} by {state.action_source.value}")
        for axis in self._moves.axes:
            if axis.owner == self._state.number and axis.plan is not None:
                axis.unload(t, self._state.clock)
        self._state.enter(MPIState.ERROR, self._state.last_action, self._state.action_source)

    def _move_done(self) -> None:
        move = self._moves.current
        assert move is not None  # scan found the current move done
        self._moves.emit(MPIEventType.MOTION_DONE, move=move)
        self._moves.end_move(move, OK, "motion done")
        t = self._host.time
        for plan in move.plans:
            axis = self._moves.axis(plan.axis)
            if plan.cam is not None and axis.plan is plan:
                axis.unload(t, self._state.clock)  # at the table's end the slave rests: it follows no longer
        if not self._moves.next_move():
            self._state.enter(MPIState.IDLE, self._state.last_action, self._state.action_source)
