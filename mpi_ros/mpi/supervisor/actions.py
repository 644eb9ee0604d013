"""mpiMotionAction: STOP, RESUME, E_STOP, ABORT, E_STOP_ABORT, RESET and MEIActionMAP.

Each action answers per docs/state-machine.md; safety actions are never refused. Stops ramp
the supervisor's feedrate (clock.py); ABORT turns the amplifiers off. An action on axes
another supervisor's motion holds goes to that supervisor too, through the controller
(SupervisorHost.act_on).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from mpi_ros.mpi.axes.axis import Axis, CommandMode
from mpi_ros.mpi.axes.status import StatusMode
from mpi_ros.mpi.base.events import MPIEventType
from mpi_ros.mpi.base.messages import STATE_MESSAGES, Message
from mpi_ros.mpi.base.outcome import Outcome
from mpi_ros.mpi.base.types import ActionSource, MPIAction, MPIState
from mpi_ros.mpi.host import SupervisorHost
from mpi_ros.mpi.supervisor.axis_list import AxisList
from mpi_ros.mpi.supervisor.moves import Moves
from mpi_ros.mpi.supervisor.state import SupervisorState

OK = Message.MPIMessageOK
DONE = Outcome(OK)
# Actions that act on another supervisor's motion on shared axes (all but MAP).
_SHARED = (MPIAction.STOP, MPIAction.RESUME, MPIAction.E_STOP, MPIAction.ABORT, MPIAction.E_STOP_ABORT,
           MPIAction.RESET)
# The own states in which these act on this supervisor's own motion (None: always).
_OWN_STATES = {MPIAction.STOP: (MPIState.MOVING,), MPIAction.RESUME: (MPIState.STOPPED,),
               MPIAction.RESET: (MPIState.IDLE, MPIState.STOPPED, MPIState.ERROR)}


class Actions:
    """The actions of one motion supervisor, on its ``state``, ``moves`` and ``axis_list``."""

    def __init__(self, host: SupervisorHost, state: SupervisorState, moves: Moves, axis_list: AxisList):
        self._host = host
        self._state = state
        self._moves = moves
        self._axis_list = axis_list
        self._handlers: dict[MPIAction, Callable[[ActionSource], Outcome]] = {
            MPIAction.STOP: self._stop,
            MPIAction.RESUME: self._resume,
            MPIAction.E_STOP: self.e_stop,
            MPIAction.ABORT: self._abort,
            MPIAction.E_STOP_ABORT: self._e_stop_abort,
            MPIAction.RESET: self._reset,
            MPIAction.MAP: self._map_action,
        }

    def knows(self, action: MPIAction) -> bool:
        return action in self._handlers

    def act(self, action: MPIAction, source: ActionSource) -> Outcome:
        """mpiMotionAction (the handle checked, the action callback called)."""
        handler = self._handlers.get(action)
        if handler is None:
            return Outcome(Message.MPIMessagePARAM_INVALID, f"unknown action {action!r}")
        if not self._axis_list.listed and not self._axis_list.mapped:
            return Outcome(Message.MEIMotionMessageNO_AXES_MAPPED, "no axes mapped to the motion supervisor")
        if action in _SHARED:
            return self._on_shared_axes(action, handler, source)
        return handler(source)

    def _sharing(self) -> list[int]:
        """Other supervisors whose motion runs on one of this supervisor's mapped axes."""
        return list(dict.fromkeys(other for _, other, _ in self._moves.held_by_others(self._axis_list.mapped)))

    def _on_shared_axes(self, action: MPIAction, handler: Callable[[ActionSource], Outcome],
                        source: ActionSource) -> Outcome:
        """STOP, RESUME, E_STOP, ABORT, E_STOP_ABORT and RESET act on the whole motion that
        holds this supervisor's axes (docs/decisions.md, "Supervisors and axes"), with that
        motion's own decel times, so a vector another supervisor runs stays on its path: the
        action goes to that supervisor as well. The answer is OK if the action did something
        anywhere, else the message of the state that refused it."""
        others = self._sharing()
        if not others:
            return handler(source)
        forwarded = {other: self._host.act_on(other, action, source) for other in others}
        allowed = _OWN_STATES.get(action)
        if allowed is None or (self._state.own_state in allowed and self._state.own_state is not MPIState.IDLE):
            return handler(source)
        if any(outcome.ok for outcome in forwarded.values()):
            return Outcome(OK, "acted on the motion of the supervisor sharing its axes")
        # Refused everywhere: the shown state's message, with why each sharing supervisor refused
        # (a RESET refused by a persisting fault names the fault: docs/faults.md).
        refusal = self._refusal(self._moves.shown_state())
        why = "; ".join(f"supervisor {other}: {outcome.detail}" for other, outcome in forwarded.items()
                        if outcome.detail)
        return Outcome(refusal.message, f"{refusal.detail}; {why}" if why else refusal.detail)

    def _refuse(self, allowed: tuple[MPIState, ...], own: bool = False) -> Outcome | None:
        """None if the action may go on, else the message of the state that refuses it.
        ``own``: decide by this supervisor's own state (its own motion), not the state it
        shows (which includes the motions of supervisors sharing its axes)."""
        state = self._moves.shown_state()
        if (self._state.own_state if own else state) in allowed:
            return None
        return self._refusal(state)

    @staticmethod
    def _refusal(state: MPIState) -> Outcome:
        """The message of ``state``, which refuses an action."""
        return Outcome(STATE_MESSAGES[state.name], f"supervisor is {state.name}")

    def _stop(self, source: ActionSource) -> Outcome:
        refused = self._refuse(_OWN_STATES[MPIAction.STOP], own=True)
        if refused:
            return refused
        t, state = self._host.time, self._state
        self._moves.rebase(t)
        state.clock = state.clock.ramp_to(t, state.config.pause_feedrate, state.config.decel_time.stop)
        state.stop_end = t + state.config.decel_time.stop
        self._set_status_mode(StatusMode.STOP)
        self._state.enter(MPIState.STOPPING, "STOP", source)
        self._moves.emit(MPIEventType.STOP)
        return DONE

    def _resume(self, source: ActionSource) -> Outcome:
        refused = self._refuse(_OWN_STATES[MPIAction.RESUME], own=True)
        if refused:
            return refused
        t, state = self._host.time, self._state
        self._moves.rebase(t)
        state.clock = state.clock.ramp_to(t, state.config.normal_feedrate, state.config.decel_time.stop)
        state.stop_end = math.inf
        for axis in self._moves.axes:
            if axis.owner == self._state.number:
                plan = axis.plan
                velocity = plan is not None and plan.is_velocity
                axis.status_mode = StatusMode.VELOCITY if velocity else StatusMode.POINT_TO_POINT
        self._state.enter(MPIState.MOVING, "RESUME", source)
        self._moves.emit(MPIEventType.RESUME)
        return DONE

    def e_stop(self, source: ActionSource, then_abort: bool = False, reason: str = "") -> Outcome:
        self._map_if_unmapped()
        t = self._host.time
        if self._state.own_state is MPIState.ERROR:
            if then_abort and not self._state.aborted:
                self.generated_abort(t)
            return Outcome(OK, "already in ERROR")
        if self._state.own_state is MPIState.STOPPING_ERROR:
            self._state.abort_after_stop |= then_abort
            return Outcome(OK, "already stopping on error")
        self._moves.rebase(t)
        e_stop = self._state.config.decel_time.e_stop
        self._state.clock = self._state.clock.ramp_to(t, 0.0, e_stop)
        self._state.stop_end = t + e_stop
        self._state.abort_after_stop = then_abort
        self._claim_axes()
        for axis in self._own_axes():
            axis.status_mode = StatusMode.E_STOP
            if axis.in_position.settle_on_estop_cmd_eq_act and axis.amp_enabled:
                axis.follow_actual(t, self._state.clock)
        self._state.enter(MPIState.STOPPING_ERROR, "E_STOP_ABORT" if then_abort else "E_STOP", source)
        self._moves.emit(MPIEventType.E_STOP, detail=reason)
        return DONE

    def _e_stop_abort(self, source: ActionSource) -> Outcome:
        return self.e_stop(source, then_abort=True)

    def _abort(self, source: ActionSource) -> Outcome:
        self._map_if_unmapped()
        t = self._host.time
        self._claim_axes()
        self._moves.rebase(t)
        self.disable_amps(t)
        if self._state.own_state is not MPIState.ERROR:
            self._state.enter(MPIState.STOPPING_ERROR, "ABORT", source)
            self._state.error_at = self._host.sample + 1
        self._moves.emit(MPIEventType.ABORT)
        return DONE

    def generated_abort(self, t: float) -> None:
        """The ABORT that E_STOP_ABORT generates once its E_STOP is done (MPI 000,
        MPIActionE_STOP_ABORT: "Next, MotionAction will generate an MPIActionABORT"): the
        amplifiers go off and, as for any ABORT, an ABORT event says so."""
        self.disable_amps(t)
        self._moves.emit(MPIEventType.ABORT)

    def disable_amps(self, t: float) -> None:
        self._state.aborted = True
        for axis in self._own_axes():
            axis.disable(t, self._moves.clock_of(axis))
            axis.status_mode = StatusMode.ABORT

    def _claim_axes(self) -> None:
        """A safety action takes over the mapped axes that no motion runs (their last
        commander is IDLE or in ERROR, or none). An axis another supervisor's motion runs
        stays with it: the action went to that supervisor (:meth:`_on_shared_axes`)."""
        t = self._host.time
        for axis in self._moves.axes:
            if axis.owner != self._state.number and axis.plan is None and not axis.holding:
                other = self._host.own_state_of(axis.owner) if axis.owner >= 0 else None
                if other is None or other in (MPIState.IDLE, MPIState.ERROR):
                    axis.rebase(t, self._moves.clock_of(axis))
                    axis.owner = self._state.number

    def _own_axes(self) -> list[Axis]:
        """The mapped axes this supervisor commands (or that no one commands)."""
        return [axis for axis in self._moves.axes if axis.owner in (self._state.number, -1)]

    def _reset(self, source: ActionSource) -> Outcome:
        state = self._moves.shown_state()
        faults = self._host.faults
        if state is MPIState.IDLE and not faults.latched_on(self._axis_list.mapped):
            self._moves.remap()
            return Outcome(OK, "already IDLE")
        refused = self._refuse((MPIState.IDLE, MPIState.STOPPED, MPIState.ERROR))
        if refused:
            return refused
        creeping = self._moves.still_creeping([axis.number for axis in self._own_axes()])
        if not creeping.ok:
            return creeping
        persisting = faults.persisting(self._axis_list.mapped)
        if persisting:  # docs/faults.md: a fault is cleared by RESET once its condition is gone
            return Outcome(Message.MPIMotionMessageERROR, f"RESET refused: {'; '.join(persisting)}: clear it first")
        amp_faulted = faults.clear(self._axis_list.mapped)
        t = self._host.time
        self._moves.rebase(t)
        self._moves.drop_pending(STATE_MESSAGES[state.name], f"dropped by RESET in {state.name}")
        for axis in self._moves.axes:
            if axis.owner == self._state.number or axis.owner == -1:
                axis.unload(t, self._moves.clock_of(axis))
                if axis.enabled and (not axis.amp_enabled or axis.mode is CommandMode.FOLLOW_ACTUAL):
                    # (an axis the host disabled stays off: Controller.axis_amp_enable_set)
                    # after an ABORT or an amplifier fault the motor coasted: the command is set to the actual
                    axis.enable(t, command_equals_actual=self._state.aborted or axis.mode is CommandMode.FOLLOW_ACTUAL
                                or axis.number in amp_faulted)
                axis.status_mode = StatusMode.POINT_TO_POINT
                axis.target = axis.rest
        self._state.clock = self._state.clock.ramp_to(t, self._state.config.normal_feedrate, 0.0)
        self._state.stop_end = math.inf
        self._state.aborted = False
        self._state.error_at = None
        self._state.abort_after_stop = False
        self._moves.remap()
        self._state.enter(MPIState.IDLE, "RESET", source)
        self._moves.emit(MPIEventType.RESET)
        return DONE

    def _map_action(self, source: ActionSource) -> Outcome:
        refused = self._refuse((MPIState.IDLE, MPIState.STOPPED, MPIState.ERROR))
        if refused:
            return refused
        if not self._axis_list.listed:
            return Outcome(Message.MEIMotionMessageNO_AXES_MAPPED, "the axis list is empty")
        remapped = self._moves.remap()
        return remapped if not remapped.ok else DONE

    def _map_if_unmapped(self) -> None:
        if not self._axis_list.mapped:
            self._moves.remap()

    def _set_status_mode(self, mode: StatusMode) -> None:
        for axis in self._moves.axes:
            if axis.owner == self._state.number:
                axis.status_mode = mode

